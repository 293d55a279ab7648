//! kerf's own services (`kerf_msgs/srv`, defined in `msgs/srv/`).

use serde::{Deserialize, Serialize};

use crate::ros_type::impl_ros_type;
use crate::trajectory_msgs::JointTrajectory;

/// Request of `kerf_msgs/srv/ValidateTrajectory`: dry-run validation of a
/// trajectory against the executor's robot model, without moving.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ValidateTrajectoryRequest {
    /// The trajectory to check, as it would be sent to `~/joint_trajectory`.
    pub trajectory: JointTrajectory,
}
impl_ros_type!(
    ValidateTrajectoryRequest,
    "kerf_msgs",
    srv,
    "ValidateTrajectory_Request"
);

/// Response of `kerf_msgs/srv/ValidateTrajectory`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ValidateTrajectoryResponse {
    /// True when the executor would accept the trajectory.
    pub valid: bool,
    /// A `control_msgs/action/FollowJointTrajectory` result code (0 when valid), see
    /// [`FollowJointTrajectoryResult`](crate::control_msgs::FollowJointTrajectoryResult).
    pub error_code: i32,
    /// Human-readable reason when invalid; empty when valid.
    pub message: String,
    /// Duration of the trajectory (last `time_from_start`), s; 0 when invalid.
    pub duration: f64,
}
impl_ros_type!(
    ValidateTrajectoryResponse,
    "kerf_msgs",
    srv,
    "ValidateTrajectory_Response"
);
