//! Joint speeds between consecutive path segments: the robot must be able
//! to follow the plan's redundancy-angle changes (kerf's constraint, not in
//! seed 004).
//!
//! Each segment's joints are those at its arc-length midpoint; the tool
//! moves from the midpoint of segment t to that of segment t + 1 in
//! `Δt = l_t/(2 f_t) + l_{t+1}/(2 f_{t+1})`, so joint j moves at about
//! `|Δq_j| / Δt`. That must stay within the URDF's velocity limit of the
//! joint (IRB 6660: 1.92, 2.27, 2.27, 2.62, 2.09, 4.19 rad/s).
//!
//! Why: near the wrist singularity (q5 → 0) a change of g turns q4 and q6
//! by large angles; measured on the default cell, the eq. 12 DP optimum
//! turned q4 by 1.56 rad within one 0.16 s segment (10 rad/s, four times
//! joint 4's limit) — a plan no controller would run.

use kerf_mill::MillCell;

use crate::error::MillPlanError;

/// The time between the midpoints of two consecutive segments \[s\].
///
/// # Arguments
/// `lengths` (l_t, l_{t+1}) \[m\], `feeds` (f_t, f_{t+1}) [m/s] (> 0).
pub fn midpoint_interval(lengths: [f64; 2], feeds: [f64; 2]) -> f64 {
    lengths[0] / (2.0 * feeds[0]) + lengths[1] / (2.0 * feeds[1])
}

/// The velocity limits of the cell's six joints \[rad/s\] (URDF + limits
/// file).
///
/// # Errors
/// [`MillPlanError::InvalidConfig`] when the robot does not have six joints
/// or a limit is not finite and > 0.
pub fn velocity_limits(cell: &MillCell) -> Result<[f64; 6], MillPlanError> {
    let joints = cell.robot().joints();
    if joints.len() != 6 {
        return Err(MillPlanError::InvalidConfig {
            name: "joint velocity limits".to_string(),
            reason: format!("the robot has {} joints, expected 6", joints.len()),
        });
    }
    let mut out = [0.0; 6];
    for (o, j) in out.iter_mut().zip(joints) {
        if !(j.max_velocity.is_finite() && j.max_velocity > 0.0) {
            return Err(MillPlanError::InvalidConfig {
                name: format!("velocity limit of {}", j.name),
                reason: format!("{} rad/s is not finite and > 0", j.max_velocity),
            });
        }
        *o = j.max_velocity;
    }
    Ok(out)
}

/// Wraps `x` to the 2π-equivalent nearest `reference`.
fn nearest_turn(x: f64, reference: f64) -> f64 {
    let two_pi = std::f64::consts::TAU;
    x - two_pi * ((x - reference) / two_pi).round()
}

/// The smallest joint motion from `from` to the pose `to`, over the
/// equivalent wrist solutions: `(q4, q5, q6)` and `(q4 + π, −q5, q6 + π)`
/// (spherical wrist), with q4 and q6 taken modulo 2π. This is the motion of
/// a branch-continuous IK (the nearest solution) between the two poses;
/// joint position limits are not applied here.
pub fn smallest_motion(from: &[f64; 6], to: &[f64; 6]) -> [f64; 6] {
    let pi = std::f64::consts::PI;
    let flipped = [to[0], to[1], to[2], to[3] + pi, -to[4], to[5] + pi];
    let mut best = [0.0; 6];
    let mut best_norm = f64::INFINITY;
    for cand in [*to, flipped] {
        let mut d = [0.0; 6];
        for (j, dj) in d.iter_mut().enumerate() {
            let target = if j == 3 || j == 5 {
                nearest_turn(cand[j], from[j])
            } else {
                cand[j]
            };
            *dj = target - from[j];
        }
        let norm = d.iter().map(|v| v * v).sum::<f64>();
        if norm < best_norm {
            best_norm = norm;
            best = d;
        }
    }
    best
}

/// The first joint whose speed `|Δq_j| / dt` exceeds its limit, as
/// (joint index, speed \[rad/s\]); `None` when all are within.
///
/// # Arguments
/// `motion` — Δq \[rad\]; `dt` — the time \[s\] (> 0); `limits` \[rad/s\].
pub fn first_violation(motion: &[f64; 6], dt: f64, limits: &[f64; 6]) -> Option<(usize, f64)> {
    (0..6).find_map(|j| {
        let speed = motion[j].abs() / dt;
        // NaN speeds are violations too.
        (speed.is_nan() || speed > limits[j]).then_some((j, speed))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrist_flip_and_turns_are_not_motion() {
        let pi = std::f64::consts::PI;
        let a = [0.1, -0.2, 0.3, 0.4, 0.5, 0.6];
        let same = [0.1, -0.2, 0.3, 0.4 + pi, -0.5, 0.6 - pi];
        let d = smallest_motion(&a, &same);
        assert!(d.iter().all(|v| v.abs() < 1e-12), "{d:?}");
        let turned = [0.1, -0.2, 0.3, 0.4 + 2.0 * pi, 0.5, 0.6 - 4.0 * pi];
        let d = smallest_motion(&a, &turned);
        assert!(d.iter().all(|v| v.abs() < 1e-12), "{d:?}");
        let moved = [0.2, -0.2, 0.3, 0.9, 0.5, 0.6];
        let d = smallest_motion(&a, &moved);
        assert!((d[0] - 0.1).abs() < 1e-12 && (d[3] - 0.5).abs() < 1e-12);
    }

    #[test]
    fn violations_and_interval() {
        let lim = [1.0; 6];
        assert_eq!(first_violation(&[0.5; 6], 1.0, &lim), None);
        assert_eq!(
            first_violation(&[0.0, 0.0, 0.0, 0.3, 0.0, 0.0], 0.1, &lim),
            Some((3, 0.3 / 0.1))
        );
        assert!(first_violation(&[f64::NAN; 6], 1.0, &lim).is_some());
        assert!((midpoint_interval([0.01, 0.02], [0.05, 0.04]) - (0.1 + 0.25)).abs() < 1e-15);
    }
}
