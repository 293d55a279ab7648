//! The harness's job function with the milling service: already-answered jobs pass through, jobs queued when the node
//! stops are answered without planning, and `ddpg` / `fixed_g` requests without a policy file
//! get the node's default policy (a missing one is that request's POLICY_ERROR, naming it).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::sync::OnceLock;
use std::time::Duration;

use kerf_budget::CancelToken;

use kerf_milling_planner::{convert, DefaultPolicies, MillService};
use kerf_millplan::{MillPlanner, MillRequest};
use kerf_msgs::msg::MillPlan;
use kerf_ros::planner::{work, Job};

/// The node's default `plan_timeout`.
const TIMEOUT: Duration = Duration::from_secs(60);

fn service() -> &'static MillService {
    static S: OnceLock<MillService> = OnceLock::new();
    S.get_or_init(|| {
        let planner = MillPlanner::with_default_cell().expect("planner");
        MillService::new(planner, policies(), String::new()).expect("service")
    })
}

fn policies() -> DefaultPolicies {
    DefaultPolicies {
        ddpg: "/nonexistent/default_ddpg.safetensors".into(),
        fixed_g: "/nonexistent/default_fixed_g.safetensors".into(),
    }
}

fn request(id: &str, planner: &str, policy_file: Option<&str>) -> Box<MillRequest> {
    Box::new(MillRequest {
        request_id: id.into(),
        planner: planner.into(),
        policy_file: policy_file.map(String::from),
        ..MillRequest::default()
    })
}

#[test]
fn answers_pass_through_and_stopping_skips_planning() {
    let stopping = CancelToken::new();
    let failed = convert::failure_msg("w1", "dp", MillPlan::POLICY_ERROR, "gone");
    let m = work(
        service(),
        &stopping,
        TIMEOUT,
        Job::Answer(Box::new(failed.clone())),
    );
    assert_eq!(m, failed);
    stopping.cancel();
    let m = work(
        service(),
        &stopping,
        TIMEOUT,
        Job::Plan(request("w2", "naive", None)),
    );
    assert_eq!(m.status, MillPlan::INTERNAL_ERROR);
    assert_eq!((m.request_id.as_str(), m.planner.as_str()), ("w2", "naive"));
    assert!(
        m.message.contains("stopped before planning"),
        "{}",
        m.message
    );
}

#[test]
fn default_policies_fill_requests_without_one() {
    let stopping = CancelToken::new();
    for (planner_name, default) in [
        ("ddpg", "/nonexistent/default_ddpg.safetensors"),
        ("fixed_g", "/nonexistent/default_fixed_g.safetensors"),
    ] {
        let m = work(
            service(),
            &stopping,
            TIMEOUT,
            Job::Plan(request("p1", planner_name, None)),
        );
        assert_eq!(m.status, MillPlan::POLICY_ERROR, "{}", m.message);
        assert_eq!(m.planner, planner_name);
        assert!(
            m.message.contains(default) && m.message.contains("not found"),
            "{}",
            m.message
        );
        // The request's own file wins over the default.
        let m = work(
            service(),
            &stopping,
            TIMEOUT,
            Job::Plan(request(
                "p2",
                planner_name,
                Some("/elsewhere/mine.safetensors"),
            )),
        );
        assert_eq!(m.status, MillPlan::POLICY_ERROR);
        assert!(
            m.message.contains("/elsewhere/mine.safetensors"),
            "{}",
            m.message
        );
    }
    // Planners without a policy are planned as they are.
    let m = work(
        service(),
        &stopping,
        TIMEOUT,
        Job::Plan(request("p3", "naive", None)),
    );
    assert_eq!(m.status, MillPlan::SUCCESS, "{}", m.message);
    assert_eq!((m.request_id.as_str(), m.planner.as_str()), ("p3", "naive"));
    assert_eq!(m.segments.len(), 100);
}

#[test]
fn a_plan_over_its_budget_is_timeout_and_the_next_one_is_planned() {
    let cancel = CancelToken::new();
    // The node's budget runs out …
    let m = work(
        service(),
        &cancel,
        Duration::from_nanos(1),
        Job::Plan(request("t1", "naive", None)),
    );
    assert_eq!(m.status, MillPlan::TIMEOUT, "{}", m.message);
    assert_eq!((m.request_id.as_str(), m.planner.as_str()), ("t1", "naive"));
    assert!(m.message.contains("time budget"), "{}", m.message);
    // … or the request's own, smaller one.
    let mut own = request("t2", "naive", None);
    own.time_budget = Some(1e-9);
    let m = work(service(), &cancel, TIMEOUT, Job::Plan(own));
    assert_eq!(m.status, MillPlan::TIMEOUT, "{}", m.message);
    // The worker is free: the next request is planned.
    let m = work(
        service(),
        &cancel,
        TIMEOUT,
        Job::Plan(request("t3", "naive", None)),
    );
    assert_eq!(m.status, MillPlan::SUCCESS, "{}", m.message);
}
