//! End to end over DDS (loopback only): the trajectory executor drives the simulated cell
//! (`hardware: sim`, `kerf_cell`) of the laser cutter with the B-pillar of case 1.
//!
//! * Case 1's plan runs in the cell with no contact and the goal succeeds; `/clock` and
//!   `~/contacts` are published and `/joint_states` carries efforts.
//! * Hand-made trajectories that drive the head into the part are aborted with the contact
//!   named, and the penetration stays below the depth stated from the approach speed, one
//!   control period of detection and the controlled stop: straight down (the C-axis housing
//!   comes within the 2 mm threshold first), and the nozzle along its axis into the sheet
//!   (the tip, a contact only when it touches, penetrates).
//! * Path tolerances are checked in sim mode (dynamic cell): a path tolerance tighter than the
//!   measured state's lag aborts the goal.
//!
//! Each test runs its own executor (in this process, own Context) on its own domain (140-144).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::{
    thread::JoinHandle,
    time::{Duration, Instant},
};

use kerf_mjto::{planner::Planner, CutRequest, LaserMachine};
use kerf_msgs::{
    builtin_interfaces::Duration as RosDuration,
    control_msgs::{
        FollowJointTrajectoryFeedback, FollowJointTrajectoryGoal, FollowJointTrajectoryResult,
        JointTolerance,
    },
    msg::CellContacts,
    rosgraph_msgs::Clock,
    sensor_msgs::JointState,
    trajectory_msgs::{JointTrajectory, JointTrajectoryPoint},
    RosType,
};
use kerf_ros::{qos, KerfNode, StopToken};
use ros2_client::{
    action::{ActionClient, GoalId, GoalStatusEnum},
    ServiceMapping, Subscription,
};

#[allow(dead_code)] // shared with the other end-to-end tests
mod support;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");
/// Waiting for what needs no planning.
const QUICK: Duration = Duration::from_secs(30);
/// Waiting for a motion to end (debug builds, two cores shared).
const MOTION: Duration = Duration::from_secs(120);
/// The laser cutter's joints.
const JOINTS: [&str; 6] = ["q1", "q2", "q3", "q4", "q5", "q6"];
/// The cell file of the laser cutter with case 1's B-pillar.
const CELL: &str = "urdf/cells/laser_bpillar.yaml";
/// Control period (s): the executor's default 250 Hz.
const DT: f64 = 0.004;

type Fjt = ActionClient<
    FollowJointTrajectoryGoal,
    FollowJointTrajectoryResult,
    FollowJointTrajectoryFeedback,
>;

/// A sim-mode executor and a client watching it.
struct SimCell {
    action: Fjt,
    states: Subscription<JointState>,
    clock: Subscription<Clock>,
    contacts: Subscription<CellContacts>,
    _client: KerfNode,
    stop: StopToken,
    executor: Option<JoinHandle<Result<(), String>>>,
}

impl SimCell {
    /// The laser cutter in its sim cell (`mode`: kinematic or dynamic) at rest at `initial`.
    fn start(domain: u16, mode: &str, initial: &[f64]) -> SimCell {
        let env = support::loopback(domain, ServiceMapping::Enhanced);
        let (stop, executor) = support::spawn_robot_executor(
            &env,
            "laser_cutter",
            &[
                "hardware:=sim".into(),
                format!("sim_cell:={ROOT}/{CELL}"),
                format!("sim_mode:={mode}"),
                support::initial_positions(initial),
            ],
        );
        let mut client = support::client_node("sim_watch", &env);
        let action: Fjt = client
            .action_client(
                "/trajectory_executor/follow_joint_trajectory",
                "control_msgs/action/FollowJointTrajectory",
            )
            .unwrap();
        let states = client
            .subscription("/joint_states", JointState::ROS_TYPE, qos::state())
            .unwrap();
        let clock = client
            .subscription("/clock", Clock::ROS_TYPE, qos::state())
            .unwrap();
        let contacts = client
            .subscription(
                "/trajectory_executor/contacts",
                CellContacts::ROS_TYPE,
                qos::state(),
            )
            .unwrap();
        assert!(
            client.wait_for_action_server(&action, QUICK),
            "action server not discovered"
        );
        support::assert_starts_at(&states, initial);
        SimCell {
            action,
            states,
            clock,
            contacts,
            _client: client,
            stop,
            executor: Some(executor),
        }
    }

