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
