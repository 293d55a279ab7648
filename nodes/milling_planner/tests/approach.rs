//! Every plan starts where the robot is (issue 27): the README's mill request framed by the
//! planner-node harness from a given start, against the shipped collision cell
//! (`urdf/cells/irb6660_plate.yaml`); a start in the stock and a start of the wrong length are
//! refused by name.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

#[path = "common/framed.rs"]
mod framed;

use std::sync::OnceLock;

use kerf_approach::{FrameSettings, StartSpec};
use kerf_budget::Budget;
use kerf_milling_planner::{DefaultPolicies, MillService};
use kerf_millplan::{MillPlanner, MillRequest};
use kerf_msgs::msg::MillPlan;
use kerf_ros::planner::{plan_checked, PlanningService};

/// The executor's start pose of `launch_scripts/params/irb6660.yaml` (all joints 0): the tool
/// tip about 0.37 m above the stock.
const HOME: [f64; 6] = [0.0; 6];

fn service() -> &'static MillService {
    static S: OnceLock<MillService> = OnceLock::new();
    S.get_or_init(|| {
        let planner = MillPlanner::with_default_cell().expect("planner");
        let policies = DefaultPolicies {
            ddpg: "/nonexistent/ddpg.safetensors".into(),
            fixed_g: "/nonexistent/fixed_g.safetensors".into(),
        };
        MillService::new(planner, policies, String::new()).expect("service")
    })
}

/// The README's request: the naive planner on the seed-004 path (1.4, −0.3, 1.7) …
/// (2.1, 0.3, 1.7) m.
fn request(start: StartSpec) -> MillRequest {
    MillRequest {
        request_id: "approach".into(),
        planner: "naive".into(),
        start,
        ..MillRequest::default()
    }
}

fn plan(start: StartSpec) -> MillPlan {
    plan_checked(
        service(),
        request(start),
        &Budget::unlimited(),
        &FrameSettings::default(),
        None,
    )
}

fn unframed() -> &'static MillPlan {
    static P: OnceLock<MillPlan> = OnceLock::new();
    P.get_or_init(|| {
        let m = plan(StartSpec::None);
        assert_eq!(m.status, MillPlan::SUCCESS, "{}", m.message);
        assert_eq!(m.stretches.start, "none");
        m
    })
}

#[test]
fn the_readme_request_is_framed_from_the_home_pose() {
    let process = unframed();
    let m = plan(StartSpec::Given(HOME.to_vec()));
    assert_eq!(m.status, MillPlan::SUCCESS, "{}", m.message);
    let world = service().surroundings(&request(StartSpec::None)).unwrap();
    let measured = framed::check_framed(
        &m.trajectory,
        &m.stretches,
        &process.trajectory,
        &HOME,
        world.as_ref(),
        &FrameSettings::default(),
    );
    println!(
        "mill: approach {:.3} s ({}), lead-in {:.3} s, clearance {:.4} m at 1 ms (certified \
         {:.4} m), lead {:.5} m; start {:?}",
        measured.approach,
        m.stretches.approach_route,
        measured.lead_in,
        measured.approach_clearance,
        m.stretches.min_clearance,
        measured.lead_clearance,
        world.clearance(&HOME, false)
    );
    assert!(measured.approach > 0.0 && measured.lead_in > 0.0);
}

#[test]
fn a_start_in_the_stock_has_no_approach_naming_it() {
    // The path's first configuration: the cutter 3 mm deep in the stock.
    let inside = unframed().trajectory.points[0].positions.clone();
    let m = plan(StartSpec::Given(inside));
    assert_eq!(m.status, MillPlan::NO_APPROACH, "{}", m.message);
    assert!(
        m.message.contains("stock (cutter on tool0)"),
        "{}",
        m.message
    );
    assert_eq!(
        (m.request_id.as_str(), m.planner.as_str()),
        ("approach", "naive")
    );
    assert!(m.trajectory.points.is_empty());
}

#[test]
fn a_start_of_the_wrong_length_is_an_invalid_request_naming_start_positions() {
    let m = plan(StartSpec::Given(vec![0.0; 5]));
    assert_eq!(m.status, MillPlan::INVALID_REQUEST, "{}", m.message);
    assert!(m.message.contains("start_positions"), "{}", m.message);
}
