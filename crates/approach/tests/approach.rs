//! Approach planning on the 2-link planar arm with circle obstacles (exact distances).
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::*;
use kerf_approach::{ApproachError, Clearance, Role, Route, ViolationKind};

#[test]
fn free_direct_approach_is_direct() {
    let circles = far();
    let world = |q: &[f64]| clearance(&circles, q);
    let planner = planner(&world, vec![SAFE.to_vec()]);
    let a = planner.approach(&START, &GOAL).unwrap();
    assert_eq!(a.route, Route::Direct);
    assert_eq!(a.path.legs().len(), 1);
    assert_eq!(a.path.start(), &START);
    assert_eq!(a.path.end(), &GOAL);
    assert!(a.closest.distance >= CLEARANCE);
    assert_eq!(a.closest.obstacle, "far");
    // Timed in whole control periods.
    let periods = a.path.duration() / PERIOD;
    assert!((periods - periods.round()).abs() < 1e-9, "{periods}");
    let samples = a.path.samples(PERIOD).unwrap();
    assert_eq!(samples.len(), periods.round() as usize + 1);
}

#[test]
fn blocked_direct_approach_goes_via_the_safe_pose() {
    let circles = fixture();
    let world = |q: &[f64]| clearance(&circles, q);
    // Without a safe pose the direct move is refused, naming the fixture.
    let e = planner(&world, vec![]).approach(&START, &GOAL).unwrap_err();
    match &e {
        ApproachError::NoApproach { direct, via } => {
            assert_eq!(direct.obstacle, "fixture");
            assert_eq!(direct.route, Route::Direct);
            assert_eq!(direct.kind, ViolationKind::TooClose);
            assert!(direct.distance < CLEARANCE);
            assert!(direct.time > 0.0);
            assert!(via.is_empty());
        }
        other => panic!("{other}"),
    }
    assert!(e.to_string().contains("fixture"), "{e}");

    // With a safe pose it goes around.
    let a = planner(&world, vec![SAFE.to_vec()])
        .approach(&START, &GOAL)
        .unwrap();
    assert_eq!(a.route, Route::ViaSafePose(0));
    assert_eq!(a.path.legs().len(), 2);
    assert_eq!(a.path.legs()[0].end(), &SAFE);
    assert!(a.closest.distance >= CLEARANCE);
    // Every control-period sample, and a much denser scan between them, keeps the clearance.
    for s in a.path.samples(PERIOD).unwrap() {
        assert!(
            clearance(&circles, &s.q).distance >= CLEARANCE,
            "t = {}",
            s.t
        );
    }
    let mut min = f64::INFINITY;
    for s in a.path.samples(1e-4).unwrap() {
        let d = clearance(&circles, &s.q).distance;
        assert!(d >= CLEARANCE, "t = {} d = {d}", s.t);
        min = min.min(d);
    }
    // The reported closest sample is within the sampling resolution of the true minimum.
    assert!(
        a.closest.distance >= min - 1e-3,
        "{} vs {min}",
        a.closest.distance
    );
}

#[test]
fn second_safe_pose_is_tried_when_the_first_is_blocked() {
    let circles = fixture();
    let world = |q: &[f64]| clearance(&circles, q);
    // Safe pose 0: the arm stretched towards the fixture (1.5, 0): blocked.
    let blocked = vec![0.0, 0.0];
    let a = planner(&world, vec![blocked, SAFE.to_vec()])
        .approach(&START, &GOAL)
        .unwrap();
    assert_eq!(a.route, Route::ViaSafePose(1));
}

#[test]
fn no_collision_free_approach_names_the_obstacle() {
    let circles = post();
    let world = |q: &[f64]| clearance(&circles, q);
    let e = planner(&world, vec![SAFE.to_vec()])
        .approach(&START, &GOAL)
        .unwrap_err();
    let ApproachError::NoApproach { direct, via } = &e else {
        panic!("{e}");
    };
    assert_eq!(direct.obstacle, "post");
    assert_eq!(via.len(), 1);
    assert_eq!(via[0].obstacle, "post");
    assert_eq!(via[0].route, Route::ViaSafePose(0));
    for v in std::iter::once(direct.as_ref()).chain(via) {
        assert!(v.distance < v.required);
        assert_eq!(v.configuration.len(), 2);
        assert!(v.time.is_finite() && v.time > 0.0);
    }
    let text = e.to_string();
    assert!(
        text.contains("post") && text.contains("safe pose 0"),
        "{text}"
    );
}

#[test]
fn start_and_goal_must_be_inside_the_limits() {
    let circles = far();
    let world = |q: &[f64]| clearance(&circles, q);
    let p = planner(&world, vec![]);
    let e = p.approach(&[3.5, 0.0], &GOAL).unwrap_err();
    assert_eq!(
        e,
        ApproachError::OutOfLimits {
            role: Role::Start,
            joint: "shoulder".into(),
            value: 3.5,
            min: -3.0,
            max: 3.0,
        }
    );
    assert!(e.to_string().contains("shoulder") && e.to_string().contains("3.5"));
    let e = p.approach(&START, &[0.0, -3.1]).unwrap_err();
    assert!(
        matches!(&e, ApproachError::OutOfLimits { role: Role::Goal, joint, .. } if joint == "elbow"),
        "{e}"
    );
    assert!(matches!(
        p.approach(&[f64::NAN, 0.0], &GOAL),
        Err(ApproachError::NonFinitePosition {
            role: Role::Start,
            ..
        })
    ));
    assert!(matches!(
        p.approach(&[0.0], &GOAL),
        Err(ApproachError::JointCount {
            expected: 2,
            found: 1,
            ..
        })
    ));
}

