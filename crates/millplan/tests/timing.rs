//! Time scaling of a planned joint trajectory to the joints' velocity and
//! acceleration limits (kerf_millplan::timing) on synthetic trajectories:
//! the cubic Hermite extremes against dense sampling, the three-point
//! derivative on parabolas, a zig-zag that must be slowed down, a slow one
//! that must not, and every refused input.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_millplan::timing::{hermite_extremes, three_point_velocity, time_scale, JointLimit};
use kerf_millplan::{JointTrajectory, MillPlanError, TrajectoryPoint, TrajectoryRequest};

fn names() -> Vec<String> {
    (1..=6).map(|i| format!("joint_{i}")).collect()
}

/// A planned trajectory of N segments of times `t` (path start, N
/// midpoints, path end) with joint 5 at `q5[k]` and the others fixed; the
/// planned velocities are irrelevant to the scaling.
fn planned(t: &[f64], q5: &[f64]) -> JointTrajectory {
    assert_eq!(t.len() + 2, q5.len());
    let mut times = vec![0.0];
    let mut elapsed = 0.0;
    for &ti in t {
        times.push(elapsed + 0.5 * ti);
        elapsed += ti;
    }
    times.push(elapsed);
    JointTrajectory {
        request: TrajectoryRequest {
            joint_names: names(),
            points: times
                .iter()
                .zip(q5)
                .map(|(&time, &q)| TrajectoryPoint {
                    positions: vec![0.1, -0.2, 0.3, 0.0, q, 0.5],
                    velocities: vec![0.0; 6],
                    time_from_start: time,
                    ..TrajectoryPoint::default()
                })
                .collect(),
            start_time: None,
        },
        arc_length: (0..times.len()).map(|k| k as f64).collect(),
        segment: (0..times.len())
            .map(|k| k.saturating_sub(1).min(t.len() - 1))
            .collect(),
    }
}

fn limits(v: f64, a: Option<f64>) -> Vec<JointLimit> {
    vec![
        JointLimit {
            max_velocity: v,
            max_acceleration: a,
        };
        6
    ]
}

/// Largest |v|/v_max and |a|/a_max of joint 5 over the Hermite cubics,
/// sampled (Hermite basis, central differences).
fn sampled_worst(t: &JointTrajectory, vmax: f64, amax: f64) -> f64 {
    let p = t.points();
    let mut worst: f64 = 0.0;
    for k in 0..p.len() - 1 {
        let h = p[k + 1].time_from_start - p[k].time_from_start;
        let at = |tau: f64| {
            let s = tau / h;
            (2.0 * s.powi(3) - 3.0 * s * s + 1.0) * p[k].positions[4]
                + (s.powi(3) - 2.0 * s * s + s) * h * p[k].velocities[4]
                + (-2.0 * s.powi(3) + 3.0 * s * s) * p[k + 1].positions[4]
                + (s.powi(3) - s * s) * h * p[k + 1].velocities[4]
        };
        let d = 1e-4 * h;
        for i in 0..=100 {
            let tau = d + (h - 2.0 * d) * f64::from(i) / 100.0;
            let (a, b, c) = (at(tau - d), at(tau), at(tau + d));
            worst = worst
                .max(((c - a) / (2.0 * d)).abs() / vmax)
                .max(((c - 2.0 * b + a) / (d * d)).abs() / amax);
        }
    }
    worst
}

#[test]
fn hermite_extremes_match_dense_sampling() {
    for &(h, p0, p1, v0, v1) in &[
        (0.5, 0.0, 1.0, 0.0, 0.0),
        (0.2, 0.3, 0.1, 2.0, -1.0),
        (1.0, 0.0, 0.0, 1.0, 1.0),
        (0.1, -0.2, 0.4, 0.0, 3.0),
    ] {
        let e = hermite_extremes(h, p0, p1, v0, v1);
        let c2 = (3.0 * (p1 - p0) / h - 2.0 * v0 - v1) / h;
        let c3 = (-2.0 * (p1 - p0) / h + v0 + v1) / (h * h);
        let pos = |t: f64| p0 + v0 * t + c2 * t * t + c3 * t * t * t;
        assert!((pos(h) - p1).abs() < 1e-12);
        let d = 1e-5 * h;
        let a0 = (pos(2.0 * d) - 2.0 * pos(d) + pos(0.0)) / (d * d);
        let a1 = (pos(h) - 2.0 * pos(h - d) + pos(h - 2.0 * d)) / (d * d);
        assert!((e.accelerations[0].1 - a0).abs() <= 1e-3 * (1.0 + a0.abs()));
        assert!((e.accelerations[1].1 - a1).abs() <= 1e-3 * (1.0 + a1.abs()));
        let mut vpeak: f64 = 0.0;
        for i in 0..=10_000 {
            let t = h * f64::from(i) / 10_000.0;
            vpeak = vpeak.max((v0 + 2.0 * c2 * t + 3.0 * c3 * t * t).abs());
        }
        assert!((e.peak_velocity.1.abs() - vpeak).abs() <= 1e-6 * (1.0 + vpeak));
        assert!((0.0..=h).contains(&e.peak_velocity.0));
    }
}

