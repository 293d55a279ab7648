//! Mirrors of `trajectory_msgs` (ros2/common_interfaces, Jazzy).

use serde::{Deserialize, Serialize};

use crate::builtin_interfaces::Duration;
use crate::geometry_msgs::{Transform, Twist};
use crate::ros_type::impl_ros_type;
use crate::std_msgs::Header;

/// `trajectory_msgs/msg/JointTrajectory`: a trajectory of single-DOF joints.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct JointTrajectory {
    /// `header.stamp` is when the trajectory starts; zero means "now".
    pub header: Header,
    /// Joint names; the order of every point's arrays.
    pub joint_names: Vec<String>,
    /// Waypoints, in increasing `time_from_start`.
    pub points: Vec<JointTrajectoryPoint>,
}
impl_ros_type!(JointTrajectory, "trajectory_msgs", msg, "JointTrajectory");

/// `trajectory_msgs/msg/JointTrajectoryPoint`: one waypoint. Each array is
/// either empty or has one entry per joint.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct JointTrajectoryPoint {
    /// Positions, rad or m.
    pub positions: Vec<f64>,
    /// Velocities, rad/s or m/s.
    pub velocities: Vec<f64>,
    /// Accelerations, rad/s² or m/s².
    pub accelerations: Vec<f64>,
    /// Efforts, N·m or N.
    pub effort: Vec<f64>,
    /// Time of this point after the trajectory start.
    pub time_from_start: Duration,
}
impl_ros_type!(
    JointTrajectoryPoint,
    "trajectory_msgs",
    msg,
    "JointTrajectoryPoint"
);

/// `trajectory_msgs/msg/MultiDOFJointTrajectory`: a trajectory of multi-DOF
/// (planar or floating) joints.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct MultiDOFJointTrajectory {
    /// `header.stamp` is when the trajectory starts; zero means "now".
    pub header: Header,
    /// Joint names; the order of every point's arrays.
    pub joint_names: Vec<String>,
    /// Waypoints, in increasing `time_from_start`.
    pub points: Vec<MultiDOFJointTrajectoryPoint>,
}
impl_ros_type!(
    MultiDOFJointTrajectory,
    "trajectory_msgs",
    msg,
    "MultiDOFJointTrajectory"
);

/// `trajectory_msgs/msg/MultiDOFJointTrajectoryPoint`: one multi-DOF waypoint.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct MultiDOFJointTrajectoryPoint {
    /// Joint poses, one per joint.
    pub transforms: Vec<Transform>,
    /// Joint velocities, one per joint or empty.
    pub velocities: Vec<Twist>,
    /// Joint accelerations, one per joint or empty.
    pub accelerations: Vec<Twist>,
    /// Time of this point after the trajectory start.
    pub time_from_start: Duration,
}
impl_ros_type!(
    MultiDOFJointTrajectoryPoint,
    "trajectory_msgs",
    msg,
    "MultiDOFJointTrajectoryPoint"
);
