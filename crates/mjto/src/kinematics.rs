//! Forward and inverse kinematics of the laser cutting machine (seed 001
//! eq. 2 and 3).
//!
//! The machine is a TTT gantry (q1, q2, q3 move the rotary-axes centre M)
//! carrying an RRT head: q4 turns about the vertical, q5 tilts, and the
//! redundant standoff axis q6 slides along the tool axis. With
//! `O = (cos q4 sin q5, sin q4 sin q5, cos q5)` (eq. 2) the cutter-location
//! point is `C = M + q6 O`, `M = (q1, q2, q3)`. The URDF chain
//! `Trans(q1, q2, q3) Rz(q4) Ry(q5) Trans(0, 0, q6)` of
//! `urdf/laser_cutter.urdf` is the same map.
//!
//! The inverse (eq. 3) is closed-form. Its only choice is the branch of the
//! rotary axes: every tool axis off the vertical has the solutions
//! `q4 = atan2(O_y, O_x) + kπ`, with `q5 = arccos(O_z)` for even `k` and
//! `q5 = -arccos(O_z)` for odd `k`. [`rotary_ikt`] picks the branch that
//! keeps q4 continuous along a path.

use nalgebra::Vector3;

use crate::machine::{AxisLimits, JOINT_NAMES};
use crate::PlanError;

/// Norm of `(O_x, O_y)` below which the tool axis counts as vertical
/// (q5 = 0 or ±π): q4 is then undefined and kept at its previous value.
pub const SINGULAR_XY_NORM: f64 = 1e-9;

/// Largest accepted deviation of a tool axis norm from 1 in the inverse
/// kinematics. The axis is normalised before use.
pub const AXIS_NORM_TOLERANCE: f64 = 1e-6;

/// Positions this close outside a joint's stroke (m or rad) are accepted
/// and clamped onto the limit: they are rounding, not a violation.
pub const STROKE_TOLERANCE: f64 = 1e-9;

/// Why the inverse kinematics has no solution.
///
/// The planner maps it to [`PlanError::Unreachable`] with the index of the
/// CL point ([`IktError::into_plan_error`]).
#[derive(Debug, Clone, PartialEq)]
pub enum IktError {
    /// An input is NaN or infinite, or the tool axis is not a unit vector.
    InvalidInput {
        /// Which input ("tool axis", "CL point", "q6", "previous q4").
        what: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// A joint would leave its stroke.
    OutOfStroke {
        /// Joint name, q1..q6.
        joint: &'static str,
        /// The position the joint would need (m or rad); for the rotary
        /// axes, the candidate nearest to the stroke.
        value: f64,
        /// Lower limit (m or rad).
        min: f64,
        /// Upper limit (m or rad).
        max: f64,
        /// Why that position is needed, e.g. the tool axis component.
        note: String,
    },
}

impl IktError {
    /// How far the needed position lies outside the stroke (m or rad);
    /// 0 for [`IktError::InvalidInput`].
    pub fn excess(&self) -> f64 {
        match self {
            IktError::InvalidInput { .. } => 0.0,
            IktError::OutOfStroke {
                value, min, max, ..
            } => outside_by(*value, *min, *max),
        }
    }

    /// The planner's error for CL point `index`:
    /// [`PlanError::Unreachable`] carrying this message.
    pub fn into_plan_error(self, index: usize) -> PlanError {
        PlanError::Unreachable {
            index,
            reason: self.to_string(),
        }
    }
}

impl std::fmt::Display for IktError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            IktError::InvalidInput { what, reason } => write!(f, "{what}: {reason}"),
            IktError::OutOfStroke {
                joint,
                value,
                min,
                max,
                note,
            } => {
                write!(
                    f,
                    "joint {joint} would be at {value:.6}, outside its stroke [{min:.6}, {max:.6}] by {:.6}",
                    outside_by(*value, *min, *max)
                )?;
                if !note.is_empty() {
                    write!(f, " ({note})")?;
                }
                Ok(())
            }
        }
    }
}

impl std::error::Error for IktError {}

/// Distance of `v` from the interval `[min, max]` (0 inside).
fn outside_by(v: f64, min: f64, max: f64) -> f64 {
    if v > max {
        v - max
    } else if v < min {
        min - v
    } else {
        0.0
    }
}

