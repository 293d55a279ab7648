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
            let t1 = std::time::Instant::now();
            let curve2 = kerf_toolpath::limit_curve(&samples, &c);
            println!("   limit curve {:.2} ms, {} nodes", t1.elapsed().as_secs_f64() * 1e3, curve2.s.len());
            let fake: Vec<kerf_toolpath::PathSample> = curve2.s.iter().map(|s| kerf_toolpath::PathSample { s: *s, point: [0.0; 3], tangent: [1.0, 0.0, 0.0], curvature: 0.0, piece: 0, u: 0.0 }).collect();
            let lb2 = bang_bang_under(&fake, curve2.node.clone(), limits.tangential_acceleration).unwrap();
            let oldcheck = check_plan(&path, &samples, &old, &c, limits.curvature.interpolation_period).unwrap();
            println!("   lb under my curve {:.3} (ratio {:.4}); old plan worst {:?}", lb2.time, plan.time / lb2.time, oldcheck.worst());
            let check = check_plan(&path, &samples, &plan, &c, limits.curvature.interpolation_period).unwrap();
            println!(
                "{name} {lname}: T {:.3} old {:.3} lb {:.3} ratio {:.4} old {:.4}; {:.1} ms, knots {}; worst {:?}",
                plan.time, old.time, lb.time, plan.time / lb.time, old.time / lb.time, dt * 1e3, plan.intervals.len(), check.worst()
            );
        }
    }
}

#[test]
fn debug_gaps() {
    let which = std::env::var("OUTLINE").unwrap_or("heart".into());
    let (_, points) = outlines().into_iter().find(|(n, _)| *n == which).unwrap();
    let (limits, delta) = if std::env::var("S000").is_ok() { seed_000_limits() } else { (feed_limits(), 1e-4) };
    let path = smooth_polyline(&points, delta).unwrap();
    let samples = sample_path(&path, 1e-5);
    let c = FeedConstraints::new(limits);
    let plan = plan_feed_optimal(&samples, &c).unwrap();
    let curve = kerf_toolpath::limit_curve(&samples, &c);
    let fake: Vec<kerf_toolpath::PathSample> = curve.s.iter().map(|s| kerf_toolpath::PathSample { s: *s, point: [0.0; 3], tangent: [1.0, 0.0, 0.0], curvature: 0.0, piece: 0, u: 0.0 }).collect();
    let lb = bang_bang_under(&fake, curve.node.clone(), limits.tangential_acceleration).unwrap();
    // time of the plan at arc length s (by sampling finely)
    let ts = plan.sample(1e-4);
    let t_at = |s: f64| { let k = ts.partition_point(|p| p.s < s).min(ts.len() - 1); ts[k].t };
    // lb time up to node k
    let mut lbt = vec![0.0; curve.s.len()];
    for k in 1..curve.s.len() {
        let ds = curve.s[k] - curve.s[k - 1];
        lbt[k] = lbt[k - 1] + 2.0 * ds / (lb.speed[k] + lb.speed[k - 1]).max(1e-12);
    }
    let mut rows = Vec::new();
    for w in plan.intervals.windows(2) {
        let (ka, kb) = (curve.s.partition_point(|s| *s < w[0].0), curve.s.partition_point(|s| *s < w[1].0));
        let tp = t_at(w[1].0) - t_at(w[0].0);
        let tl = lbt[kb] - lbt[ka];
        rows.push((tp - tl, w[0].0, w[1].0, w[0].2, w[1].2, curve.node[ka], curve.node[kb], tp, tl));
    }
    rows.sort_by(|a, b| b.0.partial_cmp(&a.0).unwrap());
    if let Ok(r) = std::env::var("RANGE") {
        let v: Vec<f64> = r.split(',').map(|x| x.parse().unwrap()).collect();
        let (ka, kb) = (curve.s.partition_point(|s| *s < v[0]), curve.s.partition_point(|s| *s < v[1]));
        let mut last = f64::NAN;
        for k in ka..=kb {
            if (curve.node[k] - last).abs() > 1e-4 || curve.node[k] < 0.0099 && k % 20 == 0 {
                let t = t_at(curve.s[k]);
                let pv = ts[ts.partition_point(|p| p.t < t).min(ts.len() - 1)].v;
                println!("  k {k} s {:.5} L {:.5} plan v {:.5} lb v {:.5}", curve.s[k], curve.node[k], pv, lb.speed[k]);
                last = curve.node[k];
            }
        }
    }
    println!("T {} lb {} knots {}", plan.time, lb.time, plan.intervals.len());
    for r in rows.iter().take(12) {
        println!("loss {:.4} s [{:.5}, {:.5}] v {:.4} {:.4} L {:.4} {:.4} plan {:.4} lb {:.4}", r.0, r.1, r.2, r.3, r.4, r.5, r.6, r.7, r.8);
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

#[test]
fn closed_form_reach_matches_bisection() {
    use kerf_toolpath::scurve::{reachable, reachable_closed_form, scurve_distance};
    for &(a, j) in &[(0.8, 20.0), (0.1, 10.0)] {
        for &v0 in &[0.0, 0.001, 0.01, 0.03, 0.2] {
            for &d in &[1e-7, 1e-5, 1e-4, 1e-3, 1e-2, 0.1] {
                let r1 = reachable(v0, d, 1.0, a, j);
                let r2 = reachable_closed_form(v0, d, 1.0, a, j);
                assert!(scurve_distance(v0, r2, a, j) <= d, "{v0} {d}");
                assert!((r1 - r2).abs() <= 1e-9 * r1.max(1e-3), "{v0} {d}: {r1} vs {r2}");
            }
        }
    }
}
