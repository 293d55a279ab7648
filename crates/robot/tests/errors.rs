//! Invalid joint vectors and invalid robot descriptions are rejected with
//! errors that name what is wrong.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use std::path::Path;

use common::{joint, urdf};
use kerf_robot::{RobotError, RobotModel};

#[test]
fn nan_and_infinite_joint_values_are_rejected() {
    let robot = common::laser_cutter();
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let q = [0.5, 0.5, 0.5, 0.0, bad, 0.0];
        for err in [
            robot.forward_kinematics(&q).unwrap_err(),
            robot.link_poses(&q).unwrap_err(),
            robot.check_positions(&q).unwrap_err(),
        ] {
            assert!(
                matches!(err, RobotError::NonFinite { ref joint, .. } if joint == "q5"),
                "{err}"
            );
        }
    }
}

#[test]
fn wrong_length_is_rejected() {
    let robot = common::irb6660();
    for len in [0, 5, 7] {
        let q = vec![0.0; len];
        for err in [
            robot.forward_kinematics(&q).unwrap_err(),
            robot.link_poses(&q).unwrap_err(),
            robot.check_positions(&q).unwrap_err(),
        ] {
            assert!(
                matches!(err, RobotError::WrongLength { expected: 6, got } if got == len),
                "{err}"
            );
        }
    }
}

#[test]
fn positions_outside_limits_are_rejected_bounds_included() {
    let robot = common::laser_cutter();
    robot
        .check_positions(&[0.0, 1.4, 3.0, -std::f64::consts::TAU, 0.0, 0.02])
        .unwrap();
    let err = robot
        .check_positions(&[0.0, 0.0, 0.0, 0.0, 0.0, 0.021])
        .unwrap_err();
    assert!(
        matches!(err, RobotError::OutOfRange { ref joint, value, min, max }
        if joint == "q6" && value == 0.021 && min == -0.1 && max == 0.02),
        "{err}"
    );
    assert!(err.to_string().contains("q6"));
}

#[test]
fn malformed_urdf_is_a_parse_error() {
    let text = common::read("irb6660.urdf");
    for bad in [
        &text[..text.len() / 2],
        "",
        "not xml at all",
        "<robot name=\"x\"><link/></robot>",
    ] {
        let err = RobotModel::from_strings(bad, None).unwrap_err();
        assert!(matches!(err, RobotError::UrdfParse { .. }), "{err}");
    }
}

#[test]
fn missing_files_name_the_path() {
    let err = RobotModel::from_files(Path::new("/nonexistent/robot.urdf"), None).unwrap_err();
    assert!(
        matches!(err, RobotError::FileRead { ref path, .. } if path == Path::new("/nonexistent/robot.urdf"))
    );
    assert!(err.to_string().contains("/nonexistent/robot.urdf"));
    let dir = common::urdf_dir();
    let err = RobotModel::from_files(&dir.join("irb6660.urdf"), Some(&dir.join("missing.yaml")))
        .unwrap_err();
    assert!(matches!(err, RobotError::FileRead { ref path, .. } if path.ends_with("missing.yaml")));
}

#[test]
fn unsupported_joint_types_and_mimic_joints_are_rejected() {
    let xml = urdf(&["a", "b"], &joint("j", "continuous", "a", "b", "0 0 1"));
    let err = RobotModel::from_strings(&xml, None).unwrap_err();
    assert!(
        matches!(err, RobotError::UnsupportedJointType { ref joint, ref kind }
        if joint == "j" && kind == "continuous"),
        "{err}"
    );

    let mimic = joint("j2", "revolute", "b", "c", "0 0 1")
        .replace("</joint>", "<mimic joint=\"j1\" multiplier=\"1\"/></joint>");
    let xml = urdf(
        &["a", "b", "c"],
        &(joint("j1", "revolute", "a", "b", "0 0 1") + &mimic),
    );
    let err = RobotModel::from_strings(&xml, None).unwrap_err();
    assert!(
        matches!(err, RobotError::MimicJoint { ref joint, ref leader }
        if joint == "j2" && leader == "j1"),
        "{err}"
    );
}

