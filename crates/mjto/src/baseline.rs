//! The conventional method the paper compares against: quaternion
//! interpolation (QI) of the tool orientation between the representative
//! tool orientations (seed 001 ref. \[3\], Ho et al.; section 3, Figures 9b,
//! 13-16).
//!
//! Between consecutive RTOs `(u_a, O_a, q6_a)` and `(u_b, O_b, q6_b)`:
//! * the tool axis is slerped along the great circle from `O_a` to `O_b`
//!   in the workpiece/machine frame ([`slerp_unit`], the quaternion
//!   interpolation of the minimal rotation) with the fraction
//!   `(u - u_a) / (u_b - u_a)`;
//! * the CL point follows the reference path `C(u)`
//!   ([`PathFrames::cl_point`]);
//! * q6 is linear in `u` between the RTO values;
//! * q4, q5 come from [`rotary_ikt`](crate::kinematics::rotary_ikt) (eq. 3) with continuity, starting
//!   from the first RTO's q4, and q1..q3 = `C - q6 O` (eq. 3).
//!
//! The result is sampled on the same time law and Δt as the plan.

use kerf_budget::Budget;
use nalgebra::Vector3;

use crate::kinematics::{inverse, tool_axis};
use crate::machine::AxisLimits;
use crate::orientation::{slerp_unit, PathFrames};
use crate::timelaw::{TimeLaw, MAX_SAMPLES};
use crate::PlanError;

/// A representative tool orientation as the baseline uses it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rto {
    /// Normalized arc length ũ of the RTO.
    pub u: f64,
    /// Rotary axis q4 (rad).
    pub q4: f64,
    /// Rotary axis q5 (rad).
    pub q5: f64,
    /// Standoff q6 (m).
    pub q6: f64,
}

impl From<&crate::plan::RtoRecord> for Rto {
    /// The RTO of a plan's record (its u and joint values).
    fn from(r: &crate::plan::RtoRecord) -> Self {
        Self {
            u: r.u,
            q4: r.q4,
            q5: r.q5,
            q6: r.q6,
        }
    }
}

/// Checks that the RTOs are usable: at least one, finite, `u` strictly
/// increasing.
fn check_rtos(rtos: &[Rto]) -> Result<(), PlanError> {
    if rtos.is_empty() {
        return Err(PlanError::invalid(
            "rtos",
            "the QI baseline needs at least one RTO",
        ));
    }
    for (i, r) in rtos.iter().enumerate() {
        if ![r.u, r.q4, r.q5, r.q6].iter().all(|v| v.is_finite()) {
            return Err(PlanError::invalid(
                format!("rtos[{i}]"),
                format!("{r:?} is not finite"),
            ));
        }
    }
    if let Some(i) = rtos.windows(2).position(|w| w[1].u <= w[0].u) {
        return Err(PlanError::invalid(
            format!("rtos[{}]", i + 1),
            "RTO parameters u must be strictly increasing",
        ));
    }
    Ok(())
}

/// The QI tool axis and standoff at `u`: `(O(u), q6(u))`. Before the first
/// RTO and after the last the end RTO's orientation and standoff are held.
/// `rtos` must be non-empty with strictly increasing `u` (checked by
/// [`qi_pose`] and [`quaternion_interpolation`]).
fn qi_axis(rtos: &[Rto], u: f64) -> (Vector3<f64>, f64) {
    let idx = rtos.partition_point(|r| r.u <= u);
    let (a, b) = match (idx.checked_sub(1).and_then(|i| rtos.get(i)), rtos.get(idx)) {
        (Some(a), Some(b)) => (a, b),
        (Some(a), None) | (None, Some(a)) => return (tool_axis(a.q4, a.q5), a.q6),
        (None, None) => return (Vector3::repeat(f64::NAN), f64::NAN),
    };
    let s = ((u - a.u) / (b.u - a.u)).clamp(0.0, 1.0);
    let o = slerp_unit(&tool_axis(a.q4, a.q5), &tool_axis(b.q4, b.q5), s);
    (o, a.q6 + s * (b.q6 - a.q6))
}

/// The QI joint vector at one path parameter `u` (module docs).
///
/// # Arguments
/// * `frames` - the reference path.
/// * `rtos` - RTOs, non-empty, `u` strictly increasing.
/// * `u` - path parameter in [0, 1].
/// * `previous_q4` - q4 of the previous sample (continuity of eq. 3).
/// * `limits` - strokes of q1..q6.
///
/// # Errors
/// [`PlanError::InvalidRequest`] for bad RTOs or a NaN `u`;
/// [`PlanError::Unreachable`] (index of the nearest CL point) when a joint
/// leaves its stroke.
pub fn qi_pose(
    frames: &PathFrames,
    rtos: &[Rto],
    u: f64,
    previous_q4: Option<f64>,
    limits: &[AxisLimits; 6],
) -> Result<[f64; 6], PlanError> {
    check_rtos(rtos)?;
    pose_unchecked(frames, rtos, u, previous_q4, limits)
}

