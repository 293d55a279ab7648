//! End to end over DDS (loopback only) for the G-code planner node (issue 14, item 6).
//!
//! * A program sent as text is planned for the laser cutter and answered in both forms; its
//!   trajectory goes planner → executor (trajectory topic remapped) → `/joint_states`, which
//!   follow the plan to its last point, at rest, with SUCCEEDED. The node's answer equals the
//!   library's plan of the same program.
//! * Bad requests — an unsupported code, a point out of the stroke, a NaN or zero tolerance, a
//!   negative limit, both a program and a file, a request for the other machine or an unknown
//!   one, a method that does not exist, a YAML error, an empty text — each get one `GcodePlan` with the right status, a message
//!   naming the cause (and `error_line` for program lines), in arrival order; no trajectory is
//!   published for them and the node keeps serving.
//! * The IRB 6660 node plans a program from a file URI (`package://kerf/...`).
//!
//! Each test runs its own nodes (in this process, own Contexts) on its own domain (75, 76).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::time::{Duration, Instant};

use kerf_budget::Budget;
use kerf_gcodeplan::{plan_request, GcodeRequest, MachineBase, MachineKind};
use kerf_msgs::msg::{self, GcodePlan, TrajectoryStatus};
use ros2_client::ServiceMapping;

#[allow(dead_code)] // shared with the other end-to-end tests
mod support;
use support::{planner::gcode, PlannerClient, QUICK};

/// Waiting for an answer that runs the planner on a busy machine.
const PLANNING: Duration = Duration::from_secs(120);

/// A 20 mm square cut with a rounded corner, then a travel back (mm, F in mm/min).
const PROGRAM: &str = "G21 G90 G17\nM3\nG1 X20 Y0 F3000\nG1 X20 Y15\nG3 X15 Y20 R5\nG1 X0 Y20\nG1 X0 Y0\nM5\nG0 X5 Y5\nM30\n";

/// The YAML text request of `program` (its newlines escaped inside a double-quoted scalar).
fn text_request(id: &str, program: &str) -> String {
    format!(
        "request_id: {id}\nprogram: \"{}\"\n",
        program.replace('\n', "\\n")
    )
}

