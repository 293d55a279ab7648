//! Sampling the smoothed path for the near time-optimal feed plan: fixed arc-length steps
//! (`sample_path`) against steps bounded in length and turning (`sample_path_adaptive`), on the
//! shipped outlines with seed 000's and seed 003's limits. Per row: samples, T_m, T_lb,
//! T_m/T_lb, the largest ratio of `check_plan` (every limit on the output at the interpolation
//! period; ≤ 1 holds) and the pipeline time (the point list read to the plan and T_lb, best of
//! 10 on one thread).
//!
//! ```sh
//! cargo bench -p kerf_toolpath --bench sampling
//! ```
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench binary reports failures by panicking

use std::time::Instant;

#[allow(dead_code)] // the tests' shared data; each bench uses some of it
#[path = "../tests/support/mod.rs"]
mod support;

use kerf_gcode::{read_points, PointUnit};
use kerf_toolpath::{
    check_plan, plan_feed_optimal, sample_path, sample_path_adaptive, smooth_polyline,
    FeedConstraints, PathSample, SmoothedPath,
};

/// How a path is sampled.
#[derive(Clone, Copy)]
enum Sampler {
    Fixed(f64),
    Adaptive(f64, f64),
}

impl Sampler {
    fn run(self, path: &SmoothedPath) -> Vec<PathSample> {
        match self {
            Sampler::Fixed(step) => sample_path(path, step),
            Sampler::Adaptive(step, turn) => sample_path_adaptive(path, step, turn).unwrap(),
        }
    }

    fn name(self) -> String {
        match self {
            Sampler::Fixed(step) => format!("fixed {} µm", step * 1e6),
            Sampler::Adaptive(step, turn) => {
                format!("adaptive {} µm, {}°", step * 1e6, turn.to_degrees())
            }
        }
    }
}

fn main() {
    let samplers: Vec<Sampler> = match std::env::var("KERF_SAMPLERS") {
        Ok(list) => list
            .split(',')
            .map(|item| {
                let v: Vec<f64> = item.split(':').map(|x| x.parse().unwrap()).collect();
                match v.as_slice() {
                    [step] => Sampler::Fixed(*step),
                    [step, turn] => Sampler::Adaptive(*step, turn.to_radians()),
                    _ => panic!("KERF_SAMPLERS: step[:turn_deg],…"),
                }
            })
            .collect(),
        Err(_) => vec![
            Sampler::Fixed(1e-5),
            Sampler::Adaptive(1e-3, 1f64.to_radians()),
            Sampler::Adaptive(1e-3, 2f64.to_radians()),
            Sampler::Adaptive(1e-3, 4f64.to_radians()),
        ],
    };
    let (limits000, delta000) = support::seed_000_limits();
    let sets = [
        ("seed 000", delta000, limits000),
        ("seed 003", 1e-4, support::feed_limits()),
    ];
    println!("| outline | limits | sampling | samples | T_m (s) | T_lb (s) | T_m/T_lb | worst check ratio | pipeline (ms) |");
    println!("|---|---|---|---:|---:|---:|---:|---|---:|");
    for path in support::outline_files() {
        let text = std::fs::read_to_string(&path).unwrap();
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        for (limits_name, delta, limits) in &sets {
            let constraints = FeedConstraints::new(*limits);
            for sampler in &samplers {
                let run = || {
                    let points = read_points(text.as_bytes(), PointUnit::Millimetre).unwrap();
                    let smoothed = smooth_polyline(&points, *delta).unwrap();
                    let samples = sampler.run(&smoothed);
                    let plan = plan_feed_optimal(&samples, &constraints).unwrap();
                    let lb = support::t_lb(&samples, limits);
                    (smoothed, samples, plan, lb)
                };
                let mut best = f64::INFINITY;
                let mut result = None;
                for _ in 0..10 {
                    let start = Instant::now();
                    let r = run();
                    best = best.min(start.elapsed().as_secs_f64());
                    result = Some(r);
                }
                let (smoothed, samples, plan, lb) = result.unwrap();
                let check = check_plan(
                    &smoothed,
                    &samples,
                    &plan,
                    &constraints,
                    limits.curvature.interpolation_period,
                )
                .unwrap();
                let (what, worst) = check.worst();
                println!(
                    "| {name} | {limits_name} | {} | {} | {:.3} | {:.3} | {:.4} | {:.5} ({what}) | {:.1} |",
                    sampler.name(),
                    samples.len(),
                    plan.time,
                    lb,
                    plan.time / lb,
                    worst.ratio,
                    best * 1e3
                );
            }
        }
    }
}
