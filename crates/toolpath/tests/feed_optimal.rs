//! The near time-optimal feed plan (`plan_feed_optimal`) on the shipped outlines and hand paths.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

#[allow(dead_code)] // each test file uses some of the shared data
mod support;
use support::{feed_limits, outlines, seed_000_limits};

use kerf_toolpath::{
    bang_bang_under, check_plan, plan_feed, plan_feed_optimal, sample_path, smooth_polyline,
    FeedConstraints,
};

#[test]
fn explore() {
    for (name, points) in outlines() {
        for (lname, (limits, delta)) in [("000", seed_000_limits()), ("003", (feed_limits(), 1e-4))] {
            let path = smooth_polyline(&points, delta).unwrap();
            let samples = sample_path(&path, 1e-5);
            let c = FeedConstraints::new(limits);
            let t0 = std::time::Instant::now();
            let plan = plan_feed_optimal(&samples, &c).unwrap();
            let dt = t0.elapsed().as_secs_f64();
            let old = plan_feed(&samples, &limits).unwrap();
            let curve: Vec<f64> = samples.iter().map(|p| limits.curvature.speed(p.curvature)).collect();
            let lb = bang_bang_under(&samples, curve, limits.tangential_acceleration).unwrap();
            let check = check_plan(&path, &samples, &plan, &c, limits.curvature.interpolation_period).unwrap();
            println!(
                "{name} {lname}: T {:.3} old {:.3} lb {:.3} ratio {:.4} old {:.4}; {:.1} ms, knots {}; worst {:?}",
                plan.time, old.time, lb.time, plan.time / lb.time, old.time / lb.time, dt * 1e3, plan.intervals.len(), check.worst()
            );
        }
    }
}

#[test]
fn debug_heart() {
    let (name, points) = outlines().into_iter().find(|(n, _)| n == "heart").unwrap();
    let (limits, delta) = seed_000_limits();
    let path = smooth_polyline(&points, delta).unwrap();
    let samples = sample_path(&path, 1e-5);
    let c = FeedConstraints::new(limits);
    let plan = plan_feed_optimal(&samples, &c).unwrap();
    let curve = kerf_toolpath::limit_curve(&samples, &c);
    println!("{name}: nodes {} samples {}", curve.s.len(), samples.len());
    for k in (15905..15920).chain(15860..15880) {
        println!("node {k} s {:.6} L {:.9} M {:.9}", curve.s[k], curve.node[k], curve.interval[k]);
    }
    for iv in &plan.intervals {
        let k = curve.s.partition_point(|s| *s < iv.0);
        println!("knot s {:.5} v {:.5} L {:.5}", iv.0, iv.2, curve.node[k]);
    }
    let mut last = 0.0;
    for p in plan.sample(0.5) {
        println!("t {:.1} s {:.5} v {:.5}  ds {:.5}", p.t, p.s, p.v, p.s - last);
        last = p.s;
    }
}