    fn send(&self, trajectory: JointTrajectory, path_tolerance: &[JointTolerance]) -> GoalId {
        let goal = FollowJointTrajectoryGoal {
            trajectory,
            path_tolerance: path_tolerance.to_vec(),
            ..Default::default()
        };
        let (req, id) = self.action.send_goal(goal).expect("send goal");
        let deadline = Instant::now() + QUICK;
        loop {
            if let Some(resp) = self
                .action
                .receive_goal_response(req)
                .expect("goal response")
            {
                assert!(resp.accepted);
                return id;
            }
            assert!(Instant::now() < deadline, "no goal response");
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    /// Waits for the result of goal `id`, meanwhile reading every joint state, clock and
    /// contacts sample into `seen`.
    fn result(&self, id: GoalId, seen: &mut Seen) -> (GoalStatusEnum, FollowJointTrajectoryResult) {
        let req = self.action.request_result(id).expect("request result");
        let deadline = Instant::now() + MOTION;
        loop {
            seen.read(self);
            if let Some(r) = self.action.receive_result(req).expect("result") {
                // What was published up to the end.
                std::thread::sleep(Duration::from_millis(300));
                seen.read(self);
                return r;
            }
            assert!(Instant::now() < deadline, "no result for goal {id:?}");
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}

impl Drop for SimCell {
    fn drop(&mut self) {
        support::stop_and_join(&self.stop, &mut self.executor);
    }
}

/// Everything the cell published while a goal ran.
#[derive(Default)]
struct Seen {
    states: Vec<JointState>,
    clocks: Vec<f64>,
    contacts: Vec<CellContacts>,
}

impl Seen {
    fn read(&mut self, cell: &SimCell) {
        while let Ok(Some((s, _))) = cell.states.take() {
            self.states.push(s);
        }
        while let Ok(Some((c, _))) = cell.clock.take() {
            self.clocks.push(c.clock.as_nanos() as f64 * 1e-9);
        }
        while let Ok(Some((c, _))) = cell.contacts.take() {
            self.contacts.push(c);
        }
    }

    /// The deepest penetration reported (m) and the number of contacts.
    fn deepest(&self) -> (f64, usize) {
        let all = self.contacts.iter().flat_map(|c| &c.contacts);
        all.fold((0.0, 0), |(d, n), c| (f64::max(d, c.depth), n + 1))
    }
}

fn case1() -> CutRequest {
    let path = std::path::Path::new(ROOT).join("crates/mjto/cases/case1.yaml");
    CutRequest::from_yaml(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn case1_runs_in_the_sim_cell_without_contact() {
    let mut planner = Planner::new(LaserMachine::default_machine().unwrap()).unwrap();
    let plan = planner.plan(&case1()).unwrap();
    let first = plan.positions[0];
    let last = *plan.positions.last().unwrap();
    let trajectory = kerf_mjto_planner::convert::trajectory_msg(&plan).unwrap();

    let cell = SimCell::start(140, "kinematic", &first);
    let id = cell.send(trajectory, &[]);
    let mut seen = Seen::default();
    let (status, result) = cell.result(id, &mut seen);
    assert_eq!(status, GoalStatusEnum::Succeeded, "{result:?}");
    assert_eq!(result.error_code, FollowJointTrajectoryResult::SUCCESSFUL);

    // No contact over the whole cut, and ~/contacts was published all along.
    let (deepest, count) = seen.deepest();
    assert_eq!(count, 0, "deepest {deepest} m");
    let duration = *plan.times.last().unwrap();
    let cycles = (duration / DT) as usize;
    assert!(
        seen.contacts.len() > cycles / 2,
        "{} contacts messages over {cycles} cycles",
        seen.contacts.len()
    );
    assert!(seen
        .contacts
        .iter()
        .all(|c| c.header.frame_id == "base_link"));
    // /clock: simulated time, one control period per cycle, never backwards.
    assert!(
        seen.clocks.len() > cycles / 2,
        "{} clocks",
        seen.clocks.len()
    );
    for w in seen.clocks.windows(2) {
        let step = w[1] - w[0];
        assert!(step > 0.0, "clock went backwards or stood: {step}");
        // Samples may be lost on a busy host, but every step is a whole number of periods.
        let periods = step / DT;
        assert!((periods - periods.round()).abs() < 1e-3, "{step}");
    }
    // /joint_states carries one effort per joint, and the head's weight shows on q3.
    assert!(seen.states.len() > cycles / 2);
    for s in &seen.states {
        assert_eq!(s.effort.len(), 6, "{s:?}");
    }
    assert!(seen.states.iter().all(|s| s.effort[2].abs() > 1.0));
    support::assert_rests_at(&cell.states, &last, 1e-6, "case 1 in the sim cell");
}

/// The approach profile of the drive-in test along one joint: rest, a raised-cosine
/// acceleration to `v` over `ta`, constant `v`, the mirror deceleration to rest; `length` in
/// all. Returns (position offset, velocity, acceleration) at `t` and the total duration.
fn approach(v: f64, ta: f64, length: f64, t: f64) -> ((f64, f64, f64), f64) {
    let cruise = (length - v * ta) / v;
    let total = 2.0 * ta + cruise;
    let w = 2.0 * std::f64::consts::PI / ta;
    // Acceleration phase from rest: a = (v/ta)(1 - cos wt).
    let ramp = |t: f64| {
        let k = v / ta;
        (
            k * (t * t / 2.0 + ((w * t).cos() - 1.0) / (w * w)),
            k * (t - (w * t).sin() / w),
            k * (1.0 - (w * t).cos()),
        )
    };
    let state = if t <= ta {
        ramp(t)
    } else if t <= ta + cruise {
        (v * ta / 2.0 + v * (t - ta), v, 0.0)
    } else {
        let (p, dv, a) = ramp((total - t).max(0.0));
        (length - p, dv, -a)
    };
    (state, total)
}

/// A move of `joint` alone from `start` by `length` downwards (towards smaller values) at
/// cruise speed `v` with raised-cosine ramps of `ta` ([`approach`]), sampled every 10 ms.
fn approach_trajectory(
    start: &[f64; 6],
    joint: usize,
    v: f64,
    ta: f64,
    length: f64,
) -> JointTrajectory {
    let (_, total) = approach(v, ta, length, 0.0);
    let n = (total / 0.01).ceil() as usize;
    let points = (0..=n)
        .map(|k| {
            let t = (k as f64 * 0.01).min(total);
            let ((p, dp, ddp), _) = approach(v, ta, length, t);
            let mut positions = start.to_vec();
            positions[joint] -= p;
            let mut velocities = vec![0.0; 6];
            velocities[joint] = -dp;
            let mut accelerations = vec![0.0; 6];
            accelerations[joint] = -ddp;
            JointTrajectoryPoint {
                positions,
                velocities,
                accelerations,
                effort: vec![],
                time_from_start: RosDuration::from_secs_f64(t).unwrap(),
            }
        })
        .collect();
    JointTrajectory {
        joint_names: JOINTS.map(String::from).to_vec(),
        points,
        ..Default::default()
    }
}

/// The executor's acceleration limit of the laser cutter's `joint` (its shipped URDF and
/// limits file).
fn laser_acceleration(joint: usize) -> f64 {
    let urdf = format!("{ROOT}/urdf/laser_cutter.urdf");
    let limits = format!("{ROOT}/urdf/laser_cutter_limits.yaml");
    let robot = kerf_robot::RobotModel::from_files(urdf.as_ref(), Some(limits.as_ref())).unwrap();
    robot.executor_limits().unwrap()[joint].max_acceleration
}

#[test]
fn head_driven_into_the_part_is_stopped_and_the_contact_named() {
    // The cell file's start: the head above case 1's first CL point, tool axis vertical.
    let start = [0.40, 0.70, 1.20, 0.0, 0.0, -0.07];
    // q3 down 0.35 m at 50 mm/s: the tool-centre point C = (q1, q2, q3 + q6) would end 0.22 m
    // below the part's surface (z about 0.9 there).
    let (v, ta, length) = (0.05, 0.5, 0.35);
    let trajectory = approach_trajectory(&start, 2, v, ta, length);
    let a3 = laser_acceleration(2);
    // The stated depth: the head moves at most v * DT into the part in the period in which
    // the contact is found (the period before, the cell saw none), then the controlled stop
    // takes v² / (2 a) along q3 (only q3 moves; synchronized linear deceleration).
    let bound = v * DT + v * v / (2.0 * a3);

    let cell = SimCell::start(141, "kinematic", &start);
    let id = cell.send(trajectory, &[]);
    let mut seen = Seen::default();
    let (status, result) = cell.result(id, &mut seen);
    assert_eq!(status, GoalStatusEnum::Aborted, "{result:?}");
    assert_eq!(
        result.error_code,
        FollowJointTrajectoryResult::PATH_TOLERANCE_VIOLATED
    );
    let msg = &result.error_string;
    for needle in ["contact during motion", "'bpillar'", "depth", "link '"] {
        assert!(msg.contains(needle), "{needle}: {msg}");
    }
    // The robot stopped well before the end of the trajectory and rests.
    std::thread::sleep(Duration::from_millis(300));
    let end = support::take_newest(&cell.states, QUICK, "joint state after the stop");
    assert!(end.velocity.iter().all(|v| v.abs() < 1e-9), "{end:?}");
    assert!(
        end.position[2] > start[2] - length + 0.1,
        "q3 ended at {}, the trajectory's end is {}",
        end.position[2],
        start[2] - length
    );
    // The penetration never exceeded the stated depth.
    let (deepest, count) = seen.deepest();
    assert!(count > 0, "no contact was published");
    println!("deepest penetration {deepest} m (bound {bound} m); {msg}");
    assert!(deepest <= bound, "penetration {deepest} m > {bound} m");
    // The link named in the result is one the contacts report.
    let named = seen
        .contacts
        .iter()
        .flat_map(|c| &c.contacts)
        .any(|c| msg.contains(&format!("link '{}'", c.robot_link)));
    assert!(named, "{msg}");
}

#[test]
fn path_tolerances_are_judged_on_the_simulated_state() {
    let start = [0.40, 0.70, 1.20, 0.0, 0.0, -0.07];
    // Along q1, clear of the part: 0.2 m in 1 s (min-jerk), then back.
    let mut to = start;
    to[0] += 0.2;
    let t = 1.0;
    let n = 50;
    let points = (0..=n)
        .map(|k| {
            let s = k as f64 / n as f64;
            let (p, dp, ddp) = (
                10.0 * s.powi(3) - 15.0 * s.powi(4) + 6.0 * s.powi(5),
                (30.0 * s.powi(2) - 60.0 * s.powi(3) + 30.0 * s.powi(4)) / t,
                (60.0 * s - 180.0 * s.powi(2) + 120.0 * s.powi(3)) / (t * t),
            );
            let d: Vec<f64> = start.iter().zip(&to).map(|(a, b)| b - a).collect();
            JointTrajectoryPoint {
                positions: start.iter().zip(&d).map(|(a, d)| a + d * p).collect(),
                velocities: d.iter().map(|d| d * dp).collect(),
                accelerations: d.iter().map(|d| d * ddp).collect(),
                effort: vec![],
                time_from_start: RosDuration::from_secs_f64(s * t).unwrap(),
            }
        })
        .collect::<Vec<_>>();
    let trajectory = JointTrajectory {
        joint_names: JOINTS.map(String::from).to_vec(),
        points,
        ..Default::default()
    };
    // The measured state lags the reference by one control period (as with the mock: the
    // state read in a cycle is the one reached towards the previous command) plus, in
    // dynamic mode, the drives' tracking error: far above 1 nm while q1 moves. This shows
    // the goal's path tolerance is checked in sim mode, on the state the cell publishes; it
    // does not tell the cell's state from the mock's (both lag by more than 1 nm).
    let tight = [JointTolerance {
        name: "q1".into(),
        position: 1e-9,
        velocity: 0.0,
        acceleration: 0.0,
    }];
    let cell = SimCell::start(142, "dynamic", &start);
    let id = cell.send(trajectory.clone(), &tight);
    let mut seen = Seen::default();
    let (status, result) = cell.result(id, &mut seen);
    assert_eq!(status, GoalStatusEnum::Aborted, "{result:?}");
    assert_eq!(
        result.error_code,
        FollowJointTrajectoryResult::PATH_TOLERANCE_VIOLATED
    );
    assert!(
        result.error_string.contains("q1"),
        "{}",
        result.error_string
    );
    // Efforts are the drives' in dynamic mode too.
    assert!(seen.states.iter().all(|s| s.effort.len() == 6));
}

/// `kerf demo cut` and `kerf demo mill`: plan → executor → simulated cell in one process; the
/// goal succeeds with no contact and the report names time, tracking error and final state.
#[test]
fn kerf_demo_cut_and_mill_succeed_without_contact() {
    for (what, mode) in [("cut", "dynamic"), ("mill", "kinematic")] {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_kerf"))
            .args(["demo", what, "--mode", mode])
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{what}: {text}{}",
            String::from_utf8_lossy(&out.stderr)
        );
        for needle in [
            "goal: SUCCEEDED",
            "contacts: 0 periods",
            "max tracking error",
            "final state: positions",
            "time: planned",
        ] {
            assert!(text.contains(needle), "{what}: {needle}: {text}");
        }
    }
    // A bad physics rate is refused with the reason.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_kerf"))
        .args(["demo", "cut", "--physics-rate", "1100"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("not an integer multiple"), "{err}");
}

/// The nozzle driven along its own axis (q6, the standoff axis) into the sheet at case 1's
/// first CL point: the tip is a contact only when it touches (standoff allowance), so here the
/// head really penetrates, and the stated depth bounds it.
#[test]
fn nozzle_driven_into_the_sheet_penetrates_less_than_the_stated_depth() {
    let mut planner = Planner::new(LaserMachine::default_machine().unwrap()).unwrap();
    let plan = planner.plan(&case1()).unwrap();
    // 10 mm back from the cut's start along the tool axis (q6 up: C = M + q6 O).
    let mut start = plan.positions[0];
    start[5] += 0.010;
    // Then 20 mm/s towards the sheet, 30 mm (20 mm past the CL point), within q6's -0.1 m.
    let v = 0.02;
    let length = (start[5] + 0.1 - 0.001).min(0.03);
    assert!(length > 0.015, "q6 starts at {}", start[5]);
    let ta = 0.2;
    let trajectory = approach_trajectory(&start, 5, v, ta, length);
    let a6 = laser_acceleration(5);
    // The stated depth: at most v * DT in the period the contact is found (the period
    // before, the tip did not touch), then the controlled stop's v² / (2 a) along q6.
    let bound = v * DT + v * v / (2.0 * a6);

    let cell = SimCell::start(143, "kinematic", &start);
    let id = cell.send(trajectory, &[]);
    let mut seen = Seen::default();
    let (status, result) = cell.result(id, &mut seen);
    assert_eq!(status, GoalStatusEnum::Aborted, "{result:?}");
    let msg = &result.error_string;
    for needle in ["link 'nozzle'", "shape 'nozzle/0'", "'bpillar'", "depth"] {
        assert!(msg.contains(needle), "{needle}: {msg}");
    }
    let (deepest, count) = seen.deepest();
    println!("deepest penetration {deepest} m (bound {bound} m); {msg}");
    assert!(count > 0, "no contact was published");
    assert!(deepest > 0.0, "the tip never touched");
    assert!(deepest <= bound, "penetration {deepest} m > {bound} m");
    std::thread::sleep(Duration::from_millis(300));
    let end = support::take_newest(&cell.states, QUICK, "joint state after the stop");
    assert!(end.velocity.iter().all(|v| v.abs() < 1e-9), "{end:?}");
}

/// `kerf launch --sim --robot laser-cutter`: the executor on the simulated cell with the
/// planners, in a child process; `/clock`, `~/contacts` and efforts on `/joint_states` arrive
/// over DDS; case 1's request on the MJTO planner's text topic is planned and runs in the cell
/// to its end (the launch connects the planners to the executor); Ctrl-C ends it cleanly.
#[test]
fn kerf_launch_sim_starts_the_cell_and_the_planners() {
    // Issue 27: no initial_positions: the robot starts at the cell's start pose and the plan
    // approaches the cut from there.
    let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_kerf"));
    command
        .args(["launch", "--sim", "--robot", "laser-cutter"])
        .env("ROS_DOMAIN_ID", "144")
        .env("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
        .env_remove("ROS_STATIC_PEERS")
        .env_remove("RMW_IMPLEMENTATION");
    let (mut launch, mut lines) = support::Lines::spawn(command);
    let ready = lines.wait_for("simulated cell", QUICK);
    assert!(ready.contains("laser_bpillar.yaml"), "{ready}");

    let env = support::loopback(144, ServiceMapping::Enhanced);
    let mut client = support::client_node("launch_watch", &env);
    let states = client
        .subscription::<JointState>("/joint_states", JointState::ROS_TYPE, qos::state())
        .unwrap();
    let clock = client
        .subscription::<Clock>("/clock", Clock::ROS_TYPE, qos::state())
        .unwrap();
    let contacts = client
        .subscription::<CellContacts>(
            "/trajectory_executor/contacts",
            CellContacts::ROS_TYPE,
            qos::state(),
        )
        .unwrap();
    let s = support::take(&states, QUICK, "joint state");
    assert_eq!(s.effort.len(), 6, "{s:?}");
    let start = s.position.clone();
    let plans = client
        .subscription::<kerf_msgs::msg::CutPlan>(
            "/mjto_planner/cut_plan",
            kerf_msgs::msg::CutPlan::ROS_TYPE,
            qos::latched(),
        )
        .unwrap();
    let c0 = support::take(&clock, QUICK, "clock").clock.as_nanos();
    let c1 = support::take(&clock, QUICK, "clock").clock.as_nanos();
    assert!(c1 > c0, "{c0} then {c1}");
    let contact = support::take(&contacts, QUICK, "contacts");
    assert_eq!(contact.header.frame_id, "base_link");
    // The planners run beside it (their plan writers are discovered).
    support::wait_for_writer(&client, "/mjto_planner/cut_plan", QUICK, "the MJTO planner");
    support::wait_for_writer(
        &client,
        "/gcode_planner/gcode_plan",
        QUICK,
        "the G-code planner",
    );
    // A request on the planner's text topic runs in the cell.
    let requests = client
        .publisher(
            "/mjto_planner/cut_request_text",
            kerf_msgs::std_msgs::StringMsg::ROS_TYPE,
            qos::commands(),
        )
        .unwrap();
    assert!(
        client.wait_for_subscriber(&requests, QUICK),
        "the MJTO planner's request topic"
    );
    let (watch, cell_states, statuses) = support::watch_cell(&env, "launch_cell", &start);
    let text =
        std::fs::read_to_string(std::path::Path::new(ROOT).join("crates/mjto/cases/case1.yaml"))
            .unwrap();
    requests
        .publish(kerf_msgs::std_msgs::StringMsg { data: text })
        .unwrap();
    let plan = support::take(&plans, MOTION, "the cut plan");
    assert_eq!(
        plan.status,
        kerf_msgs::msg::CutPlan::SUCCESS,
        "{}",
        plan.message
    );
    assert_eq!(plan.stretches.start, "current", "{:?}", plan.stretches);
    let last = plan.trajectory.points.last().unwrap().positions.clone();
    let deadline = Instant::now() + MOTION;
    let mut succeeded = false;
    while Instant::now() < deadline && !succeeded {
        succeeded |= support::drain_statuses(&statuses, "case 1 in the launched cell")
            .contains(&kerf_msgs::msg::TrajectoryStatus::SUCCEEDED);
        std::thread::sleep(Duration::from_millis(10));
    }
    assert!(
        succeeded,
        "case 1 did not run to its end in the launched cell"
    );
    support::assert_rests_at(&cell_states, &last, 1e-4, "case 1 in the launched cell");
    drop((
        plans,
        states,
        clock,
        contacts,
        requests,
        client,
        watch,
        cell_states,
        statuses,
    ));

    support::interrupt(&launch.0);
    lines.wait_for("shutting down", QUICK);
    support::assert_clean_exit(&mut launch.0, Duration::from_secs(20));
}
