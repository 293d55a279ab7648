//! The executor state machine with mock hardware.
#![allow(clippy::needless_range_loop)] // joints index several parallel arrays
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::{executor, limits6, min_jerk, pt, request, run, DT};
use kerf_executor::{
    validate, Cycle, ExecutorConfig, ExecutorError, GoalEvent, GoalId, GoalTolerances, JointSample,
    JointTolerance, MockHardware, Outcome, TrajectoryRequest, GOAL_TOLERANCE_VIOLATED,
    PATH_TOLERANCE_VIOLATED,
};

/// Minimum-jerk rest-to-rest request from `from` to `to` (all joints) in `t_total`, given as
/// `m + 1` quintic waypoints starting at `time_from_start` 0.
fn min_jerk_request(from: &[f64], to: &[f64], t_total: f64, m: usize) -> TrajectoryRequest {
    let limits = limits6();
    let points = (0..=m)
        .map(|k| {
            let t = t_total * k as f64 / m as f64;
            let s: Vec<_> = (0..6)
                .map(|j| min_jerk(from[j], to[j] - from[j], t_total, t))
                .collect();
            let p: Vec<f64> = s.iter().map(|x| x.0).collect();
            let v: Vec<f64> = s.iter().map(|x| if k == m { 0.0 } else { x.1 }).collect();
            let a: Vec<f64> = s.iter().map(|x| if k == m { 0.0 } else { x.2 }).collect();
            pt(t, &p, &v, &a)
        })
        .collect();
    request(&limits, points)
}

const TARGET: [f64; 6] = [0.5, -0.4, 0.3, 0.6, -0.2, 0.1];

fn events(cycles: &[Cycle]) -> Vec<(f64, GoalEvent)> {
    cycles
        .iter()
        .flat_map(|c| c.events.iter().map(move |e| (c.time, e.clone())))
        .collect()
}

/// Per cycle, the reference moves within the velocity limit and changes velocity within the
/// acceleration limit: no jumps.
fn assert_continuous(cycles: &[Cycle]) {
    let limits = limits6();
    for w in cycles.windows(2) {
        let (a, b) = (&w[0].reference, &w[1].reference);
        let dt = w[1].time - w[0].time;
        for (j, l) in limits.iter().enumerate() {
            let dp = (b.positions[j] - a.positions[j]).abs();
            let dv = (b.velocities[j] - a.velocities[j]).abs();
            assert!(
                dp <= l.max_velocity * dt * (1.0 + 1e-6),
                "t={} j={j} dp={dp}",
                w[1].time
            );
            assert!(
                dv <= l.max_acceleration * dt * (1.0 + 1e-6),
                "t={} j={j} dv={dv}",
                w[1].time
            );
        }
    }
}

fn goal_tolerance(position: f64) -> GoalTolerances {
    GoalTolerances {
        goal: limits6()
            .iter()
            .map(|l| JointTolerance {
                name: l.name.clone(),
                position,
                velocity: 0.0,
                acceleration: 0.0,
            })
            .collect(),
        ..Default::default()
    }
}

#[test]
fn succeeds_with_ideal_mock_hardware() {
    let limits = limits6();
    let mut exec = executor(&limits, ExecutorConfig::default(), 0.0);
    let mut hw = MockHardware::new(vec![0.0; 6]);
    let req = min_jerk_request(&[0.0; 6], &TARGET, 2.0, 20);
    let id = exec.submit(&req, &goal_tolerance(1e-6), 0.0).unwrap();
    assert_eq!(exec.active_goal(), Some(id));
    let reference = validate(
        &limits,
        exec.config(),
        &req,
        &JointSample::at_rest(vec![0.0; 6]),
        0.0,
    )
    .unwrap();

    let cycles = run(&mut exec, &mut hw, 0.0, 3.0);
    let ev = events(&cycles);
    assert_eq!(ev.len(), 1, "{ev:?}");
    let (t, e) = &ev[0];
    assert_eq!(
        e,
        &GoalEvent {
            id,
            outcome: Outcome::Succeeded
        }
    );
    assert!(*t >= 2.0 && *t <= 2.0 + 2.0 * DT, "succeeded at {t}");
    for c in &cycles {
        assert_eq!(c.reference, reference.sample(c.time));
        assert_eq!(c.feedback.is_some(), c.time < *t, "t = {}", c.time);
        if let Some(f) = c.feedback {
            assert_eq!(f.id, id);
            assert!((f.time_from_start - c.time).abs() < 1e-12);
        }
    }
    assert_continuous(&cycles);
    assert_eq!(exec.active_goal(), None);
    assert_eq!(exec.commanded(), &JointSample::at_rest(TARGET.to_vec()));
    assert_eq!(hw.state().positions, TARGET.to_vec());
}