#[test]
fn three_point_velocity_is_exact_on_parabolas() {
    let q = |t: f64| 0.3 - 1.7 * t + 2.5 * t * t;
    let dq = |t: f64| -1.7 + 5.0 * t;
    for &(t, h1, h2) in &[(0.4, 0.1, 0.3), (1.0, 0.5, 0.5), (2.0, 0.01, 0.2)] {
        let v = three_point_velocity(h1, h2, q(t - h1), q(t), q(t + h2));
        assert!((v - dq(t)).abs() < 1e-9, "{v} vs {}", dq(t));
    }
}

/// A zig-zag of joint 5 (±0.05 rad every 0.1 s segment: about 20 rad/s² at
/// the planned times) is slowed down until the sampled Hermite
/// interpolation is within 2 rad/s and 4 rad/s²; positions unchanged, rest
/// to rest, no interval shorter than planned, and the segment times and
/// feeds follow the stretch.
#[test]
fn a_zig_zag_is_slowed_to_the_limits() {
    let n = 12;
    let t = vec![0.1; n];
    let feeds = vec![0.05; n];
    let mut q5 = vec![0.0];
    q5.extend((0..n).map(|k| if k % 2 == 0 { 0.05 } else { -0.05 }));
    q5.push(0.0);
    let plan = planned(&t, &q5);
    let lim = limits(2.0, Some(4.0));
    let s = time_scale(&plan, &t, &feeds, &lim).expect("scaled");
    let p = s.trajectory.points();
    assert_eq!(p.len(), n + 2);
    assert_eq!(p[0].velocities, [0.0; 6]);
    assert_eq!(p[n + 1].velocities, [0.0; 6]);
    for (a, b) in p.iter().zip(plan.points()) {
        assert_eq!(a.positions, b.positions);
    }
    assert_eq!(
        (&s.trajectory.arc_length, &s.trajectory.segment),
        (&plan.arc_length, &plan.segment)
    );
    let worst = sampled_worst(&s.trajectory, 2.0, 4.0);
    assert!(worst <= 1.0 + 1e-3, "{worst}");
    assert!(s.stretched_intervals() > 0 && s.rounds > 0);
    for (k, c) in s.interval_stretch.iter().enumerate() {
        assert!(*c >= 1.0, "interval {k}");
        let ramp = if k == 0 || k == n { 2.0 } else { 1.0 };
        let h_plan = plan.points()[k + 1].time_from_start - plan.points()[k].time_from_start;
        let h = p[k + 1].time_from_start - p[k].time_from_start;
        assert!((h - ramp * c * h_plan).abs() <= 1e-12 * h);
    }
    // Segment k: halves in intervals k and k + 1.
    for (k, (f, c)) in s
        .segment_feeds
        .iter()
        .zip(s.interval_stretch.windows(2))
        .enumerate()
    {
        assert!((f - feeds[k] * 2.0 / (c[0] + c[1])).abs() < 1e-15);
        assert!(*f < feeds[k]);
    }
    assert!((s.machining_time() - s.duration()).abs() <= 1e-12 * s.duration());
    // The same zig-zag, slower to begin with, needs less stretch.
    let most = |c: &[f64]| c.iter().copied().fold(0.0, f64::max);
    let slow = vec![0.2; n];
    let s2 = time_scale(&planned(&slow, &q5), &slow, &feeds, &lim).expect("scaled");
    assert!(most(&s2.interval_stretch) < most(&s.interval_stretch));
}

