//! The laser cutter URDF reproduces seed 001 eq. (2) exactly.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use nalgebra::Vector3;

/// Seed 001 eq. (2): CL point C and unit tool axis O from q.
fn eq2(q: &[f64]) -> (Vector3<f64>, Vector3<f64>) {
    let o = Vector3::new(q[3].cos() * q[4].sin(), q[3].sin() * q[4].sin(), q[4].cos());
    let c = Vector3::new(q[0], q[1], q[2]) + q[5] * o;
    (c, o)
}

#[test]
fn tool0_is_the_cl_point_with_z_along_the_tool_axis() {
    let robot = common::laser_cutter();
    let mut rng = common::SplitMix64::new(0x5eed_0001);
    for _ in 0..2000 {
        let q = rng.joint_vector(&robot);
        robot.check_positions(&q).unwrap();
        let pose = robot.forward_kinematics(&q).unwrap();
        let (c, o) = eq2(&q);
        let z_axis = pose.rotation * Vector3::z();
        assert!(
            (pose.translation.vector - c).norm() < 1e-12,
            "C at q = {q:?}"
        );
        assert!((z_axis - o).norm() < 1e-12, "O at q = {q:?}");
    }
}

#[test]
fn eq2_also_holds_outside_the_joint_limits() {
    // FK does not clamp: it is the pure kinematic map.
    let robot = common::laser_cutter();
    let mut rng = common::SplitMix64::new(42);
    for _ in 0..500 {
        let q: Vec<f64> = (0..6).map(|_| rng.uniform(-10.0, 10.0)).collect();
        let pose = robot.forward_kinematics(&q).unwrap();
        let (c, o) = eq2(&q);
        let tol = 1e-12 * (1.0 + c.norm());
        assert!((pose.translation.vector - c).norm() < tol, "C at q = {q:?}");
        assert!(
            (pose.rotation * Vector3::z() - o).norm() < 1e-12,
            "O at q = {q:?}"
        );
    }
}

#[test]
fn rotary_axes_centre_is_the_m_point_and_link_poses_agree_with_fk() {
    let robot = common::laser_cutter();
    let mut rng = common::SplitMix64::new(7);
    for _ in 0..200 {
        let q = rng.joint_vector(&robot);
        let poses = robot.link_poses(&q).unwrap();
        let pose_of = |name: &str| poses.iter().find(|(n, _)| n == name).unwrap().1;
        let m = Vector3::new(q[0], q[1], q[2]);
        for link in ["z_ram", "c_axis", "a_axis"] {
            assert!(
                (pose_of(link).translation.vector - m).norm() < 1e-12,
                "{link}"
            );
        }
        let fk = robot.forward_kinematics(&q).unwrap();
        assert!((pose_of("tool0").to_homogeneous() - fk.to_homogeneous()).norm() < 1e-12);
        assert!((pose_of("nozzle").to_homogeneous() - fk.to_homogeneous()).norm() < 1e-12);
        // The standoff axis moves C along O: |C - M| = |q6|.
        assert!(((fk.translation.vector - m).norm() - q[5].abs()).abs() < 1e-12);
    }
}
