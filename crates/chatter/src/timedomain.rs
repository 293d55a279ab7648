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

use nalgebra::{Matrix2, Matrix4, Vector2, Vector4};

use crate::error::{check_non_negative, check_positive, ChatterError};
use crate::model::{force_direction, MillingProcess, Modal2};
use crate::trochoid::{chip_thickness, tangential_residual};

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

/// Measures the growth of the deviation from periodicity of a
/// [`Simulation`] and calls it stable, unstable or indeterminate.
///
/// The per-period factor is the exponential of the slope of a least-squares
/// line through `ln d_k`, over the periods after the first tenth (start
/// transient of the non-dominant multipliers) up to the first period where
/// `d_k` leaves `[1e-5, 10] × d_0` (noise floor / saturation by loss of
/// contact). Verdict: unstable if the factor exceeds 1 + 2e-3 or the run
/// ends saturated (mean deviation of the last fifth > 10 d_0); stable if
/// the factor is below 1 − 2e-3 (the fit then runs to the end of the run
/// or to the noise floor, so the deviation decays up to the end);
/// otherwise indeterminate.
///
/// # Errors
/// [`ChatterError::InvalidParameter`] for a run shorter than 8 periods or a
/// zero initial deviation; [`ChatterError::NonFinite`] for a non-finite
/// deviation.
pub fn classify(sim: &Simulation) -> Result<Growth, ChatterError> {
    let count = sim.periods.len();
    if count < 8 {
        return Err(ChatterError::InvalidParameter {
            name: "simulated periods".to_string(),
            value: count as f64,
            reason: "classification needs >= 8".to_string(),
        });
    }
    let d0 = check_positive("initial deviation [m]", sim.initial_deviation)?;
    let d: Vec<f64> = sim.periods.iter().map(|p| p.deviation).collect();
    if d.iter().any(|v| !v.is_finite()) {
        return Err(ChatterError::NonFinite {
            what: "deviation from periodicity".to_string(),
        });
    }
    let inside = |v: f64| v <= SATURATION_RATIO * d0 && v >= FLOOR_RATIO * d0 && v > 0.0;
    let mut first = (count / 10).max(1);
    let mut last = (first..count).find(|&k| !inside(d[k])).unwrap_or(count);
    if last < first + 3 {
        // Fast growth or decay: fit from the first period on.
        first = 0;
        last = (0..count).find(|&k| !inside(d[k])).unwrap_or(count);
    }
    let factor = if last >= 2 {
        log_linear_factor(&d[first..last])
    } else {
        // Left the band within one or two periods: use the first period that
        // left it.
        let k = last.min(count - 1);
        let v = d.get(k).copied().unwrap_or(d0).max(f64::MIN_POSITIVE);
        (v / d0).powf(1.0 / (k as f64 + 1.0))
    };
    let tail = (count / 5).max(1);
    let late = &sim.periods[count - tail..];
    let final_ratio = late.iter().map(|p| p.deviation).sum::<f64>() / (tail as f64 * d0);
    let late_contact_fraction = late.iter().map(|p| p.contact_fraction).sum::<f64>() / tail as f64;
    let amplification = d.iter().fold(0.0_f64, |a, &v| a.max(v)) / d0;
    let verdict = if factor > 1.0 + FACTOR_TOLERANCE || final_ratio > SATURATION_RATIO {
        Verdict::Unstable
    } else if factor < 1.0 - FACTOR_TOLERANCE {
        Verdict::Stable
    } else {
        Verdict::Indeterminate
    };
    Ok(Growth {
        factor,
        fit_range: (first, last),
        amplification,
        final_ratio,
        late_contact_fraction,
        orbit_contact_fraction: sim.orbit_contact_fraction,
        verdict,
    })
}

/// exp(slope) of the least-squares line through (k, ln d_k).
fn log_linear_factor(d: &[f64]) -> f64 {
    let n = d.len() as f64;
    let (mut sx, mut sy, mut sxx, mut sxy) = (0.0, 0.0, 0.0, 0.0);
    for (k, v) in d.iter().enumerate() {
        let (x, y) = (k as f64, v.ln());
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
    }
    let den = n * sxx - sx * sx;
    if den <= 0.0 {
        return 1.0;
    }
    ((n * sxy - sx * sy) / den).exp()
}

