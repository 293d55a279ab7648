//! Closed-form IK: round trips, branch enumeration, limits, unreachable
//! targets, the singular wrist and branch jumps along a path.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::{kinematics, pose_error, random_q, Rng};
use kerf_mill::ik::wrap;
use kerf_mill::MillError;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

fn same_angles(a: &[f64; 6], b: &[f64; 6], tol: f64) -> bool {
    a.iter().zip(b).all(|(x, y)| wrap(x - y).abs() < tol)
}

#[test]
fn ik_fk_round_trip_at_random_reachable_poses() {
    let kin = kinematics();
    let mut rng = Rng(0xD1B5_4A32_D192_ED03);
    let (mut worst_p, mut worst_r, mut worst_q) = (0.0f64, 0.0f64, 0.0f64);
    let mut counts = [0usize; 9];
    for _ in 0..2000 {
        let q = random_q(&mut rng, &kin);
        let pose = kin.flange_pose(&q).expect("fk");
        let sols = kin
            .ik_flange_all(&pose, &q)
            .expect("reachable by construction");
        counts[sols.len()] += 1;
        for s in &sols {
            let (dp, dr) = pose_error(&kin.flange_pose(&s.q).expect("fk"), &pose);
            worst_p = worst_p.max(dp);
            worst_r = worst_r.max(dr);
        }
        let best = sols
            .iter()
            .map(|s| {
                s.q.iter()
                    .zip(&q)
                    .map(|(a, b)| wrap(a - b).abs())
                    .fold(0.0, f64::max)
            })
            .fold(f64::INFINITY, f64::min);
        worst_q = worst_q.max(best);
        // The nearest valid solution to the generating q is q itself.
        let near = kin.ik_nearest(&pose, &q).expect("q is valid");
        assert!(
            near.iter().zip(&q).all(|(a, b)| (a - b).abs() < 1e-7),
            "{near:?} vs {q:?}"
        );
    }
    println!(
        "worst FK residual of all solutions: {worst_p:.3e} m, {worst_r:.3e} (rotation, Frobenius); \
         generating q recovered to {worst_q:.3e} rad; solution counts by size: {counts:?}"
    );
    assert!(worst_p < 1e-9 && worst_r < 1e-9);
    assert!(worst_q < 1e-7);
}

#[test]
fn eight_distinct_solutions_at_a_generic_pose() {
    let kin = kinematics();
    let q = [0.3, 0.2, 0.4, 0.5, 0.7, -0.4];
    let pose = kin.flange_pose(&q).expect("fk");
    let sols = kin.ik_flange_all(&pose, &q).expect("ik");
    assert_eq!(sols.len(), 8);
    for (i, a) in sols.iter().enumerate() {
        for b in &sols[i + 1..] {
            assert!(!same_angles(&a.q, &b.q, 1e-6), "duplicate solutions");
        }
    }
    // Shoulder back differs from front by pi in q1.
    let front = sols.iter().find(|s| !s.shoulder_back).expect("front");
    let back = sols.iter().find(|s| s.shoulder_back).expect("back");
    assert!((wrap(front.q[0] - back.q[0]).abs() - std::f64::consts::PI).abs() < 1e-12);
    // Wrist flip: (q4 + pi, -q5, q6 + pi).
    let a = sols
        .iter()
        .find(|s| !s.shoulder_back && !s.elbow_down && !s.wrist_flipped)
        .expect("a");
    let b = sols
        .iter()
        .find(|s| !s.shoulder_back && !s.elbow_down && s.wrist_flipped)
        .expect("b");
    assert!(wrap(a.q[3] + std::f64::consts::PI - b.q[3]).abs() < 1e-9);
    assert!((a.q[4] + b.q[4]).abs() < 1e-9);
    assert!(wrap(a.q[5] + std::f64::consts::PI - b.q[5]).abs() < 1e-9);
}

#[test]
fn unreachable_pose_reports_the_distance_beyond_reach() {
    let kin = kinematics();
    let g = kin.geometry();
    // Flange pointing down (z = -z_base) at (4, 1, 1.5): wrist centre 0.2 m above.
    let rot = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), std::f64::consts::PI);
    let pose = Isometry3::from_parts(Translation3::new(4.0, 1.0, 1.5), rot);
    let err = kin.ik_flange_all(&pose, &[0.0; 6]).expect_err("too far");
    // Independent: distance from the joint-2 axis (front shoulder) minus a2 + L.
    let pw: Vector3<f64> = Vector3::new(4.0, 1.0, 1.7);
    let r = pw.x.hypot(pw.y) - g.a1;
    let s = pw.z - g.d1;
    let expect = r.hypot(s) - (g.a2 + g.d4.hypot(g.a3));
    match err {
        MillError::Unreachable {
            distance_beyond_reach,
            ..
        } => {
            println!("beyond reach by {distance_beyond_reach:.6} m (expected {expect:.6})");
            assert!((distance_beyond_reach - expect).abs() < 1e-12);
        }
        other => panic!("unexpected {other}"),
    }
    let msg = kin
        .ik_nearest(&pose, &[0.0; 6])
        .expect_err("too far")
        .with_context(Some(12), Some(0.5))
        .to_string();
    assert!(
        msg.contains("segment 12") && msg.contains("beyond"),
        "{msg}"
    );
}

