//! The harness frames every successful plan that has a start (issue 27, item 1): the approach
//! from the start, the process unchanged, the retract ([`kerf_approach::frame`]), as one
//! `JointTrajectory` and its [`PlanStretches`].

use kerf_approach::{frame, FrameSettings, Framed, JointLimit, Route, Sample, Surroundings};
use kerf_msgs::{
    builtin_interfaces::Duration,
    msg::PlanStretches,
    trajectory_msgs::{JointTrajectory, JointTrajectoryPoint},
};

use super::start::StartKind;

/// The process samples of a planned trajectory.
///
/// # Errors
/// A message naming the point: positions missing, velocities or accelerations of another
/// length than the positions (an empty list is read as zeros only where the point is the
/// first or last, at rest), a time that does not convert.
pub fn process_samples(trajectory: &JointTrajectory) -> Result<Vec<Sample>, String> {
    let n = trajectory.joint_names.len();
    let last = trajectory.points.len().saturating_sub(1);
    trajectory
        .points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let field = |name: &str, v: &[f64]| -> Result<Vec<f64>, String> {
                match v.len() {
                    len if len == n => Ok(v.to_vec()),
                    0 if name != "positions" && (i == 0 || i == last) => Ok(vec![0.0; n]),
                    len => Err(format!(
                        "planned point {i} has {len} {name} for {n} joints: the approach needs \
                         positions, velocities and accelerations"
                    )),
                }
            };
            Ok(Sample {
                t: p.time_from_start.as_secs_f64(),
                q: field("positions", &p.positions)?,
                qd: field("velocities", &p.velocities)?,
                qdd: field("accelerations", &p.accelerations)?,
            })
        })
        .collect()
}

/// The trajectory of a framed plan (same joint names and header as the process's).
///
/// # Errors
/// A message when a sample time does not convert to a `builtin_interfaces/Duration`.
pub fn framed_trajectory(
    process: &JointTrajectory,
    framed: &Framed,
) -> Result<JointTrajectory, String> {
    let points = framed
        .timeline
        .samples
        .iter()
        .map(|s| {
            Ok(JointTrajectoryPoint {
                positions: s.q.clone(),
                velocities: s.qd.clone(),
                accelerations: s.qdd.clone(),
                effort: Vec::new(),
                time_from_start: Duration::from_secs_f64(s.t)
                    .map_err(|e| format!("sample time {} s: {e}", s.t))?,
            })
        })
        .collect::<Result<Vec<_>, String>>()?;
    Ok(JointTrajectory {
        header: process.header.clone(),
        joint_names: process.joint_names.clone(),
        points,
    })
}

/// The stretches of a framed plan.
pub fn stretches(kind: StartKind, start: &[f64], framed: &Framed) -> PlanStretches {
    let tl = &framed.timeline;
    PlanStretches {
        start: kind.as_str().into(),
        start_positions: start.to_vec(),
        process_start_time: tl.process_start,
        process_end_time: tl.process_end,
        duration: tl.samples.last().map_or(0.0, |s| s.t),
        approach_route: match (framed.approach_route, framed.auto_via) {
            (Route::ViaSafePose(_), Some(d)) => {
                format!("via the tool axis {d} m above the first point")
            }
            (Route::ViaSafePose(i), None) => format!("via safe pose {i}"),
            _ => "direct".into(),
        },
        retract_route: if framed.retract_to_safe_pose {
            "tool axis, safe pose".into()
        } else {
            "tool axis".into()
        },
        min_clearance: framed.approach_closest.distance,
        min_lead_clearance: framed.lead_closest.distance,
    }
}

/// The stretches of a plan without a start: the process alone.
pub fn unframed(trajectory: &JointTrajectory) -> PlanStretches {
    let duration = trajectory
        .points
        .last()
        .map_or(0.0, |p| p.time_from_start.as_secs_f64());
    PlanStretches {
        start: "none".into(),
        start_positions: trajectory
            .points
            .first()
            .map(|p| p.positions.clone())
            .unwrap_or_default(),
        process_start_time: 0.0,
        process_end_time: duration,
        duration,
        ..PlanStretches::default()
    }
}

/// Frames a planned trajectory from `start`.
///
/// # Returns
/// The framed trajectory and its stretches, or the [`kerf_approach::ApproachError`]'s message
/// (and whether it is a missing approach — the world blocks every route, or the start is too
/// close to an obstacle — rather than a process the approach cannot join).
///
/// # Errors
/// `(message, no_approach)`.
pub fn frame_trajectory(
    kind: StartKind,
    start: &[f64],
    process: &JointTrajectory,
    limits: &[JointLimit],
    world: &dyn Surroundings,
    settings: &FrameSettings,
) -> Result<(JointTrajectory, PlanStretches), (String, bool)> {
    let samples = process_samples(process).map_err(|m| (m, false))?;
    let framed = frame(start, samples, limits, world, settings).map_err(|e| {
        use kerf_approach::ApproachError as E;
        let blocked = matches!(
            e.root(),
            E::InCollision { .. }
                | E::NoApproach { .. }
                | E::RetractBlocked { .. }
                | E::OutOfLimits { .. }
                | E::IkFailed { .. }
                | E::IkMismatch { .. }
        );
        (e.to_string(), blocked)
    })?;
    let trajectory = framed_trajectory(process, &framed).map_err(|m| (m, false))?;
    Ok((trajectory, stretches(kind, start, &framed)))
}