fn fraction(num: usize, den: usize) -> f64 {
    if den == 0 {
        1.0
    } else {
        num as f64 / den as f64
    }
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

/// `M⁻¹`, `M⁻¹ C`, `M⁻¹ K` and the first-order matrix `A` of
/// `ż = A z + (0, M⁻¹ F)`, `z = (o, ȯ)`.
struct Structure {
    minv: Matrix2<f64>,
    minv_c: Matrix2<f64>,
    minv_k: Matrix2<f64>,
    a: Matrix4<f64>,
    velocity_scale: f64,
}

impl Structure {
    fn new(modal: &Modal2) -> Result<Self, ChatterError> {
        let minv = modal.mass_inverse()?;
        let minv_c = minv * modal.damping;
        let minv_k = minv * modal.stiffness;
        let mut a = Matrix4::zeros();
        a.fixed_view_mut::<2, 2>(0, 2)
            .copy_from(&Matrix2::identity());
        a.fixed_view_mut::<2, 2>(2, 0).copy_from(&(-minv_k));
        a.fixed_view_mut::<2, 2>(2, 2).copy_from(&(-minv_c));
        let velocity_scale = check_positive(
            "reference frequency sqrt(tr K / tr M) [rad/s]",
            (modal.stiffness.trace() / modal.mass.trace()).sqrt(),
        )?;
        Ok(Self {
            minv,
            minv_c,
            minv_k,
            a,
            velocity_scale,
        })
    }

    /// Acceleration `M⁻¹ (F − C ȯ − K o)`.
    fn accel(&self, o: Vector2<f64>, v: Vector2<f64>, f: Vector2<f64>) -> Vector2<f64> {
        self.minv * f - self.minv_c * v - self.minv_k * o
    }
}

/// One classic RK4 step of `ö = M⁻¹ (F(t, o) − C ȯ − K o)`; `f0` is the
/// force at the start of the step, `force` gives it at the later stages.
fn rk4_step<F>(
    s: &Structure,
    t: f64,
    h: f64,
    o: Vector2<f64>,
    v: Vector2<f64>,
    f0: Vector2<f64>,
    mut force: F,
) -> Result<(Vector2<f64>, Vector2<f64>), ChatterError>
where
    F: FnMut(f64, Vector2<f64>) -> Result<Vector2<f64>, ChatterError>,
{
    let k1o = v;
    let k1v = s.accel(o, v, f0);
    let o2 = o + 0.5 * h * k1o;
    let v2 = v + 0.5 * h * k1v;
    let k2o = v2;
    let k2v = s.accel(o2, v2, force(t + 0.5 * h, o2)?);
    let o3 = o + 0.5 * h * k2o;
    let v3 = v + 0.5 * h * k2v;
    let k3o = v3;
    let k3v = s.accel(o3, v3, force(t + 0.5 * h, o3)?);
    let o4 = o + h * k3o;
    let v4 = v + h * k3v;
    let k4o = v4;
    let k4v = s.accel(o4, v4, force(t + h, o4)?);
    Ok((
        o + h / 6.0 * (k1o + 2.0 * k2o + 2.0 * k3o + k4o),
        v + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v),
    ))
}

/// Stored tool-centre positions and velocities, read by cubic Hermite
/// interpolation.
trait History {
    /// Position and velocity at time `s` \[s\].
    fn at(&self, s: f64) -> Result<(Vector2<f64>, Vector2<f64>), ChatterError>;
}

/// Cubic Hermite interpolation on `[0, h]` between (p0, v0) and (p1, v1)
/// at `θ = (s − t0) / h`; returns the interpolant and its derivative.
fn hermite(
    p0: Vector2<f64>,
    v0: Vector2<f64>,
    p1: Vector2<f64>,
    v1: Vector2<f64>,
    h: f64,
    th: f64,
) -> (Vector2<f64>, Vector2<f64>) {
    let t2 = th * th;
    let t3 = t2 * th;
    let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
    let h10 = t3 - 2.0 * t2 + th;
    let h01 = -2.0 * t3 + 3.0 * t2;
    let h11 = t3 - t2;
    let p = h00 * p0 + (h10 * h) * v0 + h01 * p1 + (h11 * h) * v1;
    let d00 = 6.0 * t2 - 6.0 * th;
    let d10 = 3.0 * t2 - 4.0 * th + 1.0;
    let d11 = 3.0 * t2 - 2.0 * th;
    let dp = (d00 / h) * (p0 - p1) + d10 * v0 + d11 * v1;
    (p, dp)
}

