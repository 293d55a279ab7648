//! Mirrors of `control_msgs` (ros-controls/control_msgs, branch `jazzy`,
//! release 5.x) used by kerf.
//!
//! The action `control_msgs/action/FollowJointTrajectory` is mirrored as its
//! three parts [`FollowJointTrajectoryGoal`], [`FollowJointTrajectoryResult`]
//! and [`FollowJointTrajectoryFeedback`]; the action protocol wrappers
//! (goal id, status) are ros2-client's.

use serde::{Deserialize, Serialize};

use crate::builtin_interfaces::Duration;
use crate::ros_type::impl_ros_type;
use crate::std_msgs::Header;
use crate::trajectory_msgs::{
    JointTrajectory, JointTrajectoryPoint, MultiDOFJointTrajectory, MultiDOFJointTrajectoryPoint,
};

/// `control_msgs/msg/JointTolerance`: how far a joint may deviate from its
/// setpoint. 0 means "unspecified, use the default"; -1 means "no limit".
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct JointTolerance {
    /// Joint name.
    pub name: String,
    /// Position tolerance, rad or m.
    pub position: f64,
    /// Velocity tolerance, rad/s or m/s.
    pub velocity: f64,
    /// Acceleration tolerance, rad/s² or m/s².
    pub acceleration: f64,
}
impl_ros_type!(JointTolerance, "control_msgs", msg, "JointTolerance");

/// `control_msgs/msg/JointComponentTolerance`: tolerance of one component of a
/// multi-DOF joint; `component` is one of the associated constants.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct JointComponentTolerance {
    /// Joint name.
    pub joint_name: String,
    /// Which component: [`X_AXIS`](Self::X_AXIS) … [`ROTATION`](Self::ROTATION).
    pub component: u16,
    /// Position tolerance, m (axes, translation) or rad (rotation).
    pub position: f64,
    /// Velocity tolerance, m/s or rad/s.
    pub velocity: f64,
    /// Acceleration tolerance, m/s² or rad/s².
    pub acceleration: f64,
}
impl_ros_type!(
    JointComponentTolerance,
    "control_msgs",
    msg,
    "JointComponentTolerance"
);

impl JointComponentTolerance {
    /// Tolerance on the x axis only.
    pub const X_AXIS: u16 = 1;
    /// Tolerance on the y axis only.
    pub const Y_AXIS: u16 = 2;
    /// Tolerance on the z axis only (floating joints only).
    pub const Z_AXIS: u16 = 3;
    /// Tolerance on the Euclidean translation distance.
    pub const TRANSLATION: u16 = 4;
    /// Tolerance on the rotation angle between quaternions.
    pub const ROTATION: u16 = 5;
}

/// `control_msgs/msg/JointTrajectoryControllerState` as of control_msgs 5.3
/// (Jazzy): reference/feedback/error/output points plus their multi-DOF
/// counterparts and `speed_scaling_factor`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct JointTrajectoryControllerState {
    /// `header.stamp` is the controller update time.
    pub header: Header,
    /// Joint names, the order of the points' arrays.
    pub joint_names: Vec<String>,
    /// Setpoint (desired state).
    pub reference: JointTrajectoryPoint,
    /// Latest measured state.
    pub feedback: JointTrajectoryPoint,
    /// `reference - feedback`.
    pub error: JointTrajectoryPoint,
    /// Controller output.
    pub output: JointTrajectoryPoint,
    /// Multi-DOF joint names.
    pub multi_dof_joint_names: Vec<String>,
    /// Multi-DOF setpoint.
    pub multi_dof_reference: MultiDOFJointTrajectoryPoint,
    /// Multi-DOF measured state.
    pub multi_dof_feedback: MultiDOFJointTrajectoryPoint,
    /// Multi-DOF error.
    pub multi_dof_error: MultiDOFJointTrajectoryPoint,
    /// Multi-DOF controller output.
    pub multi_dof_output: MultiDOFJointTrajectoryPoint,
    /// Speed scaling factor the trajectory is executed with (1 = nominal speed).
    pub speed_scaling_factor: f64,
}
impl_ros_type!(
    JointTrajectoryControllerState,
    "control_msgs",
    msg,
    "JointTrajectoryControllerState"
);