#[test]
fn preemption_continues_from_the_commanded_state() {
    let limits = limits6();
    let mut exec = executor(&limits, ExecutorConfig::default(), 0.0);
    let mut hw = MockHardware::new(vec![0.0; 6]);
    let a = min_jerk_request(&[0.0; 6], &TARGET, 4.0, 8);
    let first = exec.submit(&a, &GoalTolerances::default(), 0.0).unwrap();
    let a_alone = validate(
        &limits,
        exec.config(),
        &a,
        &JointSample::at_rest(vec![0.0; 6]),
        0.0,
    )
    .unwrap();
    let mut cycles = run(&mut exec, &mut hw, 0.0, 1.0);

    // B: to −0.3 on all joints, first point 2 s ahead, from the moving state at t = 1.
    let z = [0.0; 6];
    let b = request(&limits, vec![pt(2.0, &[-0.3; 6], &z, &z)]);
    let second = exec.submit(&b, &GoalTolerances::default(), 1.0).unwrap();
    assert_ne!(first, second);
    assert_eq!(exec.active_goal(), Some(second));
    let after = run(&mut exec, &mut hw, 1.0, 4.0);
    assert_eq!(
        after[0].events,
        vec![GoalEvent {
            id: first,
            outcome: Outcome::Preempted
        }]
    );
    // At the switch the reference equals A's commanded state: no jump.
    let expected = a_alone.sample(1.0);
    for j in 0..6 {
        assert!((after[0].reference.positions[j] - expected.positions[j]).abs() < 1e-12);
        assert!((after[0].reference.velocities[j] - expected.velocities[j]).abs() < 1e-12);
        assert!((after[0].reference.accelerations[j] - expected.accelerations[j]).abs() < 1e-9);
    }
    assert!(
        expected.velocities[0].abs() > 0.1,
        "A must be moving at the switch"
    );
    cycles.extend(after);
    assert_continuous(&cycles);
    let ev = events(&cycles);
    assert_eq!(ev.len(), 2, "{ev:?}");
    assert_eq!(
        ev[1].1,
        GoalEvent {
            id: second,
            outcome: Outcome::Succeeded
        }
    );
    assert!(ev[1].0 >= 3.0);
    assert_eq!(exec.commanded().positions, vec![-0.3; 6]);
}