/// The last few periods of the simulated trajectory, on the step grid
/// `t_k = k h` (k may be negative: the prefilled periodic history).
struct RingHistory {
    step: f64,
    newest: i64,
    buf: Vec<(Vector2<f64>, Vector2<f64>)>,
}

impl RingHistory {
    fn slot(&self, k: i64) -> Result<usize, ChatterError> {
        let len = self.buf.len() as i64;
        if k > self.newest || k <= self.newest - len {
            return Err(ChatterError::Unsupported {
                reason: format!(
                    "delayed time step {k} outside the stored history ({}..={})",
                    self.newest - len + 1,
                    self.newest
                ),
            });
        }
        Ok(k.rem_euclid(len) as usize)
    }

    fn get(&self, k: i64) -> Result<(Vector2<f64>, Vector2<f64>), ChatterError> {
        let i = self.slot(k)?;
        self.buf.get(i).copied().ok_or_else(internal)
    }

    /// Stores step `k`; `k` becomes the newest step if it is later.
    fn set(&mut self, k: i64, p: Vector2<f64>, v: Vector2<f64>) -> Result<(), ChatterError> {
        let len = self.buf.len() as i64;
        if k > self.newest {
            self.newest = k;
        }
        if k <= self.newest - len {
            return Err(internal());
        }
        let i = k.rem_euclid(len) as usize;
        let slot = self.buf.get_mut(i).ok_or_else(internal)?;
        *slot = (p, v);
        Ok(())
    }
}

impl History for RingHistory {
    fn at(&self, s: f64) -> Result<(Vector2<f64>, Vector2<f64>), ChatterError> {
        let (k, frac) = grid_cell(s, self.step)?;
        let (p0, v0) = self.get(k)?;
        let (p1, v1) = self.get(k + 1)?;
        Ok(hermite(p0, v0, p1, v1, self.step, frac))
    }
}

/// A T-periodic trajectory sampled at `t_k = k h`, k = 0..n−1.
struct PeriodicHistory {
    step: f64,
    pos: Vec<Vector2<f64>>,
    vel: Vec<Vector2<f64>>,
}

impl History for PeriodicHistory {
    fn at(&self, s: f64) -> Result<(Vector2<f64>, Vector2<f64>), ChatterError> {
        let (k0, frac) = grid_cell(s, self.step)?;
        let n = self.pos.len() as i64;
        let i0 = k0.rem_euclid(n) as usize;
        let i1 = (k0 + 1).rem_euclid(n) as usize;
        let get = |i: usize| {
            self.pos
                .get(i)
                .copied()
                .zip(self.vel.get(i).copied())
                .ok_or_else(internal)
        };
        let (p0, v0) = get(i0)?;
        let (p1, v1) = get(i1)?;
        Ok(hermite(p0, v0, p1, v1, self.step, frac))
    }
}

/// The grid cell of time `s` on a grid of spacing `step`: the index k of
/// `t_k = k step ≤ s` and the fraction `(s − t_k)/step` in [0, 1).
///
/// # Errors
/// [`ChatterError::NonFinite`] for a non-finite time.
fn grid_cell(s: f64, step: f64) -> Result<(i64, f64), ChatterError> {
    let u = s / step;
    let k = u.floor();
    if !k.is_finite() {
        return Err(ChatterError::NonFinite {
            what: "delayed time".to_string(),
        });
    }
    Ok((k as i64, u - k))
}

/// The cutter of seed 004 eq. 2-4 with its force law.
struct Cutter {
    teeth: usize,
    radius: f64,
    depth: f64,
    kt: f64,
    kn: f64,
    entry: f64,
    exit: f64,
    omega: f64,
    feed: f64,
    period: f64,
    regen: usize,
    /// Half width w of the bracket `δ ∈ [−w, w]` of the delay root.
    half_width: f64,
    /// Workpiece-wall level `y_w` \[m\] of the entry edge (tooth tip in the
    /// material while `y(t) − R cos φ ≥ y_w`), if the entry is a wall.
    entry_wall: Option<f64>,
    /// Same for the exit edge (in the material while `y − R cos φ ≤ y_w`).
    exit_wall: Option<f64>,
    /// Angle offset φ_0 of the step grid \[rad\]: internally
    /// `φ_j = Ω t + φ_0 + 2π j / N_t`, i.e. the internal time is the true
    /// time minus φ_0 / Ω. With a workpiece wall, φ_0 puts the nominal wall
    /// crossings in the middle of a step, so that the actual crossing can
    /// move either way inside that step.
    phase: f64,
}

