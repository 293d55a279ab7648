//! Time budgets and cancellation of `Planner::plan_within` (issue 11, item 3): a plan that
//! runs out of its budget ends with TIMEOUT naming the stage, a cancelled plan ends promptly
//! with a cancellation, and the planner plans again afterwards.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::case;

use std::time::Duration;

use kerf_budget::{Budget, CancelToken, Interrupt};
use kerf_mjto::error::status;
use kerf_mjto::planner::Planner;
use kerf_mjto::{LaserMachine, PlanError};

fn planner() -> Planner {
    Planner::new(LaserMachine::default_machine().unwrap()).unwrap()
}

#[test]
fn the_requests_own_budget_ends_the_plan_with_timeout() {
    let mut request = case("case1");
    request.time_budget = 1e-6;
    let e = planner().plan(&request).unwrap_err();
    assert_eq!(e.status(), status::TIMEOUT, "{e}");
    let text = e.to_string();
    assert!(text.contains("time budget of 0.000 s exhausted"), "{text}");
    assert!(text.contains("during "), "{text}");
}

#[test]
fn a_node_budget_is_tightened_by_the_request_never_widened() {
    let mut request = case("case1");
    request.time_budget = 3600.0;
    // The caller's (node's) budget is already spent: the request's larger one does not help.
    let budget = Budget::new(Some(Duration::ZERO), CancelToken::new());
    std::thread::sleep(Duration::from_millis(2));
    let e = planner().plan_within(&request, &budget).unwrap_err();
    match e {
        PlanError::Interrupted(Interrupt::TimedOut { budget, .. }) => {
            assert_eq!(budget, Duration::ZERO)
        }
        other => panic!("expected a timeout, got {other}"),
    }
}

#[test]
fn bad_time_budgets_are_invalid_requests() {
    for bad in [-1.0, f64::NAN, f64::INFINITY, 1e9] {
        let mut request = case("case1");
        request.time_budget = bad;
        let e = planner().plan(&request).unwrap_err();
        assert_eq!(e.status(), status::INVALID_REQUEST, "{bad}: {e}");
        assert!(e.to_string().contains("time_budget"), "{e}");
    }
}

#[test]
fn a_cancelled_plan_stops_and_the_planner_plans_again() {
    // The largest accepted GFD grid: a long plan (RTO selection over 10⁴ candidates per RTO).
    let mut request = case("case1");
    request.options.gfd.q4_steps = 25;
    request.options.gfd.q5_steps = 25;
    request.options.gfd.q6_steps = 15;
    let token = CancelToken::new();
    let budget = Budget::new(None, token.clone());
    let canceller = {
        let token = token.clone();
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(100));
            token.cancel();
        })
    };
    let mut planner = planner();
    let e = planner.plan_within(&request, &budget).unwrap_err();
    canceller.join().unwrap();
    assert!(
        matches!(e, PlanError::Interrupted(Interrupt::Cancelled { .. })),
        "{e}"
    );
    assert_eq!(e.status(), status::INTERNAL_ERROR);
    // The same planner (its mesh cache) serves the next request.
    let mut short = case("case1");
    short.time_budget = 1e-6;
    assert_eq!(planner.plan(&short).unwrap_err().status(), status::TIMEOUT);
}
