//! Peak resident memory of each planner node for its largest accepted requests (issue 11,
//! item 5), over loopback DDS (ROS domain 97).
//!
//! For each case a child process (this binary, `KERF_PEAK_CASE` set) starts the planner node
//! in-process with a client node, reads VmRSS, sends the request on the node's text topic,
//! waits for its answer and prints the answer's status with VmRSS and VmHWM (the process's
//! peak: node, client and the DDS traffic of both). Cases:
//! * `cut-points`: the largest text request (4 MiB, ~60 000 CL points 0.1 mm apart in the
//!   line format, sampled every 8 ms: under the answer limit), parsed and planned;
//! * `cut-samples`: case 1 sampled so that its answer has 6 900 points (the most an answer
//!   carries is 6 990), planned;
//! * `mill-segments`: the default path in 2 706 segments, the most whose answer fits in
//!   4 MiB (at least 5 413 trajectory points and the segment table), ddpg.
//!
//! Run: `cargo bench --bench peak_rss`.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench binary reports failures by panicking

use std::process::Command;
use std::time::{Duration, Instant};

use kerf_msgs::{
    msg::{CutPlan, MillPlan},
    std_msgs::StringMsg,
    RosType,
};
use kerf_ros::{planner::PlanAnswer, qos, ros2_client::ServiceMapping, KerfNode};
use serde::de::DeserializeOwned;

#[allow(dead_code)]
#[path = "../tests/support/mod.rs"]
mod support;
use support::status_kib;

const CASES: [&str; 3] = ["cut-points", "cut-samples", "mill-segments"];

fn case1() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/crates/mjto/cases/case1.yaml"
    ))
    .unwrap()
}

/// Sends `text` to `topic` and waits for one answer on `answers`; returns its status, point
/// count and message, and the seconds it took.
fn round_trip<A: PlanAnswer + DeserializeOwned>(
    client: &mut KerfNode,
    topic: &str,
    answers: &str,
    text: String,
) -> (String, f64) {
    let requests = client
        .publisher::<StringMsg>(topic, StringMsg::ROS_TYPE, qos::commands())
        .unwrap();
    let plans = client
        .subscription::<A>(answers, A::ROS_TYPE, qos::latched())
        .unwrap();
    assert!(client.wait_for_subscriber(&requests, Duration::from_secs(30)));
    std::thread::sleep(Duration::from_millis(500));
    let t = Instant::now();
    requests.publish(StringMsg { data: text }).unwrap();
    loop {
        if let Ok(Some((a, _))) = plans.take() {
            let status = format!(
                "{} ({} points): {:.120}",
                a.status_name(),
                a.trajectory().points.len(),
                a.message()
            );
            return (status, t.elapsed().as_secs_f64());
        }
        assert!(t.elapsed() < Duration::from_secs(900), "no answer");
        std::thread::sleep(Duration::from_millis(2));
    }
}

fn run_case(case: &str) {
    let env = support::loopback(97, ServiceMapping::Enhanced);
    let words = vec![
        "--ros-args".to_string(),
        "--disable-rosout-logs".to_string(),
    ];
    let mill = case.starts_with("mill");
    let (stop, node) = if mill {
        support::spawn_node(&env, words, |a, e, s| {
            kerf_milling_planner::run(a, e, s).map_err(|e| e.to_string())
        })
    } else {
        support::spawn_node(&env, words, |a, e, s| {
            kerf_mjto_planner::run(a, e, s).map_err(|e| e.to_string())
        })
    };
    let mut client = support::client_node("peak_rss", &env);
    let text = match case {
        "cut-points" => {
            let mut t = String::from(
                "request_id: cut-points\nfeedrate: 0.3\nsample_period: 0.008\n\
                 max_lead_angle: 0.1\nmax_tilt_angle: 0.1\n\
                 mesh: package://kerf/urdf/meshes/bpillar.obj\n",
            );
            let mut k = 0;
            while t.len() < (4 << 20) - 80 {
                t.push_str(&format!(
                    "{:.9} -0.177632050 0.0 0 0 1\n",
                    0.6 + 1e-4 * k as f64
                ));
                k += 1;
            }
            t
        }
        "cut-samples" => {
            // Case 1 lasts 2.529 s (feed ramps included): 6 900 samples.
            case1()
                .replace(
                    "request_id: bpillar-case1-side-trim",
                    "request_id: cut-samples",
                )
                .replace(
                    "sample_period: 0.01",
                    &format!("sample_period: {}", 2.529 / 6899.0),
                )
        }
        _ => "request_id: mill-segments\nplanner: ddpg\nsegments: 2706\n\
              points: [[1.4, -0.3, 1.7], [1.6, -0.1, 1.7], [1.8, 0.1, 1.7], [2.1, 0.3, 1.7]]\n"
            .to_string(),
    };
    let bytes = text.len();
    let before = status_kib("VmRSS:");
    let (answer, seconds) = if mill {
        round_trip::<MillPlan>(
            &mut client,
            "/milling_planner/mill_request_text",
            "/milling_planner/mill_plan",
            text,
        )
    } else {
        round_trip::<CutPlan>(
            &mut client,
            "/mjto_planner/cut_request_text",
            "/mjto_planner/cut_plan",
            text,
        )
    };
    println!(
        "| {case} | {:.2} MiB | {answer} | {seconds:.2} s | {:.0} MiB | {:.0} MiB | {:.0} MiB |",
        bytes as f64 / (1 << 20) as f64,
        before as f64 / 1024.0,
        status_kib("VmRSS:") as f64 / 1024.0,
        status_kib("VmHWM:") as f64 / 1024.0,
    );
    drop(client);
    stop.stop();
    node.join().unwrap().unwrap();
}

fn main() {
    if let Ok(case) = std::env::var("KERF_PEAK_CASE") {
        run_case(&case);
        return;
    }
    println!("| case | request | answer | round trip | VmRSS before | VmRSS after | VmHWM |");
    println!("|---|---:|---|---:|---:|---:|---:|");
    for case in CASES {
        let out = Command::new(std::env::current_exe().unwrap())
            .env("KERF_PEAK_CASE", case)
            .env("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        match stdout.lines().find(|l| l.starts_with("| ")) {
            Some(line) => println!("{line}"),
            None => println!(
                "| {case} | failed: {} |",
                String::from_utf8_lossy(&out.stderr)
                    .lines()
                    .last()
                    .unwrap_or("")
            ),
        }
    }
}
