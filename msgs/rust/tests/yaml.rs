//! YAML round trips (the format `kerf echo` prints) and `Default` values.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_msgs::builtin_interfaces::{Duration, Time};
use kerf_msgs::control_msgs::{
    FollowJointTrajectoryGoal, FollowJointTrajectoryResult, JointComponentTolerance, JointTolerance,
};
use kerf_msgs::geometry_msgs::{Pose, Quaternion, Transform};
use kerf_msgs::msg::TrajectoryStatus;
use kerf_msgs::sensor_msgs::JointState;
use kerf_msgs::srv::ValidateTrajectoryResponse;
use kerf_msgs::std_msgs::Header;
use kerf_msgs::trajectory_msgs::{JointTrajectory, JointTrajectoryPoint};
use serde::{de::DeserializeOwned, Serialize};

fn round_trip<T: Serialize + DeserializeOwned + PartialEq + std::fmt::Debug>(value: &T) -> String {
    let text = serde_yaml_ng::to_string(value).expect("serialize");
    let back: T = serde_yaml_ng::from_str(&text).expect("deserialize");
    assert_eq!(&back, value, "YAML:\n{text}");
    text
}

fn trajectory() -> JointTrajectory {
    JointTrajectory {
        header: Header {
            stamp: Time {
                sec: 1_700_000_000,
                nanosec: 5,
            },
            frame_id: "base_link".into(),
        },
        joint_names: vec!["joint_1".into(), "joint_2".into()],
        points: vec![
            JointTrajectoryPoint {
                positions: vec![0.0, -0.5],
                velocities: vec![0.0, 0.0],
                accelerations: vec![],
                effort: vec![],
                time_from_start: Duration::ZERO,
            },
            JointTrajectoryPoint {
                positions: vec![0.25, -0.125],
                velocities: vec![0.1, 1e-9],
                accelerations: vec![0.0, 0.0],
                effort: vec![],
                time_from_start: Duration::from_secs_f64(1.5).unwrap(),
            },
        ],
    }
}

#[test]
fn joint_trajectory_round_trips() {
    let text = round_trip(&trajectory());
    assert!(text.contains("frame_id: base_link"), "{text}");
    assert!(text.contains("nanosec: 500000000"), "{text}");
}

#[test]
fn action_and_kerf_messages_round_trip() {
    let goal = FollowJointTrajectoryGoal {
        trajectory: trajectory(),
        path_tolerance: vec![JointTolerance {
            name: "joint_1".into(),
            position: 0.01,
            velocity: -1.0,
            acceleration: 0.0,
        }],
        component_goal_tolerance: vec![JointComponentTolerance {
            joint_name: "base".into(),
            component: JointComponentTolerance::ROTATION,
            position: 0.02,
            velocity: 0.0,
            acceleration: 0.0,
        }],
        goal_time_tolerance: Duration::from_secs_f64(-0.25).unwrap(),
        ..Default::default()
    };
    round_trip(&goal);
    round_trip(&FollowJointTrajectoryResult {
        error_code: FollowJointTrajectoryResult::PATH_TOLERANCE_VIOLATED,
        error_string: "joint_1: position error 0.02 rad > tolerance 0.01 rad".into(),
    });
    let status = TrajectoryStatus {
        header: Header {
            stamp: Time { sec: 3, nanosec: 4 },
            frame_id: String::new(),
        },
        trajectory_stamp: Time::ZERO,
        source: TrajectoryStatus::SOURCE_ACTION.into(),
        goal_id: "0123456789abcdef0123456789abcdef".into(),
        status: TrajectoryStatus::ABORTED,
        error_code: FollowJointTrajectoryResult::GOAL_TOLERANCE_VIOLATED,
        message: "joint_2 at 0.5 rad, goal 0.4 rad".into(),
    };
    let text = round_trip(&status);
    assert!(
        text.contains("status: 4") && text.contains("error_code: -5"),
        "{text}"
    );
    round_trip(&ValidateTrajectoryResponse {
        valid: true,
        error_code: 0,
        message: String::new(),
        duration: 1.5,
    });
    round_trip(&JointState {
        name: vec!["a".into()],
        position: vec![1.0],
        ..Default::default()
    });
}

#[test]
fn reads_ros2_topic_echo_output() {
    // As `ros2 topic echo` prints a trajectory_msgs/msg/JointTrajectory.
    let echo = "\
header:
  stamp:
    sec: 0
    nanosec: 0
  frame_id: ''
joint_names:
- joint_1
points:
- positions:
  - 1.0
  velocities: []
  accelerations: []
  effort: []
  time_from_start:
    sec: 2
    nanosec: 250000000
";
    let t: JointTrajectory = serde_yaml_ng::from_str(echo).unwrap();
    assert!(t.header.stamp.is_zero());
    assert_eq!(t.joint_names, ["joint_1"]);
    assert_eq!(t.points[0].positions, [1.0]);
    assert_eq!(t.points[0].time_from_start.as_secs_f64(), 2.25);
    // A missing field is an error, not a silent default.
    let missing = echo.replace("  effort: []\n", "");
    let err = serde_yaml_ng::from_str::<JointTrajectory>(&missing).unwrap_err();
    assert!(err.to_string().contains("effort"), "{err}");
}

#[test]
fn defaults_follow_the_interface_files() {
    assert_eq!(
        Quaternion::default(),
        Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 1.0
        }
    );
    assert_eq!(Pose::default().orientation.w, 1.0);
    assert_eq!(Transform::default().rotation, Quaternion::IDENTITY);
    assert_eq!(Pose::default().position.x, 0.0);
    assert!(Time::default().is_zero() && Duration::default().is_zero());
    let status = TrajectoryStatus::default();
    assert_eq!(status.status, 0);
    assert!(status.source.is_empty());
}