#[test]
fn cancel_decelerates_together_within_limits_and_stops() {
    let limits = limits6();
    let mut exec = executor(&limits, ExecutorConfig::default(), 0.0);
    let mut hw = MockHardware::new(vec![0.0; 6]);
    let big: Vec<f64> = TARGET.iter().map(|p| 3.0 * p).collect();
    let id = exec
        .submit(
            &min_jerk_request(&[0.0; 6], &big, 2.0, 10),
            &GoalTolerances::default(),
            0.0,
        )
        .unwrap();
    let before = run(&mut exec, &mut hw, 0.0, 1.0);
    exec.cancel(id, 1.0).unwrap();
    assert_eq!(exec.active_goal(), None);
    assert!(matches!(
        exec.cancel(id, 1.0),
        Err(ExecutorError::UnknownGoal { id: 1 })
    ));
    assert_eq!(
        exec.cancel(GoalId(42), 1.0).unwrap_err().error_code(),
        kerf_executor::INVALID_GOAL
    );

    let after = run(&mut exec, &mut hw, 1.0, 2.0);
    assert_eq!(
        after[0].events,
        vec![GoalEvent {
            id,
            outcome: Outcome::Canceled
        }]
    );
    assert!(after.iter().all(|c| c.feedback.is_none()));
    // The stop starts from the commanded state at the cancel time.
    let p0 = after[0].reference.positions.clone();
    let v0 = after[0].reference.velocities.clone();
    let mut all = before.clone();
    all.extend(after.iter().cloned());
    assert_continuous(&all);

    // Synchronized linear deceleration: T = max |v_i| / a_i, direction kept.
    let stop_time = limits
        .iter()
        .zip(&v0)
        .map(|(l, v)| v.abs() / l.max_acceleration)
        .fold(0.0, f64::max);
    assert!(
        stop_time > 0.1,
        "must be moving fast enough to test: {stop_time}"
    );
    for c in &after {
        let tau = c.time - 1.0;
        for j in 0..6 {
            let v = c.reference.velocities[j];
            let expected = if tau >= stop_time {
                0.0
            } else {
                v0[j] * (1.0 - tau / stop_time)
            };
            assert!(
                (v - expected).abs() < 1e-12,
                "t={} j={j}: {v} vs {expected}",
                c.time
            );
            assert!(
                c.reference.accelerations[j].abs() <= limits[j].max_acceleration * (1.0 + 1e-9)
            );
        }
    }
    let last = &after.last().unwrap().reference;
    assert!(last.velocities.iter().all(|v| *v == 0.0));
    let stopped: Vec<_> = after
        .iter()
        .filter(|c| c.time >= 1.0 + stop_time + DT)
        .collect();
    assert!(stopped
        .iter()
        .all(|c| c.reference.positions == last.positions));
    // Travel during the stop: v0 T / 2.
    for j in 0..6 {
        let expected = p0[j] + 0.5 * v0[j] * stop_time;
        assert!((last.positions[j] - expected).abs() < 1e-12, "joint {j}");
    }
}

#[test]
fn path_tolerance_violation_aborts_and_stops() {
    let limits = limits6();
    let cfg = ExecutorConfig {
        path_tolerances: vec![JointTolerance {
            name: "j1".into(),
            position: 0.01,
            velocity: 0.0,
            acceleration: 0.0,
        }],
        ..Default::default()
    };
    let mut exec = executor(&limits, cfg, 0.0);
    // Lag of 50 ms: at ~0.4 rad/s the position error is ~0.02 > 0.01.
    let mut hw = MockHardware::with_lag(vec![0.0; 6], 0.05).unwrap();
    let id = exec
        .submit(
            &min_jerk_request(&[0.0; 6], &TARGET, 2.0, 10),
            &GoalTolerances::default(),
            0.0,
        )
        .unwrap();
    let cycles = run(&mut exec, &mut hw, 0.0, 3.0);
    let ev = events(&cycles);
    assert_eq!(ev.len(), 1, "{ev:?}");
    let (t_abort, GoalEvent { id: got, outcome }) = &ev[0];
    assert_eq!(*got, id);
    match outcome {
        Outcome::Aborted {
            error_code,
            message,
        } => {
            assert_eq!(*error_code, PATH_TOLERANCE_VIOLATED);
            assert!(
                message.contains("path tolerance")
                    && message.contains("'j1'")
                    && message.contains("position"),
                "{message}"
            );
            assert!(message.contains("tolerance 0.01"), "{message}");
        }
        other => panic!("{other:?}"),
    }
    assert!(*t_abort > 0.0 && *t_abort < 2.0);
    let abort_cycle = cycles.iter().position(|c| c.time == *t_abort).unwrap();
    let e = &cycles[abort_cycle - 1].error.positions[0];
    assert!(
        e.abs() <= 0.01,
        "the cycle before the abort was within tolerance: {e}"
    );
    assert_continuous(&cycles);
    assert!(cycles[abort_cycle..].iter().all(|c| c.feedback.is_none()));
    let last = &cycles.last().unwrap().reference;
    assert!(last.velocities.iter().all(|v| *v == 0.0));
    assert!(
        last.positions[0] < TARGET[0] - 0.01,
        "stopped short of the target"
    );
}

