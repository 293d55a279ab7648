//! Deadlines and cancellation through the harness (issue 11, item 3), end to end over loopback
//! DDS: a plan over the node's `plan_timeout` is answered TIMEOUT and the node keeps serving; a
//! request asking for more than `plan_timeout`, or whose answer would be too large to send, is
//! refused before planning; stopping the node mid-plan (the stop token, and Ctrl-C of
//! `kerf launch --with-planner`) cancels the plan, answers it, and the node ends at once.
//! Domains 66 and 67.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::{
    path::Path,
    process::Command,
    time::{Duration, Instant},
};

use kerf_mjto::CutRequest;
use kerf_msgs::msg::CutPlan;
use ros2_client::ServiceMapping;

#[allow(dead_code)] // shared with the other end-to-end tests
mod support;
use support::{assert_clean_exit, expect, interrupt, planner::mjto, Lines, PlannerClient, QUICK};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

fn case1() -> CutRequest {
    let path = Path::new(ROOT).join("crates/mjto/cases/case1.yaml");
    CutRequest::from_yaml(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Case 1 with the largest GFD grid and an RTO every 2 cm: the RTO selection alone runs for
/// more than a minute (87 s measured in the test profile).
fn long_request(id: &str) -> CutRequest {
    let mut r = case1();
    r.request_id = id.into();
    r.options.gfd.q4_steps = 25;
    r.options.gfd.q5_steps = 25;
    r.options.gfd.q6_steps = 15;
    r.options.rto_indices.clear();
    r.options.rto_spacing = 0.02;
    r
}

fn text(r: &CutRequest) -> String {
    serde_yaml_ng::to_string(r).unwrap()
}

#[test]
fn timeouts_and_refusals_before_planning() {
    let env = support::loopback(66, ServiceMapping::Enhanced);
    let planner = PlannerClient::start(&mjto(), &env, &["-p", "plan_timeout:=1.5"]);

    planner.send_text(&text(&long_request("over-plan-timeout")));
    let mut asks_more = case1();
    asks_more.request_id = "asks-more".into();
    asks_more.time_budget = 5.0;
    planner.send_text(&text(&asks_more));
    let mut own_budget = long_request("own-budget");
    own_budget.time_budget = 0.2;
    planner.send_text(&text(&own_budget));
    // 0.8 m at 1 mm/s sampled every millisecond: 800 009 points, far over an answer's size.
    let mut huge = case1();
    huge.request_id = "too-many-points".into();
    huge.feedrate = 0.001;
    huge.sample_period = 0.001;
    planner.send_text(&text(&huge));

    let plan = planner.next_plan(QUICK);
    expect(
        &plan,
        "over-plan-timeout",
        CutPlan::TIMEOUT,
        &["time budget of 1.500 s exhausted", "RTO selection"],
    );
    let plan = planner.next_plan(QUICK);
    expect(
        &plan,
        "asks-more",
        CutPlan::INVALID_REQUEST,
        &["time_budget = 5 s", "plan_timeout of 1.5 s"],
    );
    let plan = planner.next_plan(QUICK);
    expect(
        &plan,
        "own-budget",
        CutPlan::TIMEOUT,
        &["time budget of 0.200 s exhausted"],
    );
    let plan = planner.next_plan(QUICK);
    expect(
        &plan,
        "too-many-points",
        CutPlan::INVALID_REQUEST,
        &["before planning", "trajectory points of 6 joints", "6990"],
    );
    planner.assert_running();
    planner.finish();
}

#[test]
fn stopping_mid_plan_cancels_and_answers_it() {
    let env = support::loopback(67, ServiceMapping::Enhanced);
    let planner = PlannerClient::start(&mjto(), &env, &[]);
    planner.send_text(&text(&long_request("cancelled")));
    // Let it get well into the RTO selection.
    std::thread::sleep(Duration::from_secs(3));
    let stop = Instant::now();
    planner.request_stop();
    let plan = planner.next_plan(QUICK);
    expect(
        &plan,
        "cancelled",
        CutPlan::INTERNAL_ERROR,
        &["planning cancelled", "the planner is stopping"],
    );
    while !planner.has_stopped() {
        assert!(
            stop.elapsed() < Duration::from_secs(20),
            "the planner node did not stop (an uncancelled plan runs for over a minute)"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    println!(
        "the planner node stopped {:.3} s after its stop token",
        stop.elapsed().as_secs_f64()
    );
    planner.finish();
}

/// `kerf launch --with-planner` exits cleanly on Ctrl-C while its planner plans.
#[test]
fn ctrl_c_mid_plan_exits_kerf_launch() {
    let kerf = || {
        let mut c = Command::new(env!("CARGO_BIN_EXE_kerf"));
        c.env("ROS_DOMAIN_ID", "68")
            .env("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
            .env_remove("ROS_STATIC_PEERS");
        c
    };
    let mut command = kerf();
    command.args(["launch", "--robot", "laser_cutter", "--with-planner"]);
    let (mut launch, mut lines) = Lines::spawn(command);
    lines.wait_for("serving cut requests", QUICK);
    let file = std::env::temp_dir().join(format!("kerf_deadline_{}.yaml", std::process::id()));
    let data = serde_yaml_ng::to_string(&kerf_msgs::std_msgs::StringMsg {
        data: text(&long_request("ctrl-c")),
    })
    .unwrap();
    std::fs::write(&file, data).unwrap();
    let out = kerf()
        .args(["pub", "/mjto_planner/cut_request_text"])
        .arg(&file)
        .output()
        .expect("run kerf pub");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    lines.wait_for("request 'ctrl-c'", QUICK);
    std::thread::sleep(Duration::from_secs(3));
    let t = Instant::now();
    interrupt(&launch.0);
    assert_clean_exit(&mut launch.0, Duration::from_secs(20));
    println!(
        "kerf launch exited {:.3} s after SIGINT, mid-plan",
        t.elapsed().as_secs_f64()
    );
    let rest = lines.rest();
    assert!(
        rest.iter().any(|l| l.contains("planning cancelled")),
        "the plan in progress was not answered as cancelled:\n{}",
        rest.join("\n")
    );
    std::fs::remove_file(&file).unwrap();
}
