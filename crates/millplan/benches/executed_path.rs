//! The executed tool path of every milling planner on the default request (issue 13, item 1):
//! the published trajectory interpolated as the executor does it, every 4 ms, the tool tip by
//! forward kinematics with the cell's TCP, against the path and the milling plane
//! (`kerf_millplan::deviation::executed_deviation`).
//!
//! `cargo bench -p kerf_millplan --bench executed_path`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench binary reports failures by panicking

#[allow(dead_code)] // each bench uses some of the shared helpers
mod common;

use common::thread_cpu_time;
use kerf_millplan::deviation::executed_deviation;
use kerf_millplan::{MillPlanner, MillRequest};

fn main() {
    let planner = MillPlanner::with_default_cell().unwrap();
    println!(
        "| planner | points | executed time (s) | off the path: max / p99 (mm) | off the plane: max (mm) | at t (s) |"
    );
    println!("|---|---:|---:|---|---:|---:|");
    // KERF_BENCH_PLANNERS=fixed_g,naive runs only those (for profiling).
    let only = std::env::var("KERF_BENCH_PLANNERS").ok();
    for name in ["ddpg", "fixed_g", "dp", "naive"] {
        if only
            .as_deref()
            .is_some_and(|o| !o.split(',').any(|x| x == name))
        {
            continue;
        }
        let request = MillRequest {
            planner: name.to_string(),
            ..MillRequest::default()
        };
        match planner.plan(&request) {
            Ok(out) => {
                let t = &out.executed.scaling.trajectory;
                let d = executed_deviation(planner.cell(), t, 0.004).unwrap();
                let sc = &out.executed.scaling;
                eprintln!(
                    "{name}: planned {:.3} s, rounds {}, uniform {}, ramp {:.3} s, slowed {}, \
                     sampled {:.4} mm, min 1/K {:.3} at {:.3} m, trajectory phase {:.1} ms, \
                     planning {:.1} ms",
                    out.plan.total_time,
                    sc.rounds,
                    sc.uniform,
                    sc.ramp_time,
                    sc.slowed_segments(),
                    sc.sampled_deviation * 1e3,
                    sc.min_condition_indicator.0,
                    sc.min_condition_indicator.1,
                    out.phases.trajectory * 1e3,
                    out.planning_seconds * 1e3
                );
                breakdown(&planner, &out);
                eprintln!("  {name}: answer fingerprint {:016x}", fingerprint(&out));
                println!(
                    "| {name} | {} | {:.2} | {:.3} / {:.3} | {:.3} | {:.2} |",
                    t.points().len(),
                    out.executed.plan.total_time,
                    d.max_off_path * 1e3,
                    d.p99_off_path * 1e3,
                    d.max_off_plane * 1e3,
                    d.time_of_max
                );
            }
            Err(e) => println!("| {name} | failed: {e} | | | | |"),
        }
    }
}

/// Where the time of step 7 goes, for one plan: the trajectory construction, the measurement
/// of its tool path at the control period.
fn breakdown(planner: &MillPlanner, out: &kerf_millplan::MillPlanOutput) {
    use kerf_budget::Budget;
    use kerf_millplan::timing::{joint_limits, time_scale, TrajectorySettings};
    use std::time::Instant;
    let cell = planner.cell();
    let limits = joint_limits(cell).unwrap();
    let settings = TrajectorySettings::default();
    let runs: usize = std::env::var("KERF_BENCH_RUNS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(5);
    let (start, cpu) = (Instant::now(), thread_cpu_time());
    for _ in 0..runs {
        time_scale(cell, &out.plan, &limits, &settings, &Budget::unlimited()).unwrap();
    }
    let build = start.elapsed().as_secs_f64() / runs as f64;
    let build_cpu = cpu
        .zip(thread_cpu_time())
        .map(|(a, b)| (b - a) / runs as f64);
    let (start, cpu) = (Instant::now(), thread_cpu_time());
    for _ in 0..runs {
        executed_deviation(cell, &out.executed.scaling.trajectory, 0.004).unwrap();
    }
    let measure = start.elapsed().as_secs_f64() / runs as f64;
    let measure_cpu = cpu
        .zip(thread_cpu_time())
        .map(|(a, b)| (b - a) / runs as f64);
    let ms = |x: Option<f64>| x.map_or("?".to_string(), |v| format!("{:.1}", v * 1e3));
    eprintln!(
        "  {}: time_scale {:.1} ms wall / {} ms CPU (of which the measurement at the control \
         period, executed_deviation: {:.1} ms wall / {} ms CPU), mean of {runs}",
        out.planner.name(),
        build * 1e3,
        ms(build_cpu),
        measure * 1e3,
        ms(measure_cpu)
    );
}

/// A hash of the answer's plan, executed plan, trajectories and measured deviation (their
/// `Debug` text: every f64 printed to the digits that round-trip, so two answers with the
/// same fingerprint are, but for hash collisions, the same bit for bit): for comparing
/// builds.
fn fingerprint(out: &kerf_millplan::MillPlanOutput) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    format!(
        "{:?} {:?} {:?} {:?}",
        out.plan, out.trajectory, out.executed, out.branch_jumps
    )
    .hash(&mut h);
    h.finish()
}