/// `v` if it lies within `limits` (up to [`STROKE_TOLERANCE`], then clamped
/// onto the limit), else `None`.
fn within(v: f64, (min, max): (f64, f64)) -> Option<f64> {
    if v >= min - STROKE_TOLERANCE && v <= max + STROKE_TOLERANCE {
        Some(v.max(min).min(max))
    } else {
        None
    }
}

/// Unit tool axis of the rotary axes (seed 001 eq. 2, rows 4-6):
/// `O = (cos q4 sin q5, sin q4 sin q5, cos q5)`.
///
/// # Arguments
/// * `q4` - rotation about the vertical (rad).
/// * `q5` - tilt from the vertical (rad).
pub fn tool_axis(q4: f64, q5: f64) -> Vector3<f64> {
    let (s4, c4) = q4.sin_cos();
    let (s5, c5) = q5.sin_cos();
    Vector3::new(c4 * s5, s4 * s5, c5)
}

/// Forward kinematics (seed 001 eq. 2): `C = M + q6 O` with
/// `M = (q1, q2, q3)` and `O` from [`tool_axis`].
///
/// # Arguments
/// * `q` - joints q1..q6 (m, m, m, rad, rad, m).
///
/// # Returns
/// `(C, O)`: the CL point (m) and the unit tool axis, in the machine frame.
/// NaN joints give NaN components.
pub fn forward(q: &[f64; 6]) -> (Vector3<f64>, Vector3<f64>) {
    let o = tool_axis(q[3], q[4]);
    let m = Vector3::new(q[0], q[1], q[2]);
    (m + q[5] * o, o)
}

/// The rotary-axes centre `M = C - q6 O` (seed 001 eq. 3 rows 1-3, eq. 46
/// with the sign of eq. 2): the position of the translational axes q1..q3.
///
/// # Arguments
/// * `c` - CL point (m).
/// * `o` - unit tool axis.
/// * `q6` - standoff axis (m).
pub fn m_point(c: &Vector3<f64>, o: &Vector3<f64>, q6: f64) -> Vector3<f64> {
    c - q6 * o
}

