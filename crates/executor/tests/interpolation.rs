//! Interpolation against closed-form curves, and limits on a dense time grid.
#![allow(clippy::needless_range_loop)] // joints index several parallel arrays
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::{limits6, min_jerk, pt, request, rest, robot, Rng, DT};
use kerf_executor::{validate, ExecutorConfig, ExecutorError, JointSample, TrajectoryRequest};

fn cfg() -> ExecutorConfig {
    ExecutorConfig::default()
}

#[test]
fn quintic_reproduces_min_jerk_exactly() {
    let limits = robot(3, 10.0, 10.0, 100.0);
    let t_total = 2.0;
    let p0 = [0.1, -0.5, 0.0];
    let d = [1.0, -2.0, 0.3];
    let times = [0.0, 0.25, 0.6, 1.1, 1.5, 1.93, 2.0];
    let points = times
        .iter()
        .map(|&t| {
            let s: Vec<_> = (0..3).map(|j| min_jerk(p0[j], d[j], t_total, t)).collect();
            let p: Vec<f64> = s.iter().map(|x| x.0).collect();
            let v: Vec<f64> = s.iter().map(|x| x.1).collect();
            let a: Vec<f64> = s.iter().map(|x| x.2).collect();
            pt(t, &p, &v, &a)
        })
        .collect();
    let now = 5.0;
    let current = JointSample::at_rest(p0.to_vec());
    let traj = validate(&limits, &cfg(), &request(&limits, points), &current, now).unwrap();
    assert_eq!(traj.end_time(), now + t_total);
    assert_eq!(traj.duration(), t_total);
    let mut rng = Rng(1);
    let mut ts: Vec<f64> = (0..2000).map(|_| rng.range(0.0, t_total)).collect();
    ts.sort_by(f64::total_cmp);
    for t in ts {
        let s = traj.sample(now + t);
        for j in 0..3 {
            let (p, v, a) = min_jerk(p0[j], d[j], t_total, t);
            assert!(
                (s.positions[j] - p).abs() < 1e-12,
                "t={t} j={j} p {} vs {p}",
                s.positions[j]
            );
            assert!(
                (s.velocities[j] - v).abs() < 1e-12,
                "t={t} j={j} v {} vs {v}",
                s.velocities[j]
            );
            assert!(
                (s.accelerations[j] - a).abs() < 1e-11,
                "t={t} j={j} a {} vs {a}",
                s.accelerations[j]
            );
        }
    }
}

#[test]
fn cubic_reproduces_smoothstep_exactly() {
    // p(t) = p0 + d (3 s² − 2 s³), s = t/T: rest to rest, a cubic (Hermite with velocities).
    let limits = robot(2, 10.0, 10.0, 100.0);
    let (t_total, p0, d) = (1.5, [0.2, -0.1], [0.8, -1.2]);
    let f = |j: usize, t: f64| {
        let s = t / t_total;
        (
            p0[j] + d[j] * (3.0 * s * s - 2.0 * s * s * s),
            d[j] / t_total * (6.0 * s - 6.0 * s * s),
            d[j] / (t_total * t_total) * (6.0 - 12.0 * s),
        )
    };
    let times = [0.0, 0.3, 0.31, 0.9, 1.5];
    let points = times
        .iter()
        .map(|&t| {
            let p: Vec<f64> = (0..2).map(|j| f(j, t).0).collect();
            let v: Vec<f64> = (0..2).map(|j| f(j, t).1).collect();
            pt(t, &p, &v, &[])
        })
        .collect();
    let current = JointSample::at_rest(p0.to_vec());
    let traj = validate(&limits, &cfg(), &request(&limits, points), &current, 0.0).unwrap();
    let mut rng = Rng(2);
    for _ in 0..2000 {
        let t = rng.range(0.0, t_total);
        let s = traj.sample(t);
        for j in 0..2 {
            let (p, v, a) = f(j, t);
            assert!((s.positions[j] - p).abs() < 1e-12);
            assert!((s.velocities[j] - v).abs() < 1e-12);
            assert!((s.accelerations[j] - a).abs() < 1e-11);
        }
    }
}

