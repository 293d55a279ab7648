//! The MDH forward kinematics equals the URDF chain's `tool0` (issue 4:
//! "FK must equal tool0 from the URDF chain, to 1e-9, at random joint values").
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::{kinematics, pose_error, random_q, robot, Rng};
use nalgebra::Isometry3;

#[test]
fn mdh_frame6_equals_urdf_tool0_at_random_joints() {
    let robot = robot();
    let kin = kinematics();
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let mut worst = (0.0f64, 0.0f64);
    for _ in 0..2000 {
        // Wider than the limits on purpose: the identity must hold for every q.
        let q: [f64; 6] = std::array::from_fn(|_| rng.range(-6.5, 6.5));
        let urdf = robot.forward_kinematics(&q).expect("urdf fk");
        let mdh = kin.flange_pose(&q).expect("mdh fk");
        let (dp, dr) = pose_error(&urdf, &mdh);
        worst = (worst.0.max(dp), worst.1.max(dr));
    }
    println!(
        "worst |dp| = {:.3e} m, worst |dR|_F = {:.3e}",
        worst.0, worst.1
    );
    assert!(worst.0 < 1e-9 && worst.1 < 1e-9, "{worst:?}");
}

#[test]
fn zero_pose_matches_the_urdf_comment() {
    let kin = kinematics();
    let p = kin.flange_pose(&[0.0; 6]).expect("fk");
    // tool0 at (a1 + d4 + d6, 0, d1 + a2 + a3), z along base +x, x along base -z.
    assert!((p.translation.vector - nalgebra::Vector3::new(2.0055, 0.0, 2.3745)).norm() < 1e-12);
    let r = p.rotation.to_rotation_matrix();
    assert!((r * nalgebra::Vector3::z() - nalgebra::Vector3::x()).norm() < 1e-12);
    assert!((r * nalgebra::Vector3::x() + nalgebra::Vector3::z()).norm() < 1e-12);
}

#[test]
fn tcp_offset_is_applied_after_the_flange() {
    let robot = robot();
    let tcp = Isometry3::translation(0.01, -0.02, 0.15);
    let kin = kerf_mill::Kinematics::from_robot(&robot, tcp, [1.0; 6]).expect("kin");
    let mut rng = Rng(7);
    let q = random_q(&mut rng, &kin);
    let expect = robot.forward_kinematics(&q).expect("fk") * tcp;
    let (dp, dr) = pose_error(&expect, &kin.tcp_pose(&q).expect("tcp"));
    assert!(dp < 1e-12 && dr < 1e-12);
    assert!(kin
        .flange_pose(&[f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0])
        .is_err());
}
