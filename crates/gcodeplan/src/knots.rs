//! A run's joint trajectory: points in time with positions, velocities and
//! accelerations, dense enough that the executor's quintic Hermite keeps
//! the tool within δ_i of the planned point, and its peaks against the
//! joint limits.
//!
//! # Steps of [`run_knots`]
//! 1. **Points** at every start of a phase of the feed plan and between them every
//!    `knot_spacing` at most ([`initial_times`]). At each: the
//!    planned (s, v, a) and p, p′, p″ ([`TimedRun::motion`]); the joints
//!    q = IK(p) nearest the previous point's; q′ and q″ in arc length by
//!    central differences of the IK at the second-order Taylor points
//!    p ± h p′ + h²/2 p″ (h ≤ 0.01/κ keeps the Taylor term's error below
//!    1e-4 of q″); then q̇ = q′ v and q̈ = q″ v² + q′ a (chain rule).
//! 2. **Check each piece** as the executor interpolates it (the quintic
//!    Hermite of `kerf_executor::spline`, JTC's splines): the tool tip by
//!    forward kinematics at ⌈Δt / control period⌉ + 2 inner times against
//!    the planned point at the same time. A piece beyond
//!    [`SPLIT_FRACTION`] δ_i is split at its middle; repeat.
//! 3. **Peaks**: the exact largest |velocity|, |acceleration| and |jerk| of
//!    each joint's quintic on each piece (ends and real roots of the next
//!    derivative). r = max(|v|/v_max, √(|a|/a_max), ∛(|j|/j_max)) over the
//!    run; when r > 1 the run is slowed uniformly by r: t → r t, so
//!    v/r, a/r², j/r³ exactly (the same quintics in scaled time: the same
//!    geometry, the same deviation).

use kerf_budget::{bytes_of, Budget};
use kerf_executor::roots::{derivative, extrema};
use kerf_executor::spline::{
    acceleration_coefficients, coefficients, evaluate, velocity_coefficients, Interpolation, Knot,
};

use crate::error::GcodePlanError;
use crate::machine::{Machine, DOF};
use crate::timed::TimedRun;

/// A piece is split when its tip leaves this fraction of δ_i: the final
/// check samples the executor's own clock, which can fall between the
/// inner times checked here.
pub const SPLIT_FRACTION: f64 = 0.8;

/// Rounds of splitting before the run is given up.
pub const MAX_SPLIT_ROUNDS: usize = 40;

/// The largest uniform slowdown of a run: a run that needs more cannot be followed (an IK
/// branch change or a singularity on the path), and is refused rather than crawled.
pub const MAX_SLOWDOWN: f64 = 100.0;

/// The largest step h of the IK's central differences \[m\].
pub const DIFF_STEP: f64 = 1e-4;

/// One trajectory point of a run (local time, before any slowdown).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointKnot {
    /// Time from the run's start \[s\].
    pub t: f64,
    /// Positions.
    pub q: [f64; DOF],
    /// Velocities.
    pub qd: [f64; DOF],
    /// Accelerations.
    pub qdd: [f64; DOF],
}

/// Which limit binds the most.
#[derive(Debug, Clone, PartialEq)]
pub struct Peak {
    /// r of the module documentation (≤ 1: within every limit).
    pub ratio: f64,
    /// The joint.
    pub joint: String,
    /// "velocity", "acceleration" or "jerk".
    pub what: &'static str,
}

/// A run's points and how it must be slowed.
#[derive(Debug, Clone, PartialEq)]
pub struct RunKnots {
    /// The points, local times before the slowdown.
    pub knots: Vec<JointKnot>,
    /// The uniform slowdown r ≥ 1 (1: none).
    pub slowdown: f64,
    /// The binding limit before the slowdown.
    pub peak: Peak,
    /// The pieces beyond a limit before the slowdown: (start, end) local times and their r.
    pub over: Vec<(f64, f64, f64)>,
}

