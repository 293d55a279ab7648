//! Issue 27, item 1, on the MJTO planning service without DDS: case 1 planned from where the
//! robot is (the shipped executor's start pose) through the harness's `plan_checked`. The
//! answer's trajectory starts at the robot, carries the offline plan unchanged in its process
//! stretch, ends at rest backed off along the tool axis, and, re-sampled at 1 ms by the
//! executor's own interpolation, keeps the approach clearance by exact distance outside the
//! lead moves. Starts in the part, out of limits or of the wrong size are refused by name.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::time::Duration;

use kerf_approach::{FrameSettings, StartSpec, Surroundings};
use kerf_budget::{Budget, CancelToken};
use kerf_mjto::{planner::Planner, CutRequest, LaserMachine};
use kerf_mjto_planner::{surroundings::LaserSurroundings, CutService};
use kerf_msgs::msg::CutPlan;
use kerf_ros::planner::{plan_checked, start::CurrentState, PlanningService};

/// The laser cutter's start pose in launch_scripts/params/laser_cutter.yaml.
const HOME: [f64; 6] = [0.8, 0.7, 1.5, 0.0, 0.0, -0.05];

fn case1() -> CutRequest {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../crates/mjto/cases/case1.yaml"
    );
    CutRequest::from_yaml(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn service() -> CutService {
    CutService::new(LaserMachine::default_machine().unwrap(), "test".into()).unwrap()
}

fn plan(service: &CutService, request: CutRequest, current: Option<&CurrentState>) -> CutPlan {
    let budget = Budget::new(Some(Duration::from_secs(120)), CancelToken::new());
    plan_checked(
        service,
        request,
        &budget,
        &FrameSettings::default(),
        current,
    )
}

fn robot_at(q: &[f64]) -> CurrentState {
    CurrentState {
        names: (1..=6).map(|i| format!("q{i}")).collect(),
        positions: q.to_vec(),
        velocities: vec![0.0; 6],
        age: 0.01,
        topic: "/joint_states".into(),
    }
}

#[test]
fn case_1_starts_where_the_robot_is_and_ends_backed_off() {
    let service = service();
    let request = case1();
    let offline = Planner::new(LaserMachine::default_machine().unwrap())
        .unwrap()
        .plan(&request)
        .unwrap();
    let robot = robot_at(&HOME);
    let started = std::time::Instant::now();
    let answer = plan(&service, request.clone(), Some(&robot));
    eprintln!("planned with approach in {:?}", started.elapsed());
    assert_eq!(answer.status, CutPlan::SUCCESS, "{}", answer.message);
    let s = &answer.stretches;
    assert_eq!(s.start, "current");
    assert_eq!(s.start_positions, HOME);
    assert_eq!(s.approach_route, "direct");
    assert_eq!(s.retract_route, "tool axis");
    assert!(s.min_clearance >= 0.01, "{s:?}");
    eprintln!("stretches: {s:?}");
    let points = &answer.trajectory.points;
    assert_eq!(points[0].positions, HOME);
    assert_eq!(points[0].time_from_start.as_secs_f64(), 0.0);
    // The process stretch is the offline plan, shifted to process_start_time.
    let at = points
        .iter()
        .position(|p| (p.time_from_start.as_secs_f64() - s.process_start_time).abs() < 1e-9)
        .unwrap();
    for (k, (t, q)) in offline.times.iter().zip(&offline.positions).enumerate() {
        let p = &points[at + k];
        assert!((p.time_from_start.as_secs_f64() - s.process_start_time - t).abs() < 2e-9);
        for (a, b) in p.positions.iter().zip(q) {
            assert!((a - b).abs() < 1e-12, "process point {k} changed");
        }
    }
    let process_end = at + offline.times.len() - 1;
    assert!((points[process_end].time_from_start.as_secs_f64() - s.process_end_time).abs() < 1e-9);
    // Ends at rest, 5 cm back along the tool axis from the last process point.
    let last = points.last().unwrap();
    assert!(last.velocities.iter().all(|v| v.abs() < 1e-9));
    let end = offline.positions.last().unwrap();
    let o = kerf_mjto::kinematics::tool_axis(end[3], end[4]);
    for k in 0..3 {
        assert!((last.positions[k] - (end[k] + 0.05 * o[k])).abs() < 1e-9);
    }
    // As executed: the trajectory re-sampled every 1 ms (quintic between points, the
    // executor's interpolation) keeps the approach clearance before the lead-in starts and
    // after the lead-out ends, by exact distance.
    let world = LaserSurroundings::new(
        &LaserMachine::default_machine().unwrap(),
        service.approach_limits().to_vec(),
        &request,
        &kerf_mjto::mesh::load(&request.mesh).unwrap(),
    )
    .unwrap();
    let lead = FrameSettings::default().lead_distance();
    let retract = FrameSettings::default().retract_distance();
    let mut worst = f64::INFINITY;
    for w in points.windows(2) {
        let (t0, t1) = (
            w[0].time_from_start.as_secs_f64(),
            w[1].time_from_start.as_secs_f64(),
        );
        let in_approach = t1 <= s.process_start_time;
        let in_retract = t0 >= s.process_end_time;
        if !(in_approach || in_retract) {
            continue;
        }
        let steps = ((t1 - t0) / 0.001).ceil() as usize;
        for k in 0..=steps {
            let u = k as f64 / steps as f64;
            let q = quintic(&w[0], &w[1], t1 - t0, u);
            // Outside the lead moves: farther along the tool axis than the lead distance
            // from the process end points (the lead moves are checked with contact left out).
            let anchor = if in_approach {
                &points[at]
            } else {
                &points[process_end]
            };
            let along = (0..3)
                .map(|i| (q[i] - anchor.positions[i]).powi(2))
                .sum::<f64>()
                .sqrt();
            let reach = if in_approach { lead } else { retract };
            if along < reach - 1e-6 {
                continue;
            }
            worst = worst.min(world.clearance(&q, false).distance);
        }
    }
    eprintln!("closest approach/retract configuration at 1 ms: {worst} m");
    assert!(worst >= 0.01 - 1e-9, "closest {worst}");
}

/// Quintic Hermite between two trajectory points at `u` in [0, 1] (positions only).
fn quintic(
    a: &kerf_msgs::trajectory_msgs::JointTrajectoryPoint,
    b: &kerf_msgs::trajectory_msgs::JointTrajectoryPoint,
    h: f64,
    u: f64,
) -> Vec<f64> {
    let (u2, u3, u4, u5) = (u * u, u * u * u, u.powi(4), u.powi(5));
    let h00 = 1.0 - 10.0 * u3 + 15.0 * u4 - 6.0 * u5;
    let h10 = u - 6.0 * u3 + 8.0 * u4 - 3.0 * u5;
    let h20 = 0.5 * (u2 - 3.0 * u3 + 3.0 * u4 - u5);
    let h01 = 10.0 * u3 - 15.0 * u4 + 6.0 * u5;
    let h11 = -4.0 * u3 + 7.0 * u4 - 3.0 * u5;
    let h21 = 0.5 * (u3 - 2.0 * u4 + u5);
    (0..a.positions.len())
        .map(|j| {
            h00 * a.positions[j]
                + h10 * h * a.velocities[j]
                + h20 * h * h * a.accelerations[j]
                + h01 * b.positions[j]
                + h11 * h * b.velocities[j]
                + h21 * h * h * b.accelerations[j]
        })
        .collect()
}

#[test]
fn bad_starts_are_refused_by_name() {
    let service = service();
    let mut request = case1();
    // Inside the part: the first process point with the nozzle pushed 5 cm into it.
    let offline = Planner::new(LaserMachine::default_machine().unwrap())
        .unwrap()
        .plan(&request)
        .unwrap();
    let mut inside = offline.positions[0].to_vec();
    let o = kerf_mjto::kinematics::tool_axis(inside[3], inside[4]);
    for k in 0..3 {
        inside[k] -= 0.05 * o[k];
    }
    request.start = StartSpec::Given(inside);
    let a = plan(&service, request.clone(), None);
    assert_eq!(a.status, CutPlan::NO_APPROACH, "{}", a.message);
    assert!(a.message.contains("workpiece"), "{}", a.message);
    assert!(a.trajectory.points.is_empty());

    request.start = StartSpec::Given(vec![0.8, 0.7, 1.5]);
    let a = plan(&service, request.clone(), None);
    assert_eq!(a.status, CutPlan::INVALID_REQUEST, "{}", a.message);
    assert!(
        a.message
            .contains("start_positions has 3 value(s) for 6 joints"),
        "{}",
        a.message
    );

    request.start = StartSpec::Given(vec![0.8, 0.7, 1.5, 0.0, 0.0, 5.0]);
    let a = plan(&service, request.clone(), None);
    assert_eq!(a.status, CutPlan::INVALID_REQUEST, "{}", a.message);
    assert!(a.message.contains("'q6'"), "{}", a.message);

    // Current without a joint state, and with a moving robot.
    request.start = StartSpec::Current;
    let a = plan(&service, request.clone(), None);
    assert_eq!(a.status, CutPlan::INVALID_REQUEST, "{}", a.message);
    assert!(a.message.contains("no joint state"), "{}", a.message);
    let mut moving = robot_at(&HOME);
    moving.velocities[0] = 0.2;
    let a = plan(&service, request.clone(), Some(&moving));
    assert!(a.message.contains("moving"), "{}", a.message);
    let mut fewer = robot_at(&HOME);
    fewer.names.pop();
    fewer.positions.pop();
    fewer.velocities.pop();
    let a = plan(&service, request, Some(&fewer));
    assert_eq!(a.status, CutPlan::INVALID_REQUEST, "{}", a.message);
    assert!(a.message.contains("q6"), "{}", a.message);
}

#[test]
fn start_none_is_todays_plan() {
    let service = service();
    let mut request = case1();
    request.start = StartSpec::None;
    let a = plan(&service, request, Some(&robot_at(&HOME)));
    assert_eq!(a.status, CutPlan::SUCCESS, "{}", a.message);
    assert_eq!(a.stretches.start, "none");
    assert_eq!(a.stretches.process_start_time, 0.0);
    assert_ne!(a.trajectory.points[0].positions, HOME);
}
