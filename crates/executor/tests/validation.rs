//! Every rejection of `validate` and of tolerances: variant, result code, message.
#![allow(clippy::needless_range_loop)] // joints index several parallel arrays
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::{limits6, names, pt, request, rest, robot};
use kerf_executor::{
    resolve_tolerances, validate, Executor, ExecutorConfig, ExecutorError, GoalTolerances,
    JointLimits, JointSample, JointTolerance, TrajectoryRequest, INVALID_GOAL, INVALID_JOINTS,
    OLD_HEADER_TIMESTAMP,
};

const Z6: [f64; 6] = [0.0; 6];

fn cfg() -> ExecutorConfig {
    ExecutorConfig::default()
}

/// A valid 6-joint request: from rest at 0 to 0.2 in 2 s, cubic.
fn good() -> TrajectoryRequest {
    let l = limits6();
    request(
        &l,
        vec![
            pt(1.0, &[0.1; 6], &[0.1; 6], &[]),
            pt(2.0, &[0.2; 6], &Z6, &[]),
        ],
    )
}

fn check(req: &TrajectoryRequest) -> Result<(), ExecutorError> {
    validate(&limits6(), &cfg(), req, &rest(6, 0.0), 10.0).map(|_| ())
}

/// Asserts the rejection: error code and all `needles` in the message.
fn rejected(result: Result<(), ExecutorError>, code: i32, needles: &[&str]) -> ExecutorError {
    let err = result.expect_err("must be rejected");
    assert_eq!(err.error_code(), code, "{err}");
    let msg = err.to_string();
    for n in needles {
        assert!(msg.contains(n), "message {msg:?} lacks {n:?}");
    }
    err
}

#[test]
fn valid_request_is_accepted() {
    let traj = validate(&limits6(), &cfg(), &good(), &rest(6, 0.0), 10.0).unwrap();
    assert_eq!(traj.start_time(), 10.0);
    assert_eq!(traj.end_time(), 12.0);
    assert_eq!(traj.joint_count(), 6);
}

#[test]
fn empty_trajectory() {
    let mut req = good();
    req.points.clear();
    let e = rejected(check(&req), INVALID_GOAL, &["no points"]);
    assert_eq!(e, ExecutorError::EmptyTrajectory);
}

#[test]
fn no_joint_names() {
    let mut req = good();
    req.joint_names.clear();
    let e = rejected(check(&req), INVALID_JOINTS, &["no joint names"]);
    assert_eq!(e, ExecutorError::NoJointNames);
}

#[test]
fn unknown_joint_lists_the_robot_joints() {
    let mut req = good();
    req.joint_names[2] = "elbow".into();
    let e = rejected(
        check(&req),
        INVALID_JOINTS,
        &["'elbow'", "j1, j2, j3, j4, j5, j6"],
    );
    assert!(matches!(e, ExecutorError::UnknownJoint { .. }));
}

#[test]
fn duplicate_joint() {
    let mut req = good();
    req.joint_names[4] = "j2".into();
    let e = rejected(check(&req), INVALID_JOINTS, &["'j2'", "twice"]);
    assert!(matches!(e, ExecutorError::DuplicateJoint { .. }));
}

#[test]
fn missing_joints() {
    let mut req = good();
    req.joint_names.truncate(4);
    for p in &mut req.points {
        p.positions.truncate(4);
        p.velocities.truncate(4);
    }
    let e = rejected(check(&req), INVALID_JOINTS, &["[j5, j6]", "partial"]);
    assert!(matches!(e, ExecutorError::MissingJoints { .. }));
}

#[test]
fn time_not_strictly_increasing() {
    let mut req = good();
    req.points[1].time_from_start = 1.0;
    let e = rejected(check(&req), INVALID_GOAL, &["point 1", "1 s", "point 0"]);
    assert_eq!(
        e,
        ExecutorError::NonIncreasingTime {
            index: 1,
            time: 1.0,
            previous_index: 0,
            previous: 1.0
        }
    );
    req.points[1].time_from_start = 0.2;
    rejected(check(&req), INVALID_GOAL, &["point 1", "0.2 s", "1 s"]);
}