#[test]
fn a_program_runs_from_planner_through_executor_and_bad_ones_are_answered() {
    // Issue 27: the executor starts where launch_scripts/params/laser_cutter.yaml puts it, and
    // the plan starts there (approach, the program unchanged, retract).
    let home = [0.8, 0.7, 1.5, 0.0, 0.0, -0.05];
    let offline = plan_request(
        &GcodeRequest {
            request_id: "square".into(),
            program: Some(PROGRAM.into()),
            ..GcodeRequest::default()
        },
        &MachineBase::load(MachineKind::LaserCutter).unwrap(),
        &Budget::unlimited(),
    )
    .unwrap();

    let env = support::loopback(75, ServiceMapping::Enhanced);
    let (exec_stop, executor) =
        support::spawn_robot_executor(&env, "laser_cutter", &[support::initial_positions(&home)]);
    let planner = PlannerClient::start_feeding_executor(&gcode(), &env);
    let (watch, states, statuses) = support::watch_cell(&env, "gcode_watch", &home);
    std::thread::sleep(Duration::from_millis(500));

    planner.send_text(&text_request("square", PROGRAM));
    let plan = planner.expect_in_both_forms(PLANNING, "square", GcodePlan::SUCCESS, &["runs"]);
    assert_eq!(plan.machine, "laser-cutter");
    assert_eq!(plan.method, "kerf");
    assert_eq!(
        plan.trajectory.joint_names,
        ["q1", "q2", "q3", "q4", "q5", "q6"]
    );
    let s = &plan.stretches;
    assert_eq!(s.start, "current", "{s:?}");
    assert_eq!(plan.trajectory.points[0].positions, home);
    let at = plan
        .trajectory
        .points
        .iter()
        .position(|p| (p.time_from_start.as_secs_f64() - s.process_start_time).abs() < 1e-9)
        .expect("a point at process_start_time");
    assert!(plan.trajectory.points.len() > at + offline.trajectory.points.len());
    for (a, b) in plan.trajectory.points[at..]
        .iter()
        .zip(&offline.trajectory.points)
    {
        assert!(
            (a.time_from_start.as_secs_f64() - s.process_start_time - b.time_from_start).abs()
                < 1e-6
        );
        assert_eq!(a.positions, b.positions, "the node's plan is the library's");
    }
    let last = plan.trajectory.points.last().unwrap().positions.clone();
    assert_eq!(plan.arcs, 1);
    assert_eq!(plan.cut_runs, 1);
    let switches: Vec<(bool, u32)> = plan
        .tool_events
        .iter()
        .map(|e| (e.tool_on, e.line))
        .collect();
    assert_eq!(switches, [(true, 2), (false, 8)]);
    assert!(plan.lower_bound_time > 0.0 && plan.feed_time >= plan.lower_bound_time);
    assert!(plan.max_interpolation_deviation <= 0.1 * plan.tolerance);
    assert!(plan.max_corner_deviation <= 0.7 * plan.tolerance + 1e-15);

    // The executor runs it to its end.
    let deadline = Instant::now() + PLANNING;
    let mut succeeded = false;
    let mut moved = 0.0_f64;
    while Instant::now() < deadline && !succeeded {
        succeeded |=
            support::drain_statuses(&statuses, "square").contains(&TrajectoryStatus::SUCCEEDED);
        while let Ok(Some((s, _))) = states.take() {
            moved = moved.max((s.position[0] - home[0]).abs());
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(succeeded, "the executor did not finish the program");
    assert!(moved > 0.019, "q1 moved only {moved} m");
    support::assert_rests_at(&states, &last, 1e-6, "square");

    // Bad requests, one answer each, in order; nothing published.
    let bad: [(&str, String, u8, &[&str]); 9] = [
        (
            "g93",
            text_request("g93", "G21\nG1 X1 F100\nG93 X2\n"),
            GcodePlan::PROGRAM_ERROR,
            &["line 3", "G93"],
        ),
        (
            "far",
            text_request("far", "G1 X100 F1000\nG1 X1500\n"),
            GcodePlan::UNREACHABLE,
            &["line 2", "q1"],
        ),
        (
            "both",
            "request_id: both\nprogram: \"G1 X1 F100\"\nprogram_file: /nonexistent.ngc\n".into(),
            GcodePlan::INVALID_REQUEST,
            &["not both"],
        ),
        (
            "other",
            "request_id: other\nmachine: irb6660\nprogram: \"G1 X1 F100\"\n".into(),
            GcodePlan::INVALID_REQUEST,
            &["plans for laser-cutter"],
        ),
        (
            "method",
            "request_id: method\nmethod: spline\nprogram: \"G1 X1 F100\"\n".into(),
            GcodePlan::INVALID_REQUEST,
            &["method 'spline'", "kerf, kerf-curvature, icr, ccr, nurbs"],
        ),
        (
            "drill",
            "request_id: drill\nmachine: drill\nprogram: \"G1 X1 F100\"\n".into(),
            GcodePlan::INVALID_REQUEST,
            &["machine 'drill'", "laser-cutter or irb6660"],
        ),
        (
            "zero-tolerance",
            "request_id: zero-tolerance\ntolerance: 0.0\nprogram: \"G1 X1 F100\"\n".into(),
            GcodePlan::INVALID_REQUEST,
            &["tolerance", "must be finite and > 0"],
        ),
        (
            "negative-jerk",
            "request_id: negative-jerk\nlimits: {tangential_jerk: -1.0}\nprogram: \"G1 X1 F100\"\n"
                .into(),
            GcodePlan::INVALID_REQUEST,
            &["tangential", "jerk"],
        ),
        (
            "yaml",
            "request_id: yaml\nprogram: [1, 2]\n".into(),
            GcodePlan::INVALID_REQUEST,
            &["request", "line 2"],
        ),
    ];
    for (_, text, _, _) in &bad {
        planner.send_text(text);
    }
    for (id, _, status, needles) in &bad {
        let answer = planner.expect_in_both_forms(PLANNING, id, *status, needles);
        if *id == "g93" {
            assert_eq!(answer.error_line, 3);
        }
        if *id == "far" {
            assert_eq!(answer.error_line, 2);
        }
    }
    planner.send_text("  ");
    planner.expect_in_both_forms(QUICK, "", GcodePlan::INVALID_REQUEST, &["empty"]);
    // The message form: a NaN tolerance names the field.
    planner.send(msg::GcodeRequest {
        request_id: "nan".into(),
        program: "G1 X1 F100".into(),
        tolerance: f64::NAN,
        ..msg::GcodeRequest::default()
    });
    planner.expect_in_both_forms(QUICK, "nan", GcodePlan::INVALID_REQUEST, &["tolerance"]);
    // No trajectory reached the executor for a failure: it reports nothing new.
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(
        support::drain_statuses(&statuses, "bad requests"),
        Vec::<u8>::new()
    );
    planner.assert_running();

    planner.finish();
    drop((states, statuses, watch));
    exec_stop.stop();
    executor.join().unwrap().unwrap();
}

#[test]
fn the_irb6660_node_plans_a_shipped_program_file() {
    let env = support::loopback(76, ServiceMapping::Enhanced);
    let planner = PlannerClient::start(&gcode(), &env, &["-p", "machine:=irb6660"]);
    planner.send(msg::GcodeRequest {
        request_id: "w".into(),
        machine: msg::GcodeRequest::MACHINE_IRB6660.into(),
        program_uri: "package://kerf/crates/gcode/data/programs/w_shape.ngc".into(),
        has_placement: true,
        origin: kerf_msgs::geometry_msgs::Point {
            x: 1.4,
            y: -0.3,
            z: 1.7,
        },
        redundancy_angle: 0.3,
        ..msg::GcodeRequest::default()
    });
    let plan = planner.expect_in_both_forms(PLANNING, "w", GcodePlan::SUCCESS, &["runs"]);
    assert_eq!(plan.machine, "irb6660");
    assert_eq!(
        plan.trajectory.joint_names,
        ["joint_1", "joint_2", "joint_3", "joint_4", "joint_5", "joint_6"]
    );
    assert!(plan.lines > 10 && plan.corners >= 3);
    assert_eq!(planner.trajectories_received(), 1);
    // A program file that does not exist.
    planner.send(msg::GcodeRequest {
        request_id: "missing".into(),
        machine: msg::GcodeRequest::MACHINE_IRB6660.into(),
        program_uri: "/nonexistent/part.ngc".into(),
        ..msg::GcodeRequest::default()
    });
    planner.expect_in_both_forms(
        PLANNING,
        "missing",
        GcodePlan::INVALID_REQUEST,
        &["part.ngc"],
    );
    planner.finish();
}