#[test]
fn goal_tolerance_timeout_aborts() {
    let limits = limits6();
    let mut exec = executor(&limits, ExecutorConfig::default(), 0.0);
    let mut hw = MockHardware::with_lag(vec![0.0; 6], 0.3).unwrap();
    let mut tol = goal_tolerance(1e-3);
    tol.goal_time = 0.1;
    let id = exec
        .submit(&min_jerk_request(&[0.0; 6], &TARGET, 2.0, 10), &tol, 0.0)
        .unwrap();
    let cycles = run(&mut exec, &mut hw, 0.0, 3.0);
    let ev = events(&cycles);
    assert_eq!(ev.len(), 1, "{ev:?}");
    let (t, GoalEvent { id: got, outcome }) = &ev[0];
    assert_eq!(*got, id);
    assert!(*t > 2.1 && *t <= 2.1 + DT + 1e-9, "aborted at {t}");
    match outcome {
        Outcome::Aborted {
            error_code,
            message,
        } => {
            assert_eq!(*error_code, GOAL_TOLERANCE_VIOLATED);
            assert!(
                message
                    .contains("goal tolerance not reached 0.1 s after the trajectory end at 2 s"),
                "{message}"
            );
            assert!(
                message.contains("joint 'j") && message.contains("tolerance 0.001"),
                "{message}"
            );
        }
        other => panic!("{other:?}"),
    }
    // The reference keeps holding the end.
    assert_eq!(
        cycles.last().unwrap().reference,
        JointSample::at_rest(TARGET.to_vec())
    );
}

#[test]
fn goal_time_zero_waits_until_the_tolerance_is_reached() {
    let limits = limits6();
    let mut exec = executor(&limits, ExecutorConfig::default(), 0.0);
    let mut hw = MockHardware::with_lag(vec![0.0; 6], 0.3).unwrap();
    let id = exec
        .submit(
            &min_jerk_request(&[0.0; 6], &TARGET, 2.0, 10),
            &goal_tolerance(1e-3),
            0.0,
        )
        .unwrap();
    let cycles = run(&mut exec, &mut hw, 0.0, 6.0);
    let ev = events(&cycles);
    assert_eq!(ev.len(), 1);
    assert_eq!(
        ev[0].1,
        GoalEvent {
            id,
            outcome: Outcome::Succeeded
        }
    );
    assert!(
        ev[0].0 > 2.3,
        "succeeded only after the lag settled: {}",
        ev[0].0
    );
    let c = cycles.iter().find(|c| c.time == ev[0].0).unwrap();
    assert!(c.error.positions.iter().all(|e| e.abs() <= 1e-3));
}

#[test]
fn goal_requires_the_stopped_velocity_tolerance() {
    let limits = limits6();
    let mut exec = executor(&limits, ExecutorConfig::default(), 0.0);
    let z = [0.0; 6];
    let id = exec
        .submit(
            &request(&limits, vec![pt(1.0, &TARGET, &z, &[])]),
            &GoalTolerances::default(),
            0.0,
        )
        .unwrap();
    let mut measured = JointSample::at_rest(TARGET.to_vec());
    measured.velocities[4] = 0.02; // > stopped_velocity_tolerance 0.01
    let c = exec.update(1.0, &measured).unwrap();
    assert!(c.events.is_empty());
    assert_eq!(c.feedback.map(|f| f.id), Some(id));
    measured.velocities[4] = 0.005;
    let c = exec.update(1.004, &measured).unwrap();
    assert_eq!(
        c.events,
        vec![GoalEvent {
            id,
            outcome: Outcome::Succeeded
        }]
    );
}