impl RunKnots {
    /// The points in scaled time, shifted by `offset` \[s\].
    pub fn scaled(&self, offset: f64) -> impl Iterator<Item = JointKnot> + '_ {
        let r = self.slowdown;
        self.knots.iter().map(move |k| JointKnot {
            t: offset + k.t * r,
            q: k.q,
            qd: k.qd.map(|v| v / r),
            qdd: k.qdd.map(|a| a / (r * r)),
        })
    }
}

/// The joints at time `t` of a run (step 1).
///
/// # Errors
/// The machine's reason when the point (or a Taylor point 1e-4 m from it)
/// is out of reach.
pub fn knot_at(
    machine: &dyn Machine,
    run: &TimedRun,
    t: f64,
    reference: Option<&[f64; DOF]>,
) -> Result<JointKnot, String> {
    let m = run.motion(t);
    let q = machine.joints(m.point, reference)?;
    let kappa = m.curvature_normal.iter().map(|v| v * v).sum::<f64>().sqrt();
    let h = if kappa > 0.0 {
        DIFF_STEP.min(0.01 / kappa)
    } else {
        DIFF_STEP
    };
    let taylor = |sign: f64| -> [f64; 3] {
        std::array::from_fn(|k| {
            m.point[k] + sign * h * m.tangent[k] + 0.5 * h * h * m.curvature_normal[k]
        })
    };
    let qp = machine.joints(taylor(1.0), Some(&q))?;
    let qm = machine.joints(taylor(-1.0), Some(&q))?;
    let mut qd = [0.0; DOF];
    let mut qdd = [0.0; DOF];
    for j in 0..DOF {
        let d1 = (qp[j] - qm[j]) / (2.0 * h);
        let d2 = (qp[j] - 2.0 * q[j] + qm[j]) / (h * h);
        qd[j] = d1 * m.speed;
        qdd[j] = d2 * m.speed * m.speed + d1 * m.acceleration;
    }
    Ok(JointKnot { t, q, qd, qdd })
}

/// The quintic of joint `j` between two points, local time τ ∈ [0, t1 − t0].
pub fn quintic(a: &JointKnot, b: &JointKnot, j: usize) -> [f64; 6] {
    coefficients(
        Interpolation::Quintic,
        Knot {
            p: a.q[j],
            v: a.qd[j],
            a: a.qdd[j],
        },
        Knot {
            p: b.q[j],
            v: b.qd[j],
            a: b.qdd[j],
        },
        b.t - a.t,
    )
}

/// The largest distance of the interpolated tip from the planned point over
/// the inner check times of a piece (step 2) \[m\].
///
/// # Errors
/// The machine's reason for a non-finite joint vector.
pub fn piece_deviation(
    machine: &dyn Machine,
    run: &TimedRun,
    a: &JointKnot,
    b: &JointKnot,
    control_period: f64,
) -> Result<f64, String> {
    let dt = b.t - a.t;
    let inner = (dt / control_period).ceil() as usize + 2;
    let coeffs: [[f64; 6]; DOF] = std::array::from_fn(|j| quintic(a, b, j));
    let mut worst: f64 = 0.0;
    for i in 1..=inner {
        let tau = dt * i as f64 / (inner + 1) as f64;
        let q: [f64; DOF] = std::array::from_fn(|j| evaluate(&coeffs[j], tau).0);
        let tip = machine.tip(&q)?;
        let planned = run.motion(a.t + tau).point;
        let d = (0..3)
            .map(|k| (tip[k] - planned[k]).powi(2))
            .sum::<f64>()
            .sqrt();
        worst = worst.max(d);
    }
    Ok(worst)
}

/// The exact peaks of every joint's quintic between two points, as ratios
/// to the limits: (velocity, acceleration, jerk) per joint.
pub fn piece_peaks(machine: &dyn Machine, a: &JointKnot, b: &JointKnot) -> [[f64; 3]; DOF] {
    let dt = b.t - a.t;
    std::array::from_fn(|j| {
        let c = quintic(a, b, j);
        let v = velocity_coefficients(&c);
        let acc = acceleration_coefficients(&c);
        let jerk = derivative(&acc);
        let largest = |p: &[f64]| {
            let ((_, lo), (_, hi)) = extrema(p, 0.0, dt);
            lo.abs().max(hi.abs())
        };
        let bound = &machine.bounds()[j];
        [
            largest(&v) / bound.velocity,
            largest(&acc) / bound.acceleration,
            largest(&jerk) / bound.jerk,
        ]
    })
}