/// Goal of `control_msgs/action/FollowJointTrajectory`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct FollowJointTrajectoryGoal {
    /// Trajectory of the single-DOF (revolute, continuous, prismatic) joints.
    pub trajectory: JointTrajectory,
    /// Trajectory of the multi-DOF (planar, floating) joints.
    pub multi_dof_trajectory: MultiDOFJointTrajectory,
    /// Tolerances applied while executing; violation aborts with
    /// [`FollowJointTrajectoryResult::PATH_TOLERANCE_VIOLATED`].
    pub path_tolerance: Vec<JointTolerance>,
    /// Multi-DOF path tolerances.
    pub component_path_tolerance: Vec<JointComponentTolerance>,
    /// Tolerances on the final point; violation aborts with
    /// [`FollowJointTrajectoryResult::GOAL_TOLERANCE_VIOLATED`].
    pub goal_tolerance: Vec<JointTolerance>,
    /// Multi-DOF goal tolerances.
    pub component_goal_tolerance: Vec<JointComponentTolerance>,
    /// Extra time after the trajectory's end for reaching the goal tolerance.
    pub goal_time_tolerance: Duration,
}
impl_ros_type!(
    FollowJointTrajectoryGoal,
    "control_msgs",
    action,
    "FollowJointTrajectory_Goal"
);

/// Result of `control_msgs/action/FollowJointTrajectory`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct FollowJointTrajectoryResult {
    /// One of the associated result-code constants.
    pub error_code: i32,
    /// Human-readable description of the error.
    pub error_string: String,
}
impl_ros_type!(
    FollowJointTrajectoryResult,
    "control_msgs",
    action,
    "FollowJointTrajectory_Result"
);

impl FollowJointTrajectoryResult {
    /// The trajectory was executed successfully.
    pub const SUCCESSFUL: i32 = 0;
    /// The goal is invalid (e.g. a trajectory in the past, bad values).
    pub const INVALID_GOAL: i32 = -1;
    /// The goal's joints do not match the controller's.
    pub const INVALID_JOINTS: i32 = -2;
    /// The goal's header stamp is too old.
    pub const OLD_HEADER_TIMESTAMP: i32 = -3;
    /// A path tolerance was violated during execution.
    pub const PATH_TOLERANCE_VIOLATED: i32 = -4;
    /// The goal tolerance was not met in time.
    pub const GOAL_TOLERANCE_VIOLATED: i32 = -5;
}

/// Feedback of `control_msgs/action/FollowJointTrajectory`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct FollowJointTrajectoryFeedback {
    /// `header.stamp` is when the feedback was produced.
    pub header: Header,
    /// Joint names, the order of the points' arrays.
    pub joint_names: Vec<String>,
    /// Desired state.
    pub desired: JointTrajectoryPoint,
    /// Measured state.
    pub actual: JointTrajectoryPoint,
    /// `desired - actual`.
    pub error: JointTrajectoryPoint,
    /// Multi-DOF joint names.
    pub multi_dof_joint_names: Vec<String>,
    /// Multi-DOF desired state.
    pub multi_dof_desired: MultiDOFJointTrajectoryPoint,
    /// Multi-DOF measured state.
    pub multi_dof_actual: MultiDOFJointTrajectoryPoint,
    /// Multi-DOF error.
    pub multi_dof_error: MultiDOFJointTrajectoryPoint,
}
impl_ros_type!(
    FollowJointTrajectoryFeedback,
    "control_msgs",
    action,
    "FollowJointTrajectory_Feedback"
);