/// One boundary of the RK4 sub-steps of a step.
#[derive(Debug, Clone, Copy)]
struct Edge {
    /// Nominal time \[s\] (the tooth crosses the edge angle).
    time: f64,
    /// For a workpiece-wall edge: the tooth and the wall level y_w \[m\].
    wall: Option<(usize, f64)>,
}

/// Force of all teeth at one instant.
struct Cut {
    force: Vector2<f64>,
    chip: f64,
    order: usize,
    engaged: usize,
    contact: usize,
}

impl Cutter {
    fn new(p: &MillingProcess, rpm: f64, feed: f64, period: f64, regen: usize) -> Self {
        let pi = std::f64::consts::PI;
        Self {
            teeth: p.teeth,
            radius: p.radius,
            depth: p.axial_depth,
            kt: p.kt,
            kn: p.kn,
            entry: p.entry_angle,
            exit: p.exit_angle,
            omega: rpm * pi / 30.0,
            feed,
            period,
            regen,
            half_width: (0.25 * pi).min(0.5 * pi / p.teeth as f64),
            entry_wall: None,
            exit_wall: None,
            phase: 0.0,
        }
    }

    /// Boundaries `[t, s_1, .., t + h]` of the RK4 sub-steps of the step
    /// `[t, t + h]`: the step is split where a tooth crosses the entry or
    /// exit angle, so that the force, which jumps there, is smooth on every
    /// sub-step and RK4 keeps its order (a jump inside a step would cost an
    /// O(h) error in the impulse).
    ///
    /// Edges where the tooth meets a workpiece wall carry the wall level
    /// (the simulator then moves them to the actual crossing).
    fn substeps(&self, t: f64, h: f64, out: &mut Vec<Edge>) {
        let two_pi = 2.0 * std::f64::consts::PI;
        out.clear();
        out.push(Edge {
            time: t,
            wall: None,
        });
        let eps = 1e-9 * h;
        for j in 0..self.teeth {
            let phi = self.omega * t + self.phase + two_pi * j as f64 / self.teeth as f64;
            for (edge, wall) in [(self.entry, self.entry_wall), (self.exit, self.exit_wall)] {
                let past = (phi - edge).rem_euclid(two_pi);
                let dt = (two_pi - past) / self.omega;
                if dt > eps && dt < h - eps {
                    out.push(Edge {
                        time: t + dt,
                        wall: wall.map(|w| (j, w)),
                    });
                }
            }
        }
        out.push(Edge {
            time: t + h,
            wall: None,
        });
        out.sort_by(|a, b| a.time.total_cmp(&b.time));
        out.dedup_by(|a, b| (a.time - b.time).abs() <= eps);
    }

    /// The actual time at which `tooth` meets the workpiece wall `y_w`
    /// near its nominal crossing `nominal`: the root of
    /// `g(t) = y(t) − R cos φ(t) − y_w` (the tooth tip reaches the wall
    /// line, fixed in the workpiece: Bachrathy et al. 2011, and the wall term
    /// of [`crate::linearize`]), with `y(t)` from the sub-step `sub` started
    /// at `start` (the tooth still on its side before the crossing). Newton
    /// with `ġ = ẏ + R Ω sin φ`, kept inside `(start, upper)`; a crossing
    /// outside that window (only for a vibration comparable to `R Ω h`) is
    /// clamped to it.
    ///
    /// # Errors
    /// [`ChatterError::NotConverged`] at the iteration cap; errors of `sub`.
    #[allow(clippy::too_many_arguments)]
    fn wall_crossing<F>(
        &self,
        tooth: usize,
        wall: f64,
        start: f64,
        nominal: f64,
        upper: f64,
        h: f64,
        sub: &mut F,
    ) -> Result<f64, ChatterError>
    where
        F: FnMut(f64) -> Result<(Vector2<f64>, Vector2<f64>), ChatterError>,
    {
        let offset = 2.0 * std::f64::consts::PI * tooth as f64 / self.teeth as f64;
        let (lo, hi) = (start + 1e-9 * h, upper - 1e-9 * h);
        let mut tc = nominal;
        let mut g = f64::NAN;
        for _ in 0..DELAY_MAX_ITERATIONS {
            let (p, v) = sub(tc)?;
            let (s, c) = (self.omega * tc + self.phase + offset).sin_cos();
            g = p.y - self.radius * c - wall;
            let dg = v.y + self.radius * self.omega * s;
            if !(g.is_finite() && dg.is_finite()) {
                return Err(ChatterError::NonFinite {
                    what: "workpiece-wall crossing".to_string(),
                });
            }
            if g == 0.0 || dg <= 0.0 {
                return Ok(tc);
            }
            let next = (tc - g / dg).clamp(lo, hi);
            if (next - tc).abs() <= 1e-9 * h || next == lo || next == hi {
                return Ok(next);
            }
            tc = next;
        }
        Err(ChatterError::NotConverged {
            what: format!("workpiece-wall crossing of tooth {tooth}"),
            iterations: DELAY_MAX_ITERATIONS,
            residual: g,
        })
    }

