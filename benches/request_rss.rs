//! Resident memory of each planner node over sequential requests (issue 33, item 3), over
//! loopback DDS. The node runs in a `kerf launch --with-planner` process (as a cell runs it:
//! the robot's executor and planners), its client in this process; the node plans in its
//! worker process. Prints the node process's and the worker's VmRSS every `KERF_RSS_EVERY`
//! answers and the slope over the second half.
//!
//! Run: `cargo bench --bench request_rss -- [cut|mill|gcode] [COUNT]` (default: all three,
//! 10 000 requests for cut and G-code, 1 000 for milling); `KERF_RSS_LAUNCH_ARGS` adds
//! arguments to `kerf launch` (e.g. `--ros-args --disable-rosout-logs`).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench binary reports failures by panicking

use kerf_msgs::msg::{CutPlan, GcodePlan, MillPlan};

#[allow(dead_code)]
#[path = "../tests/support/mod.rs"]
mod support;
use support::rss::{sequential, slope_kib, Reading};

fn report(name: &str, readings: &[Reading]) {
    println!("{name}: answered, node VmRSS MiB, worker VmRSS MiB");
    for r in readings {
        println!("  {:6} {:8.1} {:8.1}", r.answered, r.node_mib, r.worker_mib);
    }
    let last = readings.last().map_or(0, |r| r.answered);
    let at_100 = readings.iter().find(|r| r.answered >= 100);
    let end = readings.last();
    if let (Some(a), Some(b)) = (at_100, end) {
        println!(
            "{name}: node {:.1} MiB after 100, {:.1} MiB after {last} ({:+.1} %); worker {:.1} -> {:.1} MiB; slope over the second half: node {:.2} KiB/request, worker {:.2} KiB/request",
            a.node_mib,
            b.node_mib,
            100.0 * (b.node_mib / a.node_mib - 1.0),
            a.worker_mib,
            b.worker_mib,
            slope_kib(readings, last / 2, |r| r.node_mib),
            slope_kib(readings, last / 2, |r| r.worker_mib),
        );
    }
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    let which = args.first().cloned().unwrap_or_else(|| "all".into());
    let count: Option<usize> = args.get(1).and_then(|c| c.parse().ok());
    let every: usize = std::env::var("KERF_RSS_EVERY")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(100);
    // More arguments of `kerf launch` (e.g. `--ros-args --disable-rosout-logs`).
    let extra = std::env::var("KERF_RSS_LAUNCH_ARGS").unwrap_or_default();
    // The planner alone (`--only`): since issue 27 `--with-planner` connects the planners to
    // the executor, whose preparation of every plan would then be measured too.
    let launch = |robot: &'static str, planner: &'static str| -> Vec<String> {
        ["--robot", robot, "--with-planner", "--only", planner]
            .into_iter()
            .map(String::from)
            .chain(extra.split_whitespace().map(String::from))
            .collect()
    };
    if which == "all" || which == "cut" {
        let case1 = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/crates/mjto/cases/case1.yaml"
        ))
        .unwrap();
        // Every plan is framed from the launch's start pose (issue 27), given: the executor
        // runs the first plan, so the robot is elsewhere for the next ones.
        let case1 = format!("{case1}\nstart: [0.8, 0.7, 1.5, 0, 0, -0.05]\n");
        let r = sequential(
            &support::planner::mjto(),
            91,
            &launch("laser_cutter", "mjto_planner"),
            count.unwrap_or(10_000),
            every,
            CutPlan::SUCCESS,
            |_| case1.clone(),
        );
        report("cut (case 1)", &r);
    }
    if which == "all" || which == "gcode" {
        let text = "request_id: square\nprogram: \"G21 G90 G17\\nM3\\nG1 X20 Y0 F3000\\nG1 X20 Y15\\nG3 X15 Y20 R5\\nG1 X0 Y20\\nG1 X0 Y0\\nM5\\nM30\\n\"\n";
        let r = sequential(
            &support::planner::gcode(),
            92,
            &launch("laser_cutter", "gcode_planner"),
            count.unwrap_or(10_000),
            every,
            GcodePlan::SUCCESS,
            |_| text.to_string(),
        );
        report("gcode (20 mm square)", &r);
    }
    if which == "all" || which == "mill" {
        // The seed 004 path (the default cell's), as `kerf plan mill` takes it.
        let points: Vec<String> = kerf_millplan::MillRequest::default()
            .points
            .iter()
            .map(|p| format!("[{:?}, {:?}, {:?}]", p[0], p[1], p[2]))
            .collect();
        let mill_text = format!(
            "request_id: naive\nplanner: naive\npoints: [{}]\n\
             start: [-0.369639, -0.539469, 0.534629, 1.565075, 0.702171, -1.563303]\n",
            points.join(", ")
        );
        let r = sequential(
            &support::planner::mill(),
            93,
            &launch("irb6660", "milling_planner"),
            count.unwrap_or(1_000),
            every,
            MillPlan::SUCCESS,
            |_| mill_text.clone(),
        );
        report("mill (default path, naive)", &r);
    }
}
