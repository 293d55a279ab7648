//! The metrics of seeds 000 and 003 on feed plans: a straight line has no curvature, turning or
//! chord error and its a_rms is the plan's own; a smoothed zig-zag keeps its measured chord error
//! and its contour-error estimate within seed 003's limits (which the feed plan was built for).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

#[allow(dead_code)] // each test file uses some of the shared data
mod support;
use support::{feed_limits, ZIG_ZAG};

use kerf_toolpath::{metrics, plan_feed, sample_path, smooth_polyline};

#[test]
fn a_straight_line() {
    let path = smooth_polyline(&[[0.0; 3], [0.1, 0.02, 0.0]], 1e-4).unwrap();
    let samples = sample_path(&path, 1e-4);
    let l = feed_limits();
    let plan = plan_feed(&samples, &l).unwrap();
    let m = metrics(&plan, &path, &samples, 0.002, l.curvature.servo.as_ref());
    assert_eq!(m.time, plan.time);
    assert_eq!(m.max_curvature, 0.0);
    assert!(m.max_turning_angle < 1e-6, "{}", m.max_turning_angle);
    assert!(m.max_chord_error < 1e-12);
    assert_eq!(m.max_contour_error, 0.0);
    // a_rms against the plan's own tangential acceleration at the samples.
    let timed = plan.sample(0.002);
    let own = (timed.iter().map(|p| p.a * p.a).sum::<f64>() / timed.len() as f64).sqrt();
    assert!(
        (m.rms_acceleration - own).abs() < 0.02 * own,
        "{} vs {own}",
        m.rms_acceleration
    );
    assert!(m.rms_jerk > 0.0 && m.rms_jerk <= 20.0 * 1.01);
}

#[test]
fn a_smoothed_zig_zag_keeps_the_chord_and_contour_feed_limits() {
    let poly = ZIG_ZAG;
    let path = smooth_polyline(&poly, 1e-4).unwrap();
    let samples = sample_path(&path, 1e-5);
    let l = feed_limits();
    let plan = plan_feed(&samples, &l).unwrap();
    let m = metrics(
        &plan,
        &path,
        &samples,
        l.curvature.interpolation_period,
        l.curvature.servo.as_ref(),
    );
    println!("{m:?}");
    assert!(m.max_curvature > 0.0 && m.max_turning_angle > 0.0);
    // The chord error: eq. 16's limit plus the linear interpolation between 10 µm samples.
    assert!(
        m.max_chord_error <= l.curvature.chord_error + 2e-8,
        "{}",
        m.max_chord_error
    );
    assert!(m.max_chord_error > 0.0);
    let servo = l.curvature.servo.unwrap();
    assert!(
        m.max_contour_error <= servo.contour_error * (1.0 + 1e-6),
        "{}",
        m.max_contour_error
    );
}