    /// Nominal delays m T, laid out `[tooth * M + (m − 1)]`.
    fn nominal_delays(&self) -> Vec<f64> {
        (0..self.teeth * self.regen)
            .map(|i| ((i % self.regen) + 1) as f64 * self.period)
            .collect()
    }

    /// Cutting force at time `t` with present position `o` and the history
    /// `hist` (module documentation); `warm` holds the last delay of every
    /// (tooth, m) as the Newton start. Whether a tooth is inside the
    /// engagement window is decided at `member` (the midpoint of the current
    /// RK4 sub-step, which no window edge crosses), so that every stage of a
    /// sub-step sees the same set of teeth.
    fn force<H: History>(
        &self,
        t: f64,
        member: f64,
        o: Vector2<f64>,
        hist: &H,
        warm: &mut [f64],
    ) -> Result<Cut, ChatterError> {
        let two_pi = 2.0 * std::f64::consts::PI;
        let mut cut = Cut {
            force: Vector2::zeros(),
            chip: 0.0,
            order: 0,
            engaged: 0,
            contact: 0,
        };
        for j in 0..self.teeth {
            let offset = two_pi * j as f64 / self.teeth as f64;
            let inside = (self.omega * member + self.phase + offset).rem_euclid(two_pi);
            if inside < self.entry || inside > self.exit {
                continue;
            }
            let phi = self.omega * t + self.phase + offset;
            cut.engaged += 1;
            let (mut h, mut order) = (f64::INFINITY, 0);
            for m in 1..=self.regen {
                let slot = warm.get_mut(j * self.regen + m - 1).ok_or_else(internal)?;
                let (tau, hm) = self.solve_delay(t, phi, o, m, hist, *slot)?;
                *slot = tau;
                if hm < h {
                    h = hm;
                    order = m;
                }
            }
            if h > 0.0 {
                cut.contact += 1;
                if h > cut.chip {
                    cut.chip = h;
                    cut.order = order;
                }
                cut.force += self.depth * h * force_direction(phi, self.kt, self.kn);
            }
        }
        Ok(cut)
    }

