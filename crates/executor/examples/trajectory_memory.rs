//! What a large trajectory costs the executor core in memory: RSS before, with the request,
//! the peak while preparing it, what the prepared trajectory holds, and what is left after
//! everything was dropped.
//!
//! ```sh
//! cargo run --release -p kerf_executor --example trajectory_memory -- 1000000
//! ```
//!
//! The request: `POINTS` (default 10⁶) quintic points of 6 joints, 10 ms apart, at rest at
//! both ends; its wire size is `POINTS × (3 × 6 + 1) × 8` bytes. Linux only (reads
//! `/proc/self/status`, resets the peak through `/proc/self/clear_refs`).

#![allow(clippy::unwrap_used, clippy::expect_used)] // a measurement program: fail loudly

use std::time::Instant;

use kerf_executor::{prepare, ExecutorConfig, JointLimits, TrajectoryPoint, TrajectoryRequest};

const JOINTS: usize = 6;

fn status_kib(field: &str) -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").expect("/proc/self/status");
    status
        .lines()
        .find_map(|l| l.strip_prefix(field))
        .and_then(|v| v.split_whitespace().next())
        .and_then(|v| v.parse::<f64>().ok())
        .expect("field")
}

fn mb(kib: f64) -> f64 {
    kib / 1024.0
}

fn main() {
    let points: usize = std::env::args().nth(1).map_or(1_000_000, |a| {
        a.parse().expect("POINTS: a number of points")
    });
    assert!(points >= 2, "POINTS must be at least 2");
    let limits: Vec<JointLimits> = (1..=JOINTS)
        .map(|j| JointLimits {
            name: format!("joint_{j}"),
            min_position: -3.0,
            max_position: 3.0,
            max_velocity: 2.0,
            max_acceleration: 10.0,
        })
        .collect();
    let base = status_kib("VmRSS:");
    let w = 0.5;
    let req = TrajectoryRequest {
        joint_names: limits.iter().map(|l| l.name.clone()).collect(),
        points: (0..points)
            .map(|i| {
                let t = 0.01 * i as f64;
                let rest = if i == 0 || i == points - 1 { 0.0 } else { 1.0 };
                let phase = |j: usize| w * t + j as f64;
                TrajectoryPoint {
                    positions: (0..JOINTS).map(|j| 0.01 * phase(j).sin()).collect(),
                    velocities: (0..JOINTS)
                        .map(|j| rest * 0.01 * w * phase(j).cos())
                        .collect(),
                    accelerations: (0..JOINTS)
                        .map(|j| -rest * 0.01 * w * w * phase(j).sin())
                        .collect(),
                    effort: Vec::new(),
                    time_from_start: t,
                }
            })
            .collect(),
        start_time: None,
    };
    let with_request = status_kib("VmRSS:");
    std::fs::write("/proc/self/clear_refs", "5").expect("reset the peak RSS");
    let started = Instant::now();
    let prepared = prepare(&limits, &ExecutorConfig::default(), &req).expect("valid");
    let seconds = started.elapsed().as_secs_f64();
    let peak = status_kib("VmHWM:");
    let held = status_kib("VmRSS:") - with_request;
    drop(req);
    let without_request = status_kib("VmRSS:");
    drop(prepared);
    let after = status_kib("VmRSS:");
    let wire = (points * (3 * JOINTS + 1) * 8) as f64 / 1024.0;
    println!(
        "points {points}, joints {JOINTS}, wire size {:.1} MB",
        mb(wire)
    );
    println!(
        "RSS: {:.1} MB at start, {:.1} MB with the request ({:.1} MB)",
        mb(base),
        mb(with_request),
        mb(with_request - base)
    );
    println!(
        "prepare: {seconds:.2} s, peak growth {:.1} MB ({:.2} × wire), prepared trajectory holds \
         {:.1} MB ({:.2} × wire)",
        mb(peak - with_request),
        (peak - with_request) / wire,
        mb(held),
        held / wire
    );
    println!(
        "after dropping the request: {:.1} MB; after dropping the trajectory: {:.1} MB ({:.1} MB \
         above the start, without malloc_trim)",
        mb(without_request),
        mb(after),
        mb(after - base)
    );
}
