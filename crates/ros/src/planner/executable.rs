//! The executability check of published plans, and the one conversion from
//! `trajectory_msgs/JointTrajectory` to the executor's [`TrajectoryRequest`] (used by the
//! trajectory executor node too, so that a plan is judged by exactly what the executor runs).

use kerf_executor::{
    check_executable, ExecutorConfig, JointLimits, TrajectoryPoint, TrajectoryRequest,
};
use kerf_msgs::{
    builtin_interfaces::{Duration, Time},
    std_msgs::Header,
    trajectory_msgs::{JointTrajectory, JointTrajectoryPoint},
};

fn duration_secs(d: &Duration, what: impl FnOnce() -> String) -> Result<f64, String> {
    if d.nanosec >= 1_000_000_000 {
        return Err(format!(
            "{}: nanosec {} is not below 1e9",
            what(),
            d.nanosec
        ));
    }
    Ok(d.as_secs_f64())
}

/// Converts a `trajectory_msgs/JointTrajectory` into the executor's ROS-free type.
///
/// # Arguments
/// * `msg` — the message.
/// * `start_time` — the executor's time of a non-zero `header.stamp` (a zero stamp means
///   "start on receipt": `start_time` `None`).
///
/// # Returns
/// The request, or why a time field is malformed (a `nanosec` of 1e9 or more). Everything
/// else is checked by the executor's validation.
pub fn trajectory_request(
    msg: &JointTrajectory,
    start_time: impl FnOnce(&Time) -> f64,
) -> Result<TrajectoryRequest, String> {
    if msg.header.stamp.nanosec >= 1_000_000_000 {
        return Err(format!(
            "header.stamp.nanosec {} is not below 1e9",
            msg.header.stamp.nanosec
        ));
    }
    let start_time = (!msg.header.stamp.is_zero()).then(|| start_time(&msg.header.stamp));
    let points = msg
        .points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            Ok(TrajectoryPoint {
                positions: p.positions.clone(),
                velocities: p.velocities.clone(),
                accelerations: p.accelerations.clone(),
                effort: p.effort.clone(),
                time_from_start: duration_secs(&p.time_from_start, || {
                    format!("point {i} time_from_start")
                })?,
            })
        })
        .collect::<Result<Vec<_>, String>>()?;
    Ok(TrajectoryRequest {
        joint_names: msg.joint_names.clone(),
        points,
        start_time,
    })
}

/// Converts the executor's ROS-free trajectory into a `trajectory_msgs/JointTrajectory` with
/// `header.stamp` zero (an executor starts it on receipt); the inverse of
/// [`trajectory_request`] for a trajectory without a start time.
///
/// # Errors
/// A point time that does not fit a `builtin_interfaces/Duration` (negative, NaN, too large),
/// naming the point; a trajectory with a `start_time` (a planner's output starts on receipt).
pub fn trajectory_msg(trajectory: &TrajectoryRequest) -> Result<JointTrajectory, String> {
    if let Some(t) = trajectory.start_time {
        return Err(format!(
            "the trajectory has a start time ({t} s); a planned trajectory starts on receipt"
        ));
    }
    let points = trajectory
        .points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            Ok(JointTrajectoryPoint {
                positions: p.positions.clone(),
                velocities: p.velocities.clone(),
                accelerations: p.accelerations.clone(),
                effort: p.effort.clone(),
                time_from_start: Duration::from_secs_f64(p.time_from_start)
                    .map_err(|e| format!("point {i}: time {} s: {e}", p.time_from_start))?,
            })
        })
        .collect::<Result<Vec<_>, String>>()?;
    Ok(JointTrajectory {
        header: Header::default(),
        joint_names: trajectory.joint_names.clone(),
        points,
    })
}

/// Would the trajectory executor (default configuration, robot standing still at the first
/// point) run this published trajectory? The message is converted as the executor converts
/// it and checked by its own validation ([`check_executable`]).
///
/// # Returns
/// `Ok` or the executor's reason for refusing it.
///
/// # Performance
/// A copy of the message plus [`check_executable`]: O(points · joints), milliseconds for
/// thousands of points.
pub fn check_trajectory_msg(limits: &[JointLimits], msg: &JointTrajectory) -> Result<(), String> {
    // A stamped plan is checked as if its start were now: the check does not depend on a clock.
    let request = trajectory_request(msg, |_| 0.0)?;
    check_executable(limits, &ExecutorConfig::default(), &request)
        .map(|_| ())
        .map_err(|e| e.to_string())
}
