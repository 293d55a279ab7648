//! The rules of the executor's inputs: `trajectory_msgs/JointTrajectory` (the
//! `~/joint_trajectory` topic), the `control_msgs/action/FollowJointTrajectory` goal and the
//! `kerf_msgs/srv/ValidateTrajectory` request. The executor's own validation (joint limits,
//! increasing times, tolerances' meaning) stays; these bounds are far outside any joint's
//! limits and refuse only what no robot could mean.

use super::{declare_rules, Rule, Section};
use crate::control_msgs::FollowJointTrajectoryGoal;
use crate::srv::ValidateTrajectoryRequest;
use crate::trajectory_msgs::JointTrajectory;

/// Largest |joint position| (rad or m): 1591 turns of a continuous joint.
pub const MAX_POSITION: f64 = 1e4;
/// Largest |joint velocity| (rad/s or m/s).
pub const MAX_VELOCITY: f64 = 1e4;
/// Largest |joint acceleration| (rad/s^2 or m/s^2).
pub const MAX_ACCELERATION: f64 = 1e6;
/// Largest |joint effort| (N m or N).
pub const MAX_EFFORT: f64 = 1e7;
/// Largest `time_from_start` and `goal_time_tolerance` (s): 10^7 s, 115 days.
pub const MAX_SECONDS: f64 = 1e7;
/// Largest `nanosec` of a time or duration (ns): the ROS convention `[0, 1e9)`.
pub const MAX_NANOSEC: f64 = 999_999_999.0;

/// The rules of a `JointTrajectory` (at the top level, or under a prefix).
pub const JOINT_TRAJECTORY: &[Rule] = &[
    // A stamp is ROS time: never negative; 0 = start now.
    Rule::closed("header.stamp.sec", 0.0, i32::MAX as f64, "s"),
    Rule::closed("header.stamp.nanosec", 0.0, MAX_NANOSEC, "ns"),
    Rule::closed(
        "points[].positions[]",
        -MAX_POSITION,
        MAX_POSITION,
        "rad or m",
    ),
    Rule::closed(
        "points[].velocities[]",
        -MAX_VELOCITY,
        MAX_VELOCITY,
        "rad/s or m/s",
    ),
    Rule::closed(
        "points[].accelerations[]",
        -MAX_ACCELERATION,
        MAX_ACCELERATION,
        "rad/s^2 or m/s^2",
    ),
    Rule::closed("points[].effort[]", -MAX_EFFORT, MAX_EFFORT, "N m or N"),
    Rule::closed("points[].time_from_start.sec", 0.0, MAX_SECONDS, "s"),
    Rule::closed("points[].time_from_start.nanosec", 0.0, MAX_NANOSEC, "ns"),
];

/// The rules of a `MultiDOFJointTrajectory` (the goal's `multi_dof_trajectory`; the executor
/// refuses a non-empty one, its numbers are checked all the same).
pub const MULTI_DOF_TRAJECTORY: &[Rule] = &[
    Rule::closed("header.stamp.sec", 0.0, i32::MAX as f64, "s"),
    Rule::closed("header.stamp.nanosec", 0.0, MAX_NANOSEC, "ns"),
    Rule::closed(
        "points[].transforms[].translation.*",
        -MAX_POSITION,
        MAX_POSITION,
        "m",
    ),
    Rule::closed("points[].transforms[].rotation.*", -1.001, 1.001, "-"),
    Rule::closed(
        "points[].velocities[].linear.*",
        -MAX_VELOCITY,
        MAX_VELOCITY,
        "m/s",
    ),
    Rule::closed(
        "points[].velocities[].angular.*",
        -MAX_VELOCITY,
        MAX_VELOCITY,
        "rad/s",
    ),
    Rule::closed(
        "points[].accelerations[].linear.*",
        -MAX_ACCELERATION,
        MAX_ACCELERATION,
        "m/s^2",
    ),
    Rule::closed(
        "points[].accelerations[].angular.*",
        -MAX_ACCELERATION,
        MAX_ACCELERATION,
        "rad/s^2",
    ),
    Rule::closed("points[].time_from_start.sec", 0.0, MAX_SECONDS, "s"),
    Rule::closed("points[].time_from_start.nanosec", 0.0, MAX_NANOSEC, "ns"),
];

