//! Milling chatter stability for kerf's milling planner (seed 004,
//! `../shared/seeds/004_*.txt`, issue 4 parts 4-5): the chatter indicator
//! |μ|max — the spectral radius of the monodromy matrix of the milling
//! delay-differential equation — for the constant-delay model and for the
//! state-dependent model of seed 004 section 2, stability lobes, and a
//! nonlinear time-domain simulation that cross-checks both.
//!
//! | module | what | source |
//! |---|---|---|
//! | [`model`] | frames and angles, 2-DOF tool-tip dynamics, process, the linear periodic DDE | seed 004 eq. 1, Fig. 2 |
//! | [`directional`] | constant-delay model: exact sub-interval averages of H(t) | Insperger & Stépán 2004 |
//! | [`fdm`] | full discretization, precomputed per spindle speed; fractional and multiple delays | Ding et al. 2010 |
//! | [`spectral`] | restarted Arnoldi (capped) with a dense Schur reference | Floquet theory |
//! | [`lobes`] | critical depth per speed: coarse scan + bisection | Insperger & Stépán 2004 §5 |
//! | [`lobe_map`] | one state's chart: both lobes and the feed × speed map over a speed grid | seed 004 Fig. 4, 7 |
//! | [`feed_bound`] | the lowest feed from which every higher feed is stable | seed 004 Fig. 4, 7 |
//! | [`modes`] | closed forms: stiffness eigenvalues, undamped natural frequencies | |
//! | [`trochoid`] | exact tooth-path geometry: delay and chip | seed 004 eq. 2-4 |
//! | [`equilibrium`] | periodic forced response with feed-dependent delays, loss of contact, multiple regeneration; optional power-law force | seed 004 eq. 1-7, Bachrathy et al. 2011 |
//! | [`linearize`] | the variational system about it, with the workpiece-wall term | seed 004 eq. 8 |
//! | [`indicator`] | the public entry point: \|μ\|max, the feed × speed map | seed 004 §2, Fig. 7 |
//! | [`timedomain`] | nonlinear RK4 simulation with the full chip geometry, growth classifier | seed 004 eq. 1-4 |
//!
//! Validation against things kerf did not write: `tests/textbook.rs` (the
//! 2-DOF example of Insperger & Stépán against the published
//! full-discretization code of Ding et al. 2010), `tests/time_domain.rs`
//! (simulation agrees with |μ| on both sides of the boundary),
//! `tests/feed_effect.rs` (the feed lower bound of seed 004 Fig. 4/7).
//!
//! # Example
//!
//! ```
//! use kerf_chatter::{
//!     chatter_indicator, stability_lobes, DelayModel, IndicatorSettings, LobeOptions,
//!     MillingProcess, Modal2, Mode,
//! };
//!
//! // The classic 2-DOF example (Insperger & Stépán): 922 Hz, ζ = 0.011,
//! // 0.03993 kg in x and y, 2 teeth, a/D = 0.05 down milling.
//! let mode = Mode { natural_frequency_hz: 922.0, damping_ratio: 0.011, modal_mass: 0.03993 };
//! let modal = Modal2::from_modes(mode, mode)?;
//! let (entry_angle, exit_angle) = MillingProcess::down_milling_angles(0.05)?;
//! let process = MillingProcess {
//!     teeth: 2, radius: 0.01, axial_depth: 1.0e-3, kt: 6e8, kn: 2e8, entry_angle, exit_angle,
//! };
//!
//! // The critical depth at 10 000 rpm is about 1.48 mm (Ding et al. 2010).
//! let lobes = stability_lobes(&modal, &process, &[10_000.0], &LobeOptions::default())?;
//! let a_lim = lobes[0].critical_depth.expect("unstable below 10 mm");
//! assert!((a_lim - 1.484e-3).abs() < 0.05e-3);
//!
//! // Below it the cut is stable (|μ|max < 1), above it it chatters.
//! let constant = IndicatorSettings::default().model(DelayModel::Constant);
//! for (depth, stable) in [(0.8 * a_lim, true), (1.2 * a_lim, false)] {
//!     let p = MillingProcess { axial_depth: depth, ..process };
//!     let mu = chatter_indicator(&modal, &p, 10_000.0, 0.0, &constant)?.spectral_radius;
//!     assert_eq!(mu < 1.0, stable);
//!     // The state-dependent model needs the feed (here 0.1 mm per tooth).
//!     let sd = IndicatorSettings::default();
//!     let mu_sd = chatter_indicator(&modal, &p, 10_000.0, 0.0333, &sd)?.spectral_radius;
//!     assert!((mu_sd - mu).abs() < 0.05);
//! }
//!
//! // Bad input is an error, never a NaN passed on as a number.
//! assert!(chatter_indicator(&modal, &process, f64::NAN, 0.0, &constant).is_err());
//! # Ok::<(), kerf_chatter::ChatterError>(())
//! ```

pub mod error;
pub mod model;

// Constant-delay model, discretization, spectral radius, lobes.
pub mod directional;
pub mod fdm;
pub mod lobes;
// The stability chart of one state (`kerf lobes`): lobes, feed map, feed bound, modes.
pub mod feed_bound;
pub mod lobe_map;
pub mod modes;
pub mod spectral;

// State-dependent model (seed 004 section 2) and time-domain simulation.
pub mod equilibrium;
pub mod indicator;
pub mod linearize;
pub mod timedomain;
pub mod trochoid;

pub use directional::{
    constant_delay_dde, constant_delay_dde_unit_depth, directional_averages,
    mean_directional_matrix, scale_dde,
};
pub use equilibrium::{
    ChipState, Equilibrium, EquilibriumDiagnostics, EquilibriumSettings, ForceLaw,
};
pub use error::ChatterError;
pub use fdm::{CompiledDde, Discretization, DEFAULT_STEPS};
pub use feed_bound::{feed_lower_bound, FeedBound};
pub use indicator::{
    chatter_indicator, indicator_dde, indicator_map, DelayModel, Indicator, IndicatorSettings,
};
pub use linearize::{chip_sensitivity, linearize, tooth_gain, ChipSensitivity, LinearizeSettings};
pub use lobe_map::{LobeGrid, LobeMap};
pub use lobes::{critical_depth, stability_lobes, LobeOptions, LobePoint};
pub use model::{
    chip_direction, force_direction, DdeSample, DelayTerm, MillingProcess, Modal2, Mode,
    PeriodicDde, MAX_TEETH,
};
pub use modes::{natural_frequencies, symmetric_eigenvalues};
pub use spectral::{
    eigenvalues_dense, spectral_radius_arnoldi, spectral_radius_dense, ArnoldiOptions,
};
pub use timedomain::{
    classify, simulate, Growth, PeriodSample, Simulation, SimulationSettings, StepSample, Verdict,
};