#[test]
fn linear_segments_without_velocities() {
    let limits = robot(1, 10.0, 1.0, 100.0);
    let cfg = ExecutorConfig {
        control_period: 0.01,
        ..ExecutorConfig::default()
    };
    // Velocity 0.2 then −0.3: steps of at most 0.5 within 10 ms = 50 ≤ 100.
    let points = vec![
        pt(0.0, &[0.0], &[], &[]),
        pt(1.0, &[0.2], &[], &[]),
        pt(2.0, &[-0.1], &[], &[]),
    ];
    let traj = validate(&limits, &cfg, &request(&limits, points), &rest(1, 0.0), 0.0).unwrap();
    for &(t, p, v) in &[
        (0.0, 0.0, 0.2),
        (0.5, 0.1, 0.2),
        (1.0, 0.2, -0.3),
        (1.5, 0.05, -0.3),
        (2.0, -0.1, 0.0),
        (9.0, -0.1, 0.0),
    ] {
        let s = traj.sample(t);
        assert!(
            (s.positions[0] - p).abs() < 1e-15,
            "t={t}: {} vs {p}",
            s.positions[0]
        );
        assert!(
            (s.velocities[0] - v).abs() < 1e-15,
            "t={t}: {} vs {v}",
            s.velocities[0]
        );
        assert_eq!(s.accelerations[0], 0.0);
    }
}

#[test]
fn start_segment_is_continuous_with_a_moving_state() {
    let limits = limits6();
    let current = JointSample {
        positions: vec![0.1, 0.2, 0.3, -0.1, -0.2, -0.3],
        velocities: vec![0.5, -0.4, 0.3, -0.2, 0.1, 0.0],
        accelerations: vec![1.0, -1.0, 0.5, 0.0, 0.2, -0.3],
    };
    let p = [0.5, 0.0, 0.4, -0.2, 0.0, -0.3];
    let z = [0.0; 6];
    let req = request(&limits, vec![pt(1.0, &p, &z, &z)]);
    let now = 3.0;
    let traj = validate(&limits, &cfg(), &req, &current, now).unwrap();
    assert_eq!(traj.segment_count(), 1);
    let s = traj.sample(now);
    for j in 0..6 {
        assert!((s.positions[j] - current.positions[j]).abs() < 1e-15);
        assert!((s.velocities[j] - current.velocities[j]).abs() < 1e-15);
        assert!((s.accelerations[j] - current.accelerations[j]).abs() < 1e-14);
    }
    let e = traj.sample(now + 1.0 - 1e-12);
    for j in 0..6 {
        assert!((e.positions[j] - p[j]).abs() < 1e-9);
        assert!(e.velocities[j].abs() < 1e-9);
    }
}

#[test]
fn holds_before_a_future_start_and_after_the_end() {
    let limits = robot(2, 3.0, 2.0, 10.0);
    let mut req = request(&limits, vec![pt(1.0, &[0.5, -0.5], &[0.0, 0.0], &[])]);
    req.start_time = Some(12.0);
    let traj = validate(&limits, &cfg(), &req, &rest(2, 0.1), 10.0).unwrap();
    assert_eq!(traj.start_time(), 12.0);
    assert_eq!(traj.end_time(), 13.0);
    for t in [10.0, 11.0, 11.999] {
        assert_eq!(traj.sample(t), rest(2, 0.1), "t = {t}");
    }
    assert!(traj.sample(12.5).velocities[0] > 0.0);
    assert_eq!(traj.sample(13.0), JointSample::at_rest(vec![0.5, -0.5]));
    assert_eq!(traj.sample(100.0), JointSample::at_rest(vec![0.5, -0.5]));
}

#[test]
fn sampling_backwards_and_jumping_agrees_with_forward_sampling() {
    let limits = robot(1, 100.0, 100.0, 1000.0);
    let points: Vec<_> = (0..200)
        .map(|k| {
            let t = 0.1 * (k + 1) as f64;
            let v = if k == 199 { 0.0 } else { (t * 3.0).cos() };
            pt(t, &[(t * 3.0).sin() / 3.0], &[v], &[])
        })
        .collect();
    let traj = validate(
        &limits,
        &cfg(),
        &request(&limits, points),
        &rest(1, 0.0),
        0.0,
    )
    .unwrap();
    let fresh = |t: f64| traj.clone().sample(t);
    let mut rng = Rng(3);
    for _ in 0..500 {
        let t = rng.range(-1.0, 21.0);
        assert_eq!(traj.sample(t), fresh(t), "t = {t}");
    }
}

