//! Time-domain simulation of the full nonlinear milling model of seed 004
//! (eq. 1-4): state-dependent regenerative delays, multiple regeneration and
//! loss of contact, integrated by fixed-step RK4, and a classifier that says
//! whether a perturbation of the periodic forced response decays or grows.
//!
//! # The model (seed 004 eq. 1-4)
//!
//! `M ö + C ȯ + K o = F(t)` (seed 004 eq. 1) with `o = (x, y)` the tool-centre
//! vibration in the cutting frame of [`crate::model`] (feed f along −x). Tooth
//! j (j = 0..N_t−1) sits at `φ_j(t) = Ω t + 2π j / N_t`. While φ_j lies in
//! the engagement window `[φ_en, φ_ex]` (the workpiece wall), it cuts the
//! surface left by the earlier teeth:
//!
//! * for every regeneration order m = 1..M the delay τ_j^m (≈ m T) is the
//!   root of seed 004 eq. 3 ([`crate::trochoid::tangential_residual`]) with
//!   `Δc = (f τ + x(t − τ) − x(t), y(t − τ) − y(t))` read from the stored
//!   tool-centre history, and the chip against that tooth path is
//!   `h_j^m` of seed 004 eq. 4 ([`crate::trochoid::chip_thickness`]);
//! * the surface is the envelope of the earlier tooth paths, i.e. the
//!   material was removed by whichever earlier tooth went deepest, so the
//!   chip is `h_j = min_m h_j^m` (multiple regeneration, seed 004 Fig. 1b);
//! * the workpiece wall ([`SimulationSettings::workpiece_wall`], default):
//!   an edge of the window strictly inside (0, π) (the entry of down
//!   milling, the exit of up milling) is the free edge of the workpiece, a
//!   line `y = y_w` fixed in the workpiece, so the tooth enters (leaves)
//!   when its tip `y(t) − R cos φ` crosses `y_w`, a time that moves with the
//!   vibration: the RK4 step is split at that crossing, located by Newton
//!   on the integrated sub-step (edges at 0 or π, where the chip vanishes,
//!   and all edges without the wall, stay at fixed angles);
//! * loss of contact (seed 004 Fig. 1b): `h_j ≤ 0` gives no force;
//! * the force on the tool is `F_j = a_p h_j (K_t (cos φ, −sin φ) +
//!   K_n (sin φ, cos φ))` ([`crate::model::force_direction`]).
//!
//! `F = Σ_j F_j`. The delayed positions are cubic-Hermite interpolants of
//! the stored positions and velocities (a ring buffer of M + 2 periods),
//! evaluated at every RK4 stage. Each RK4 step is split where a tooth
//! crosses an edge of the window, so that the force is smooth on every
//! sub-step (a jump inside a step would cost RK4 an O(h) impulse error: 2 %
//! of the mean force at 200 steps per period for the cut of seed 004).
//!
//! # Start and measure
//!
//! The run starts on the T-periodic forced response `õ` (the "equilibrium"
//! of seed 004 section 2, Bachrathy 2011) plus a small displacement
//! perturbation. `õ` is computed here by a fixed-point iteration on the
//! simulator's own grid: given an iterate `õ_i`, the RK4 stage forces of
//! one simulator step from every grid state of `õ_i` (with `õ_i` as the
//! history), then the exact T-periodic solution of the discretized linear
//! structure driven by those forces (`z_0 = (I − Φ)⁻¹ z_T|_{z_0 = 0}`, `Φ`
//! the product of the RK4 transition matrices of the sub-steps over one
//! period). For a T-periodic `õ` the chip depends on `õ` only through
//! `õ(t − τ) − õ(t)` with `τ − m T` of order `f_z / (R Ω)`, so the map is a
//! strong contraction and converges in a few iterations; its fixed point is
//! a fixed point of the simulator's step map, so an unperturbed run stays
//! on it to round-off. It agrees with [`crate::equilibrium`] (computed
//! independently) to ~1e-7 of the forced amplitude (`tests/time_domain.rs`).
//!
//! Stability of `õ` is read from the deviation from T-periodicity
//! `d_k = max_{t ∈ period k} ‖z(t) − z(t − T)‖`, `z = (o, ȯ / ω_ref)`,
//! `ω_ref = √(tr K / tr M)`: for a periodic orbit it is zero, a perturbation
//! makes it evolve like `|μ|max^k` (Floquet theory; `μ` the characteristic
//! multipliers of the linearization, seed 004 eq. 8) until nonlinearity
//! (loss of contact) saturates it.