#[test]
fn negative_or_non_finite_time() {
    for bad in [-0.1, f64::NAN, f64::INFINITY] {
        let mut req = good();
        req.points[0].time_from_start = bad;
        let e = rejected(check(&req), INVALID_GOAL, &["point 0", "time_from_start"]);
        assert!(matches!(
            e,
            ExecutorError::InvalidTimeFromStart { index: 0, .. }
        ));
    }
}

#[test]
fn non_finite_values_name_point_field_and_joint() {
    for (field, name) in [(0, "positions"), (1, "velocities"), (2, "accelerations")] {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut req = good();
            let p = &mut req.points[1];
            p.accelerations = Z6.to_vec();
            match field {
                0 => p.positions[3] = bad,
                1 => p.velocities[3] = bad,
                _ => p.accelerations[3] = bad,
            }
            let e = rejected(check(&req), INVALID_GOAL, &["point 1", name, "'j4'"]);
            assert!(
                matches!(e, ExecutorError::NonFiniteValue { index: 1, .. }),
                "{e:?}"
            );
        }
    }
}

#[test]
fn wrong_lengths() {
    let mut req = good();
    req.points[1].positions.pop();
    let e = rejected(
        check(&req),
        INVALID_GOAL,
        &["point 1", "positions", "5 values", "expected 6"],
    );
    assert!(matches!(
        e,
        ExecutorError::WrongLength {
            index: 1,
            field: "positions",
            ..
        }
    ));

    let mut req = good();
    req.points[0].velocities.push(0.0);
    rejected(
        check(&req),
        INVALID_GOAL,
        &["point 0", "velocities", "7 values", "or none"],
    );

    let mut req = good();
    req.points[0].accelerations = vec![0.0; 2];
    rejected(
        check(&req),
        INVALID_GOAL,
        &["point 0", "accelerations", "2 values"],
    );
}

#[test]
fn accelerations_without_velocities() {
    let mut req = good();
    req.points[0].velocities.clear();
    req.points[0].accelerations = Z6.to_vec();
    let e = rejected(
        check(&req),
        INVALID_GOAL,
        &["point 0", "accelerations", "without velocities"],
    );
    assert_eq!(
        e,
        ExecutorError::AccelerationsWithoutVelocities { index: 0 }
    );
}

#[test]
fn effort_is_rejected() {
    let mut req = good();
    req.points[1].effort = vec![1.0; 6];
    let e = rejected(
        check(&req),
        INVALID_GOAL,
        &["point 1", "effort", "no effort command interface"],
    );
    assert_eq!(e, ExecutorError::EffortNotSupported { index: 1 });
}

#[test]
fn last_point_must_be_at_rest() {
    let mut req = good();
    req.points[1].velocities[5] = 0.01;
    let e = rejected(
        check(&req),
        INVALID_GOAL,
        &["last point 1", "velocity", "'j6'", "0.01"],
    );
    assert!(matches!(
        e,
        ExecutorError::NonZeroFinalState {
            index: 1,
            field: "velocity",
            ..
        }
    ));

    let mut req = good();
    req.points[1].accelerations = vec![0.0, -0.5, 0.0, 0.0, 0.0, 0.0];
    req.points[0].accelerations = Z6.to_vec();
    let e = rejected(
        check(&req),
        INVALID_GOAL,
        &["last point 1", "acceleration", "'j2'", "-0.5"],
    );
    assert!(matches!(
        e,
        ExecutorError::NonZeroFinalState {
            field: "acceleration",
            ..
        }
    ));
}

