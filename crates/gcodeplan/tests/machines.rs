//! Programs planned for both machines and checked independently of the
//! planner: the executor's own validation and interpolation at its control
//! period, the tool tip by the URDF's forward kinematics, its exact distance
//! from the programmed lines and arcs, and every joint's velocity,
//! acceleration and jerk by central differences.
#![allow(clippy::unwrap_used)]

mod support;

use kerf_budget::Budget;
use kerf_gcodeplan::{plan_program, LaserSheet, Machine, MillingPlane, PlanSettings, RunKind};
use nalgebra::Isometry3;
use support::{difference_ratios, distance, execute, shapes, tips};

/// A square with a rounded corner (G3, IJK), a travel move with the beam
/// off, a dwell, a second contour (G2, R form) and the end.
const PROGRAM: &str = "\
(two contours)
G21 G90 G17
G0 X0 Y0
M3 S1000
G1 X20 Y0 F3000
G1 X20 Y15
G3 X15 Y20 I-5 J0
G1 X0 Y20
G1 X0 Y0
M5
G0 X30 Y0
G4 P0.25
M3
G1 X40 Y0 F1500
G2 X50 Y10 R10
G1 X30 Y10
G1 X30 Y0
M5
M30
";

/// Checks the plan as the robot runs it; returns the worst distance.
fn check(
    machine: &dyn Machine,
    plan: &kerf_gcodeplan::GcodePlan,
    tcp: &Isometry3<f64>,
    to_program: impl Fn([f64; 3]) -> [f64; 3],
) -> f64 {
    let robot = machine.robot();
    let executed = execute(robot, plan);
    let geometry = shapes(PROGRAM);
    let tip = tips(robot, &executed, tcp, to_program);
    let worst = tip
        .iter()
        .map(|p| distance(&geometry, *p))
        .fold(0.0, f64::max);
    assert!(
        worst <= plan.tolerance,
        "{}: the executed tip is {worst:.3e} m from the program (tolerance {:.1e})",
        machine.name(),
        plan.tolerance
    );
    for (j, r) in difference_ratios(robot, &executed).iter().enumerate() {
        // Differences of an exact quintic at 4 ms stay within its exact peaks,
        // up to the differences' own truncation (1 % here).
        for (k, what) in ["velocity", "acceleration", "jerk"].iter().enumerate() {
            assert!(
                r[k] <= 1.01,
                "{}: joint {j} {what} at {:.3} of its limit",
                machine.name(),
                r[k]
            );
        }
    }
    for (j, r) in plan.peak_ratios.iter().enumerate() {
        assert!(
            r.iter().all(|v| *v <= 1.0 + 1e-6),
            "joint {j}: exact peaks {r:?}"
        );
    }
    // From rest to rest.
    let first = &plan.trajectory.points[0];
    let last = plan.trajectory.points.last().unwrap();
    assert!(first
        .velocities
        .iter()
        .chain(&last.velocities)
        .all(|v| *v == 0.0));
    assert!(plan.max_interpolation_deviation <= 0.1 * plan.tolerance);
    worst
}

#[test]
fn laser_cutter_cuts_both_contours_within_the_tolerance() {
    let laser = LaserSheet::default_sheet().unwrap();
    let settings = PlanSettings::laser_cutter();
    let plan = plan_program(PROGRAM.as_bytes(), &laser, &settings, &Budget::unlimited()).unwrap();
    // Runs: rapid to the start is of zero length; cut, rapid, cut.
    let kinds: Vec<RunKind> = plan.runs.iter().map(|r| r.kind).collect();
    assert_eq!(kinds, [RunKind::Cut, RunKind::Rapid, RunKind::Cut]);
    assert_eq!(plan.zero_length_moves, 1);
    assert_eq!(plan.arcs, 2);
    // Beam on before each cut, off after, at the runs' ends.
    let on: Vec<(bool, usize)> = plan.events.iter().map(|e| (e.on, e.line)).collect();
    assert_eq!(on, [(true, 4), (false, 10), (true, 13), (false, 18)]);
    assert_eq!(plan.events[1].time, plan.runs[1].start_time);
    assert!((plan.dwell_time - 0.25).abs() < 1e-12);
    // q3..q6 never move: a flat sheet with a vertical beam.
    for p in &plan.trajectory.points {
        assert_eq!(&p.positions[3..], &[0.0, 0.0, -0.08]);
        assert!((p.positions[2] - 0.58).abs() < 1e-12);
    }
    // Every run's feed plan holds every path limit on its output at the interpolation period,
    // checked here independently of the planner's own check.
    for (report, timed) in plan.runs.iter().zip(&plan.timed) {
        let mut limits = settings.limits;
        limits.curvature.feed = report.feed;
        let check = kerf_toolpath::check_plan(
            &timed.path,
            &timed.samples,
            &timed.plan,
            &kerf_toolpath::FeedConstraints::new(limits),
            limits.curvature.interpolation_period,
        )
        .unwrap();
        assert!(
            check.holds(1e-6),
            "lines {:?}: {:?}",
            report.lines,
            check.worst()
        );
    }
    let origin = laser.origin();
    let worst = check(&laser, &plan, &Isometry3::identity(), |p| {
        [p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]]
    });
    // The corners use most of the tolerance: the check can see a violation.
    assert!(worst > 0.3 * plan.tolerance, "worst {worst:.3e}");
    assert!(plan.lower_bound > 0.0 && plan.path_time >= plan.lower_bound);
    assert!(plan.feed_time >= plan.lower_bound);
}

#[test]
fn irb6660_mills_both_contours_within_the_tolerance() {
    let plane = MillingPlane::default_plane(0.3).unwrap();
    // The default cell's plane is horizontal with the tool pointing down:
    // the program frame is the base frame moved to the origin.
    let approach = plane.cell().path().approach();
    assert!((approach.z + 1.0).abs() < 1e-9, "approach {approach:?}");
    let settings = PlanSettings::irb6660();
    let plan = plan_program(PROGRAM.as_bytes(), &plane, &settings, &Budget::unlimited()).unwrap();
    assert_eq!(plan.runs.len(), 3);
    let origin = plane.origin();
    let tcp = *plane.cell().kinematics().tcp();
    let worst = check(&plane, &plan, &tcp, |p| {
        [p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]]
    });
    assert!(worst > 0.3 * plan.tolerance, "worst {worst:.3e}");
}