/// The first times of a run's points: every start of a constant-jerk phase of its feed plan
/// (so that no piece straddles a jump of the path jerk, which a quintic would overshoot; on a
/// line a phase's motion is a cubic in time, which the quintic Hermite reproduces exactly),
/// and between them a grid of at most `spacing`.
/// The number of [`initial_times`] of a run, at most: one per phase and one per `spacing` of
/// its duration (saturating: a plan of 10³⁰⁰ s gives `u64::MAX`), known before any is made.
fn initial_count(run: &TimedRun, spacing: f64) -> u64 {
    let count = (run.duration() / spacing).ceil() + 2.0 * run.plan.phases.len() as f64 + 2.0;
    if count.is_finite() && count < u64::MAX as f64 {
        count as u64
    } else {
        u64::MAX
    }
}

fn initial_times(run: &TimedRun, spacing: f64, shortest: f64) -> Vec<f64> {
    let duration = run.duration();
    let mut bounds: Vec<f64> = vec![0.0];
    for t in run.plan.phases.iter().map(|p| p.t0) {
        // A phase shorter than `shortest` is straddled: a piece that short has enormous
        // quintic coefficients (1/Δt⁵) for the rounding in its end states.
        if t - bounds[bounds.len() - 1] >= shortest && duration - t >= shortest {
            bounds.push(t);
        }
    }
    bounds.push(duration);
    let mut times = Vec::with_capacity(bounds.len() + (duration / spacing) as usize + 1);
    for w in bounds.windows(2) {
        let span = w[1] - w[0];
        if span <= 0.0 {
            continue;
        }
        let n = ((span / spacing).ceil() as usize).max(1);
        for k in 0..n {
            times.push(w[0] + span * k as f64 / n as f64);
        }
    }
    times.push(duration);
    times
}