#[test]
fn fixed_branches_are_allowed_and_posed() {
    // a -j1-> b -j2-> c (chain) and b -fixed-> sensor (branch): two leaves,
    // no tool0, so the tip must be named.
    let joints = joint("j1", "revolute", "a", "b", "0 0 1")
        + &joint("j2", "prismatic", "b", "c", "1 0 0")
        + &joint("mount", "fixed", "b", "sensor", "1 0 0");
    let xml = urdf(&["a", "b", "c", "sensor"], &joints);
    let err = RobotModel::from_strings(&xml, None).unwrap_err();
    assert!(
        matches!(err, RobotError::AmbiguousTip { ref leaves } if leaves.len() == 2),
        "{err}"
    );

    let robot = RobotModel::from_strings_with_tip(&xml, None, "c").unwrap();
    assert_eq!(robot.joint_names(), ["j1", "j2"]);
    let poses = robot
        .link_poses(&[std::f64::consts::FRAC_PI_2, 0.25])
        .unwrap();
    let names: Vec<&str> = poses.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["a", "b", "c", "sensor"]);
    // Origins are 0.5 m along z each; j1 turns x into y, j2 slides 0.25 m along x.
    let c = poses[2].1.translation.vector;
    assert!(
        (c - nalgebra::Vector3::new(0.0, 0.25, 1.0)).norm() < 1e-12,
        "{c}"
    );
    let sensor = poses[3].1.translation.vector;
    assert!(
        (sensor - nalgebra::Vector3::new(0.0, 0.0, 1.0)).norm() < 1e-12,
        "{sensor}"
    );
    let fk = robot
        .forward_kinematics(&[std::f64::consts::FRAC_PI_2, 0.25])
        .unwrap();
    assert!((fk.translation.vector - c).norm() < 1e-15);
}

#[test]
fn movable_joints_off_the_chain_are_rejected() {
    let joints = joint("j1", "revolute", "a", "b", "0 0 1")
        + &joint("j2", "revolute", "b", "c", "0 1 0")
        + &joint("side", "prismatic", "b", "tool0_sibling", "1 0 0")
        + &joint("flange", "fixed", "c", "tool0", "1 0 0");
    let xml = urdf(&["a", "b", "c", "tool0_sibling", "tool0"], &joints);
    let err = RobotModel::from_strings(&xml, None).unwrap_err();
    assert!(
        matches!(err, RobotError::MovableJointOffChain { ref joint, ref root, ref tip }
        if joint == "side" && root == "a" && tip == "tool0"),
        "{err}"
    );
}

/// Predicate on the expected error of a test case.
type ErrorCheck = fn(&RobotError) -> bool;

