//! Request → plan latency of the MJTO planner node over loopback DDS.
//!
//! Starts `mjto_planner` in this process and a client node, both on loopback (own Contexts,
//! ROS domain 96), sends case 1 (`crates/mjto/cases/case1.yaml`, 241 CL points) as YAML on
//! `~/cut_request_text` `KERF_CUT_RUNS` times (default 20, after one warm-up that also loads
//! the mesh) and prints p50 / max of the time from `publish` to the `CutPlan` taken from
//! `~/cut_plan`, beside the planner's own `time_total` (so the difference is DDS, queueing,
//! parsing and message conversion of a 241-point request and a ~200-point plan).
//!
//! Run: `cargo bench --bench cut_latency`. Timings are reported, never asserted.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::time::{Duration, Instant};

use kerf_msgs::{msg::CutPlan, std_msgs::StringMsg, RosType};
use kerf_ros::{qos, ros2_client::ServiceMapping};

// Shared with the end-to-end tests; spawn_executor is not used here.
#[allow(dead_code)]
#[path = "../tests/support/mod.rs"]
mod support;

fn percentile(v: &mut [f64], p: f64) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[((v.len() - 1) as f64 * p).round() as usize]
}

fn main() {
    let runs: usize = std::env::var("KERF_CUT_RUNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(20);
    let env = support::loopback(96, ServiceMapping::Enhanced);
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/crates/mjto/cases/case1.yaml"
    ))
    .expect("case 1");
    let words = vec![
        "--ros-args".to_string(),
        "--disable-rosout-logs".to_string(),
    ];
    let (stop, planner) = support::spawn_node(&env, words, |a, e, s| {
        kerf_mjto_planner::run(a, e, s).map_err(|e| e.to_string())
    });
    let mut client = support::client_node("cut_latency", &env);
    let requests = client
        .publisher::<StringMsg>(
            "/mjto_planner/cut_request_text",
            StringMsg::ROS_TYPE,
            qos::commands(),
        )
        .expect("publisher");
    let plans = client
        .subscription::<CutPlan>("/mjto_planner/cut_plan", CutPlan::ROS_TYPE, qos::commands())
        .expect("subscription");
    assert!(
        client.wait_for_subscriber(&requests, Duration::from_secs(30)),
        "planner not matched"
    );
    std::thread::sleep(Duration::from_millis(500));

    let mut latency = Vec::new();
    let mut planner_time = Vec::new();
    for k in 0..=runs {
        let t = Instant::now();
        requests
            .publish(StringMsg { data: text.clone() })
            .expect("publish");
        let plan = loop {
            match plans.take() {
                Ok(Some((p, _))) => break p,
                Ok(None) => std::thread::sleep(Duration::from_micros(200)),
                Err(e) => panic!("reading CutPlan: {e:?}"),
            }
            assert!(
                t.elapsed() < Duration::from_secs(60),
                "no CutPlan within 60 s"
            );
        };
        let dt = t.elapsed().as_secs_f64() * 1e3;
        assert_eq!(plan.status, CutPlan::SUCCESS, "{}", plan.message);
        if k > 0 {
            latency.push(dt);
            planner_time.push(plan.time_total * 1e3);
        }
    }
    let p50 = percentile(&mut latency, 0.5);
    let max = percentile(&mut latency, 1.0);
    let plan50 = percentile(&mut planner_time, 0.5);
    println!("case 1 over loopback DDS, {runs} requests: request → CutPlan p50 {p50:.1} ms, max {max:.1} ms; planner time_total p50 {plan50:.1} ms");
    drop(plans);
    drop(requests);
    drop(client);
    stop.stop();
    let _ = planner.join();
}
