//! Time budgets and cancellation of `MillPlanner::plan_within` (issue 11, item 3): a plan that
//! runs out of its budget ends with TIMEOUT naming the stage, a cancelled DP ends promptly with
//! a cancellation, and the planner plans again afterwards.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::time::Duration;

use kerf_budget::{Budget, CancelToken, Interrupt};
use kerf_millplan::{status, status_of, MillPlanError, MillPlanner, MillRequest};

fn planner() -> MillPlanner {
    MillPlanner::with_default_cell().expect("planner")
}

#[test]
fn the_requests_own_budget_ends_the_plan_with_timeout() {
    let request = MillRequest {
        time_budget: Some(1e-6),
        ..MillRequest::default()
    };
    let e = planner().plan(&request).unwrap_err();
    assert_eq!(status_of(&e), status::TIMEOUT, "{e}");
    let text = e.to_string();
    assert!(text.contains("time budget of 0.000 s exhausted"), "{text}");
    // A request may ask for less than the caller, never more.
    let request = MillRequest {
        time_budget: Some(3600.0),
        ..MillRequest::default()
    };
    let spent = Budget::new(Some(Duration::ZERO), CancelToken::new());
    std::thread::sleep(Duration::from_millis(2));
    let e = planner().plan_within(&request, &spent).unwrap_err();
    assert_eq!(status_of(&e), status::TIMEOUT, "{e}");
}

#[test]
fn bad_time_budgets_are_invalid_requests() {
    for bad in [-1.0, f64::NAN, f64::INFINITY, 1e9] {
        let request = MillRequest {
            time_budget: Some(bad),
            ..MillRequest::default()
        };
        let e = planner().plan(&request).unwrap_err();
        assert_eq!(status_of(&e), status::INVALID_REQUEST, "{bad}: {e}");
        assert!(e.to_string().contains("time_budget"), "{e}");
    }
}

#[test]
fn a_cancelled_dp_stops_and_the_planner_plans_again() {
    let planner = planner();
    if planner.cache().is_none() {
        // The DP needs the shipped indicator cache (present in the repository).
        panic!("the default cell's indicator cache did not load");
    }
    let request = MillRequest {
        planner: "dp".to_string(),
        ..MillRequest::default()
    };
    let token = CancelToken::new();
    let budget = Budget::new(None, token.clone());
    let canceller = {
        let token = token.clone();
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(150));
            token.cancel();
        })
    };
    let e = planner.plan_within(&request, &budget).unwrap_err();
    canceller.join().unwrap();
    assert!(
        matches!(e, MillPlanError::Interrupted(Interrupt::Cancelled { .. })),
        "{e}"
    );
    assert_eq!(status_of(&e), status::INTERNAL_ERROR);
    let naive = MillRequest {
        planner: "naive".to_string(),
        ..MillRequest::default()
    };
    planner.plan(&naive).expect("the next plan");
}
