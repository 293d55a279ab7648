//! Every plan starts where the robot is (issue 27): a 20 mm G-code square framed by the
//! planner-node harness from a given start on each machine — the laser cutter over the sheet
//! under the program, the IRB 6660 in its shipped collision cell
//! (`urdf/cells/irb6660_plate.yaml`); a start in the sheet or the stock and a start of the
//! wrong length are refused by name.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

#[path = "../../milling_planner/tests/common/framed.rs"]
mod framed;

use std::sync::OnceLock;

use kerf_approach::{FrameSettings, StartSpec};
use kerf_budget::Budget;
use kerf_gcode_planner::GcodeService;
use kerf_gcodeplan::{GcodeRequest, MachineBase, MachineKind};
use kerf_msgs::msg::GcodePlan;
use kerf_ros::planner::{plan_checked, PlanningService};

/// A 20 mm square, cut.
const SQUARE: &str = "G21 G90\nM3\nG1 X20 F3000\nG1 Y20\nG1 X0\nG1 Y0\nM5\n";

/// The executors' start poses: `launch_scripts/params/laser_cutter.yaml` (gantry mid-travel,
/// M 1 m above the sheet) and `launch_scripts/params/irb6660.yaml` (all joints 0).
const LASER_HOME: [f64; 6] = [0.8, 0.7, 1.5, 0.0, 0.0, -0.05];
const IRB_HOME: [f64; 6] = [0.0; 6];

fn service(kind: MachineKind) -> &'static GcodeService {
    static LASER: OnceLock<GcodeService> = OnceLock::new();
    static IRB: OnceLock<GcodeService> = OnceLock::new();
    let cell = match kind {
        MachineKind::LaserCutter => &LASER,
        MachineKind::Irb6660 => &IRB,
    };
    cell.get_or_init(|| GcodeService::new(MachineBase::load(kind).unwrap()).unwrap())
}

fn request(kind: MachineKind, start: StartSpec) -> GcodeRequest {
    GcodeRequest {
        request_id: format!("square-{}", kind.name()),
        machine: kind.name().into(),
        program: Some(SQUARE.into()),
        start,
        ..GcodeRequest::default()
    }
}

fn plan(kind: MachineKind, start: StartSpec) -> GcodePlan {
    plan_checked(
        service(kind),
        request(kind, start),
        &Budget::unlimited(),
        &FrameSettings::default(),
        None,
    )
}

fn unframed(kind: MachineKind) -> GcodePlan {
    let m = plan(kind, StartSpec::None);
    assert_eq!(m.status, GcodePlan::SUCCESS, "{}", m.message);
    assert_eq!(m.stretches.start, "none");
    m
}

/// Frames the square from `start` and checks it ([`framed::check_framed`]).
fn framed_from(kind: MachineKind, start: &[f64]) -> framed::Measured {
    let process = unframed(kind);
    let m = plan(kind, StartSpec::Given(start.to_vec()));
    assert_eq!(m.status, GcodePlan::SUCCESS, "{}", m.message);
    let world = service(kind)
        .surroundings(&request(kind, StartSpec::None))
        .unwrap();
    let measured = framed::check_framed(
        &m.trajectory,
        &m.stretches,
        &process.trajectory,
        start,
        world.as_ref(),
        &FrameSettings::default(),
    );
    println!(
        "{}: approach {:.3} s ({}), lead-in {:.3} s, clearance {:.4} m at 1 ms (certified \
         {:.4} m), lead {:.5} m; start {:?}",
        kind.name(),
        measured.approach,
        m.stretches.approach_route,
        measured.lead_in,
        measured.approach_clearance,
        m.stretches.min_clearance,
        measured.lead_clearance,
        world.clearance(start, false)
    );
    measured
}

#[test]
fn a_square_on_the_laser_cutter_is_framed_from_its_home_pose() {
    let m = framed_from(MachineKind::LaserCutter, &LASER_HOME);
    assert!(m.approach > 0.0 && m.lead_in > 0.0);
}

#[test]
fn a_square_on_the_irb6660_is_framed_from_its_home_pose() {
    let m = framed_from(MachineKind::Irb6660, &IRB_HOME);
    assert!(m.approach > 0.0 && m.lead_in > 0.0);
}

#[test]
fn a_start_in_the_sheet_or_the_stock_has_no_approach_naming_it() {
    // The laser nozzle pushed 5 mm down from the square's first point: through the sheet.
    let mut q = unframed(MachineKind::LaserCutter).trajectory.points[0]
        .positions
        .clone();
    q[2] -= 0.005;
    let m = plan(MachineKind::LaserCutter, StartSpec::Given(q));
    assert_eq!(m.status, GcodePlan::NO_APPROACH, "{}", m.message);
    assert!(m.message.contains("sheet"), "{}", m.message);
    assert!(m.trajectory.points.is_empty());
    // The IRB 6660 at the square's first point: the cutter 3 mm deep in the stock.
    let q = unframed(MachineKind::Irb6660).trajectory.points[0]
        .positions
        .clone();
    let m = plan(MachineKind::Irb6660, StartSpec::Given(q));
    assert_eq!(m.status, GcodePlan::NO_APPROACH, "{}", m.message);
    assert!(
        m.message.contains("stock (cutter on tool0)"),
        "{}",
        m.message
    );
    assert_eq!(m.request_id, "square-irb6660");
}

#[test]
fn a_start_of_the_wrong_length_is_an_invalid_request_naming_start_positions() {
    for kind in [MachineKind::LaserCutter, MachineKind::Irb6660] {
        let m = plan(kind, StartSpec::Given(vec![0.5; 5]));
        assert_eq!(m.status, GcodePlan::INVALID_REQUEST, "{}", m.message);
        assert!(m.message.contains("start_positions"), "{}", m.message);
    }
}
