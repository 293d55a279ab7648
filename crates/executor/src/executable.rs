//! [`check_executable`]: would the executor run this trajectory? The one executability check
//! of kerf: every planner runs its output through it before publishing a success.

use crate::{
    error::ExecutorError,
    trajectory::ValidatedTrajectory,
    types::{ExecutorConfig, JointLimits, JointSample, TrajectoryRequest},
    validate::prepare,
};

/// Checks a trajectory exactly as the executor would accept it from a robot standing still at
/// the trajectory's first point: the executor's own validation ([`crate::validate()`]), a pure
/// function of the trajectory and the robot model.
///
/// # Arguments
/// * `limits` — the robot model the trajectory will run on (model joint order).
/// * `cfg` — the executor's configuration (control period, start tolerance); the planners use
///   [`ExecutorConfig::default`], the trajectory executor node's defaults.
/// * `trajectory` — the planned trajectory, joints in any order. A `start_time` is taken as
///   "now" (the check does not depend on the clock).
///
/// # Returns
/// The validated trajectory (model order, on time from its start), or the first reason the
/// executor would refuse it ([`ExecutorError`]; an empty trajectory is
/// [`ExecutorError::EmptyTrajectory`]: for a planner, "no motion" is not a plan).
///
/// # Performance
/// As [`prepare`]: O(points · joints), about 3 ms for 6 joints × 1000 quintic points in a
/// release build.
pub fn check_executable(
    limits: &[JointLimits],
    cfg: &ExecutorConfig,
    trajectory: &TrajectoryRequest,
) -> Result<ValidatedTrajectory, ExecutorError> {
    let prepared = prepare(limits, cfg, trajectory)?;
    // `prepare` checked that the names are exactly the model's joints and that the first
    // point exists with one finite position per name.
    let first = &trajectory.points[0].positions;
    let start: Vec<f64> = limits
        .iter()
        .map(|l| {
            trajectory
                .joint_names
                .iter()
                .position(|name| name == &l.name)
                .and_then(|k| first.get(k).copied())
                .unwrap_or(f64::NAN)
        })
        .collect();
    let now = trajectory.start_time.unwrap_or(0.0);
    prepared.finish(limits, cfg, &JointSample::at_rest(start), now)
}
