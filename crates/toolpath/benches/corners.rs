//! Corner smoothing methods compared on the shipped outlines (issue 14, the baselines): kerf's
//! quintic corner against ICR (Zhao, Zhu and Ding 2013), CCR (Xu and Sun 2018) and seed 003's
//! NURBS corner chosen by a particle swarm (`kerf_toolpath::baseline`), each through the same
//! pipeline as `benches/pipeline.rs`: smooth within δ (`smooth_polyline_with`), sample by arc
//! length, plan the feed (`plan_feed`), T_lb (`bang_bang_under`) and seed 000's Table 1 metrics at
//! the interpolation period (`metrics`). The two limit sets are the pipeline bench's (seed 000's
//! appendix C read as mm and s, δ 0.5 mm; seed 003's Table 1, δ 0.1 mm).
//!
//! Smoothing time: `smooth_polyline_with` alone on the point list in memory, best of 20 runs (3
//! for the swarm), on one thread.
//!
//! ```sh
//! cargo bench -p kerf_toolpath --bench corners
//! ```
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench binary reports failures by panicking

use std::time::Instant;

#[allow(dead_code)] // the tests' shared data; each bench uses some of it
#[path = "../tests/support/mod.rs"]
mod support;

use kerf_gcode::{read_points, PointUnit};
use kerf_toolpath::{
    bang_bang_under, corner_jerk::sampled_max_jerk_norm, metrics, plan_feed, plan_feed_optimal,
    sample_path, smooth_polyline_with, CornerMethod, FeedConstraints, NurbsSettings,
};

/// Arc length between samples for planning \[m\] (as the pipeline bench).
const STEP: f64 = 1e-5;

fn main() {
    let names = support::outline_files();
    let (limits000, delta000) = support::seed_000_limits();
    let seed000 = ("seed 000", delta000, limits000);
    let seed003 = ("seed 003", 1e-4, support::feed_limits());
    let methods = [
        CornerMethod::Kerf,
        CornerMethod::KerfCurvature,
        CornerMethod::Icr,
        CornerMethod::Ccr,
        CornerMethod::Nurbs(NurbsSettings::default()),
    ];
    println!(
        "| outline | limits | method | T_m (s) | T_lb (s) | κ_max (1/mm) | g_max (1/mm²) | θ_max (°) | a_rms (mm/s²) | j_rms (mm/s³) | max chord error (µm) | max deviation (mm) | smoothing (ms) | near-opt. T_m (s) | near-opt. T_m/T_lb | near-opt. j_rms (mm/s³) | whole j_n: T_m (s) | whole j_n: T_m/T_lb | whole j_n: j_rms (mm/s³) |"
    );
    println!("|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for path in &names {
        let text = std::fs::read_to_string(path).unwrap();
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        let points = read_points(text.as_bytes(), PointUnit::Millimetre).unwrap();
        for (limits_name, delta, limits) in [&seed000, &seed003] {
            for method in &methods {
                let runs = if matches!(method, CornerMethod::Nurbs(_)) {
                    3
                } else {
                    20
                };
                let mut best = f64::INFINITY;
                let mut smoothed = None;
                for _ in 0..runs {
                    let start = Instant::now();
                    let s = smooth_polyline_with(&points, *delta, method).unwrap();
                    best = best.min(start.elapsed().as_secs_f64());
                    smoothed = Some(s);
                }
                let smoothed = smoothed.unwrap();
                let samples = sample_path(&smoothed, STEP);
                let plan = plan_feed(&samples, limits).unwrap();
                let curve: Vec<f64> = samples
                    .iter()
                    .map(|p| limits.curvature.speed(p.curvature))
                    .collect();
                let lb = bang_bang_under(&samples, curve, limits.tangential_acceleration).unwrap();
                let m = metrics(
                    &plan,
                    &smoothed,
                    &samples,
                    limits.curvature.interpolation_period,
                    limits.curvature.servo.as_ref(),
                );
                let optimal = plan_feed_optimal(&samples, &FeedConstraints::new(*limits)).unwrap();
                let mo = metrics(
                    &optimal,
                    &smoothed,
                    &samples,
                    limits.curvature.interpolation_period,
                    limits.curvature.servo.as_ref(),
                );
                // The near-optimal plan bounding the whole normal jerk v³ √(κ′² + κ⁴) (against the
                // same T_lb).
                let whole = plan_feed_optimal(
                    &samples,
                    &FeedConstraints {
                        whole_normal_jerk: true,
                        ..FeedConstraints::new(*limits)
                    },
                )
                .unwrap();
                let mw = metrics(
                    &whole,
                    &smoothed,
                    &samples,
                    limits.curvature.interpolation_period,
                    limits.curvature.servo.as_ref(),
                );
                let g_max = smoothed
                    .corners()
                    .map(|c| sampled_max_jerk_norm(&c.curve, 4000))
                    .fold(0.0, f64::max);
                println!(
                    "| {name} | {limits_name} | {} | {:.3} | {:.3} | {:.3} | {:.1} | {:.2} | {:.1} | {:.0} | {:.3} | {:.4} | {:.2} | {:.3} | {:.3} | {:.0} | {:.3} | {:.3} | {:.0} |",
                    method.name(),
                    m.time,
                    lb.time,
                    m.max_curvature * 1e-3,
                    g_max * 1e-6,
                    m.max_turning_angle.to_degrees(),
                    m.rms_acceleration * 1e3,
                    m.rms_jerk * 1e3,
                    m.max_chord_error * 1e6,
                    smoothed.max_deviation() * 1e3,
                    best * 1e3,
                    optimal.time,
                    optimal.time / lb.time,
                    mo.rms_jerk * 1e3,
                    whole.time,
                    whole.time / lb.time,
                    mw.rms_jerk * 1e3
                );
            }
        }
    }
}
