//! The jerk-limited feed plan: exact on a straight line, every limit held at the interpolation
//! period on a smoothed zig-zag (tangential acceleration and jerk from the plan, speed against
//! the velocity-limit curve of seed 003 eq. 22 at the sampled arc length), never faster than T_lb,
//! and close corners lower their speeds so that the gaps between them can be run.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

#[allow(dead_code)] // each test file uses some of the shared data
mod support;
use support::{feed_limits, ZIG_ZAG};

use kerf_toolpath::{bang_bang_under, plan_feed, sample_path, smooth_polyline, PathSample};

/// The curvature at arc length `s` (the larger of the two samples around it).
fn curvature_at(samples: &[PathSample], s: f64) -> f64 {
    let k = samples.partition_point(|p| p.s < s).min(samples.len() - 1);
    samples[k]
        .curvature
        .max(samples[k.saturating_sub(1)].curvature)
}

#[test]
fn a_straight_line_is_the_s_curve_trapezoid() {
    let path = smooth_polyline(&[[0.0; 3], [0.1, 0.0, 0.0]], 1e-4).unwrap();
    let samples = sample_path(&path, 1e-3);
    let l = feed_limits();
    let plan = plan_feed(&samples, &l).unwrap();
    let (f, a, j) = (0.070, 0.8, 20.0);
    // F ≥ A²/J: the acceleration reaches A; t_acc = F/A + A/J, d_acc = F/2 t_acc.
    let t_acc = f / a + a / j;
    let d_acc = 0.5 * f * t_acc;
    let expected = 2.0 * t_acc + (0.1 - 2.0 * d_acc) / f;
    assert!(
        (plan.time - expected).abs() < 1e-12,
        "{} vs {expected}",
        plan.time
    );
    let end = plan.sample(0.002).last().copied().unwrap();
    assert!(
        (end.s - 0.1).abs() < 1e-12 && end.v.abs() < 1e-12,
        "{end:?}"
    );
}

#[test]
fn every_limit_holds_at_the_interpolation_period_and_t_is_at_least_t_lb() {
    let poly = ZIG_ZAG;
    let path = smooth_polyline(&poly, 1e-4).unwrap();
    let samples = sample_path(&path, 1e-5);
    let l = feed_limits();
    let plan = plan_feed(&samples, &l).unwrap();
    let curve: Vec<f64> = samples
        .iter()
        .map(|p| l.curvature.speed(p.curvature))
        .collect();
    let lb = bang_bang_under(&samples, curve, l.tangential_acceleration).unwrap();
    assert!(plan.time >= lb.time, "{} < T_lb {}", plan.time, lb.time);
    println!(
        "T = {:.4} s, T_lb = {:.4} s, T/T_lb = {:.3}, intervals {:?}",
        plan.time,
        lb.time,
        plan.time / lb.time,
        plan.intervals
    );
    let period = l.curvature.interpolation_period;
    let ts = plan.sample(period);
    assert!((ts.last().unwrap().s - plan.length).abs() < 1e-9);
    for w in ts.windows(2) {
        let p = w[1];
        assert!(
            p.a.abs() <= l.tangential_acceleration * (1.0 + 1e-9),
            "{p:?}"
        );
        assert!(p.j.abs() <= l.tangential_jerk, "{p:?}");
        // The speed against the limit at this arc length.
        let kappa = curvature_at(&samples, p.s);
        let vmax = l.curvature.speed(kappa);
        assert!(p.v <= vmax * (1.0 + 1e-9), "{p:?}: limit {vmax}");
        // Speeds by differences agree with the plan's (the plan is what is sampled).
        let mean = (w[1].s - w[0].s) / (w[1].t - w[0].t);
        assert!(mean <= l.curvature.feed * (1.0 + 1e-9));
        assert!(w[1].s >= w[0].s - 1e-15);
    }
    // The corners bind: some interval runs below F.
    assert!(plan.intervals.iter().any(|iv| iv.2 < l.curvature.feed));
}

#[test]
fn close_corners_lower_their_speeds_until_the_gap_can_be_run() {
    // Two sharp corners 1 mm apart with long lines around them.
    let poly = [
        [0.0, 0.0, 0.0],
        [0.05, 0.0, 0.0],
        [0.05, 0.001, 0.0],
        [0.0, 0.001, 0.0],
    ];
    let path = smooth_polyline(&poly, 1e-4).unwrap();
    let samples = sample_path(&path, 1e-5);
    let l = feed_limits();
    let plan = plan_feed(&samples, &l).unwrap();
    assert!(!plan.intervals.is_empty());
    // Between every two intervals the S-curve from one speed to the next fits.
    for w in plan.intervals.windows(2) {
        let d = w[1].0 - w[0].1;
        let need = kerf_toolpath::scurve::scurve_distance(w[0].2, w[1].2, 0.8, 20.0);
        assert!(
            need <= d * (1.0 + 1e-9) + 1e-15,
            "{w:?}: needs {need}, has {d}"
        );
    }
    let ts = plan.sample(0.002);
    assert!(ts.iter().all(|p| p.a.abs() <= 0.8 * (1.0 + 1e-9)));
}

#[test]
fn bad_limits_are_refused() {
    let path = smooth_polyline(&[[0.0; 3], [0.1, 0.0, 0.0]], 1e-4).unwrap();
    let samples = sample_path(&path, 1e-3);
    let mut l = feed_limits();
    l.tangential_jerk = 0.0;
    assert!(plan_feed(&samples, &l).is_err());
    let mut l = feed_limits();
    l.curvature.feed = f64::NAN;
    assert!(plan_feed(&samples, &l).is_err());
    assert!(plan_feed(&samples[..1], &feed_limits()).is_err());
}