#[test]
fn position_out_of_range_at_a_waypoint() {
    let mut req = good();
    req.points[0].positions[1] = 3.5;
    let e = rejected(
        check(&req),
        INVALID_GOAL,
        &["'j2'", "point 0", "3.5", "[-3, 3]"],
    );
    assert!(matches!(e, ExecutorError::PositionLimit { .. }));
}

#[test]
fn limits_allow_rounding_slack_but_not_more() {
    // Exactly at the limit, and a relative 1e-12 beyond, pass; 1e-6 beyond fails.
    let l = robot(1, 1.0, 1.0, 10.0);
    let make = |p: f64| request(&l, vec![pt(0.0, &[p], &[], &[]), pt(1e6, &[p], &[], &[])]);
    let at = |p: f64| validate(&l, &cfg(), &make(p), &JointSample::at_rest(vec![p]), 0.0);
    assert!(at(1.0).is_ok());
    assert!(at(1.0 + 1e-12).is_ok());
    assert!(matches!(
        at(1.0 + 1e-6),
        Err(ExecutorError::PositionLimit { .. })
    ));
}

#[test]
fn velocity_over_the_limit_on_a_linear_segment() {
    // j3 limit 2.4: 0.1 → 3 in 1 s is 2.9/s.
    let l = limits6();
    let mut p1 = [0.1; 6];
    p1[2] = 2.9;
    let mut p2 = p1;
    p2[2] = 0.0;
    let req = request(
        &l,
        vec![
            pt(1.0, &[0.1; 6], &[], &[]),
            pt(2.0, &p1, &[], &[]),
            pt(300.0, &p2, &[], &[]),
        ],
    );
    let e = rejected(
        check(&req),
        INVALID_GOAL,
        &["'j3'", "between point 0 and point 1", "2.4"],
    );
    assert!(matches!(e, ExecutorError::VelocityLimit { .. }), "{e:?}");
}

#[test]
fn velocity_step_of_linear_segments_is_an_acceleration() {
    // Slope 0.1/s from rest: Δv 0.1 in 4 ms = 25 > 10 (j1's limit).
    let l = limits6();
    let req = request(
        &l,
        vec![pt(0.0, &Z6, &[], &[]), pt(1.0, &[0.1; 6], &[], &[])],
    );
    let e = rejected(
        check(&req),
        INVALID_GOAL,
        &["'j1'", "point 0", "control period", "0.004"],
    );
    match e {
        ExecutorError::VelocityStep {
            acceleration,
            limit,
            from,
            to,
            ..
        } => {
            assert!((acceleration - 25.0).abs() < 1e-9);
            assert_eq!(limit, 10.0);
            assert_eq!(from, 0.0);
            assert!((to - 0.1).abs() < 1e-15);
        }
        other => panic!("{other:?}"),
    }
    // The same path slowed down to 0.02/s passes (5 ≤ 10), including the stop at the end.
    let req = request(
        &l,
        vec![pt(0.0, &Z6, &[], &[]), pt(5.0, &[0.1; 6], &[], &[])],
    );
    assert!(check(&req).is_ok());
}

#[test]
fn acceleration_over_the_limit_on_a_cubic() {
    // Rest to rest over 0.2 in 0.2 s: |v| peaks at 1.5 d / T = 1.5 ≤ 2, |a| at 6 d / T² = 30
    // > 10 at the ends.
    let l = limits6();
    let req = request(
        &l,
        vec![pt(0.0, &Z6, &Z6, &[]), pt(0.2, &[0.2; 6], &Z6, &[])],
    );
    let e = rejected(
        check(&req),
        INVALID_GOAL,
        &["'j1'", "acceleration", "30", "limit 10"],
    );
    assert!(matches!(e, ExecutorError::AccelerationLimit { .. }));
}

