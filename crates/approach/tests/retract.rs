//! Retracts: to a safe pose, blocked, and the tool-axis target (3-link planar arm IK).
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::*;
use kerf_approach::{tool_axis_target, ApproachError, Role, Route};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

#[test]
fn retract_to_the_safe_pose_is_checked_and_clear() {
    let circles = fixture();
    let world = |q: &[f64]| clearance(&circles, q);
    let p = planner(&world, vec![SAFE.to_vec()]);
    let r = p.retract(&GOAL, &[SAFE]).unwrap();
    assert_eq!(r.route, Route::Retract);
    assert_eq!(r.path.start(), &GOAL);
    assert_eq!(r.path.end(), &SAFE);
    assert!(r.closest.distance >= CLEARANCE);
    for s in r.path.samples(1e-4).unwrap() {
        assert!(clearance(&circles, &s.q).distance >= CLEARANCE);
    }
    // Through two targets: both are passed at rest.
    let r = p.retract(&GOAL, &[[1.0, 0.5], SAFE]).unwrap();
    assert_eq!(r.path.legs().len(), 2);
}

#[test]
fn blocked_retract_names_the_obstacle() {
    let circles = fixture();
    let world = |q: &[f64]| clearance(&circles, q);
    let p = planner(&world, vec![]);
    // From above the fixture down across it, stretched.
    let e = p.retract(&GOAL, &[START]).unwrap_err();
    match &e {
        ApproachError::RetractBlocked { violation } => {
            assert_eq!(violation.obstacle, "fixture");
            assert_eq!(violation.route, Route::Retract);
            assert!(violation.distance < CLEARANCE);
        }
        other => panic!("{other}"),
    }
    assert!(e.to_string().contains("fixture"), "{e}");
}

#[test]
fn retract_configurations_are_checked() {
    let circles = fixture();
    let world = |q: &[f64]| clearance(&circles, q);
    let p = planner(&world, vec![]);
    assert!(matches!(
        p.retract(&[0.0, 0.0], &[SAFE]),
        Err(ApproachError::InCollision {
            role: Role::RetractStart,
            ..
        })
    ));
    assert!(matches!(
        p.retract(&GOAL, &[[0.0, 9.0]]),
        Err(ApproachError::OutOfLimits {
            role: Role::RetractTarget(0),
            ..
        })
    ));
    let none: [[f64; 2]; 0] = [];
    assert!(matches!(
        p.retract(&GOAL, &none),
        Err(ApproachError::TooFewWaypoints { .. })
    ));
}

/// A 3R planar arm (link lengths 1.0, 0.8, 0.2), tool frame at the tip with its z axis along
/// the last link (from the wrist out through the tip).
const A: [f64; 3] = [1.0, 0.8, 0.2];

fn fk3(q: &[f64]) -> Isometry3<f64> {
    let (a1, a2, a3) = (q[0], q[0] + q[1], q[0] + q[1] + q[2]);
    let x = A[0] * a1.cos() + A[1] * a2.cos() + A[2] * a3.cos();
    let y = A[0] * a1.sin() + A[1] * a2.sin() + A[2] * a3.sin();
    // Rz(φ)·Ry(π/2) maps the tool z axis onto (cos φ, sin φ, 0).
    let r = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), a3)
        * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), std::f64::consts::FRAC_PI_2);
    Isometry3::from_parts(Translation3::new(x, y, 0.0), r)
}

/// Analytic IK with the elbow sign of `like`.
fn ik3(pose: &Isometry3<f64>, like: &[f64]) -> Option<Vec<f64>> {
    let z = pose.rotation * Vector3::z();
    let phi = z.y.atan2(z.x);
    let wx = pose.translation.x - A[2] * phi.cos();
    let wy = pose.translation.y - A[2] * phi.sin();
    let c2 = (wx * wx + wy * wy - A[0] * A[0] - A[1] * A[1]) / (2.0 * A[0] * A[1]);
    if !(-1.0..=1.0).contains(&c2) {
        return None;
    }
    let q2 = c2.acos().copysign(like[1]);
    let q1 = wy.atan2(wx) - (A[1] * q2.sin()).atan2(A[0] + A[1] * q2.cos());
    Some(vec![q1, q2, phi - q1 - q2])
}

#[test]
fn tool_axis_target_moves_the_tool_along_its_axis() {
    let last = [0.3, 0.9, -0.4];
    let ik = |p: &Isometry3<f64>| ik3(p, &last);
    for d in [-0.05, 0.02] {
        let q = tool_axis_target(&last, d, fk3, ik).unwrap();
        let (p0, p1) = (fk3(&last), fk3(&q));
        let axis = p0.rotation * Vector3::z();
        let moved = p1.translation.vector - p0.translation.vector;
        assert!((moved - d * axis).norm() < 1e-9, "{moved:?}");
        assert!(p1.rotation.angle_to(&p0.rotation) < 1e-9);
    }
}

#[test]
fn tool_axis_target_refuses_bad_answers() {
    let last = [0.3, 0.9, -0.4];
    let ik = |p: &Isometry3<f64>| ik3(p, &last);
    for d in [0.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            tool_axis_target(&last, d, fk3, ik),
            Err(ApproachError::InvalidRetractDistance { .. })
        ));
    }
    // Unreachable: far beyond the arm's reach.
    assert!(matches!(
        tool_axis_target(&last, 10.0, fk3, ik),
        Err(ApproachError::IkFailed { .. })
    ));
    // An IK that answers something else.
    let wrong = |_: &Isometry3<f64>| Some(vec![0.0, 0.0, 0.0]);
    assert!(matches!(
        tool_axis_target(&last, 0.05, fk3, wrong),
        Err(ApproachError::IkMismatch { .. })
    ));
    let short = |_: &Isometry3<f64>| Some(vec![0.0]);
    assert!(matches!(
        tool_axis_target(&last, 0.05, fk3, short),
        Err(ApproachError::JointCount { .. })
    ));
    let nan = |_: &Isometry3<f64>| Some(vec![f64::NAN, 0.0, 0.0]);
    assert!(matches!(
        tool_axis_target(&last, 0.05, fk3, nan),
        Err(ApproachError::NonFinitePosition { .. })
    ));
    let bad_fk = |_: &[f64]| Isometry3::translation(f64::NAN, 0.0, 0.0);
    assert!(matches!(
        tool_axis_target(&last, 0.05, bad_fk, ik),
        Err(ApproachError::NonFinitePose { .. })
    ));
}