#[test]
fn rejected_trajectory_leaves_the_active_motion_untouched() {
    let limits = limits6();
    let mut exec = executor(&limits, ExecutorConfig::default(), 0.0);
    let mut hw = MockHardware::new(vec![0.0; 6]);
    let req = min_jerk_request(&[0.0; 6], &TARGET, 2.0, 10);
    let id = exec.submit(&req, &GoalTolerances::default(), 0.0).unwrap();
    let alone = validate(
        &limits,
        exec.config(),
        &req,
        &JointSample::at_rest(vec![0.0; 6]),
        0.0,
    )
    .unwrap();
    let mut cycles = run(&mut exec, &mut hw, 0.0, 0.5);

    let mut bad = req.clone();
    bad.joint_names[0] = "nope".into();
    assert!(exec.submit(&bad, &GoalTolerances::default(), 0.5).is_err());
    let too_fast = request(&limits, vec![pt(0.1, &[2.0; 6], &[0.0; 6], &[])]);
    assert!(matches!(
        exec.submit(&too_fast, &GoalTolerances::default(), 0.5),
        Err(ExecutorError::VelocityLimit { .. } | ExecutorError::AccelerationLimit { .. })
    ));
    assert!(exec
        .validate(&too_fast, &GoalTolerances::default(), 0.5)
        .is_err());
    assert_eq!(exec.active_goal(), Some(id));

    cycles.extend(run(&mut exec, &mut hw, 0.5, 3.0));
    for c in &cycles {
        assert_eq!(c.reference, alone.sample(c.time), "t = {}", c.time);
    }
    let ev = events(&cycles);
    assert_eq!(ev.len(), 1);
    assert_eq!(
        ev[0].1,
        GoalEvent {
            id,
            outcome: Outcome::Succeeded
        }
    );
}

#[test]
fn update_rejects_bad_time_and_measurements_without_change() {
    let limits = limits6();
    let mut exec = executor(&limits, ExecutorConfig::default(), 0.1);
    let ok = JointSample::at_rest(vec![0.1; 6]);
    exec.update(1.0, &ok).unwrap();
    let before = exec.clone();
    let e = exec.update(0.9, &ok).unwrap_err();
    assert!(
        matches!(e, ExecutorError::TimeWentBackwards { now, last } if now == 0.9 && last == 1.0)
    );
    assert!(matches!(
        exec.update(f64::NAN, &ok),
        Err(ExecutorError::NonFiniteTime { .. })
    ));
    let short = JointSample {
        positions: vec![0.1; 5],
        ..Default::default()
    };
    let e = exec.update(1.1, &short).unwrap_err();
    assert!(
        e.to_string().contains("measured state") && e.to_string().contains("5 values"),
        "{e}"
    );
    let mut nan = ok.clone();
    nan.positions[5] = f64::NAN;
    let e = exec.update(1.1, &nan).unwrap_err();
    assert!(e.to_string().contains("'j6'"), "{e}");
    assert_eq!(format!("{before:?}"), format!("{exec:?}"));
    // Measurements without velocities/accelerations are fine; their errors are empty.
    let c = exec
        .update(
            1.1,
            &JointSample {
                positions: vec![0.1; 6],
                ..Default::default()
            },
        )
        .unwrap();
    assert!(c.error.velocities.is_empty() && c.error.accelerations.is_empty());
    assert_eq!(c.error.positions, vec![0.0; 6]);
    assert!(!exec.is_moving(1.1));
}