use nalgebra::Vector2;

use crate::error::{check_non_negative, check_positive, ChatterError};
use crate::model::{MillingProcess, Modal2};

mod classify;
mod cutter;
mod history;
mod integrate;
mod orbit;

pub use classify::classify;

use classify::fraction;
use cutter::Cutter;
use history::{History, RingHistory};
use integrate::{rk4_step, Structure};
use orbit::periodic_response;

/// Iteration cap of the delay root solve (seed 004 eq. 3).
const DELAY_MAX_ITERATIONS: usize = 60;
/// Growth over the initial deviation beyond which the run is taken as
/// saturated (nonlinear): the fit of the per-period factor stops there, and a
/// run that ends above it is unstable.
const SATURATION_RATIO: f64 = 10.0;
/// Decay below the initial deviation beyond which numerical noise (the
/// periodic orbit is known to about `orbit_tolerance`) may dominate.
const FLOOR_RATIO: f64 = 1e-5;
/// Band around 1 inside which a per-period factor is not called decay or
/// growth.
const FACTOR_TOLERANCE: f64 = 2e-3;

/// Settings of [`simulate`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimulationSettings {
    /// RK4 steps per tooth period T (≥ 200, i.e. step ≤ T / 200).
    pub steps_per_period: usize,
    /// Number of tooth periods simulated after the start (≥ 8).
    pub periods: usize,
    /// Highest regeneration order M (≥ 1): the chip is the minimum over the
    /// paths of the M previous teeth. Default 3.
    pub max_regeneration: usize,
    /// Initial displacement perturbation added to the periodic forced
    /// response \[m\] (non-zero).
    pub perturbation: Vector2<f64>,
    /// Record every RK4 step in [`Simulation::steps`] (memory: one
    /// [`StepSample`] per step).
    pub record_steps: bool,
    /// Convergence tolerance of the periodic forced response \[m\] (max
    /// change of the position over one period between iterates).
    pub orbit_tolerance: f64,
    /// Iteration cap of the periodic forced response.
    pub orbit_max_iterations: usize,
    /// Model the workpiece wall (default true): where the engagement edge
    /// lies strictly inside (0, π) (the entry of down milling, the exit of
    /// up milling) the tooth enters or leaves where its tip crosses the
    /// free edge of the workpiece, a line `y = y_w` fixed in the workpiece
    /// (placed through the periodic response's tip at φ_en / φ_ex), so the
    /// crossing moves with the vibration. False: the window is fixed in tool
    /// angle, as in the constant-delay model.
    pub workpiece_wall: bool,
}

impl Default for SimulationSettings {
    fn default() -> Self {
        Self {
            steps_per_period: 200,
            periods: 60,
            max_regeneration: 3,
            perturbation: Vector2::new(1e-6, 1e-6),
            record_steps: false,
            orbit_tolerance: 1e-13,
            orbit_max_iterations: 50,
            workpiece_wall: true,
        }
    }
}

/// The state at one instant, with the cutting force acting on it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepSample {
    /// Time t \[s\] in the angle convention of [`crate::model`]
    /// (φ_j = Ω t + 2π j / N_t). The step grid starts at t = 0, or, with a
    /// workpiece wall, up to one step later (it is offset so that the
    /// nominal wall crossings fall mid-step).
    pub time: f64,
    /// Tool-centre displacement o(t) \[m\].
    pub position: Vector2<f64>,
    /// Tool-centre velocity ȯ(t) \[m/s\].
    pub velocity: Vector2<f64>,
    /// Cutting force on the tool F(t) \[N\].
    pub force: Vector2<f64>,
    /// Largest chip thickness of the teeth inside the engagement window
    /// \[m\] (0 when none is inside or none is in contact).
    pub chip: f64,
    /// Regeneration order m of that chip: the earlier tooth whose path is
    /// the surface being cut (1 = the previous tooth; ≥ 2 = multiple
    /// regeneration, the teeth in between left the cut); 0 without a chip.
    pub order: usize,
}