#[test]
fn start_time_future_past_and_old() {
    let l = limits6();
    let now = 10.0;
    let run = |start: Option<f64>| {
        let mut req = good();
        req.start_time = start;
        validate(&l, &cfg(), &req, &rest(6, 0.0), now)
    };
    // None and 0 mean now.
    assert_eq!(run(None).unwrap().start_time(), now);
    assert_eq!(run(Some(0.0)).unwrap().start_time(), now);
    // Future: held until then.
    let t = run(Some(12.0)).unwrap();
    assert_eq!((t.start_time(), t.end_time()), (12.0, 14.0));
    assert_eq!(t.sample(11.99), rest(6, 0.0));
    assert!(t.sample(12.01).velocities[0] > 0.0);
    // Past, first point (1 s) still ahead: shorter start segment, still checked.
    let t = run(Some(9.7)).unwrap();
    assert_eq!(t.start_time(), 9.7);
    assert_eq!(t.sample(10.0).positions, vec![0.0; 6]);
    assert_eq!(t.sample(10.0).velocities, vec![0.0; 6]);
    assert_eq!(t.sample(10.7).positions, vec![0.1; 6]);
    // Past, first point due: OLD_HEADER_TIMESTAMP.
    let e = run(Some(9.0)).unwrap_err();
    assert_eq!(e.error_code(), OLD_HEADER_TIMESTAMP);
    assert!(
        e.to_string().contains("9 s") && e.to_string().contains("now = 10"),
        "{e}"
    );
    let e = run(Some(1.0)).unwrap_err();
    assert!(
        matches!(e, ExecutorError::OldHeaderTimestamp { start_time, first_point_time, now }
        if start_time == 1.0 && first_point_time == 2.0 && now == 10.0)
    );
    // Past with a start segment too short for the limits: rejected by the limit check.
    let e = run(Some(9.0001)).unwrap_err();
    assert!(
        matches!(
            e,
            ExecutorError::AccelerationLimit { .. } | ExecutorError::VelocityLimit { .. }
        ),
        "{e:?}"
    );
    assert!(e.to_string().contains("start segment"));
    // Invalid stamps.
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let e = run(Some(bad)).unwrap_err();
        assert!(matches!(e, ExecutorError::InvalidStartTime { .. }));
        assert_eq!(e.error_code(), INVALID_GOAL);
    }
    // A negative time is before the clock's origin: simply in the past.
    let e = run(Some(-1.0)).unwrap_err();
    assert!(
        matches!(e, ExecutorError::OldHeaderTimestamp { .. }),
        "{e:?}"
    );
}

#[test]
fn first_point_due_now_must_match_the_current_position() {
    let l = limits6();
    let mut p0 = [0.0; 6];
    p0[3] = 0.0005; // within the default 1e-3
    let req = request(
        &l,
        vec![pt(0.0, &p0, &Z6, &[]), pt(1.0, &[0.1; 6], &Z6, &[])],
    );
    assert!(check(&req).is_ok());
    p0[3] = 0.01;
    let req = request(
        &l,
        vec![pt(0.0, &p0, &Z6, &[]), pt(1.0, &[0.1; 6], &Z6, &[])],
    );
    let e = rejected(
        check(&req),
        INVALID_GOAL,
        &["'j4'", "0.01", "start tolerance 0.001"],
    );
    assert!(matches!(e, ExecutorError::StartMismatch { .. }));
    // A larger configured tolerance accepts it.
    let cfg = ExecutorConfig {
        start_tolerance: 0.02,
        ..cfg()
    };
    assert!(validate(&l, &cfg, &req, &rest(6, 0.0), 10.0).is_ok());
}

#[test]
fn shuffled_joint_order_is_mapped_to_model_order() {
    let l = limits6();
    let order = [3usize, 0, 5, 1, 4, 2];
    let target = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]; // model order
    let shuffled: Vec<f64> = order.iter().map(|&j| target[j]).collect();
    let req = TrajectoryRequest {
        joint_names: order.iter().map(|&j| l[j].name.clone()).collect(),
        points: vec![pt(1.0, &shuffled, &Z6, &[])],
        start_time: None,
    };
    let traj = validate(&l, &cfg(), &req, &rest(6, 0.0), 0.0).unwrap();
    assert_eq!(traj.final_positions(), &target);
    assert_eq!(traj.sample(1.0).positions, target.to_vec());
    let mid = traj.sample(0.5);
    for j in 0..6 {
        assert!(
            (mid.positions[j] - target[j] / 2.0).abs() < 1e-12,
            "joint {j}"
        );
    }
}

