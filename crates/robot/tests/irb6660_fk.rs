//! The IRB 6660 URDF against Craig's modified Denavit-Hartenberg chain.
//!
//! MDH parameters (Craig, "Introduction to Robotics", 3rd ed., eq. 3.6:
//! `T = RotX(alpha_{i-1}) TransX(a_{i-1}) RotZ(theta_i) TransZ(d_i)`):
//!
//! | i | alpha_{i-1} | a_{i-1} | d_i    | theta_i   |
//! |---|-------------|---------|--------|-----------|
//! | 1 | 0           | 0       | 0.8145 | q1        |
//! | 2 | -pi/2       | 0.300   | 0      | q2 - pi/2 |
//! | 3 | 0           | 1.280   | 0      | q3        |
//! | 4 | -pi/2       | 0.280   | 1.5055 | q4        |
//! | 5 | pi/2        | 0       | 0      | q5        |
//! | 6 | -pi/2       | 0       | 0.200  | q6 + pi   |
//!
//! Result: every MDH z axis coincides with the positive URDF joint axis
//! (z1 = +z, z2 = z3 = +y of link_1, z4 = +x, z5 = +y, z6 = +x at q = 0), so
//! NO joint variable needs a sign flip, and the constant rotation between
//! MDH frame 6 and URDF `tool0` is the identity: frame 6 at q = 0 has
//! x = -Z, y = +Y, z = +X of the base, which is exactly link_6 rotated by
//! rpy (0, pi/2, 0).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use std::f64::consts::{FRAC_PI_2, PI};

use nalgebra::{Isometry3, Rotation3, Translation3, UnitQuaternion, Vector3};

/// Craig MDH link transform `RotX(alpha) TransX(a) RotZ(theta) TransZ(d)`.
fn mdh(alpha: f64, a: f64, theta: f64, d: f64) -> Isometry3<f64> {
    let rot_x = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), alpha);
    let rot_z = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), theta);
    Isometry3::from_parts(Translation3::identity(), rot_x)
        * Isometry3::from_parts(Translation3::new(a, 0.0, 0.0), UnitQuaternion::identity())
        * Isometry3::from_parts(Translation3::identity(), rot_z)
        * Isometry3::from_parts(Translation3::new(0.0, 0.0, d), UnitQuaternion::identity())
}

/// Frame 6 of the MDH table in the base frame.
fn mdh_frame6(q: &[f64]) -> Isometry3<f64> {
    let rows = [
        (0.0, 0.0, q[0], 0.8145),
        (-FRAC_PI_2, 0.300, q[1] - FRAC_PI_2, 0.0),
        (0.0, 1.280, q[2], 0.0),
        (-FRAC_PI_2, 0.280, q[3], 1.5055),
        (FRAC_PI_2, 0.0, q[4], 0.0),
        (-FRAC_PI_2, 0.0, q[5] + PI, 0.200),
    ];
    rows.iter()
        .fold(Isometry3::identity(), |t, &(alpha, a, theta, d)| {
            t * mdh(alpha, a, theta, d)
        })
}

#[test]
fn tool0_position_equals_the_mdh_chain() {
    let robot = common::irb6660();
    let mut rng = common::SplitMix64::new(6660);
    for _ in 0..2000 {
        let q = rng.joint_vector(&robot);
        let urdf = robot.forward_kinematics(&q).unwrap();
        let mdh = mdh_frame6(&q);
        let err = (urdf.translation.vector - mdh.translation.vector).norm();
        assert!(err < 1e-9, "position differs by {err} m at q = {q:?}");
    }
}

#[test]
fn tool0_orientation_differs_from_mdh_frame6_by_one_constant_rotation() {
    let robot = common::irb6660();
    let zero = [0.0; 6];
    let offset =
        mdh_frame6(&zero).rotation.inverse() * robot.forward_kinematics(&zero).unwrap().rotation;
    // The constant rotation is the identity (see the module documentation).
    assert!(offset.angle() < 1e-12, "offset rotation {offset:?}");
    let frame6 = Rotation3::from(mdh_frame6(&zero).rotation);
    assert!((frame6 * Vector3::x() - -Vector3::z()).norm() < 1e-12);
    assert!((frame6 * Vector3::z() - Vector3::x()).norm() < 1e-12);

    let mut rng = common::SplitMix64::new(1);
    for _ in 0..2000 {
        let q = rng.joint_vector(&robot);
        let urdf = robot.forward_kinematics(&q).unwrap().rotation;
        let predicted = mdh_frame6(&q).rotation * offset;
        let angle = urdf.angle_to(&predicted);
        assert!(
            angle < 1e-9,
            "orientation differs by {angle} rad at q = {q:?}"
        );
    }
}

#[test]
fn a_sign_flip_would_be_detected() {
    // Guard against a vacuous comparison: flipping any single joint variable
    // in the MDH chain must break the agreement somewhere in the workspace.
    let robot = common::irb6660();
    let mut rng = common::SplitMix64::new(99);
    for flipped in 0..6 {
        let mut worst: f64 = 0.0;
        for _ in 0..50 {
            let q = rng.joint_vector(&robot);
            let mut q_flip = q.clone();
            q_flip[flipped] = -q_flip[flipped];
            let urdf = robot.forward_kinematics(&q).unwrap();
            let mdh = mdh_frame6(&q_flip);
            let pos = (urdf.translation.vector - mdh.translation.vector).norm();
            worst = worst.max(pos + urdf.rotation.angle_to(&mdh.rotation));
        }
        assert!(worst > 1e-3, "flipping q{} went unnoticed", flipped + 1);
    }
}

#[test]
fn explicit_tip_link_6_differs_from_tool0_by_the_fixed_rotation() {
    let robot = kerf_robot::RobotModel::from_strings_with_tip(
        &common::read("irb6660.urdf"),
        Some(&common::read("irb6660_limits.yaml")),
        "link_6",
    )
    .unwrap();
    assert_eq!(robot.tip_link(), "link_6");
    let tool0_in_link6 = UnitQuaternion::from_euler_angles(0.0, FRAC_PI_2, 0.0);
    let full = common::irb6660();
    let mut rng = common::SplitMix64::new(3);
    for _ in 0..100 {
        let q = rng.joint_vector(&robot);
        let flange = robot.forward_kinematics(&q).unwrap();
        let tool0 = full.forward_kinematics(&q).unwrap();
        assert!((flange.translation.vector - tool0.translation.vector).norm() < 1e-12);
        assert!((flange.rotation * tool0_in_link6).angle_to(&tool0.rotation) < 1e-12);
    }
}