/// A slow, smooth trajectory is only given its ramps: every stretch 1,
/// feeds bit for bit the planned ones, duration = planned + the halves of
/// the first and last segments.
#[test]
fn a_feasible_trajectory_only_gets_its_ramps() {
    let n = 10;
    let t: Vec<f64> = (0..n).map(|k| 0.5 + 0.01 * k as f64).collect();
    let feeds: Vec<f64> = (0..n).map(|k| 0.04 + 1e-3 * k as f64).collect();
    let q5: Vec<f64> = (0..n + 2).map(|k| 0.01 * k as f64).collect();
    let plan = planned(&t, &q5);
    let s = time_scale(&plan, &t, &feeds, &limits(2.0, Some(4.0))).expect("scaled");
    assert_eq!(s.stretched_intervals(), 0);
    assert_eq!(s.rounds, 0);
    assert!(!s.uniform);
    assert_eq!(s.segment_feeds, feeds);
    let total: f64 = t.iter().sum();
    let expected = total + 0.5 * t[0] + 0.5 * t[n - 1];
    assert!((s.duration() - expected).abs() < 1e-12);
    assert!((s.segment_times[0] - 1.5 * t[0]).abs() < 1e-12);
    assert!((s.segment_times[1] - t[1]).abs() < 1e-12);
    // Without an acceleration limit only the speed counts.
    let s = time_scale(&plan, &t, &feeds, &limits(2.0, None)).expect("scaled");
    assert_eq!(s.stretched_intervals(), 0);
}

#[test]
fn bad_inputs_are_refused_with_a_reason() {
    let t = vec![0.1; 3];
    let feeds = vec![0.05; 3];
    let q5 = vec![0.0, 0.01, 0.02, 0.03, 0.04];
    let plan = planned(&t, &q5);
    let lim = limits(2.0, Some(4.0));
    let reason = |e: MillPlanError| match e {
        MillPlanError::InvalidConfig { reason, .. } => reason,
        other => panic!("unexpected {other}"),
    };
    // Point and segment counts.
    let e = time_scale(&plan, &t[..2], &feeds[..2], &lim).unwrap_err();
    assert!(reason(e).contains("expected N + 2"));
    let e = time_scale(&plan, &t, &feeds[..2], &lim).unwrap_err();
    assert!(reason(e).contains("2 segment feeds"));
    // Limits: count, NaN, zero, negative acceleration.
    let e = time_scale(&plan, &t, &feeds, &lim[..5]).unwrap_err();
    assert!(reason(e).contains("5 joint limits for 6 joints"));
    for bad in [
        JointLimit {
            max_velocity: f64::NAN,
            max_acceleration: None,
        },
        JointLimit {
            max_velocity: 0.0,
            max_acceleration: None,
        },
        JointLimit {
            max_velocity: 1.0,
            max_acceleration: Some(-1.0),
        },
    ] {
        let mut l = lim.clone();
        l[2] = bad;
        let e = time_scale(&plan, &t, &feeds, &l).unwrap_err();
        assert!(reason(e).contains("joint 2"));
    }
    // Times not increasing; intervals that are not the segments' halves.
    let mut p = plan.clone();
    p.request.points[2].time_from_start = p.request.points[1].time_from_start;
    let e = time_scale(&p, &t, &feeds, &lim).unwrap_err();
    assert!(reason(e).contains("not strictly increasing between points 1 and 2"));
    let e = time_scale(&plan, &[0.1, 0.2, 0.1], &feeds, &lim).unwrap_err();
    assert!(reason(e).contains("interval 1 lasts 0.1"));
    // A NaN position.
    let mut p = plan.clone();
    p.request.points[3].positions[4] = f64::NAN;
    let e = time_scale(&p, &t, &feeds, &lim).unwrap_err();
    assert!(reason(e).contains("non-finite position of joint 4 at point 3"));
    // Side tables and points that do not match the joints.
    let mut p = plan.clone();
    p.segment.pop();
    let e = time_scale(&p, &t, &feeds, &lim).unwrap_err();
    assert!(reason(e).contains("5 points, 5 arc lengths and 4 segments"));
    let mut p = plan.clone();
    p.request.points[1].velocities.pop();
    let e = time_scale(&p, &t, &feeds, &lim).unwrap_err();
    assert!(reason(e).contains("point 1 has 6 positions and 5 velocities for 6 joints"));
}