#[test]
fn current_state_is_checked() {
    let l = limits6();
    let bad = JointSample {
        positions: vec![0.0; 5],
        ..Default::default()
    };
    let e = validate(&l, &cfg(), &good(), &bad, 0.0).unwrap_err();
    assert!(e.to_string().contains("current state") && e.to_string().contains("positions"));
    let mut bad = rest(6, 0.0);
    bad.velocities[1] = f64::NAN;
    let e = validate(&l, &cfg(), &good(), &bad, 0.0).unwrap_err();
    assert!(e.to_string().contains("'j2'"), "{e}");
    let e = validate(&l, &cfg(), &good(), &rest(6, 0.0), f64::NAN).unwrap_err();
    assert!(matches!(e, ExecutorError::NonFiniteTime { .. }));
}

#[test]
fn tolerances_are_validated() {
    let l = limits6();
    let tol = |name: &str, p: f64| JointTolerance {
        name: name.into(),
        position: p,
        velocity: 0.0,
        acceleration: 0.0,
    };
    let goal = |path, goal_tol, goal_time| GoalTolerances {
        path,
        goal: goal_tol,
        goal_time,
    };

    let e =
        resolve_tolerances(&l, &cfg(), &goal(vec![tol("wrist", 0.1)], vec![], 0.0)).unwrap_err();
    assert_eq!(e.error_code(), INVALID_JOINTS);
    assert!(
        e.to_string().contains("path")
            && e.to_string().contains("'wrist'")
            && e.to_string().contains("j1, j2")
    );

    let e = resolve_tolerances(
        &l,
        &cfg(),
        &goal(vec![], vec![tol("j1", 0.1), tol("j1", 0.2)], 0.0),
    )
    .unwrap_err();
    assert_eq!(e.error_code(), INVALID_JOINTS);

    for bad in [-0.5, -2.0, f64::NAN, f64::INFINITY] {
        let e =
            resolve_tolerances(&l, &cfg(), &goal(vec![], vec![tol("j3", bad)], 0.0)).unwrap_err();
        assert_eq!(e.error_code(), INVALID_GOAL);
        assert!(
            e.to_string().contains("goal tolerance of joint 'j3'")
                && e.to_string().contains("position"),
            "{e}"
        );
    }
    for bad in [-1.0, f64::NAN] {
        let e = resolve_tolerances(&l, &cfg(), &goal(vec![], vec![], bad)).unwrap_err();
        assert!(matches!(e, ExecutorError::InvalidGoalTime { .. }));
    }

    // 0 = default, −1 = none, > 0 = value; default goal velocity = stopped_velocity_tolerance.
    let cfg = ExecutorConfig {
        path_tolerances: vec![tol("j1", 0.05), tol("j2", 0.05)],
        goal_time_tolerance: 0.7,
        ..cfg()
    };
    let r = resolve_tolerances(
        &l,
        &cfg,
        &goal(
            vec![tol("j1", 0.0), tol("j2", -1.0), tol("j3", 0.3)],
            vec![],
            0.0,
        ),
    )
    .unwrap();
    assert_eq!(r.path[0].position, 0.05);
    assert_eq!(r.path[1].position, 0.0);
    assert_eq!(r.path[2].position, 0.3);
    assert_eq!(r.path[3].position, 0.0);
    assert_eq!(r.goal[4].velocity, 0.01);
    assert_eq!(r.goal_time, 0.7);
    let r = resolve_tolerances(&l, &cfg, &goal(vec![], vec![], 2.0)).unwrap();
    assert_eq!(r.goal_time, 2.0);
}