/// Inverse kinematics of the rotary axes (seed 001 eq. 3 rows 4-5),
/// choosing the branch that keeps q4 continuous.
///
/// Eq. 3 prints `q4 = arctan2(O_x, O_y)`; with eq. 2
/// (`O_x = cos q4 sin q5`, `O_y = sin q4 sin q5`) the correct form is
/// `q4 = atan2(O_y, O_x)`, used here. The branches are
/// `q4 = atan2(O_y, O_x) + kπ` for every integer `k` whose q4 lies within
/// `limits_q4` (k = 0, ±1 in the paper; ±2 as well for the 2π unwraps that
/// q4 ∈ [-2π, 2π] allows); an odd `k` flips the sign of q5
/// (`q5 = -arccos(O_z)`), since `cos(q4 + π) sin(-q5) = cos q4 sin q5`.
///
/// Choice among the branches within both limits:
/// * with `previous_q4`, the q4 nearest to it (continuity along a path;
///   on a tie, even `k` first);
/// * without, `k = 0` if it is within the limits, else the smallest |q4|.
///
/// At the singular pose (`|(O_x, O_y)| <` [`SINGULAR_XY_NORM`], q5 = 0)
/// q4 is undefined: it keeps `previous_q4` (0 without one, clamped into
/// its stroke) and never jumps.
///
/// # Arguments
/// * `o` - tool axis; its norm must be 1 within [`AXIS_NORM_TOLERANCE`]
///   (it is normalised).
/// * `previous_q4` - q4 of the previous path point (rad), if any.
/// * `limits_q4`, `limits_q5` - strokes `(min, max)` (rad).
///
/// # Returns
/// `(q4, q5)` in rad.
///
/// # Errors
/// [`IktError::InvalidInput`] for a NaN, infinite or non-unit axis or a
/// non-finite `previous_q4`; [`IktError::OutOfStroke`] when no branch is
/// within the limits, naming the joint and by how much (e.g. `O_z < 0`
/// needs `|q5| > π/2`).
///
/// # Performance
/// O(1), no allocation.
pub fn rotary_ikt(
    o: &Vector3<f64>,
    previous_q4: Option<f64>,
    limits_q4: (f64, f64),
    limits_q5: (f64, f64),
) -> Result<(f64, f64), IktError> {
    let o = unit_axis(o)?;
    if let Some(p) = previous_q4 {
        if !p.is_finite() {
            return Err(IktError::InvalidInput {
                what: "previous q4",
                reason: format!("{p} is not finite"),
            });
        }
    }
    let q5_abs = o.z.clamp(-1.0, 1.0).acos();
    let rho = o.x.hypot(o.y);

    if rho < SINGULAR_XY_NORM {
        // Vertical axis: q5 = 0 (or ±π when pointing down), q4 is free.
        let q4 = previous_q4.unwrap_or(0.0).max(limits_q4.0).min(limits_q4.1);
        return match within(q5_abs, limits_q5).or_else(|| within(-q5_abs, limits_q5)) {
            Some(q5) => Ok((q4, q5)),
            None => Err(q5_error(q5_abs, limits_q5, o.z)),
        };
    }

    let base = o.y.atan2(o.x);
    let target = previous_q4.unwrap_or(0.0);
    // Branches are searched around the target clamped into the stroke: the
    // in-stroke branch nearest to the target is one of the three around
    // it, even for a target outside the stroke.
    let search = target.max(limits_q4.0).min(limits_q4.1);
    let mut best: Option<(f64, f64, f64, i64)> = None; // (q4, q5, score, k)
    let mut any_q5 = false;
    let mut nearest_q4 = f64::NAN;
    for parity in [0_i64, 1] {
        let q5_raw = if parity == 0 { q5_abs } else { -q5_abs };
        let Some(q5) = within(q5_raw, limits_q5) else {
            continue;
        };
        any_q5 = true;
        // Branches of this parity: base + parity π + 2π j; the ones around
        // the target are the only candidates for "nearest".
        let offset = base + parity as f64 * std::f64::consts::PI;
        let j0 = ((search - offset) / std::f64::consts::TAU).round();
        for dj in [-1.0, 0.0, 1.0] {
            let j = j0 + dj;
            let q4_raw = offset + std::f64::consts::TAU * j;
            if nearest_q4.is_nan()
                || outside_by(q4_raw, limits_q4.0, limits_q4.1)
                    < outside_by(nearest_q4, limits_q4.0, limits_q4.1)
            {
                nearest_q4 = q4_raw;
            }
            let Some(q4) = within(q4_raw, limits_q4) else {
                continue;
            };
            let k = parity + 2 * j as i64;
            let score = match previous_q4 {
                Some(p) => (q4 - p).abs(),
                // Without a previous value: k = 0 first, then |q4|.
                None if k == 0 => -1.0,
                None => q4.abs(),
            };
            let better = match best {
                None => true,
                Some((_, _, s, bk)) => {
                    score < s || (score == s && k.rem_euclid(2) < bk.rem_euclid(2))
                }
            };
            if better {
                best = Some((q4, q5, score, k));
            }
        }
    }
    match best {
        Some((q4, q5, _, _)) => Ok((q4, q5)),
        None if !any_q5 => Err(q5_error(q5_abs, limits_q5, o.z)),
        None => Err(IktError::OutOfStroke {
            joint: JOINT_NAMES[3],
            value: nearest_q4,
            min: limits_q4.0,
            max: limits_q4.1,
            note: format!(
                "every branch atan2(O_y, O_x) + kπ = {base:.6} + kπ rad is outside the stroke"
            ),
        }),
    }
}

/// The q5 error: neither `+arccos(O_z)` nor `-arccos(O_z)` is in the stroke.
fn q5_error(q5_abs: f64, (min, max): (f64, f64), oz: f64) -> IktError {
    let value = if outside_by(q5_abs, min, max) <= outside_by(-q5_abs, min, max) {
        q5_abs
    } else {
        -q5_abs
    };
    IktError::OutOfStroke {
        joint: JOINT_NAMES[4],
        value,
        min,
        max,
        note: format!("tool axis O_z = {oz:.6} needs |q5| = arccos(O_z) = {q5_abs:.6} rad"),
    }
}

/// The unit form of a tool axis, or why it is not one.
fn unit_axis(o: &Vector3<f64>) -> Result<Vector3<f64>, IktError> {
    if o.iter().any(|v| !v.is_finite()) {
        return Err(IktError::InvalidInput {
            what: "tool axis",
            reason: format!("[{}, {}, {}] is not finite", o.x, o.y, o.z),
        });
    }
    let norm = o.norm();
    if (norm - 1.0).abs() > AXIS_NORM_TOLERANCE {
        return Err(IktError::InvalidInput {
            what: "tool axis",
            reason: format!("norm {norm:.9} is not 1 (tolerance {AXIS_NORM_TOLERANCE:e})"),
        });
    }
    Ok(o / norm)
}

