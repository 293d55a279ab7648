//! The executed tool path of every milling planner on the default request (issue 13, item 1):
//! the published trajectory interpolated as the executor does it, every 4 ms, the tool tip by
//! forward kinematics with the cell's TCP, against the path and the milling plane
//! (`kerf_millplan::deviation::executed_deviation`).
//!
//! `cargo bench -p kerf_millplan --bench executed_path`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench binary reports failures by panicking

use kerf_millplan::deviation::executed_deviation;
use kerf_millplan::{MillPlanner, MillRequest};

fn main() {
    let planner = MillPlanner::with_default_cell().unwrap();
    println!(
        "| planner | points | executed time (s) | off the path: max / p99 (mm) | off the plane: max (mm) | at t (s) |"
    );
    println!("|---|---:|---:|---|---:|---:|");
    for name in ["ddpg", "fixed_g", "dp", "naive"] {
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
    use kerf_millplan::timing::{time_scale, JointLimit, TrajectorySettings};
    use std::time::Instant;
    let cell = planner.cell();
    let limits: Vec<JointLimit> = cell
        .robot()
        .joints()
        .iter()
        .map(|j| JointLimit {
            max_velocity: j.max_velocity,
            max_acceleration: j.max_acceleration,
            max_jerk: j.max_jerk,
        })
        .collect();
    let settings = TrajectorySettings::default();
    let runs = 5;
    let start = Instant::now();
    for _ in 0..runs {
        time_scale(cell, &out.plan, &limits, &settings, &Budget::unlimited()).unwrap();
    }
    let build = start.elapsed().as_secs_f64() / runs as f64;
    let start = Instant::now();
    for _ in 0..runs {
        executed_deviation(cell, &out.executed.scaling.trajectory, 0.004).unwrap();
    }
    let measure = start.elapsed().as_secs_f64() / runs as f64;
    eprintln!(
        "  {}: time_scale {:.1} ms, executed_deviation {:.1} ms (mean of {runs})",
        out.planner.name(),
        build * 1e3,
        measure * 1e3
    );
}
