//! The G-code front end's deterministic pipeline on the shipped outlines (issue 14, items 2–4, first
//! figures: kerf's corner transition and the jerk-limited feed plan; the baselines come later):
//! read the point list (`kerf_gcode::read_points`), smooth every corner within δ
//! (`smooth_polyline`), sample by arc length (every 10 µm), plan the feed (`plan_feed`), T_lb
//! (`bang_bang_under`) and the metrics at the interpolation period (`metrics`). Two limit sets:
//!
//! * seed 000's (its appendix C, units not stated; read as mm and s: v 10 mm/s, a 100 mm/s²,
//!   j 10 000 mm/s³, δ 0.5 mm, T 0.5 ms; normal acceleration and jerk taken equal to the
//!   tangential ones, the chord error of the period not limited beyond δ);
//! * seed 003's Table 1 (`CurvatureLimits::seed_003_table_1`, A_t 800 mm/s², J_t 20 000 mm/s³,
//!   δ 0.1 mm).
//!
//! Timing: the whole pipeline from the text in memory to the plan and T_lb, best of 20 runs, on
//! one thread.
//!
//! A second table has kerf's near time-optimal planner (`plan_feed_optimal`) on the same
//! smoothed paths, sampled by `sample_path_adaptive` (steps of at most 1 mm and 2° of turning,
//! a sample at every extremum of a corner's curvature): T_m, T_lb, T_m/T_lb, the planning time alone (best of 20), the
//! whole pipeline with it (best of 20; wall clock and the thread's CPU time, which other
//! processes on the machine do not inflate), the largest ratio of `check_plan` (every limit on the
//! output at the period) for it and for `plan_feed` (on its 10 µm samples), and with the laser
//! cutter's axis limits.
//!
//! ```sh
//! cargo bench -p kerf_toolpath --bench pipeline
//! ```
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench binary reports failures by panicking

use std::time::Instant;

#[allow(dead_code)] // the tests' shared data; each bench uses some of it
#[path = "../tests/support/mod.rs"]
mod support;

use kerf_gcode::{read_points, PointUnit};
use kerf_toolpath::{
    bang_bang_under, check_plan, metrics, plan_feed, plan_feed_optimal, sample_path,
    sample_path_adaptive, smooth_polyline, AxisLimits, FeedConstraints,
};

/// Arc length between samples for seed 003's planner (`plan_feed`, first table) \[m\].
const FIXED_STEP: f64 = 1e-5;

/// The longest step between samples for kerf's planner \[m\] (`sample_path_adaptive`).
const STEP: f64 = 1e-3;

/// The largest turning between samples for planning \[rad\] (2°).
const TURN: f64 = 2.0 * std::f64::consts::PI / 180.0;

