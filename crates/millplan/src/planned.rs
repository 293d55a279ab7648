//! The planned joint trajectory of a plan (step 6 of
//! [`crate::planner::MillPlanner::plan`]).
//!
//! The environment and the plan place the tool at each segment's
//! arc-length MIDPOINT. The trajectory has N + 2 points: the path start
//! (t = 0, g of segment 0), the N midpoints with the plan's joints
//! exactly (t = Σ_{j<i} l_j/f_j + l_i/(2 f_i): the time the tool reaches
//! the midpoint at the planned feeds), and the path end
//! (t = Σ l_i/f_i, the plan's machining time, g of the last segment). The
//! end points' joints are the IK solutions nearest the adjacent midpoint's
//! (continuous branch). Joint names are the URDF's (`joint_1` …
//! `joint_6`). Velocities: the derivative of the parabola through each
//! point and its two neighbours (non-uniform three-point finite
//! difference, Fornberg 1988), one-sided differences at the two ends; no
//! accelerations. Joint steps above the cell's branch-jump threshold are
//! reported in [`crate::MillPlanOutput::branch_jumps`], not hidden.

use kerf_mill::{BranchJump, MillCell, MillError};

use crate::error::MillPlanError;
use crate::plan::Plan;
use crate::timing::three_point_velocity;
use crate::trajectory::{JointTrajectory, TrajectoryPoint, TrajectoryRequest};

/// The trajectory of the module documentation and its branch jumps.
///
/// # Arguments
/// * `cell` — the request's cell (path, kinematics, branch-jump threshold).
/// * `plan` — the evaluated plan (at least one segment).
///
/// # Returns
/// The planned trajectory and the joint steps above the cell's branch-jump
/// threshold (index = the later point).
///
/// # Errors
/// [`MillPlanError::InvalidConfig`] for a plan without segments or times
/// that do not increase (a zero segment time); the cell's IK errors at the
/// path's ends; [`MillError::NonFinite`] for a non-finite velocity.
pub fn planned_trajectory(
    cell: &MillCell,
    plan: &Plan,
) -> Result<(JointTrajectory, Vec<BranchJump>), MillPlanError> {
    let path = cell.path();
    let (Some(first), Some(last)) = (plan.segments.first(), plan.segments.last()) else {
        return Err(MillPlanError::InvalidConfig {
            name: "plan".to_string(),
            reason: "no segments".to_string(),
        });
    };
    let total_length = path.total_length();
    let mut points = Vec::with_capacity(plan.segments.len() + 2);
    let start = cell.joints_at(0.0, first.g, Some(&first.joints))?;
    points.push((start, 0.0, 0.0, 0usize));
    let mut elapsed = 0.0;
    let mut s = 0.0;
    for seg in &plan.segments {
        let length = path.segment(seg.segment)?.length;
        points.push((
            seg.joints,
            elapsed + 0.5 * seg.time,
            s + 0.5 * length,
            seg.segment,
        ));
        elapsed += seg.time;
        s += length;
    }
    let end = cell.joints_at(total_length, last.g, Some(&last.joints))?;
    points.push((end, elapsed, total_length, last.segment));
    for w in points.windows(2) {
        if w[1].1.partial_cmp(&w[0].1) != Some(std::cmp::Ordering::Greater) {
            return Err(MillPlanError::InvalidConfig {
                name: "trajectory".to_string(),
                reason: format!(
                    "times not increasing ({} then {} s): a zero segment time",
                    w[0].1, w[1].1
                ),
            });
        }
    }
    let n = points.len();
    let mut out = Vec::with_capacity(n);
    let mut arc_length = Vec::with_capacity(n);
    let mut segments = Vec::with_capacity(n);
    for k in 0..n {
        let (q, t, arc, segment) = points[k];
        let mut v = [0.0; 6];
        if k == 0 || k + 1 == n {
            let (a, b) = if k == 0 {
                (points[0], points[1])
            } else {
                (points[n - 2], points[n - 1])
            };
            for (j, vj) in v.iter_mut().enumerate() {
                *vj = (b.0[j] - a.0[j]) / (b.1 - a.1);
            }
        } else {
            // Fornberg 1988: derivative of the parabola through 3 points.
            let (qm, tm) = (points[k - 1].0, points[k - 1].1);
            let (qp, tp) = (points[k + 1].0, points[k + 1].1);
            let (h1, h2) = (t - tm, tp - t);
            for (j, vj) in v.iter_mut().enumerate() {
                *vj = three_point_velocity(h1, h2, qm[j], q[j], qp[j]);
            }
        }
        if v.iter().any(|x| !x.is_finite()) {
            return Err(MillError::NonFinite {
                what: format!("joint velocity at trajectory point {k}"),
            }
            .into());
        }
        out.push(TrajectoryPoint {
            positions: q.to_vec(),
            velocities: v.to_vec(),
            time_from_start: t,
            ..TrajectoryPoint::default()
        });
        arc_length.push(arc);
        segments.push(segment);
    }
    let names: Vec<String> = cell
        .kinematics()
        .joints()
        .iter()
        .map(|j| j.name.clone())
        .collect();
    let threshold = cell.branch_jump_threshold();
    let mut jumps = Vec::new();
    for (k, w) in out.windows(2).enumerate() {
        let (j, step) = w[1]
            .positions
            .iter()
            .zip(&w[0].positions)
            .map(|(a, b)| (a - b).abs())
            .enumerate()
            .fold((0, 0.0), |acc, (j, s)| if s > acc.1 { (j, s) } else { acc });
        if step > threshold {
            jumps.push(BranchJump {
                index: k + 1,
                joint: names.get(j).cloned().unwrap_or_default(),
                step,
            });
        }
    }
    Ok((
        JointTrajectory {
            request: TrajectoryRequest {
                joint_names: names,
                points: out,
                start_time: None,
            },
            arc_length,
            segment: segments,
        },
        jumps,
    ))
}