/// The points of a run (module documentation).
///
/// # Arguments
/// * `reference` — the joints the run starts from (the previous run's
///   end), or `None`.
/// * `deviation` — δ_i \[m\].
/// * `max_points` — the most points the run may take.
///
/// # Errors
/// [`GcodePlanError::Unreachable`] (with `line`) for a point out of reach;
/// [`GcodePlanError::TooManyPoints`]; [`GcodePlanError::NotExecutable`]
/// when a piece shorter than a control period / 64 still leaves the
/// tolerance (a jump of the joints: an IK branch change or a singularity);
/// [`GcodePlanError::Interrupted`].
#[allow(clippy::too_many_arguments)]
pub fn run_knots(
    machine: &dyn Machine,
    run: &TimedRun,
    line: usize,
    reference: Option<&[f64; DOF]>,
    knot_spacing: f64,
    control_period: f64,
    deviation: f64,
    max_points: usize,
    budget: &Budget,
) -> Result<RunKnots, GcodePlanError> {
    let unreachable = |t: f64, reason: String| {
        let p = run.motion(t).point;
        GcodePlanError::Unreachable {
            line,
            x: p[0],
            y: p[1],
            z: p[2],
            reason,
        }
    };
    // Counted before they are made: a run of 10³⁰⁰ s (a feed of 10⁻³⁰⁰ m/s) is refused here,
    // not by the allocator.
    let count = initial_count(run, knot_spacing);
    if count > max_points as u64 + 2 * run.plan.phases.len() as u64 + 2 {
        return Err(GcodePlanError::TooManyPoints { max: max_points });
    }
    budget.check_memory(
        bytes_of::<f64>(count).saturating_add(bytes_of::<JointKnot>(count.saturating_mul(2))),
        &format!(
            "joint points of the run at line {line}: {:.3e} s every {knot_spacing} s, about \
             {count} points",
            run.duration()
        ),
    )?;
    let times = initial_times(run, knot_spacing, 0.25 * control_period);
    if times.len() > max_points {
        return Err(GcodePlanError::TooManyPoints { max: max_points });
    }
    let n = times.len() - 1;
    let mut knots: Vec<JointKnot> = Vec::with_capacity(n + 1);
    let mut previous = reference.copied();
    for (k, &t) in times.iter().enumerate() {
        if k % 256 == 255 {
            budget.check("joint trajectory (inverse kinematics)")?;
        }
        let mut knot =
            knot_at(machine, run, t, previous.as_ref()).map_err(|e| unreachable(t, e))?;
        if k == 0 || k == n {
            // The feed plan starts and ends at rest (v = a = 0): exactly, not 1e-18.
            knot.qd = [0.0; DOF];
            knot.qdd = [0.0; DOF];
        }
        previous = Some(knot.q);
        knots.push(knot);
    }
    let limit = SPLIT_FRACTION * deviation;
    let shortest = control_period / 64.0;
    for round in 0..=MAX_SPLIT_ROUNDS {
        budget.check("joint trajectory")?;
        let mut next: Vec<JointKnot> = Vec::with_capacity(knots.len());
        let mut split = false;
        for (k, w) in knots.windows(2).enumerate() {
            if k % 256 == 255 {
                budget.check("joint trajectory (interpolation check)")?;
            }
            next.push(w[0]);
            let d = piece_deviation(machine, run, &w[0], &w[1], control_period)
                .map_err(|e| unreachable(w[0].t, e))?;
            if d > limit {
                let dt = w[1].t - w[0].t;
                if dt < shortest || round == MAX_SPLIT_ROUNDS {
                    return Err(GcodePlanError::NotExecutable {
                        line,
                        reason: format!(
                            "line {line}: the tool leaves the tolerance by {d:.3e} m between \
                             {:.6} s and {:.6} s into the run even with points {dt:.2e} s \
                             apart (the joints jump: an IK branch change or a singularity)",
                            w[0].t, w[1].t
                        ),
                    });
                }
                let t = 0.5 * (w[0].t + w[1].t);
                next.push(knot_at(machine, run, t, Some(&w[0].q)).map_err(|e| unreachable(t, e))?);
                split = true;
            }
        }
        if let Some(last) = knots.last() {
            next.push(*last);
        }
        knots = next;
        if knots.len() > max_points {
            return Err(GcodePlanError::TooManyPoints { max: max_points });
        }
        if !split {
            break;
        }
    }
    let mut peak = Peak {
        ratio: 0.0,
        joint: String::new(),
        what: "velocity",
    };
    let mut ratio: f64 = 0.0;
    let mut over = Vec::new();
    for (k, w) in knots.windows(2).enumerate() {
        if k % 256 == 255 {
            budget.check("joint trajectory (peaks)")?;
        }
        let peaks = piece_peaks(machine, &w[0], &w[1]);
        let mut piece: f64 = 0.0;
        for (j, p) in peaks.iter().enumerate() {
            let scaled = [p[0], p[1].sqrt(), p[2].cbrt()];
            piece = piece.max(scaled[0]).max(scaled[1]).max(scaled[2]);
            for (k, what) in ["velocity", "acceleration", "jerk"].into_iter().enumerate() {
                if scaled[k] > ratio {
                    ratio = scaled[k];
                    peak = Peak {
                        ratio,
                        joint: machine.bounds()[j].name.clone(),
                        what,
                    };
                }
            }
        }
        if piece > 1.0 {
            over.push((w[0].t, w[1].t, piece));
        }
    }
    if !(ratio.is_finite() && ratio <= MAX_SLOWDOWN) {
        return Err(GcodePlanError::NotExecutable {
            line,
            reason: format!(
                "line {line}: the {} of {} would need a slowdown of {ratio:.3e} \
                 (more than {MAX_SLOWDOWN}): the joints cannot follow this path",
                peak.what, peak.joint
            ),
        });
    }
    // 1e-9 above r: the scaled peaks land just inside the limits despite rounding.
    let slowdown = if ratio > 1.0 {
        ratio * (1.0 + 1e-9)
    } else {
        1.0
    };
    Ok(RunKnots {
        knots,
        slowdown,
        peak,
        over,
    })
}