#[test]
fn singular_wrist_keeps_q4_from_the_reference() {
    let kin = kinematics();
    let q = [0.2, 0.3, 0.1, 0.9, 0.0, -0.5];
    let pose = kin.flange_pose(&q).expect("fk");
    let reference = [0.2, 0.3, 0.1, 1.3, 0.0, 0.0];
    let sols = kin.ik_flange_all(&pose, &reference).expect("ik");
    for s in &sols {
        let (dp, dr) = pose_error(&kin.flange_pose(&s.q).expect("fk"), &pose);
        assert!(dp < 1e-9 && dr < 1e-9);
    }
    let near = kin.ik_nearest(&pose, &reference).expect("valid");
    assert!((near[3] - 1.3).abs() < 1e-12, "q4 kept: {near:?}");
    assert!(
        (near[3] + near[5] - (0.9 - 0.5)).abs() < 1e-9,
        "q4 + q6 preserved"
    );
}

#[test]
fn q4_and_q6_wrap_to_the_equivalent_nearest_the_reference() {
    let kin = kinematics();
    let q = [0.1, 0.2, 0.3, 4.5, 0.6, -5.5]; // q4 = 258 deg, q6 = -315 deg: within limits
    let pose = kin.flange_pose(&q).expect("fk");
    let near = kin.ik_nearest(&pose, &q).expect("valid");
    assert!(
        near.iter().zip(&q).all(|(a, b)| (a - b).abs() < 1e-9),
        "{near:?}"
    );
    // With a reference near the principal values the principal ones are chosen.
    let principal = q.map(wrap);
    let near = kin.ik_nearest(&pose, &principal).expect("valid");
    assert!(near
        .iter()
        .zip(&principal)
        .all(|(a, b)| (a - b).abs() < 1e-9));
}

#[test]
fn joint_limit_violation_names_the_joint_and_excess() {
    let kin = kinematics();
    // A pose only reachable with q2 beyond its lower limit -42 deg on every branch
    // that reaches it is hard to construct; use check_limits and a path instead.
    let err = kin
        .check_limits(&[0.0, -0.9, 0.0, 0.0, 0.5, 0.0])
        .expect_err("q2 < -42 deg");
    match err {
        MillError::JointLimit {
            joint,
            value,
            lower,
            excess,
            ..
        } => {
            assert_eq!(joint, "joint_2");
            assert_eq!(value, -0.9);
            assert!((excess - (lower - value)).abs() < 1e-15 && excess > 0.0);
        }
        other => panic!("unexpected {other}"),
    }
    // A target straight below the base (wrist centre on the joint-1 axis, low):
    // the arm reaches it only by folding far beyond the J2/J3 limits.
    let rot = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), std::f64::consts::PI);
    let pose = Isometry3::from_parts(Translation3::new(0.35, 0.0, -0.4), rot);
    match kin.ik_nearest(&pose, &[0.0; 6]) {
        Err(MillError::JointLimit {
            joint,
            excess,
            value,
            lower,
            upper,
            ..
        }) => {
            println!("{joint} = {value} outside [{lower}, {upper}] by {excess}");
            assert!(excess > 0.0 && (value < lower || value > upper));
        }
        other => panic!("expected a joint-limit error, got {other:?}"),
    }
}

#[test]
fn a_path_reports_branch_jumps_instead_of_hiding_them() {
    let kin = kinematics();
    // q4 sweeps from 0 to 6.0 rad: beyond its +300 deg (5.236 rad) limit the
    // nearest valid solution is the flipped wrist (q4 - pi, -q5, q6 + pi):
    // a jump of about pi in q4 and q6.
    let poses: Vec<Isometry3<f64>> = (0..=60)
        .map(|i| {
            let q = [0.0, 0.2, 0.3, 0.1 * i as f64, 0.8, 0.0];
            kin.tcp_pose(&q).expect("fk")
        })
        .collect();
    let path = kin
        .ik_path(&poses, &[0.0, 0.2, 0.3, 0.0, 0.8, 0.0], 0.5)
        .expect("valid");
    assert_eq!(path.joints.len(), 61);
    println!("jumps: {:?}", path.jumps);
    assert_eq!(path.jumps.len(), 1);
    let jump = &path.jumps[0];
    assert_eq!(jump.index, 53); // q4 = 5.3 > 5.236
    assert!(jump.joint == "joint_4" || jump.joint == "joint_6");
    assert!(jump.step > 3.0, "{jump:?}");
    let (a, b) = (path.joints[52], path.joints[53]);
    assert!((a[4] + b[4]).abs() < 1e-9, "wrist flipped: q5 changes sign");
    // Without the limit crossing there is no jump.
    let smooth = kin
        .ik_path(&poses[..50], &[0.0, 0.2, 0.3, 0.0, 0.8, 0.0], 0.5)
        .expect("ok");
    assert!(smooth.jumps.is_empty());
}