#[test]
fn mock_hardware_follows_exactly_or_with_lag() {
    let limits = limits6();
    let cmd = JointSample {
        positions: vec![0.2; 6],
        velocities: vec![0.1; 6],
        accelerations: vec![0.05; 6],
    };
    let mut ideal = MockHardware::new(vec![0.0; 6]);
    ideal.write(&limits, &cmd, DT).unwrap();
    assert_eq!(ideal.state(), &cmd);

    let mut lag = MockHardware::with_lag(vec![0.0; 6], 0.1).unwrap();
    lag.write(&limits, &cmd, 0.1).unwrap();
    let expected = 0.2 * (1.0 - (-1.0f64).exp());
    assert!((lag.state().positions[0] - expected).abs() < 1e-15);
    assert!((lag.state().velocities[0] - expected / 0.1).abs() < 1e-12);
    for _ in 0..100 {
        lag.write(&limits, &cmd, 0.1).unwrap();
    }
    assert!((lag.state().positions[3] - 0.2).abs() < 1e-12);

    assert!(MockHardware::with_lag(vec![0.0], -1.0).is_err());
    assert!(MockHardware::with_lag(vec![0.0], f64::NAN).is_err());
    assert!(lag.write(&limits, &cmd, 0.0).is_err());
    assert!(lag
        .write(&limits, &JointSample::at_rest(vec![0.0; 5]), 0.1)
        .is_err());
}

#[test]
fn stop_profile_keeps_position_limits() {
    use kerf_executor::{JointLimits, StopProfile};
    let lim = |name: &str, acc: f64| JointLimits {
        name: name.into(),
        min_position: -1.0,
        max_position: 1.0,
        max_velocity: 2.0,
        max_acceleration: acc,
    };
    let limits = vec![lim("a", 10.0), lim("b", 1.0)];
    let state = JointSample {
        positions: vec![0.9, 0.0],
        velocities: vec![1.0, 1.0],
        accelerations: vec![0.0, 0.0],
    };
    let stop = StopProfile::new(&limits, &state, 5.0);
    // Common stop time 1 s (joint b) would carry joint a to 1.4: it stops in its own 0.1 s.
    assert_eq!(stop.end_time(), 6.0);
    let end = stop.final_positions();
    assert!(
        (end[0] - 0.95).abs() < 1e-15 && (end[1] - 0.5).abs() < 1e-15,
        "{end:?}"
    );
    let mut s = JointSample::default();
    stop.sample_into(5.05, &mut s);
    assert!((s.velocities[0] - 0.5).abs() < 1e-12 && (s.accelerations[0] + 10.0).abs() < 1e-12);
    assert!((s.velocities[1] - 0.95).abs() < 1e-12 && (s.accelerations[1] + 1.0).abs() < 1e-12);
}

/// A trajectory prepared earlier (as on a worker thread) is finished against the state at
/// submission: it behaves exactly as `submit` at that time, and its start segment is checked
/// then, against the state the robot has then.
#[test]
fn prepared_trajectories_start_from_the_state_at_submission() {
    let limits = limits6();
    let cfg = ExecutorConfig::default();
    let a = min_jerk_request(&[0.0; 6], &TARGET, 4.0, 8);
    let z = [0.0; 6];
    let b = request(&limits, vec![pt(2.0, &[-0.3; 6], &z, &z)]);

    // Reference: plain submit at t = 1 during A.
    let mut plain = executor(&limits, cfg.clone(), 0.0);
    let mut hw_plain = MockHardware::new(vec![0.0; 6]);
    plain.submit(&a, &GoalTolerances::default(), 0.0).unwrap();
    run(&mut plain, &mut hw_plain, 0.0, 1.0);
    plain.submit(&b, &GoalTolerances::default(), 1.0).unwrap();
    let plain_cycles = run(&mut plain, &mut hw_plain, 1.0, 4.0);

    // Same, with B prepared at t = 0 (before A even moved) and submitted at t = 1.
    let prepared_b = kerf_executor::prepare(&limits, &cfg, &b).unwrap();
    assert_eq!(prepared_b.duration(), 2.0);
    let mut split = executor(&limits, cfg.clone(), 0.0);
    let mut hw_split = MockHardware::new(vec![0.0; 6]);
    split.submit(&a, &GoalTolerances::default(), 0.0).unwrap();
    run(&mut split, &mut hw_split, 0.0, 1.0);
    split
        .submit_prepared(&prepared_b, &GoalTolerances::default(), 1.0)
        .unwrap();
    let split_cycles = run(&mut split, &mut hw_split, 1.0, 4.0);
    assert_eq!(plain_cycles, split_cycles);
    assert_continuous(&split_cycles);

    // A first point due at once is valid at rest where it is, but not once the robot has
    // moved away: the state-dependent check happens at submission.
    let here = request(&limits, vec![pt(0.0, &z, &[], &[])]);
    let prepared = kerf_executor::prepare(&limits, &cfg, &here).unwrap();
    let mut exec = executor(&limits, cfg.clone(), 0.0);
    let mut hw = MockHardware::new(vec![0.0; 6]);
    exec.submit(&a, &GoalTolerances::default(), 0.0).unwrap();
    run(&mut exec, &mut hw, 0.0, 2.0);
    let err = exec
        .submit_prepared(&prepared, &GoalTolerances::default(), 2.0)
        .unwrap_err();
    assert!(
        matches!(err, ExecutorError::StartMismatch { .. }),
        "{err:?}"
    );
}

