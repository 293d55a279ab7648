//! Resident memory of a planner node over sequential requests (issue 33, item 3): the node in
//! a `kerf launch --with-planner` process of its own (what a cell runs), its client in this
//! process, the plans in the node's worker process.

use std::{
    fmt::Debug,
    process::{Command, Stdio},
    time::Duration,
};

use kerf_msgs::RosType;
use kerf_ros::ros2_client::ServiceMapping;
use serde::Serialize;

use super::planner::{Answer, Planner, PlannerClient};
use super::Killed;

/// A field of `/proc/<pid>/status` in MiB (`"VmRSS:"`, `"VmHWM:"`); 0 when unreadable.
pub fn status_mib(pid: u32, field: &str) -> f64 {
    kerf_ros::memory::status_kib_of(pid, field).map_or(0.0, |kib| kib as f64 / 1024.0)
}

/// Resident memory (MiB) of the children of process `pid` (a planner's worker process).
pub fn children_mib(pid: u32) -> f64 {
    let mut total = 0.0;
    let Ok(tasks) = std::fs::read_dir(format!("/proc/{pid}/task")) else {
        return 0.0;
    };
    for task in tasks.flatten() {
        let Ok(children) = std::fs::read_to_string(task.path().join("children")) else {
            continue;
        };
        for child in children.split_whitespace() {
            if let Ok(child) = child.parse::<u32>() {
                total += status_mib(child, "VmRSS:");
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
    /// The node's process (`kerf launch`), MiB.
    pub node_mib: f64,
    /// The worker process, MiB.
    pub worker_mib: f64,
}

/// Starts `kerf launch LAUNCH…` on `domain` (loopback only), connects a client to `planner`
/// in it, sends `text(k)` for k in 0..count one at a time (waiting for each answer, which must
/// have status `status`), and reads the node's and its worker's memory every `every` answers.
#[allow(clippy::too_many_arguments)]
pub fn sequential<Req: RosType + Serialize + Debug, Plan: Answer>(
    planner: &Planner<Req, Plan>,
    domain: u16,
    launch: &[impl AsRef<std::ffi::OsStr>],
    count: usize,
    every: usize,
    status: u8,
    text: impl Fn(usize) -> String,
) -> Vec<Reading> {
    let node = Killed(
        Command::new(env!("CARGO_BIN_EXE_kerf"))
            .arg("launch")
            .args(launch)
            .env("ROS_DOMAIN_ID", domain.to_string())
            .env("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
            .env_remove("ROS_STATIC_PEERS")
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("start kerf launch"),
    );
    let pid = node.0.id();
    let env = super::loopback(domain, ServiceMapping::Enhanced);
    let client = PlannerClient::connect(planner, &env);
    let read = |answered| Reading {
        answered,
        node_mib: status_mib(pid, "VmRSS:"),
        worker_mib: children_mib(pid),
    };
    let mut readings = Vec::new();
    for k in 0..count {
        if k % every == 0 {
            readings.push(read(k));
        }
        client.send_text(&text(k));
        let plan = client.next_plan(Duration::from_secs(120));
        assert_eq!(plan.status(), status, "request {k}: {}", plan.message());
        // The text form of the answer and the trajectory too: every subscription is read.
        let _ = client.next_plan_text();
        let _ = client.trajectories_received();
    }
    readings.push(read(count));
    client.finish();
    drop(node);
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