/// A random valid trajectory of 6 joints: `n` points, cubic or quintic or linear, time-scaled
/// until it passes validation.
fn random_trajectory(rng: &mut Rng, n: usize) -> (TrajectoryRequest, JointSample) {
    let limits = limits6();
    let kind = rng.next_u64() % 3;
    let current = JointSample::at_rest((0..6).map(|_| rng.range(-1.0, 1.0)).collect());
    let mut positions = Vec::new();
    let mut velocities = Vec::new();
    let mut accelerations = Vec::new();
    let mut dts = Vec::new();
    for k in 0..n {
        let last = k == n - 1;
        positions.push((0..6).map(|_| rng.range(-2.5, 2.5)).collect::<Vec<_>>());
        velocities.push(
            (0..6)
                .map(|_| if last { 0.0 } else { rng.range(-1.0, 1.0) })
                .collect::<Vec<_>>(),
        );
        accelerations.push(
            (0..6)
                .map(|_| if last { 0.0 } else { rng.range(-3.0, 3.0) })
                .collect::<Vec<_>>(),
        );
        dts.push(rng.range(0.5, 2.0));
    }
    let mut scale = 1.0;
    for _ in 0..40 {
        let mut t = 0.0;
        let points = (0..n)
            .map(|k| {
                t += dts[k] * scale;
                let v: Vec<f64> = velocities[k].iter().map(|v| v / scale).collect();
                let a: Vec<f64> = accelerations[k]
                    .iter()
                    .map(|a| a / (scale * scale))
                    .collect();
                match kind {
                    0 => pt(t, &positions[k], &[], &[]),
                    1 => pt(t, &positions[k], &v, &[]),
                    _ => pt(t, &positions[k], &v, &a),
                }
            })
            .collect();
        let req = request(&limits, points);
        if validate(&limits, &cfg(), &req, &current, 0.0).is_ok() {
            return (req, current);
        }
        scale *= 1.5;
    }
    panic!("no valid time scaling found");
}

#[test]
fn dense_grid_stays_within_limits_and_velocity_is_the_derivative() {
    let limits = limits6();
    let mut rng = Rng(4);
    for _ in 0..30 {
        let (req, current) = random_trajectory(&mut rng, 6);
        let traj = validate(&limits, &cfg(), &req, &current, 0.0).unwrap();
        let h = DT / 10.0;
        let steps = (traj.end_time() / h).ceil() as usize + 10;
        let mut prev: Option<JointSample> = None;
        for k in 0..steps {
            let t = k as f64 * h;
            let s = traj.sample(t);
            for (j, l) in limits.iter().enumerate() {
                assert!(
                    s.positions[j] >= l.min_position - 1e-9
                        && s.positions[j] <= l.max_position + 1e-9
                );
                assert!(
                    s.velocities[j].abs() <= l.max_velocity * (1.0 + 1e-9),
                    "t={t} j={j} v={}",
                    s.velocities[j]
                );
                assert!(
                    s.accelerations[j].abs() <= l.max_acceleration * (1.0 + 1e-9),
                    "t={t} j={j} a={}",
                    s.accelerations[j]
                );
                if let Some(p) = &prev {
                    // Between samples the mean velocity lies within the velocity limit.
                    let mean = (s.positions[j] - p.positions[j]) / h;
                    assert!(mean.abs() <= l.max_velocity * (1.0 + 1e-6));
                    // Velocity steps (linear segments) are within the control-period rule.
                    let dv = (s.velocities[j] - p.velocities[j]).abs();
                    assert!(
                        dv <= l.max_acceleration * DT.max(h) * (1.0 + 1e-6),
                        "t={t} j={j} dv={dv}"
                    );
                }
            }
            // Central differences agree with the sampled velocity away from segment joins.
            if !req.points[0].velocities.is_empty() && k > 0 {
                let (a, b) = (traj.sample(t - 1e-6), traj.sample(t + 1e-6));
                for j in 0..6 {
                    let fd = (b.positions[j] - a.positions[j]) / 2e-6;
                    assert!(
                        (fd - s.velocities[j]).abs() < 1e-4,
                        "t={t} j={j} fd={fd} v={}",
                        s.velocities[j]
                    );
                }
            }
            prev = Some(s);
        }
    }
}

/// The validator's extrema are exact: shrinking a limit just below the dense-grid maximum
/// is rejected, keeping it just above is accepted.
#[test]
fn limit_checks_are_tight_against_dense_sampling() {
    let mut rng = Rng(5);
    let mut checked = 0;
    for _ in 0..30 {
        let (req, current) = random_trajectory(&mut rng, 4);
        if req.points[0].velocities.is_empty() {
            continue; // linear: velocity steps dominate the acceleration check
        }
        checked += 1;
        let limits = limits6();
        let traj = validate(&limits, &cfg(), &req, &current, 0.0).unwrap();
        let mut max_v = [0.0f64; 6];
        let mut max_a = [0.0f64; 6];
        let mut max_p = [f64::MIN; 6];
        let h = 1e-4;
        for k in 0..=(traj.end_time() / h) as usize {
            let s = traj.sample(k as f64 * h);
            for j in 0..6 {
                max_v[j] = max_v[j].max(s.velocities[j].abs());
                max_a[j] = max_a[j].max(s.accelerations[j].abs());
                max_p[j] = max_p[j].max(s.positions[j]);
            }
        }
        let j = (rng.next_u64() % 6) as usize;
        let mut tight = limits.clone();
        tight[j].max_velocity = max_v[j] * 1.001;
        assert!(validate(&tight, &cfg(), &req, &current, 0.0).is_ok());
        tight[j].max_velocity = max_v[j] * 0.999;
        assert!(matches!(
            validate(&tight, &cfg(), &req, &current, 0.0),
            Err(ExecutorError::VelocityLimit { .. })
        ));
        let mut tight = limits.clone();
        tight[j].max_acceleration = max_a[j] * 1.001;
        assert!(validate(&tight, &cfg(), &req, &current, 0.0).is_ok());
        tight[j].max_acceleration = max_a[j] * 0.999;
        assert!(matches!(
            validate(&tight, &cfg(), &req, &current, 0.0),
            Err(ExecutorError::AccelerationLimit { .. } | ExecutorError::VelocityStep { .. })
        ));
        let mut tight = limits.clone();
        tight[j].max_position = max_p[j] + 1e-6;
        assert!(validate(&tight, &cfg(), &req, &current, 0.0).is_ok());
        tight[j].max_position = max_p[j] - 1e-6;
        assert!(matches!(
            validate(&tight, &cfg(), &req, &current, 0.0),
            Err(ExecutorError::PositionLimit { .. })
        ));
    }
    assert!(checked >= 10, "only {checked} spline trajectories checked");
}