#[test]
fn submit_validates_tolerances_too() {
    let l = limits6();
    let mut exec = Executor::new(l.clone(), cfg(), vec![0.0; 6]).unwrap();
    let tolerances = GoalTolerances {
        path: vec![JointTolerance {
            name: "j9".into(),
            ..Default::default()
        }],
        ..Default::default()
    };
    let e = exec.submit(&good(), &tolerances, 0.0).unwrap_err();
    assert_eq!(e.error_code(), INVALID_JOINTS);
    assert_eq!(exec.active_goal(), None);
}

#[test]
fn invalid_robot_model_config_and_initial_positions() {
    let l = limits6();
    let with = |f: &dyn Fn(&mut JointLimits)| {
        let mut l = limits6();
        f(&mut l[1]);
        Executor::new(l, cfg(), vec![0.0; 6]).unwrap_err()
    };
    assert!(with(&|l| l.max_velocity = 0.0)
        .to_string()
        .contains("joint 'j2': invalid limit max_velocity = 0"));
    assert!(with(&|l| l.max_acceleration = f64::NAN)
        .to_string()
        .contains("max_acceleration"));
    assert!(with(&|l| l.min_position = 5.0)
        .to_string()
        .contains("below max_position"));
    assert!(with(&|l| l.name = "j1".into())
        .to_string()
        .contains("'j1' appears twice"));
    // Continuous joints: infinite position limits are allowed.
    let mut cont = limits6();
    cont[0].min_position = f64::NEG_INFINITY;
    cont[0].max_position = f64::INFINITY;
    assert!(Executor::new(cont, cfg(), vec![0.0; 6]).is_ok());

    assert_eq!(
        Executor::new(vec![], cfg(), vec![]).unwrap_err(),
        ExecutorError::NoJoints
    );
    let e = Executor::new(
        l.clone(),
        ExecutorConfig {
            control_period: 0.0,
            ..cfg()
        },
        vec![0.0; 6],
    )
    .unwrap_err();
    assert!(e.to_string().contains("control_period"));
    let e = Executor::new(
        l.clone(),
        ExecutorConfig {
            start_tolerance: -1.0,
            ..cfg()
        },
        vec![0.0; 6],
    )
    .unwrap_err();
    assert!(e.to_string().contains("start_tolerance"));
    let e = Executor::new(l.clone(), cfg(), vec![0.0; 5]).unwrap_err();
    assert!(e.to_string().contains("initial positions") && e.to_string().contains("5 values"));
    let e = Executor::new(l.clone(), cfg(), vec![0.0, 0.0, 4.0, 0.0, 0.0, 0.0]).unwrap_err();
    assert!(e.to_string().contains("'j3'") && e.to_string().contains("outside its limits"));
    let e = Executor::new(l.clone(), cfg(), vec![0.0, f64::NAN, 0.0, 0.0, 0.0, 0.0]).unwrap_err();
    assert!(e.to_string().contains("'j2'"));
    let _ = names(&l);
}

#[test]
fn velocity_step_from_a_moving_state_into_a_linear_start_segment() {
    // Current velocity 0.5 on j5; a linear start segment to a point 10 s away has slope ~0:
    // Δv 0.5 in 4 ms = 125 > 14 (j5's limit).
    let l = limits6();
    let mut current = rest(6, 0.0);
    current.velocities[4] = 0.5;
    let req = request(&l, vec![pt(10.0, &[0.01; 6], &[], &[])]);
    let e = validate(&l, &cfg(), &req, &current, 0.0).map(|_| ());
    let e = rejected(
        e,
        INVALID_GOAL,
        &["'j5'", "start of the start segment", "from 0.5"],
    );
    assert!(matches!(e, ExecutorError::VelocityStep { limit, .. } if limit == 14.0));
}
