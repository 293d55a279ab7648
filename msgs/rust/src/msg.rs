//! kerf's own messages (`kerf_msgs/msg`, defined in `msgs/msg/`).

use serde::{Deserialize, Serialize};

use crate::builtin_interfaces::Time;
use crate::ros_type::impl_ros_type;
use crate::std_msgs::Header;

/// `kerf_msgs/msg/TrajectoryStatus`: status of one trajectory received by the
/// trajectory executor on its `~/joint_trajectory` topic or as a
/// `~/follow_joint_trajectory` action goal; published on `~/trajectory_status`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct TrajectoryStatus {
    /// `header.stamp`: when this status was produced (executor clock).
    pub header: Header,
    /// `header.stamp` of the trajectory this status refers to (zero if it had none).
    pub trajectory_stamp: Time,
    /// Where the trajectory came from: [`SOURCE_TOPIC`](Self::SOURCE_TOPIC) or
    /// [`SOURCE_ACTION`](Self::SOURCE_ACTION).
    pub source: String,
    /// Action goal id as 32 lowercase hex digits; empty for the topic input.
    pub goal_id: String,
    /// One of the status constants ([`ACCEPTED`](Self::ACCEPTED) …).
    pub status: u8,
    /// A `control_msgs/action/FollowJointTrajectory` result code, see
    /// [`FollowJointTrajectoryResult`](crate::control_msgs::FollowJointTrajectoryResult).
    pub error_code: i32,
    /// Human-readable reason; says exactly what is wrong (joint, point, value, limit).
    pub message: String,
}
impl_ros_type!(TrajectoryStatus, "kerf_msgs", msg, "TrajectoryStatus");

impl TrajectoryStatus {
    /// The trajectory passed validation and was queued or started.
    pub const ACCEPTED: u8 = 1;
    /// The trajectory failed validation and was never executed.
    pub const REJECTED: u8 = 2;
    /// The trajectory was executed to its end within tolerance.
    pub const SUCCEEDED: u8 = 3;
    /// Execution stopped early because a tolerance or limit was violated.
    pub const ABORTED: u8 = 4;
    /// Execution was replaced by a newer trajectory before it finished.
    pub const PREEMPTED: u8 = 5;
    /// Execution was stopped by an action cancel request.
    pub const CANCELED: u8 = 6;

    /// Value of `source` for the topic input. Not an IDL constant: the `.msg`
    /// file documents the allowed values in a comment.
    pub const SOURCE_TOPIC: &'static str = "topic";
    /// Value of `source` for the action input. Not an IDL constant.
    pub const SOURCE_ACTION: &'static str = "action";

    /// Name of a status value (`"ACCEPTED"` …), or `None` for an unknown value.
    pub fn status_name(status: u8) -> Option<&'static str> {
        match status {
            Self::ACCEPTED => Some("ACCEPTED"),
            Self::REJECTED => Some("REJECTED"),
            Self::SUCCEEDED => Some("SUCCEEDED"),
            Self::ABORTED => Some("ABORTED"),
            Self::PREEMPTED => Some("PREEMPTED"),
            Self::CANCELED => Some("CANCELED"),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn status_names() {
        assert_eq!(
            TrajectoryStatus::status_name(TrajectoryStatus::ABORTED),
            Some("ABORTED")
        );
        assert_eq!(TrajectoryStatus::status_name(6), Some("CANCELED"));
        assert_eq!(TrajectoryStatus::status_name(0), None);
        assert_eq!(TrajectoryStatus::status_name(7), None);
    }
}
