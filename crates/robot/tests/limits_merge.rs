//! Merging a MoveIt `joint_limits.yaml` into the URDF limits.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use kerf_robot::{RobotError, RobotModel};

/// Loads the laser cutter URDF with `yaml` as its limits file.
fn load(yaml: &str) -> Result<RobotModel, RobotError> {
    RobotModel::from_strings(&common::read("laser_cutter.urdf"), Some(yaml))
}

#[test]
fn yaml_may_tighten_position_and_velocity_limits() {
    let robot = load(
        "joint_limits:\n  q1:\n    min_position: 0.1\n    max_position: 1.0\n    max_velocity: 1.5\n  \
         q4:\n    has_position_limits: true\n    min_position: -3.0\n    max_position: 3.0\n",
    )
    .unwrap();
    let q1 = &robot.joints()[0];
    assert_eq!(
        (q1.min_position, q1.max_position, q1.max_velocity),
        (0.1, 1.0, 1.5)
    );
    let q4 = &robot.joints()[3];
    assert_eq!(
        (q4.min_position, q4.max_position, q4.max_velocity),
        (-3.0, 3.0, 10.0)
    );
    // Untouched joints keep the URDF values and get no acceleration limit.
    let q2 = &robot.joints()[1];
    assert_eq!(
        (q2.min_position, q2.max_position, q2.max_velocity),
        (0.0, 1.4, 2.0)
    );
    assert_eq!(q2.max_acceleration, None);
    // The tightened range is enforced.
    let err = robot
        .check_positions(&[1.2, 0.0, 0.0, 0.0, 0.0, 0.0])
        .unwrap_err();
    assert!(
        matches!(err, RobotError::OutOfRange { ref joint, value, min, max }
        if joint == "q1" && value == 1.2 && min == 0.1 && max == 1.0),
        "{err}"
    );
}

#[test]
fn yaml_equal_to_urdf_is_accepted() {
    let robot = common::laser_cutter();
    assert_eq!(robot.joints()[3].min_position, -std::f64::consts::TAU);
}

#[test]
fn widening_any_limit_is_an_error_naming_joint_and_values() {
    let cases = [
        ("q1", "max_position: 1.7", "max_position", 1.6, 1.7),
        ("q2", "min_position: -0.5", "min_position", 0.0, -0.5),
        ("q6", "max_velocity: 2.5", "max_velocity", 2.0, 2.5),
    ];
    for (joint_name, line, expected_field, expected_urdf, expected_yaml) in cases {
        let err = load(&format!("joint_limits:\n  {joint_name}:\n    {line}\n")).unwrap_err();
        match &err {
            RobotError::LimitWidened {
                joint,
                field,
                urdf,
                yaml,
            } => {
                assert_eq!(joint, joint_name);
                assert_eq!(*field, expected_field);
                assert_eq!((*urdf, *yaml), (expected_urdf, expected_yaml));
            }
            other => panic!("expected LimitWidened for {line}, got {other}"),
        }
        let message = err.to_string();
        assert!(
            message.contains(joint_name) && message.contains(expected_field),
            "{message}"
        );
    }
}

#[test]
fn dropping_a_urdf_limit_is_an_error() {
    for flag in ["has_position_limits", "has_velocity_limits"] {
        let err = load(&format!("joint_limits:\n  q3:\n    {flag}: false\n")).unwrap_err();
        assert!(
            matches!(err, RobotError::LimitRemoved { ref joint, field }
            if joint == "q3" && field == flag),
            "{err}"
        );
    }
}

#[test]
fn unknown_and_fixed_joints_in_yaml_are_errors() {
    let err = load("joint_limits:\n  q7:\n    max_acceleration: 1.0\n").unwrap_err();
    assert!(
        matches!(err, RobotError::UnknownJoint { ref name } if name == "q7"),
        "{err}"
    );
    let err = load("joint_limits:\n  nozzle-tool0:\n    max_acceleration: 1.0\n").unwrap_err();
    assert!(
        matches!(err, RobotError::LimitsForFixedJoint { ref joint } if joint == "nozzle-tool0"),
        "{err}"
    );
}

#[test]
fn acceleration_and_jerk_follow_moveit_flags() {
    // has_*_limits: false means "no limit"; the value next to it is ignored.
    let robot = load(
        "joint_limits:\n  q1:\n    has_acceleration_limits: false\n    max_acceleration: 0\n    \
         max_jerk: 50.0\n",
    )
    .unwrap();
    assert_eq!(robot.joints()[0].max_acceleration, None);
    assert_eq!(robot.joints()[0].max_jerk, Some(50.0));

    let err = load("joint_limits:\n  q1:\n    has_jerk_limits: true\n").unwrap_err();
    assert!(
        matches!(err, RobotError::MissingLimitValue { ref joint, flag, field }
        if joint == "q1" && flag == "has_jerk_limits" && field == "max_jerk"),
        "{err}"
    );
    let err = load("joint_limits:\n  q1:\n    has_position_limits: true\n    min_position: 0.0\n")
        .unwrap_err();
    assert!(
        matches!(
            err,
            RobotError::MissingLimitValue {
                field: "max_position",
                ..
            }
        ),
        "{err}"
    );
}

#[test]
fn non_finite_and_non_positive_yaml_values_are_errors() {
    let cases = [
        ("max_acceleration: -1.0", "max_acceleration"),
        ("max_acceleration: 0.0", "max_acceleration"),
        ("max_jerk: .nan", "max_jerk"),
        ("max_jerk: .inf", "max_jerk"),
        ("max_velocity: 0.0", "max_velocity"),
        ("min_position: .nan", "min_position"),
    ];
    for (line, expected_field) in cases {
        let err = load(&format!("joint_limits:\n  q5:\n    {line}\n")).unwrap_err();
        assert!(
            matches!(err, RobotError::InvalidLimit { ref joint, field, .. }
            if joint == "q5" && field == expected_field),
            "{line}: {err}"
        );
    }
}

#[test]
fn tightening_to_an_empty_range_is_an_error() {
    let err =
        load("joint_limits:\n  q1:\n    min_position: 1.0\n    max_position: 0.5\n").unwrap_err();
    assert!(
        matches!(err, RobotError::EmptyRange { ref joint, min, max }
        if joint == "q1" && min == 1.0 && max == 0.5),
        "{err}"
    );
}

#[test]
fn malformed_yaml_is_a_parse_error() {
    for yaml in [
        "joint_limits:\n  q1:\n    max_accleration: 1.0\n", // typo: unknown field
        "limits:\n  q1:\n    max_acceleration: 1.0\n",      // wrong root key
        "joint_limits:\n  q1:\n    max_acceleration: fast\n", // not a number
        "joint_limits: [",                                  // not YAML
    ] {
        let err = load(yaml).unwrap_err();
        assert!(
            matches!(err, RobotError::LimitsParse { .. }),
            "{yaml}: {err}"
        );
    }
}