fn pose_unchecked(
    frames: &PathFrames,
    rtos: &[Rto],
    u: f64,
    previous_q4: Option<f64>,
    limits: &[AxisLimits; 6],
) -> Result<[f64; 6], PlanError> {
    if !u.is_finite() {
        return Err(PlanError::invalid("u", format!("{u} is not finite")));
    }
    let (o, q6) = qi_axis(rtos, u);
    let c = frames.cl_point(u);
    inverse(&c, &o, q6, previous_q4, limits).map_err(|e| PlanError::Unreachable {
        index: frames.nearest_index(u),
        reason: format!("QI baseline at u = {u:.6}: {e}"),
    })
}

/// The QI baseline trajectory sampled at the plan's time law and Δt.
///
/// At every sample time `t` (from [`TimeLaw::sample_times`]) the path
/// parameter is `u = s(t)/σ` (eq. 1) and the joints come from the module's
/// QI rule, q4 continuous from the first RTO's q4.
///
/// # Arguments
/// * `frames` - the reference CL path.
/// * `rtos` - RTOs in path order (at least one; normally the first at
///   u = 0 and the last at u = 1).
/// * `law` - the feed profile of the plan.
/// * `sigma` - path length σ (m); must equal the law's.
/// * `dt` - sample period Δt (s).
/// * `limits` - strokes of q1..q6.
///
/// # Returns
/// `(times, positions)`.
///
/// # Errors
/// [`PlanError::InvalidRequest`] for bad RTOs, a σ different from the
/// law's, a non-positive `dt` or more than [`MAX_SAMPLES`] samples;
/// [`PlanError::Unreachable`] when a sample leaves a stroke.
///
/// # Performance
/// O(samples · log(N + RTOs)).
pub fn quaternion_interpolation(
    frames: &PathFrames,
    rtos: &[Rto],
    law: &TimeLaw,
    sigma: f64,
    dt: f64,
    limits: &[AxisLimits; 6],
) -> Result<(Vec<f64>, Vec<[f64; 6]>), PlanError> {
    quaternion_interpolation_within(frames, rtos, law, sigma, dt, limits, &Budget::unlimited())
}

/// [`quaternion_interpolation`] under a time budget, checked every
/// [`crate::planner::BUDGET_STRIDE`] samples.
///
/// # Errors
/// As [`quaternion_interpolation`], and [`PlanError::Interrupted`].
pub fn quaternion_interpolation_within(
    frames: &PathFrames,
    rtos: &[Rto],
    law: &TimeLaw,
    sigma: f64,
    dt: f64,
    limits: &[AxisLimits; 6],
    budget: &Budget,
) -> Result<(Vec<f64>, Vec<[f64; 6]>), PlanError> {
    check_rtos(rtos)?;
    if !(sigma.is_finite() && (sigma - law.sigma()).abs() <= 1e-9 * law.sigma().max(1.0)) {
        return Err(PlanError::invalid(
            "sigma",
            format!(
                "{sigma} m differs from the time law's path length {} m",
                law.sigma()
            ),
        ));
    }
    let times = law.checked_sample_times(dt, MAX_SAMPLES)?;
    let path: Vec<f64> = times.iter().map(|&t| law.eval(t)[0]).collect();
    let positions = quaternion_interpolation_along(frames, rtos, &path, sigma, limits, budget)?;
    Ok((times, positions))
}

/// The QI poses at the path positions `path` (m, one per sample, in [0, σ]): the baseline on
/// any time law, e.g. the time-optimal one of a plan (`CutPlan::path_positions`), so that both
/// methods are compared on the same s(t).
///
/// # Errors
/// [`PlanError::InvalidRequest`] for bad RTOs or a position outside `[0, σ]`;
/// [`PlanError::Unreachable`] when a sample leaves a stroke; [`PlanError::Interrupted`].
///
/// # Performance
/// O(samples · log(N + RTOs)).
pub fn quaternion_interpolation_along(
    frames: &PathFrames,
    rtos: &[Rto],
    path: &[f64],
    sigma: f64,
    limits: &[AxisLimits; 6],
    budget: &Budget,
) -> Result<Vec<[f64; 6]>, PlanError> {
    check_rtos(rtos)?;
    let mut positions = Vec::with_capacity(path.len());
    let mut previous = rtos.first().map(|r| r.q4);
    for (k, &s) in path.iter().enumerate() {
        if k.is_multiple_of(crate::planner::BUDGET_STRIDE) {
            budget.check("the QI baseline")?;
        }
        if !(s.is_finite() && (-1e-9 * sigma..=sigma * (1.0 + 1e-9)).contains(&s)) {
            return Err(PlanError::invalid(
                "path positions",
                format!("{s} m at sample {k} is outside [0, {sigma}] m"),
            ));
        }
        let u = (s / sigma).clamp(0.0, 1.0);
        let q = pose_unchecked(frames, rtos, u, previous, limits)?;
        previous = Some(q[3]);
        positions.push(q);
    }
    Ok(positions)
}