#[test]
fn start_or_goal_in_collision_is_refused() {
    let circles = fixture();
    let world = |q: &[f64]| clearance(&circles, q);
    let p = planner(&world, vec![SAFE.to_vec()]);
    // Stretched along angle 0: the tip (1.8, 0) is inside the fixture.
    let e = p.approach(&[0.0, 0.0], &GOAL).unwrap_err();
    match &e {
        ApproachError::InCollision {
            role,
            obstacle,
            distance,
            ..
        } => {
            assert_eq!(*role, Role::Start);
            assert_eq!(obstacle, "fixture");
            assert!(*distance < 0.0);
        }
        other => panic!("{other}"),
    }
    assert!(matches!(
        p.approach(&START, &[0.0, 0.0]),
        Err(ApproachError::InCollision {
            role: Role::Goal,
            ..
        })
    ));
}

#[test]
fn safe_pose_outside_the_limits_is_refused_up_front() {
    let circles = far();
    let world = |q: &[f64]| clearance(&circles, q);
    let e = kerf_approach::ApproachPlanner::new(settings(vec![vec![0.0, 3.2]]), limits(), &world)
        .unwrap_err();
    assert!(
        matches!(&e, ApproachError::OutOfLimits { role: Role::SafePose(0), joint, value, .. } if joint == "elbow" && *value == 3.2),
        "{e}"
    );
}

#[test]
fn nan_from_the_clearance_function_is_an_error() {
    // NaN at the goal.
    let world = |q: &[f64]| {
        if q[0] > 0.0 {
            Clearance::new(f64::NAN, "broken")
        } else {
            Clearance::new(1.0, "ok")
        }
    };
    assert!(planner(&world, vec![])
        .approach(&[-0.5, 0.0], &[-0.1, 0.0])
        .is_ok());
    let e = planner(&world, vec![])
        .approach(&[-0.5, 0.0], &[0.5, 0.0])
        .unwrap_err();
    assert!(matches!(e, ApproachError::InvalidClearance { .. }), "{e}");
    // NaN in the middle of a move.
    let world = |q: &[f64]| {
        if q[0].abs() < 0.1 {
            Clearance::new(f64::NAN, "broken")
        } else {
            Clearance::new(1.0, "ok")
        }
    };
    let e = planner(&world, vec![])
        .approach(&[-0.5, 0.0], &[0.5, 0.0])
        .unwrap_err();
    assert!(
        matches!(&e, ApproachError::InvalidClearance { obstacle, .. } if obstacle == "broken"),
        "{e}"
    );
}

#[test]
fn grazing_motion_is_refined_not_refused() {
    // A wall the arm's tip passes at just over the clearance: the plain half-sweep bound
    // fails between 4 ms samples near the closest point, refinement certifies it.
    let circles = vec![Circle {
        name: "wall",
        center: [0.0, L1 + L2 + LINK_RADIUS + CLEARANCE + 0.5 + 2e-4],
        radius: 0.5,
    }];
    let world = |q: &[f64]| clearance(&circles, q);
    let p = planner(&world, vec![]);
    let a = p.approach(&[1.2, 0.0], &[1.9, 0.0]).unwrap();
    assert_eq!(a.route, Route::Direct);
    // The plain bound alone fails somewhere between control-period samples.
    let samples = a.path.samples(PERIOD).unwrap();
    let check = p.clearance_check();
    let unproven = samples.windows(2).any(|w| {
        let (da, db) = (world(&w[0].q).distance, world(&w[1].q).distance);
        da + db < 2.0 * CLEARANCE + check.sweep(&w[0].q, &w[1].q)
    });
    assert!(unproven, "the test should need refinement");
    assert!(
        a.closest.distance < CLEARANCE + 3e-4,
        "{}",
        a.closest.distance
    );
}

#[test]
fn unprovable_motion_is_uncertified_not_accepted() {
    // A Lipschitz bound so large nothing can be certified: refused, never accepted.
    let circles = far();
    let world = |q: &[f64]| clearance(&circles, q);
    let settings = kerf_approach::ApproachSettings::builder()
        .clearance(CLEARANCE)
        .lipschitz(vec![1e12, 1e12])
        .build()
        .unwrap();
    let p = kerf_approach::ApproachPlanner::new(settings, limits(), &world).unwrap();
    let e = p.approach(&START, &GOAL).unwrap_err();
    let ApproachError::NoApproach { direct, .. } = &e else {
        panic!("{e}");
    };
    assert_eq!(direct.kind, ViolationKind::Uncertified);
    assert!(direct.required > direct.distance);
}

#[test]
fn zero_length_approach_is_a_single_sample() {
    let circles = far();
    let world = |q: &[f64]| clearance(&circles, q);
    let a = planner(&world, vec![]).approach(&GOAL, &GOAL).unwrap();
    assert_eq!(a.path.duration(), 0.0);
    let s = a.path.samples(PERIOD).unwrap();
    assert_eq!(s.len(), 1);
    assert_eq!(s[0].q, GOAL.to_vec());
}