#[test]
fn cubic_overshooting_the_velocity_limit_between_waypoints_is_rejected() {
    // Rest to rest over 0.9 in 1 s: waypoint velocities 0, mean 0.9 < 1, but the cubic peaks
    // at 1.5 · 0.9 = 1.35 at t = 0.5.
    let limits = robot(1, 3.0, 1.0, 10.0);
    let req = request(
        &limits,
        vec![pt(0.0, &[0.0], &[0.0], &[]), pt(1.0, &[0.9], &[0.0], &[])],
    );
    let err = validate(&limits, &cfg(), &req, &rest(1, 0.0), 0.0).unwrap_err();
    match &err {
        ExecutorError::VelocityLimit {
            joint,
            location,
            time,
            value,
            limit,
        } => {
            assert_eq!(joint, "j1");
            assert!(
                location.contains("between point 0 and point 1"),
                "{location}"
            );
            assert!((time - 0.5).abs() < 1e-9);
            assert!((value - 1.35).abs() < 1e-12);
            assert_eq!(*limit, 1.0);
        }
        other => panic!("unexpected {other:?}"),
    }
    assert_eq!(err.error_code(), kerf_executor::INVALID_GOAL);
    assert!(
        err.to_string().contains("'j1'") && err.to_string().contains("between point 0 and point 1")
    );
}

#[test]
fn cubic_overshooting_the_position_limit_between_waypoints_is_rejected() {
    // From 0.95 at 0.5/s to 0.95 at rest in 1 s peaks at 0.95 + 2/27 ≈ 1.024 > 1 at τ = 1/3.
    let limits = robot(1, 1.0, 5.0, 10.0);
    let req = request(
        &limits,
        vec![pt(1.0, &[0.95], &[0.5], &[]), pt(2.0, &[0.95], &[0.0], &[])],
    );
    let err = validate(&limits, &cfg(), &req, &rest(1, 0.0), 0.0).unwrap_err();
    match &err {
        ExecutorError::PositionLimit {
            joint,
            location,
            time,
            value,
            ..
        } => {
            assert_eq!(joint, "j1");
            assert!(
                location.contains("between point 0 and point 1"),
                "{location}"
            );
            assert!((time - (1.0 + 1.0 / 3.0)).abs() < 1e-9, "{time}");
            assert!((value - (0.95 + 2.0 / 27.0)).abs() < 1e-12, "{value}");
        }
        other => panic!("unexpected {other:?}"),
    }
}

#[test]
fn quintic_overshooting_the_acceleration_limit_between_waypoints_is_rejected() {
    // Min-jerk over d in T peaks at |a| = 10/√3 · d/T² ≈ 5.7735 d/T² at s = (3 ± √3)/6.
    let limits = robot(1, 3.0, 5.0, 5.0);
    let req = request(
        &limits,
        vec![
            pt(0.0, &[0.0], &[0.0], &[0.0]),
            pt(1.0, &[0.9], &[0.0], &[0.0]),
        ],
    );
    let err = validate(&limits, &cfg(), &req, &rest(1, 0.0), 0.0).unwrap_err();
    match &err {
        ExecutorError::AccelerationLimit { value, time, .. } => {
            assert!(
                (value.abs() - 10.0 / 3f64.sqrt() * 0.9).abs() < 1e-9,
                "{value}"
            );
            let s = time / 1.0;
            assert!(
                (s - (3.0 - 3f64.sqrt()) / 6.0).abs() < 1e-6
                    || (s - (3.0 + 3f64.sqrt()) / 6.0).abs() < 1e-6
            );
        }
        other => panic!("unexpected {other:?}"),
    }
}