fn main() {
    let names = support::outline_files();
    let (limits000, delta000) = support::seed_000_limits();
    let seed000 = ("seed 000", delta000, limits000);
    let seed003 = ("seed 003", 1e-4, support::feed_limits());
    println!(
        "| outline | limits | corners | T_m (s) | T_lb (s) | T_m/T_lb | κ_max (1/mm) | θ_max (°) | a_rms (mm/s²) | j_rms (mm/s³) | max chord error (µm) | max deviation (mm) | pipeline (ms) |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for path in &names {
        let text = std::fs::read_to_string(path).unwrap();
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        for (limits_name, delta, limits) in [&seed000, &seed003] {
            let run = || {
                let points = read_points(text.as_bytes(), PointUnit::Millimetre).unwrap();
                let smoothed = smooth_polyline(&points, *delta).unwrap();
                let samples = sample_path(&smoothed, FIXED_STEP);
                let plan = plan_feed(&samples, limits).unwrap();
                let curve: Vec<f64> = samples
                    .iter()
                    .map(|p| limits.curvature.speed(p.curvature))
                    .collect();
                let lb = bang_bang_under(&samples, curve, limits.tangential_acceleration).unwrap();
                (smoothed, samples, plan, lb)
            };
            let mut best = f64::INFINITY;
            let mut result = None;
            for _ in 0..20 {
                let start = Instant::now();
                let r = run();
                best = best.min(start.elapsed().as_secs_f64());
                result = Some(r);
            }
            let (smoothed, samples, plan, lb) = result.unwrap();
            let m = metrics(
                &plan,
                &smoothed,
                &samples,
                limits.curvature.interpolation_period,
                limits.curvature.servo.as_ref(),
            );
            println!(
                "| {name} | {limits_name} | {} | {:.3} | {:.3} | {:.3} | {:.3} | {:.2} | {:.1} | {:.0} | {:.3} | {:.4} | {:.1} |",
                smoothed.corners().count(),
                m.time,
                lb.time,
                m.time / lb.time,
                m.max_curvature * 1e-3,
                m.max_turning_angle.to_degrees(),
                m.rms_acceleration * 1e3,
                m.rms_jerk * 1e3,
                m.max_chord_error * 1e6,
                smoothed.max_deviation() * 1e3,
                best * 1e3
            );
        }
    }
    println!();
    println!(
        "| outline | limits | T_m (s) | T_lb (s) | T_m/T_lb | plan_feed T_m/T_lb | planning (ms) | pipeline (ms) | pipeline CPU (ms) | worst check ratio | plan_feed worst check ratio | T_m with laser-cutter axes (s) | its worst check ratio |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|---|---|---:|---|");
    for path in &names {
        let text = std::fs::read_to_string(path).unwrap();
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        for (limits_name, delta, limits) in [&seed000, &seed003] {
            let constraints = FeedConstraints::new(*limits);
            let run = || {
                let points = read_points(text.as_bytes(), PointUnit::Millimetre).unwrap();
                let smoothed = smooth_polyline(&points, *delta).unwrap();
                let samples = sample_path_adaptive(&smoothed, STEP, TURN).unwrap();
                let plan = plan_feed_optimal(&samples, &constraints).unwrap();
                let curve: Vec<f64> = samples
                    .iter()
                    .map(|p| limits.curvature.speed(p.curvature))
                    .collect();
                let lb = bang_bang_under(&samples, curve, limits.tangential_acceleration).unwrap();
                (smoothed, samples, plan, lb)
            };
            let mut best = f64::INFINITY;
            let mut best_cpu = f64::INFINITY;
            let mut result = None;
            for _ in 0..20 {
                let start = Instant::now();
                let cpu = thread_cpu();
                let r = run();
                best_cpu = best_cpu.min(thread_cpu() - cpu);
                best = best.min(start.elapsed().as_secs_f64());
                result = Some(r);
            }
            let (smoothed, samples, plan, lb) = result.unwrap();
            let mut planning = f64::INFINITY;
            for _ in 0..20 {
                let start = Instant::now();
                let p = plan_feed_optimal(&samples, &constraints).unwrap();
                planning = planning.min(start.elapsed().as_secs_f64());
                assert_eq!(p.time, plan.time);
            }
            let period = limits.curvature.interpolation_period;
            let worst_on = |s: &[kerf_toolpath::PathSample],
                            p: &kerf_toolpath::FeedPlan,
                            c: &FeedConstraints| {
                let c = check_plan(&smoothed, s, p, c, period).unwrap();
                let (what, w) = c.worst();
                format!("{:.5} ({what})", w.ratio)
            };
            let worst = |p: &kerf_toolpath::FeedPlan, c: &FeedConstraints| worst_on(&samples, p, c);
            // Seed 003's planner on the samples it is built for (every 10 µm).
            let fixed = sample_path(&smoothed, FIXED_STEP);
            let old = plan_feed(&fixed, limits).unwrap();
            let axes = FeedConstraints {
                axes: Some(AxisLimits::laser_cutter()),
                ..constraints
            };
            let with_axes = plan_feed_optimal(&samples, &axes).unwrap();
            println!(
                "| {name} | {limits_name} | {:.3} | {:.3} | {:.4} | {:.4} | {:.1} | {:.1} | {:.1} | {} | {} | {:.3} | {} |",
                plan.time,
                lb.time,
                plan.time / lb.time,
                old.time / lb.time,
                planning * 1e3,
                best * 1e3,
                best_cpu * 1e3,
                worst(&plan, &constraints),
                worst_on(&fixed, &old, &constraints),
                with_axes.time,
                worst(&with_axes, &axes)
            );
        }
    }
}

/// CPU time of the calling thread \[s\] (`CLOCK_THREAD_CPUTIME_ID`): unlike the wall clock, it
/// does not count the time other processes hold the core.
fn thread_cpu() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes one timespec through a valid pointer.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}