/// Finishing a prepared trajectory shares its segments (no copy proportional to its points),
/// and with deferred drops a replaced trajectory is handed back to the caller instead of being
/// freed inside the call that replaced it (preemption, cancel).
#[test]
fn finishing_shares_segments_and_replaced_trajectories_are_handed_back() {
    let limits = limits6();
    let cfg = ExecutorConfig::default();
    let a = kerf_executor::prepare(&limits, &cfg, &min_jerk_request(&[0.0; 6], &TARGET, 4.0, 8))
        .unwrap();
    let z = [0.0; 6];
    let b = kerf_executor::prepare(
        &limits,
        &cfg,
        &request(&limits, vec![pt(2.0, &[-0.3; 6], &z, &z)]),
    )
    .unwrap();
    let exec = executor(&limits, cfg.clone(), 0.0);
    let dry = exec
        .validate_prepared(&a, &GoalTolerances::default(), 0.0)
        .unwrap();
    assert!(dry.shares_segments_with(&a));
    assert!(!dry.shares_segments_with(&b));
    assert_eq!(dry.point_count(), a.point_count());

    // Default: replaced trajectories are dropped in place, nothing is kept.
    let mut plain = executor(&limits, cfg.clone(), 0.0);
    plain
        .submit_prepared(&a, &GoalTolerances::default(), 0.0)
        .unwrap();
    plain
        .submit_prepared(&b, &GoalTolerances::default(), 0.0)
        .unwrap();
    assert!(plain.take_retired().is_none());

    // Deferred: the preempted trajectory (A), then the canceled one (B) come back, in turn.
    let mut exec = executor(&limits, cfg.clone(), 0.0);
    exec.defer_drops();
    let mut hw = MockHardware::new(vec![0.0; 6]);
    exec.submit_prepared(&a, &GoalTolerances::default(), 0.0)
        .unwrap();
    assert!(exec.take_retired().is_none());
    run(&mut exec, &mut hw, 0.0, 1.0);
    let id_b = exec
        .submit_prepared(&b, &GoalTolerances::default(), 1.0)
        .unwrap();
    let first = exec.take_retired().expect("the preempted trajectory");
    assert!(first.shares_segments_with(&a));
    assert!(exec.take_retired().is_none());
    run(&mut exec, &mut hw, 1.0, 2.0);
    exec.cancel(id_b, 2.0).unwrap();
    let second = exec.take_retired().expect("the canceled trajectory");
    assert!(second.shares_segments_with(&b));
    assert!(exec.take_retired().is_none());
}