    /// Solves seed 004 eq. 3 for the delay τ of regeneration order m by a
    /// safeguarded Newton iteration on the bracket `δ ∈ [−w, w]`
    /// (`δ = Ω τ − 2π m / N_t`) and returns τ and the chip of seed 004
    /// eq. 4.
    ///
    /// Residual and derivative (s = t − τ, history interpolant x, y):
    /// `g(τ) = R sin δ + (f τ + x(s) − x(t)) cos φ − (y(s) − y(t)) sin φ`,
    /// `g'(τ) = R Ω cos δ + (f − ẋ(s)) cos φ + ẏ(s) sin φ`.
    fn solve_delay<H: History>(
        &self,
        t: f64,
        phi: f64,
        o: Vector2<f64>,
        m: usize,
        hist: &H,
        guess: f64,
    ) -> Result<(f64, f64), ChatterError> {
        let base = 2.0 * std::f64::consts::PI * m as f64 / self.teeth as f64;
        let (sphi, cphi) = phi.sin_cos();
        let eval = |tau: f64| -> Result<(f64, f64, f64, f64, f64), ChatterError> {
            let (p, v) = hist.at(t - tau)?;
            let delta = self.omega * tau - base;
            let dcx = self.feed * tau + p.x - o.x;
            let dcy = p.y - o.y;
            let g = tangential_residual(self.radius, delta, dcx, dcy, phi);
            let dg = self.radius * self.omega * delta.cos() + (self.feed - v.x) * cphi + v.y * sphi;
            Ok((g, dg, delta, dcx, dcy))
        };
        let mut lo = (base - self.half_width) / self.omega;
        let mut hi = (base + self.half_width) / self.omega;
        let glo = eval(lo)?.0;
        let ghi = eval(hi)?.0;
        if !(glo < 0.0 && ghi > 0.0) {
            return Err(ChatterError::NotConverged {
                what: format!(
                    "delay of regeneration order {m} (seed 004 eq. 3): no sign change on its \
                     bracket at phi = {:.4} rad (vibration too large for the tool radius?)",
                    phi.rem_euclid(2.0 * std::f64::consts::PI)
                ),
                iterations: 0,
                residual: if glo.is_finite() { glo } else { ghi },
            });
        }
        let tol = 1e-12 * self.period;
        let mut tau = if guess > lo && guess < hi {
            guess
        } else {
            0.5 * (lo + hi)
        };
        let mut last = f64::NAN;
        for _ in 0..DELAY_MAX_ITERATIONS {
            let (g, dg, delta, dcx, dcy) = eval(tau)?;
            if !g.is_finite() || !dg.is_finite() {
                return Err(ChatterError::NonFinite {
                    what: format!("delay residual of regeneration order {m} (seed 004 eq. 3)"),
                });
            }
            last = g;
            if g < 0.0 {
                lo = tau;
            } else {
                hi = tau;
            }
            let newton = tau - g / dg;
            let next = if dg > 0.0 && newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            if g == 0.0 || (next - tau).abs() <= tol {
                let h = chip_thickness(self.radius, delta, dcx, dcy, phi);
                return Ok((tau, h));
            }
            tau = next;
        }
        Err(ChatterError::NotConverged {
            what: format!("delay of regeneration order {m} (seed 004 eq. 3)"),
            iterations: DELAY_MAX_ITERATIONS,
            residual: last,
        })
    }
}

/// The periodic forced response and what it took.
struct Orbit {
    history: PeriodicHistory,
    samples: Vec<StepSample>,
    iterations: usize,
    contact_fraction: f64,
}