/// The state at the start of one tooth period (Poincaré section) and what
/// happened during that period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeriodSample {
    /// Time k T (plus the grid offset of [`StepSample::time`]) \[s\].
    pub time: f64,
    /// Tool-centre displacement at k T \[m\].
    pub position: Vector2<f64>,
    /// Tool-centre velocity at k T \[m/s\].
    pub velocity: Vector2<f64>,
    /// Deviation from T-periodicity over this period,
    /// `d_k = max_t ‖z(t) − z(t − T)‖` with `z = (o, ȯ / ω_ref)` \[m\].
    pub deviation: f64,
    /// Fraction of the (step, tooth) pairs inside the engagement window that
    /// had a positive chip (1 = the tool never left the cut).
    pub contact_fraction: f64,
}

/// Result of [`simulate`].
#[derive(Debug, Clone, PartialEq)]
pub struct Simulation {
    /// Tooth period T \[s\].
    pub period: f64,
    /// Feed per tooth f_z = f T \[m\].
    pub feed_per_tooth: f64,
    /// Regeneration order M used.
    pub max_regeneration: usize,
    /// Velocity scale ω_ref = √(tr K / tr M) \[rad/s\] of the deviation norm.
    pub velocity_scale: f64,
    /// The periodic forced response over one period (one sample per step,
    /// starting at t = 0).
    pub orbit: Vec<StepSample>,
    /// Fixed-point iterations the periodic forced response took.
    pub orbit_iterations: usize,
    /// Contact fraction of the periodic forced response.
    pub orbit_contact_fraction: f64,
    /// Scaled norm of the initial perturbation (the deviation at t = 0) \[m\].
    pub initial_deviation: f64,
    /// One sample per simulated period.
    pub periods: Vec<PeriodSample>,
    /// One sample per RK4 step if [`SimulationSettings::record_steps`].
    pub steps: Vec<StepSample>,
}

/// Stable or not.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// The deviation from periodicity decays: the periodic forced response
    /// is asymptotically stable (no chatter).
    Stable,
    /// The deviation grows, or has grown into saturation by loss of contact
    /// (chatter).
    Unstable,
    /// Neither could be told apart within the run (too close to the
    /// boundary, or too short a run).
    Indeterminate,
}

/// What [`classify`] measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Growth {
    /// Per-period factor of the deviation, from a log-linear least-squares
    /// fit of `ln d_k` over `fit_range` (compare with |μ|max).
    pub factor: f64,
    /// Periods `[first, last)` of the fit: after the start transient, before
    /// saturation or the noise floor.
    pub fit_range: (usize, usize),
    /// `max_k d_k / d_0` (d_0 the initial deviation).
    pub amplification: f64,
    /// Mean deviation over the last fifth of the run divided by d_0 (the
    /// amplitude of the non-periodic part at the end).
    pub final_ratio: f64,
    /// Mean contact fraction over the last fifth of the run.
    pub late_contact_fraction: f64,
    /// Contact fraction of the periodic forced response.
    pub orbit_contact_fraction: f64,
    /// The verdict.
    pub verdict: Verdict,
}