#[test]
fn fault_aborts_with_its_message_and_stops_within_limits() {
    let limits = limits6();
    let mut exec = executor(&limits, ExecutorConfig::default(), 0.0);
    let mut hw = MockHardware::new(vec![0.0; 6]);
    let big: Vec<f64> = TARGET.iter().map(|p| 3.0 * p).collect();
    let id = exec
        .submit(
            &min_jerk_request(&[0.0; 6], &big, 2.0, 10),
            &GoalTolerances::default(),
            0.0,
        )
        .unwrap();
    let before = run(&mut exec, &mut hw, 0.0, 1.0);
    let message = "contact: nozzle/0 with bpillar, depth 0.3 mm".to_string();
    let aborted = exec.fault(1.0, PATH_TOLERANCE_VIOLATED, message.clone());
    assert_eq!(aborted.unwrap(), Some(id));
    assert_eq!(exec.active_goal(), None);
    // A second fault during the stop aborts nothing and keeps the stop going.
    assert_eq!(
        exec.fault(1.0, PATH_TOLERANCE_VIOLATED, "again".into())
            .unwrap(),
        None
    );
    let after = run(&mut exec, &mut hw, 1.0, 2.0);
    assert_eq!(
        events(&after),
        vec![(
            after[0].time,
            GoalEvent {
                id,
                outcome: Outcome::Aborted {
                    error_code: PATH_TOLERANCE_VIOLATED,
                    message
                }
            }
        )]
    );
    let mut all = before;
    all.extend(after.iter().cloned());
    assert_continuous(&all);
    let last = &after.last().unwrap().reference;
    assert!(last.velocities.iter().all(|v| *v == 0.0));
    assert!(!exec.is_moving(2.0));
    // At rest and idle a fault changes nothing.
    assert_eq!(
        exec.fault(2.0, PATH_TOLERANCE_VIOLATED, "idle".into())
            .unwrap(),
        None
    );
    assert!(!exec.is_moving(2.1));
}

/// Issue 27: a real robot's measured state becomes the hold while the robot is at rest; never
/// while a goal runs or a stop is in progress, and never at an invalid position.
#[test]
fn hold_at_moves_the_hold_to_the_measured_state_only_at_rest() {
    let limits = limits6();
    let mut exec = executor(&limits, ExecutorConfig::default(), 0.0);
    let mut hw = MockHardware::new(vec![0.0; 6]);
    let measured = [0.1, -0.1, 0.05, 0.0, 0.2, -0.3];
    exec.hold_at(0.0, &measured).unwrap();
    assert_eq!(exec.commanded().positions, measured);
    assert!(exec.commanded().velocities.iter().all(|v| *v == 0.0));
    let cycle = exec
        .update(0.004, &JointSample::at_rest(measured.to_vec()))
        .unwrap();
    assert_eq!(cycle.reference.positions, measured);
    // A goal from there starts at the measured state.
    let id = exec
        .submit(
            &min_jerk_request(&measured, &TARGET, 2.0, 4),
            &GoalTolerances::default(),
            0.008,
        )
        .unwrap();
    let e = exec.hold_at(0.5, &measured).unwrap_err();
    assert!(matches!(e, ExecutorError::HoldWhileMoving { .. }), "{e}");
    // During the stop of a cancel: still refused; at rest again: accepted.
    run(&mut exec, &mut hw, 0.008, 0.5);
    exec.cancel(id, 0.5).unwrap();
    exec.update(0.504, &JointSample::at_rest(measured.to_vec()))
        .unwrap();
    assert!(exec.hold_at(0.504, &measured).is_err());
    run(&mut exec, &mut hw, 0.508, 3.0);
    exec.hold_at(3.0, &measured).unwrap();
    // Invalid positions change nothing.
    for bad in [vec![0.0; 5], vec![f64::NAN; 6], vec![100.0; 6]] {
        assert!(exec.hold_at(3.0, &bad).is_err(), "{bad:?}");
    }
    assert_eq!(exec.commanded().positions, measured);
    assert!(exec.hold_at(f64::NAN, &measured).is_err());
}