/// A tolerance: 0 = default, -1 = no tolerance, else > 0 (control_msgs/JointTolerance).
const TOLERANCE: &[(f64, &str)] = &[(0.0, "default"), (-1.0, "no tolerance")];

/// The rules of the goal's own fields.
pub const GOAL: &[Rule] = &[
    Rule::closed("path_tolerance[].position", 1e-9, MAX_POSITION, "rad or m").or(TOLERANCE),
    Rule::closed(
        "path_tolerance[].velocity",
        1e-9,
        MAX_VELOCITY,
        "rad/s or m/s",
    )
    .or(TOLERANCE),
    Rule::closed(
        "path_tolerance[].acceleration",
        1e-9,
        MAX_ACCELERATION,
        "rad/s^2 or m/s^2",
    )
    .or(TOLERANCE),
    // control_msgs/JointComponentTolerance: X_AXIS = 1 ... ROTATION = 5.
    Rule::closed("component_path_tolerance[].component", 1.0, 5.0, "-"),
    Rule::closed(
        "component_path_tolerance[].position",
        1e-9,
        MAX_POSITION,
        "m or rad",
    )
    .or(TOLERANCE),
    Rule::closed(
        "component_path_tolerance[].velocity",
        1e-9,
        MAX_VELOCITY,
        "m/s or rad/s",
    )
    .or(TOLERANCE),
    Rule::closed(
        "component_path_tolerance[].acceleration",
        1e-9,
        MAX_ACCELERATION,
        "m/s^2 or rad/s^2",
    )
    .or(TOLERANCE),
    Rule::closed("goal_tolerance[].position", 1e-9, MAX_POSITION, "rad or m").or(TOLERANCE),
    Rule::closed(
        "goal_tolerance[].velocity",
        1e-9,
        MAX_VELOCITY,
        "rad/s or m/s",
    )
    .or(TOLERANCE),
    Rule::closed(
        "goal_tolerance[].acceleration",
        1e-9,
        MAX_ACCELERATION,
        "rad/s^2 or m/s^2",
    )
    .or(TOLERANCE),
    Rule::closed("component_goal_tolerance[].component", 1.0, 5.0, "-"),
    Rule::closed(
        "component_goal_tolerance[].position",
        1e-9,
        MAX_POSITION,
        "m or rad",
    )
    .or(TOLERANCE),
    Rule::closed(
        "component_goal_tolerance[].velocity",
        1e-9,
        MAX_VELOCITY,
        "m/s or rad/s",
    )
    .or(TOLERANCE),
    Rule::closed(
        "component_goal_tolerance[].acceleration",
        1e-9,
        MAX_ACCELERATION,
        "m/s^2 or rad/s^2",
    )
    .or(TOLERANCE),
    Rule::closed("goal_time_tolerance.sec", 0.0, MAX_SECONDS, "s"),
    Rule::closed("goal_time_tolerance.nanosec", 0.0, MAX_NANOSEC, "ns"),
];

declare_rules!(
    JointTrajectory,
    &[Section {
        prefix: "",
        rules: JOINT_TRAJECTORY
    }]
);

declare_rules!(
    FollowJointTrajectoryGoal,
    &[
        Section {
            prefix: "trajectory.",
            rules: JOINT_TRAJECTORY
        },
        Section {
            prefix: "multi_dof_trajectory.",
            rules: MULTI_DOF_TRAJECTORY
        },
        Section {
            prefix: "",
            rules: GOAL
        },
    ]
);

declare_rules!(
    ValidateTrajectoryRequest,
    &[Section {
        prefix: "trajectory.",
        rules: JOINT_TRAJECTORY
    }]
);