/// The T-periodic forced response by the fixed-point iteration of the
/// module documentation.
fn periodic_response(
    s: &Structure,
    cutter: &Cutter,
    h: f64,
    n: usize,
    settings: &SimulationSettings,
) -> Result<Orbit, ChatterError> {
    // The sub-step pattern of every step of the period (the simulator's).
    let mut pattern = Vec::with_capacity(n);
    for k in 0..n {
        let mut edges = Vec::new();
        cutter.substeps(k as f64 * h, h, &mut edges);
        pattern.push(edges.iter().map(|e| e.time).collect::<Vec<f64>>());
    }
    // RK4 transition matrix of ż = A z over one sub-step of length dt:
    // P(dt) = Σ_{i≤4} (dt A)^i / i!; over the period Φ = Π P(dt).
    let rk4_matrix = |dt: f64| {
        let ha = s.a * dt;
        let mut p = Matrix4::<f64>::identity();
        let mut term = Matrix4::<f64>::identity();
        for i in 1..=4 {
            term = term * ha / i as f64;
            p += term;
        }
        p
    };
    let mut phi = Matrix4::<f64>::identity();
    for bounds in &pattern {
        for w in bounds.windows(2) {
            phi = rk4_matrix(w[1] - w[0]) * phi;
        }
    }
    let inv = (Matrix4::identity() - phi)
        .try_inverse()
        .ok_or(ChatterError::Unsupported {
            reason: "undamped structure resonant with the tooth period: no periodic forced \
                     response (I - Phi singular)"
                .to_string(),
        })?;

    let mut hist = PeriodicHistory {
        step: h,
        pos: vec![Vector2::zeros(); n],
        vel: vec![Vector2::zeros(); n],
    };
    let mut warm = cutter.nominal_delays();
    // Stage forces per step and sub-step.
    let mut forces: Vec<Vec<[Vector2<f64>; 4]>> = pattern
        .iter()
        .map(|b| vec![[Vector2::zeros(); 4]; b.len().saturating_sub(1)])
        .collect();
    let mut chips = vec![(0.0, 0usize); n];
    let mut change = f64::NAN;
    for iteration in 1..=settings.orbit_max_iterations {
        let (mut engaged, mut contact) = (0usize, 0usize);
        for (k, ((fk, ck), bounds)) in forces
            .iter_mut()
            .zip(chips.iter_mut())
            .zip(pattern.iter())
            .enumerate()
        {
            // The RK4 stage forces of the simulator's step from the
            // iterate's state z_k, delayed values from the iterate.
            let mut o = hist.pos.get(k).copied().ok_or_else(internal)?;
            let mut v = hist.vel.get(k).copied().ok_or_else(internal)?;
            for (i, (w, fs)) in bounds.windows(2).zip(fk.iter_mut()).enumerate() {
                let (ta, tb) = (w[0], w[1]);
                let mid = 0.5 * (ta + tb);
                let c0 = cutter.force(ta, mid, o, &hist, &mut warm)?;
                if i == 0 {
                    engaged += c0.engaged;
                    contact += c0.contact;
                    *ck = (c0.chip, c0.order);
                }
                let mut stage = [c0.force; 4];
                let mut next = 1;
                (o, v) = rk4_step(s, ta, tb - ta, o, v, c0.force, |tt, oo| {
                    let f = cutter.force(tt, mid, oo, &hist, &mut warm)?.force;
                    if let Some(slot) = stage.get_mut(next) {
                        *slot = f;
                    }
                    next += 1;
                    Ok(f)
                })?;
                *fs = stage;
            }
        }
        let run = |z0: Vector4<f64>, store: Option<&mut PeriodicHistory>| {
            let mut o = Vector2::new(z0[0], z0[1]);
            let mut v = Vector2::new(z0[2], z0[3]);
            let mut out = store;
            for (k, (fk, bounds)) in forces.iter().zip(pattern.iter()).enumerate() {
                if let Some(st) = out.as_deref_mut() {
                    if let (Some(ps), Some(vs)) = (st.pos.get_mut(k), st.vel.get_mut(k)) {
                        *ps = o;
                        *vs = v;
                    }
                }
                for (w, f) in bounds.windows(2).zip(fk.iter()) {
                    let mut next = 1;
                    (o, v) = rk4_step(s, w[0], w[1] - w[0], o, v, f[0], |_, _| {
                        let fs = f.get(next).copied().ok_or_else(internal);
                        next += 1;
                        fs
                    })?;
                }
            }
            Ok::<Vector4<f64>, ChatterError>(Vector4::new(o.x, o.y, v.x, v.y))
        };
        let from_rest = run(Vector4::zeros(), None)?;
        let z0 = inv * from_rest;
        let mut next = PeriodicHistory {
            step: h,
            pos: vec![Vector2::zeros(); n],
            vel: vec![Vector2::zeros(); n],
        };
        run(z0, Some(&mut next))?;
        change = next
            .pos
            .iter()
            .zip(hist.pos.iter())
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        if !change.is_finite() {
            return Err(ChatterError::NonFinite {
                what: "periodic forced response".to_string(),
            });
        }
        hist = next;
        if change <= settings.orbit_tolerance {
            let samples = (0..n)
                .map(|k| StepSample {
                    time: k as f64 * h,
                    position: hist.pos.get(k).copied().unwrap_or_default(),
                    velocity: hist.vel.get(k).copied().unwrap_or_default(),
                    force: forces
                        .get(k)
                        .and_then(|f| f.first())
                        .map(|f| f[0])
                        .unwrap_or_default(),
                    chip: chips.get(k).map(|c| c.0).unwrap_or_default(),
                    order: chips.get(k).map(|c| c.1).unwrap_or_default(),
                })
                .collect();
            return Ok(Orbit {
                history: hist,
                samples,
                iterations: iteration,
                contact_fraction: fraction(contact, engaged),
            });
        }
    }
    Err(ChatterError::NotConverged {
        what: "periodic forced response (fixed-point iteration)".to_string(),
        iterations: settings.orbit_max_iterations,
        residual: change,
    })
}
