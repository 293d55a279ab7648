//! Milling chatter stability for kerf's milling planner (seed 004,
//! `../shared/seeds/004_*.txt`).
//!
//! * [`model`] — tool-tip dynamics, milling process, the linear periodic DDE.
//! * [`error`] — [`ChatterError`].

pub mod error;
pub mod model;

// Constant-delay model, discretization, spectral radius, lobes.
pub mod directional;
pub mod fdm;
pub mod lobes;
pub mod spectral;

// State-dependent model (seed 004 section 2) and time-domain simulation.
pub mod equilibrium;
pub mod indicator;
pub mod linearize;
pub mod timedomain;
pub mod trochoid;

pub use error::ChatterError;
pub use model::{
    chip_direction, force_direction, DdeSample, DelayTerm, MillingProcess, Modal2, Mode,
    PeriodicDde,
};
pub use directional::{
    constant_delay_dde, constant_delay_dde_unit_depth, directional_averages,
    mean_directional_matrix, scale_dde,
};
pub use fdm::{CompiledDde, Discretization, DEFAULT_STEPS};
pub use lobes::{critical_depth, stability_lobes, LobeOptions, LobePoint};
pub use spectral::{
    eigenvalues_dense, spectral_radius_arnoldi, spectral_radius_dense, ArnoldiOptions,
};
pub use timedomain::{
    classify, simulate, Growth, PeriodSample, Simulation, SimulationSettings, StepSample, Verdict,
};
pub use equilibrium::{
    ChipState, Equilibrium, EquilibriumDiagnostics, EquilibriumSettings, ForceLaw,
};
pub use indicator::{
    chatter_indicator, indicator_dde, indicator_map, DelayModel, Indicator, IndicatorSettings,
};
pub use linearize::{chip_sensitivity, linearize, tooth_gain, ChipSensitivity, LinearizeSettings};
