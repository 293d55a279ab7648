//! Issue 33: a spindle speed range of 1e308 rpm panicked the milling planner ("capacity
//! overflow" collecting the per-path grid). The grids now count their nodes before allocating
//! and refuse the range with an error.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_mill::MillCell;
use kerf_millplan::path_cache::path_grid;
use kerf_millplan::request::RequestLimits;
use kerf_millplan::{status, status_of, MillPlanner, MillRequest};

fn huge_spindle_cell() -> MillCell {
    let cell = MillCell::default_cell().unwrap();
    let mut limits = *cell.state_limits();
    limits.spindle_rpm = [2000.0, 1e308];
    cell.with_state_limits(limits).unwrap()
}

#[test]
fn a_huge_spindle_range_is_refused_by_the_per_path_grid() {
    let e = path_grid(&huge_spindle_cell(), 0.0).unwrap_err();
    assert!(e.to_string().contains("spindle speed"), "{e}");
}

#[test]
fn a_huge_spindle_range_is_refused_by_every_planner_without_panicking() {
    let planner = MillPlanner::with_default_cell().unwrap();
    // The planners that build a per-path cache over the range (the shipped cache does not
    // cover it).
    for name in ["dp", "naive"] {
        let request = MillRequest {
            planner: name.to_string(),
            segments: Some(4),
            limits: Some(RequestLimits {
                spindle_rpm: Some([2000.0, 1e308]),
                ..RequestLimits::default()
            }),
            time_budget: Some(20.0),
            ..MillRequest::default()
        };
        let Err(e) = planner.plan(&request) else {
            panic!("{name}: planned over a spindle range of 1e308 rpm");
        };
        assert_eq!(status_of(&e), status::INVALID_REQUEST, "{name}: {e}");
    }
}