#[test]
fn malformed_trees_are_rejected() {
    let j = |n: &str, p: &str, c: &str| joint(n, "revolute", p, c, "0 0 1");
    let cases: Vec<(String, ErrorCheck)> = vec![
        (
            urdf(&["a", "a"], ""),
            |e| matches!(e, RobotError::DuplicateLink { name } if name == "a"),
        ),
        (
            urdf(&["a", "b", "c"], &(j("j", "a", "b") + &j("j", "b", "c"))),
            |e| matches!(e, RobotError::DuplicateJoint { name } if name == "j"),
        ),
        (
            urdf(&["a"], &j("j", "a", "ghost")),
            |e| matches!(e, RobotError::UnknownLink { joint, link } if joint == "j" && link == "ghost"),
        ),
        (
            urdf(&["a", "b", "c"], &(j("j1", "a", "c") + &j("j2", "b", "c"))),
            |e| {
                matches!(e, RobotError::MultipleParents { link, first_joint, second_joint }
                if link == "c" && first_joint == "j1" && second_joint == "j2")
            },
        ),
        (
            urdf(&["a", "b"], ""),
            |e| matches!(e, RobotError::RootNotUnique { roots } if roots.len() == 2),
        ),
        (
            urdf(&["a", "b"], &(j("j1", "a", "b") + &j("j2", "b", "a"))),
            |e| matches!(e, RobotError::RootNotUnique { roots } if roots.is_empty()),
        ),
        (
            urdf(
                &["a", "b", "c", "d"],
                &(j("j1", "a", "b") + &j("j2", "c", "d") + &j("j3", "d", "c")),
            ),
            |e| matches!(e, RobotError::Unreachable { link, root } if link == "c" && root == "a"),
        ),
    ];
    for (xml, check) in cases {
        let err = RobotModel::from_strings(&xml, None).unwrap_err();
        assert!(check(&err), "unexpected error {err:?} for\n{xml}");
    }
    let xml = urdf(&["a", "b"], &j("j1", "a", "b"));
    let err = RobotModel::from_strings_with_tip(&xml, None, "nope").unwrap_err();
    assert!(
        matches!(err, RobotError::UnknownTip { ref tip } if tip == "nope"),
        "{err}"
    );
}

#[test]
fn invalid_axes_origins_and_urdf_limits_are_rejected() {
    let one = |text: String| RobotModel::from_strings(&urdf(&["a", "b"], &text), None).unwrap_err();
    let base = joint("j", "revolute", "a", "b", "0 0 1");

    let err = one(joint("j", "revolute", "a", "b", "0 0 0"));
    assert!(
        matches!(err, RobotError::InvalidAxis { ref joint, axis } if joint == "j" && axis == [0.0; 3]),
        "{err}"
    );
    let err = one(base.replace("xyz=\"0 0 0.5\"", "xyz=\"0 NaN 0.5\""));
    assert!(
        matches!(err, RobotError::InvalidOrigin { ref joint, .. } if joint == "j"),
        "{err}"
    );
    let err = one(base.replace("lower=\"-1\"", "lower=\"2\""));
    assert!(
        matches!(err, RobotError::EmptyRange { ref joint, min, max } if joint == "j" && min == 2.0 && max == 1.0),
        "{err}"
    );
    let err = one(base.replace("velocity=\"1\"", "velocity=\"-1\""));
    assert!(
        matches!(err, RobotError::InvalidLimit { field, value, .. } if field.contains("velocity") && value == -1.0),
        "{err}"
    );
    let err = one(base.replace("effort=\"10\"", "effort=\"0\""));
    assert!(
        matches!(err, RobotError::InvalidLimit { field, .. } if field.contains("effort")),
        "{err}"
    );
    let err = one(base.replace("upper=\"1\"", "upper=\"inf\""));
    assert!(
        matches!(err, RobotError::InvalidLimit { field, .. } if field.contains("upper")),
        "{err}"
    );
    // A revolute joint without <limit>: urdf-rs fills zeros, caught here.
    let no_limit = base.replace(
        "<limit lower=\"-1\" upper=\"1\" effort=\"10\" velocity=\"1\"/>",
        "",
    );
    let err = RobotModel::from_strings(&urdf(&["a", "b"], &no_limit), None);
    assert!(
        matches!(err, Err(RobotError::InvalidLimit { ref joint, field, value, .. })
        if joint == "j" && field.contains("velocity") && value == 0.0),
        "{err:?}"
    );
}

#[test]
fn non_unit_axes_are_normalised() {
    let xml = urdf(&["a", "b"], &joint("j", "prismatic", "a", "b", "0 0 2"));
    let robot = RobotModel::from_strings(&xml, None).unwrap();
    let pose = robot.forward_kinematics(&[0.25]).unwrap();
    assert!(
        (pose.translation.z - 0.75).abs() < 1e-15,
        "{}",
        pose.translation.z
    );
}