/// Full inverse kinematics (seed 001 eq. 3): the rotary axes from
/// [`rotary_ikt`], then `(q1, q2, q3) = M = C - q6 O` with the tool axis
/// re-evaluated from the chosen (q4, q5) (eq. 2), so that
/// `forward(inverse(..)) = (C, O)` to rounding.
///
/// # Arguments
/// * `c` - CL point in the machine frame (m).
/// * `o` - unit tool axis.
/// * `q6` - standoff (m).
/// * `previous_q4` - q4 of the previous path point, for continuity.
/// * `limits` - strokes of q1..q6.
///
/// # Returns
/// The joint vector q1..q6.
///
/// # Errors
/// [`IktError::InvalidInput`] for non-finite inputs or a non-unit axis;
/// [`IktError::OutOfStroke`] naming the first joint (q6, then q4/q5, then
/// q1..q3) that leaves its stroke, with the amount.
///
/// # Performance
/// O(1), no allocation.
pub fn inverse(
    c: &Vector3<f64>,
    o: &Vector3<f64>,
    q6: f64,
    previous_q4: Option<f64>,
    limits: &[AxisLimits; 6],
) -> Result<[f64; 6], IktError> {
    if c.iter().any(|v| !v.is_finite()) {
        return Err(IktError::InvalidInput {
            what: "CL point",
            reason: format!("[{}, {}, {}] is not finite", c.x, c.y, c.z),
        });
    }
    if !q6.is_finite() {
        return Err(IktError::InvalidInput {
            what: "q6",
            reason: format!("{q6} is not finite"),
        });
    }
    let q6 = checked(5, q6, limits, String::new())?;
    let [_, _, _, l4, l5, _] = limits;
    let (q4, q5) = rotary_ikt(o, previous_q4, (l4.min, l4.max), (l5.min, l5.max))?;
    let axis = tool_axis(q4, q5);
    let m = m_point(c, &axis, q6);
    let mut q = [0.0, 0.0, 0.0, q4, q5, q6];
    for (i, slot) in q.iter_mut().take(3).enumerate() {
        *slot = checked(
            i,
            m[i],
            limits,
            format!("M = C - q6 O = [{:.6}, {:.6}, {:.6}]", m.x, m.y, m.z),
        )?;
    }
    Ok(q)
}

/// `v` clamped into the stroke of joint `i` (within [`STROKE_TOLERANCE`]),
/// or the out-of-stroke error.
fn checked(i: usize, v: f64, limits: &[AxisLimits; 6], note: String) -> Result<f64, IktError> {
    let (l, joint) = match (limits.get(i), JOINT_NAMES.get(i)) {
        (Some(l), Some(j)) => (l, *j),
        _ => {
            return Err(IktError::InvalidInput {
                what: "joint index",
                reason: format!("{i} is not a joint of q1..q6"),
            })
        }
    };
    within(v, (l.min, l.max)).ok_or(IktError::OutOfStroke {
        joint,
        value: v,
        min: l.min,
        max: l.max,
        note,
    })
}

/// The configuration with the head `distance` m further back along its tool axis, away from
/// the part (issue 27, approach and retract): the gantry moves the rotary-axes centre
/// `M = (q1, q2, q3)` by `distance · O(q4, q5)` (eq. 2: `C = M + q6 O`, the head above the
/// part along `O`); the head's orientation and the standoff q6 are unchanged.
///
/// # Errors
/// [`kerf_approach::ApproachError::JointCount`] for a configuration of another length than 6,
/// [`kerf_approach::ApproachError::OutOfLimits`] (and the other configuration errors) when
/// the result leaves `limits`.
pub fn tool_axis_back_off(
    q: &[f64],
    distance: f64,
    limits: &[kerf_approach::JointLimit],
) -> Result<Vec<f64>, kerf_approach::ApproachError> {
    if q.len() != 6 {
        return Err(kerf_approach::ApproachError::JointCount {
            what: "tool-axis back-off".into(),
            expected: 6,
            found: q.len(),
        });
    }
    let o = tool_axis(q[3], q[4]);
    let mut out = q.to_vec();
    for (k, v) in out.iter_mut().take(3).enumerate() {
        *v += distance * o[k];
    }
    kerf_approach::limits::check_configuration(kerf_approach::Role::Waypoint(0), &out, limits)?;
    Ok(out)
}
