//! Resident memory of a planner node over sequential requests (issue 33, item 3): the node
//! and its client in this process, the plans in the node's worker process.

use std::{fmt::Debug, time::Duration};

use kerf_msgs::RosType;
use kerf_ros::RosEnv;
use serde::Serialize;

use super::planner::{Answer, Planner, PlannerClient};

/// Resident memory (MiB) of this process (the node and its client).
pub fn own_mib() -> f64 {
    super::status_kib("VmRSS:") as f64 / 1024.0
}

/// Bytes in use by glibc's allocator in this process (MiB): live allocations, as opposed to
/// resident memory that fragmentation keeps.
pub fn heap_in_use_mib() -> f64 {
    // SAFETY: mallinfo2 only reads the allocator's statistics.
    let info = unsafe { libc::mallinfo2() };
    (info.uordblks + info.hblkhd) as f64 / (1024.0 * 1024.0)
}

/// Resident memory (MiB) of this process's children (the planner's worker process).
pub fn children_mib() -> f64 {
    let mut total = 0.0;
    let Ok(tasks) = std::fs::read_dir("/proc/self/task") else {
        return 0.0;
    };
    for task in tasks.flatten() {
        let Ok(children) = std::fs::read_to_string(task.path().join("children")) else {
            continue;
        };
        for pid in children.split_whitespace() {
            if let Ok(statm) = std::fs::read_to_string(format!("/proc/{pid}/statm")) {
                if let Some(pages) = statm
                    .split_whitespace()
                    .nth(1)
                    .and_then(|p| p.parse::<f64>().ok())
                {
                    total += pages * 4096.0 / (1024.0 * 1024.0);
                }
            }
        }
    }
    total
}

/// One reading: requests answered so far, the node's and the worker's resident memory (MiB).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reading {
    /// Requests answered before the reading.
    pub answered: usize,
    /// This process (node and client), MiB.
    pub node_mib: f64,
    /// The worker process, MiB.
    pub worker_mib: f64,
    /// Live heap of this process (allocations in use), MiB.
    pub heap_mib: f64,
}

/// Starts `planner`, sends `text(k)` for k in 0..count one at a time (waiting for each
/// answer, which must have status `status`), and reads the memory every `every` answers.
pub fn sequential<Req: RosType + Serialize + Debug, Plan: Answer>(
    planner: &Planner<Req, Plan>,
    env: &RosEnv,
    extra: &[&str],
    count: usize,
    every: usize,
    status: u8,
    text: impl Fn(usize) -> String,
) -> Vec<Reading> {
    let client = PlannerClient::start(planner, env, extra);
    let mut readings = Vec::new();
    for k in 0..count {
        if k % every == 0 {
            readings.push(Reading {
                answered: k,
                node_mib: own_mib(),
                worker_mib: children_mib(),
                heap_mib: heap_in_use_mib(),
            });
        }
        client.send_text(&text(k));
        let plan = client.next_plan(Duration::from_secs(120));
        assert_eq!(plan.status(), status, "request {k}: {}", plan.message());
        // The text form of the answer and the trajectory too: every subscription is read.
        let _ = client.next_plan_text();
        let _ = client.trajectories_received();
    }
    readings.push(Reading {
        answered: count,
        node_mib: own_mib(),
        worker_mib: children_mib(),
        heap_mib: heap_in_use_mib(),
    });
    client.finish();
    readings
}

/// Least-squares slope (KiB per request) of `value` over the readings from `from` answers on.
pub fn slope_kib(readings: &[Reading], from: usize, value: impl Fn(&Reading) -> f64) -> f64 {
    let points: Vec<(f64, f64)> = readings
        .iter()
        .filter(|r| r.answered >= from)
        .map(|r| (r.answered as f64, value(r) * 1024.0))
        .collect();
    let n = points.len() as f64;
    if n < 2.0 {
        return 0.0;
    }
    let (mx, my) = (
        points.iter().map(|p| p.0).sum::<f64>() / n,
        points.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    if sxx == 0.0 {
        0.0
    } else {
        sxy / sxx
    }
}
