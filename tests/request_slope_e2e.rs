//! No growth per request (issue 33, item 3), the short form of `benches/request_rss.rs`: a
//! G-code planner node in a `kerf launch --robot laser_cutter --with-planner` process (loopback
//! DDS, domain 174) answers 1 500 small requests one at a time. Past its warm-up (the first
//! 500), the node's resident memory grows by less than 8 KiB per request (least squares), and
//! its worker process's by less than 1 KiB per request. Over 10⁴ requests the bench shows the
//! node's RSS as a bounded saw-tooth (33-47 MiB, rising about 5 KiB per request between
//! drops, no trend) and the worker flat; before issue 33 a G-code node grew 38 KiB per request
//! without a plateau (BENCHMARKS.md, "Memory per request"), which this bound catches.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_msgs::msg::GcodePlan;

#[allow(dead_code)] // shared with the other end-to-end tests
mod support;
use support::rss::{sequential, slope_kib, Reading};

/// A 20 mm square with an arc, beam on: planned in about 25 ms, framed from the launch's start
/// pose (given: the executor runs the first plan, so the robot is elsewhere for the next ones).
const SQUARE: &str = "request_id: square\nprogram: \"G21 G90 G17\\nM3\\nG1 X20 Y0 F3000\\nG1 X20 Y15\\nG3 X15 Y20 R5\\nG1 X0 Y20\\nG1 X0 Y0\\nM5\\nM30\\n\"\nstart: [0.8, 0.7, 1.5, 0, 0, -0.05]\n";

#[test]
fn a_planner_node_does_not_grow_per_request() {
    let readings = sequential(
        &support::planner::gcode(),
        174,
        // The planner alone: `--with-planner` connects it to the executor, whose preparation
        // of every plan is not the planner's memory.
        &[
            "--robot",
            "laser_cutter",
            "--with-planner",
            "--only",
            "gcode_planner",
        ],
        1_500,
        10,
        GcodePlan::SUCCESS,
        |_| SQUARE.to_string(),
    );
    for r in readings.iter().step_by(10) {
        eprintln!(
            "{:5} answered: node {:6.1} MiB, worker {:6.1} MiB",
            r.answered, r.node_mib, r.worker_mib
        );
    }
    // The node's RSS is a saw-tooth (freed answers and DDS samples given back when idle, every
    // second): a least-squares slope of sparse readings aliases it. The slope of the saw-tooth's
    // peaks (the largest reading in each window of 250 requests) is what grows, if anything.
    let peaks: Vec<Reading> = readings
        .chunks(25)
        .filter_map(|w| {
            w.iter()
                .copied()
                .max_by(|a, b| a.node_mib.total_cmp(&b.node_mib))
        })
        .collect();
    let node = slope_kib(&peaks, 500, |r| r.node_mib);
    let worker = slope_kib(&readings, 500, |r| r.worker_mib);
    eprintln!("slope past the warm-up: node {node:.2} KiB/request, worker {worker:.2} KiB/request");
    assert!(
        readings
            .iter()
            .all(|r| r.node_mib > 0.0 && r.worker_mib > 0.0),
        "memory not read: {readings:?}"
    );
    assert!(node < 8.0, "the node grows {node:.2} KiB per request");
    assert!(worker < 1.0, "the worker grows {worker:.2} KiB per request");
}