/// Simulates the nonlinear milling model of seed 004 eq. 1-4 (module
/// documentation) from its periodic forced response plus
/// `settings.perturbation`.
///
/// # Arguments
/// * `modal` — tool-tip dynamics M, C, K
/// * `process` — cutter, force law, engagement window, axial depth
/// * `rpm` — spindle speed \[rev/min\]
/// * `feed` — feed rate f \[m/s\] (the tool moves along −x)
/// * `settings` — step, length, regeneration order, start
///
/// # Returns
/// The periodic forced response, one [`PeriodSample`] per period and, if
/// asked, every step.
///
/// # Errors
/// * [`ChatterError::InvalidParameter`] for invalid inputs or settings;
/// * [`ChatterError::NotConverged`] if the delay equation (seed 004 eq. 3)
///   has no root in its bracket (vibration comparable to the tool radius) or
///   its solve or the periodic forced response hits its iteration cap;
/// * [`ChatterError::Unsupported`] for an undamped structure (no periodic
///   forced response);
/// * [`ChatterError::NonFinite`] if the state blows up.
///
/// # Performance
/// O(periods × steps_per_period × N_t × M) delay solves of a few Newton
/// iterations each.
pub fn simulate(
    modal: &Modal2,
    process: &MillingProcess,
    rpm: f64,
    feed: f64,
    settings: &SimulationSettings,
) -> Result<Simulation, ChatterError> {
    modal.validate()?;
    process.validate()?;
    let period = process.tooth_period(rpm)?;
    let feed = check_non_negative("feed rate [m/s]", feed)?;
    check_settings(settings)?;

    let structure = Structure::new(modal)?;
    let mut cutter = Cutter::new(process, rpm, feed, period, settings.max_regeneration);
    let n = settings.steps_per_period;
    let h = period / n as f64;
    let pi = std::f64::consts::PI;
    let has_entry_wall = settings.workpiece_wall && process.entry_angle > 1e-9;
    let has_exit_wall = settings.workpiece_wall && process.exit_angle < pi - 1e-9;
    let wall_angle = if has_entry_wall {
        Some(process.entry_angle)
    } else if has_exit_wall {
        Some(process.exit_angle)
    } else {
        None
    };
    if let Some(angle) = wall_angle {
        let step_angle = cutter.omega * h;
        cutter.phase = (angle - 0.5 * step_angle).rem_euclid(step_angle);
    }
    // True time of internal time t: t + shift.
    let shift = cutter.phase / cutter.omega;

    let orbit = periodic_response(&structure, &cutter, h, n, settings)?;
    // The wall lines through the tooth tip of the periodic response at the
    // nominal entry / exit (edges strictly inside (0, π), where the chip
    // does not vanish).
    let level = |angle: f64| -> Result<f64, ChatterError> {
        let (p, _) = orbit.history.at((angle - cutter.phase) / cutter.omega)?;
        Ok(p.y - cutter.radius * angle.cos())
    };
    if has_entry_wall {
        cutter.entry_wall = Some(level(process.entry_angle)?);
    }
    if has_exit_wall {
        cutter.exit_wall = Some(level(process.exit_angle)?);
    }

    // Ring buffer of M + 2 periods, prefilled with the periodic extension of
    // the orbit (the surface the earlier teeth left before t = 0).
    let len = (settings.max_regeneration + 2) * n + 4;
    let mut ring = RingHistory {
        step: h,
        newest: 0,
        buf: vec![(Vector2::zeros(), Vector2::zeros()); len],
    };
    for back in 0..len {
        let k = -(back as i64);
        let i = (k.rem_euclid(n as i64)) as usize;
        let s = orbit.history.pos.get(i).zip(orbit.history.vel.get(i));
        let (p, v) = s.ok_or_else(internal)?;
        ring.set(k, *p, *v)?;
    }
    let z0_orbit = ring.get(0)?;
    let start_pos = z0_orbit.0 + settings.perturbation;
    ring.set(0, start_pos, z0_orbit.1)?;

    let scale = structure.velocity_scale;
    let initial_deviation = scaled_norm(settings.perturbation, Vector2::zeros(), scale);
    check_positive("perturbation norm [m]", initial_deviation)?;

    let total = settings.periods * n;
    let mut warm = cutter.nominal_delays();
    let mut periods = Vec::with_capacity(settings.periods);
    let mut steps = Vec::with_capacity(if settings.record_steps { total } else { 0 });
    let mut pos = start_pos;
    let mut vel = z0_orbit.1;
    let mut dev_max: f64 = 0.0;
    let (mut engaged, mut contact) = (0usize, 0usize);
    let mut period_start = (0.0, pos, vel);
    let mut edges = Vec::with_capacity(2 * process.teeth + 2);
    let mut mids = Vec::with_capacity(2 * process.teeth + 1);
    for step in 0..total {
        let t = step as f64 * h;
        if step % n == 0 {
            period_start = (t + shift, pos, vel);
        }
        cutter.substeps(t, h, &mut edges);
        // Membership of the teeth is fixed per sub-step at its nominal
        // midpoint, before wall edges are moved to the actual crossing.
        mids.clear();
        mids.extend(edges.windows(2).map(|w| 0.5 * (w[0].time + w[1].time)));
        let first_mid = mids.first().copied().ok_or_else(internal)?;
        let cut = cutter.force(t, first_mid, pos, &ring, &mut warm)?;
        engaged += cut.engaged;
        contact += cut.contact;
        if settings.record_steps {
            steps.push(StepSample {
                time: t + shift,
                position: pos,
                velocity: vel,
                force: cut.force,
                chip: cut.chip,
                order: cut.order,
            });
        }
        let (mut p1, mut v1) = (pos, vel);
        let mut ta = t;
        for (i, &mid) in mids.iter().enumerate() {
            let f0 = if i == 0 {
                cut.force
            } else {
                cutter.force(ta, mid, p1, &ring, &mut warm)?.force
            };
            let mut sub = |tb: f64| {
                rk4_step(&structure, ta, tb - ta, p1, v1, f0, |tt, o| {
                    cutter.force(tt, mid, o, &ring, &mut warm).map(|c| c.force)
                })
            };
            let end = edges.get(i + 1).copied().ok_or_else(internal)?;
            let tb = match (end.wall, edges.get(i + 2)) {
                (Some((tooth, wall)), Some(after)) => {
                    cutter.wall_crossing(tooth, wall, ta, end.time, after.time, h, &mut sub)?
                }
                _ => end.time,
            };
            (p1, v1) = sub(tb)?;
            ta = tb;
        }
        if !(p1.iter().chain(v1.iter()).all(|v| v.is_finite())) {
            return Err(ChatterError::NonFinite {
                what: format!("time-domain state at t = {:e} s", t + h),
            });
        }
        pos = p1;
        vel = v1;
        let k = step as i64 + 1;
        ring.set(k, pos, vel)?;
        let (pb, vb) = ring.get(k - n as i64)?;
        dev_max = dev_max.max(scaled_norm(pos - pb, vel - vb, scale));
        if (step + 1) % n == 0 {
            let (time, position, velocity) = period_start;
            periods.push(PeriodSample {
                time,
                position,
                velocity,
                deviation: dev_max,
                contact_fraction: fraction(contact, engaged),
            });
            dev_max = 0.0;
            engaged = 0;
            contact = 0;
        }
    }

    Ok(Simulation {
        period,
        feed_per_tooth: feed * period,
        max_regeneration: settings.max_regeneration,
        velocity_scale: scale,
        orbit: orbit
            .samples
            .into_iter()
            .map(|s| StepSample {
                time: s.time + shift,
                ..s
            })
            .collect(),
        orbit_iterations: orbit.iterations,
        orbit_contact_fraction: orbit.contact_fraction,
        initial_deviation,
        periods,
        steps,
    })
}

fn scaled_norm(dp: Vector2<f64>, dv: Vector2<f64>, scale: f64) -> f64 {
    (dp.norm_squared() + dv.norm_squared() / (scale * scale)).sqrt()
}

fn internal() -> ChatterError {
    ChatterError::Unsupported {
        reason: "internal: history index out of range".to_string(),
    }
}

fn check_settings(s: &SimulationSettings) -> Result<(), ChatterError> {
    let bad = ChatterError::invalid;
    if s.steps_per_period < 200 {
        return Err(bad(
            "steps per period",
            s.steps_per_period as f64,
            "must be >= 200 (step <= T/200)",
        ));
    }
    if s.periods < 8 {
        return Err(bad("simulated periods", s.periods as f64, "must be >= 8"));
    }
    if s.max_regeneration == 0 {
        return Err(bad("regeneration order M", 0.0, "must be >= 1"));
    }
    if s.orbit_max_iterations == 0 {
        return Err(bad("orbit iteration cap", 0.0, "must be >= 1"));
    }
    check_positive("orbit tolerance [m]", s.orbit_tolerance)?;
    for v in s.perturbation.iter() {
        if !v.is_finite() {
            return Err(bad("perturbation [m]", *v, "must be finite"));
        }
    }
    Ok(())
}
