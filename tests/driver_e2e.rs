//! End to end over DDS (loopback only): the trajectory executor drives a robot driver in
//! another process (issue 27, item 2), the simulated driver `tools/sim_driver` (no kerf code:
//! it stands for ros2_control's forward_command_controller and joint_trajectory_controller).
//!
//! * `hardware: topic` on both robots: a goal succeeds on the driver's measured state and
//!   ends within the goal tolerance; the robot starts where the driver says, goals wait for
//!   it; both command types.
//! * Faults, each ending in a controlled stop checked on the commands the executor sends
//!   (`~/joint_command`: within the velocity and acceleration limits, decelerating after the
//!   fault, at rest at the end) and a result naming the fault: stale feedback (`drop`), the
//!   driver killed (SIGKILL) and restarted elsewhere, NaN, a missing joint, a stamp that goes
//!   back, a frozen axis (path tolerance).
//! * `hardware: jtc`: a goal forwarded to the driver's FollowJointTrajectory server succeeds
//!   with relayed feedback; a rejected goal and a server that dies are reported.
//! * A driver topic of the wrong type (publisher or subscription) refuses goals naming both
//!   types; a state topic that is the executor's own is refused at start-up.
//! * A second goal preempts the running one on topic hardware, without a jump.
//!
//! The driver runs as a child process (`target/<profile>/sim_driver`, built once with
//! `cargo build -p sim_driver` if missing); every DDS participant stays on 127.0.0.1
//! (`ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`) and each test has its own domain (185-195).
//! Timings are printed, never asserted.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::{
    path::Path,
    sync::{
        atomic::{AtomicBool, Ordering},
        Arc, Mutex,
    },
    thread::JoinHandle,
    time::{Duration, Instant},
};

use kerf_executor::JointLimits;
use kerf_msgs::{
    builtin_interfaces::Duration as RosDuration,
    control_msgs::{
        FollowJointTrajectoryFeedback, FollowJointTrajectoryGoal, FollowJointTrajectoryResult,
    },
    msg::TrajectoryStatus,
    sensor_msgs::JointState,
    srv::{ValidateTrajectoryRequest, ValidateTrajectoryResponse},
    std_msgs::StringMsg,
    trajectory_msgs::{JointTrajectory, JointTrajectoryPoint},
    RosType,
};
use kerf_ros::{qos, KerfNode, StopToken};
use ros2_client::{
    action::{ActionClient, GoalId, GoalStatusEnum},
    Client, Publisher, ServiceMapping, Subscription,
};

#[allow(dead_code)] // shared with the other end-to-end tests
mod support;
use support::{driver::Driver, max_diff, min_jerk};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");
/// Waiting for discovery, a first state, an answer.
const QUICK: Duration = Duration::from_secs(30);
/// PATH_TOLERANCE_VIOLATED and INVALID_GOAL (control_msgs/FollowJointTrajectory).
const PATH_TOLERANCE_VIOLATED: i32 = -4;
const INVALID_GOAL: i32 = -1;

type Fjt = ActionClient<
    FollowJointTrajectoryGoal,
    FollowJointTrajectoryResult,
    FollowJointTrajectoryFeedback,
>;

// ----- the driver process ------------------------------------------------------------------

/// The driver's arguments for `robot`'s joints, starting at `initial`, with `extra`.
fn driver_args(robot: &Robot, initial: &[f64], extra: &[&str]) -> Vec<String> {
    let q: Vec<String> = initial.iter().map(|v| format!("{v:?}")).collect();
    let mut args = vec![
        "--joints".to_string(),
        robot.joints.join(","),
        "--initial".into(),
        q.join(","),
    ];
    args.extend(extra.iter().map(|s| s.to_string()));
    args
}

// ----- robots ------------------------------------------------------------------------------

struct Robot {
    stem: &'static str,
    joints: Vec<String>,
    limits: Vec<JointLimits>,
}

impl Robot {
    fn load(stem: &'static str) -> Robot {
        let urdf = Path::new(ROOT).join(format!("urdf/{stem}.urdf"));
        let lim = Path::new(ROOT).join(format!("urdf/{stem}_limits.yaml"));
        let model = kerf_robot::RobotModel::from_files(&urdf, Some(&lim)).unwrap();
        let limits = model.executor_limits().unwrap();
        Robot {
            stem,
            joints: limits.iter().map(|l| l.name.clone()).collect(),
            limits,
        }
    }

    /// The executor's ROS arguments: the robot's shipped parameter file (its tolerances),
    /// its model, and `params`.
    fn executor_words(&self, params: &[String]) -> Vec<String> {
        let mut words = vec![
            "--ros-args".to_string(),
            "--disable-rosout-logs".into(),
            "--params-file".into(),
            format!("{ROOT}/launch_scripts/params/{}.yaml", self.stem),
            "-p".into(),
            format!("urdf_file:={ROOT}/urdf/{}.urdf", self.stem),
            "-p".into(),
            format!("joint_limits_file:={ROOT}/urdf/{}_limits.yaml", self.stem),
        ];
        for p in params {
            words.push("-p".into());
            words.push(p.clone());
        }
        words
    }
}

/// The parameters of `hardware: topic` with the driver in `/driver`, stale after `periods`
/// control periods (the default 5 where staleness is tested; 25, 100 ms, elsewhere, so that
/// a driver process starved by a loaded machine does not end an unrelated test).
fn topic_params(periods: u32) -> Vec<String> {
    vec![
        "hardware:=topic".into(),
        "hardware.command_topic:=/driver/commands".into(),
        "hardware.state_topic:=/driver/joint_states".into(),
        format!("hardware.feedback_timeout_periods:={periods}"),
    ]
}

/// Feedback timeout of the tests that are not about staleness (control periods).
const LENIENT: u32 = 25;

// ----- recording a stream ------------------------------------------------------------------

/// A subscription read on its own thread into a shared list, so that nothing is lost while
/// the test waits for something else.
struct Recorder<M> {
    seen: Arc<Mutex<Vec<M>>>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl<M: serde::de::DeserializeOwned + Send + 'static> Recorder<M> {
    fn new(sub: Subscription<M>) -> Self {
        let seen = Arc::new(Mutex::new(Vec::new()));
        let stop = Arc::new(AtomicBool::new(false));
        let (s, st) = (Arc::clone(&seen), Arc::clone(&stop));
        let thread = std::thread::spawn(move || {
            while !st.load(Ordering::Relaxed) {
                match sub.take() {
                    Ok(Some((m, _))) => s.lock().unwrap().push(m),
                    _ => std::thread::sleep(Duration::from_micros(500)),
                }
            }
        });
        Recorder {
            seen,
            stop,
            thread: Some(thread),
        }
    }

    fn len(&self) -> usize {
        self.seen.lock().unwrap().len()
    }
}

impl<M: Clone> Recorder<M> {
    fn since(&self, from: usize) -> Vec<M> {
        self.seen.lock().unwrap()[from..].to_vec()
    }

    fn last(&self) -> Option<M> {
        self.seen.lock().unwrap().last().cloned()
    }
}

impl<M> Drop for Recorder<M> {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

fn secs(s: &JointState) -> f64 {
    s.header.stamp.as_nanos() as f64 * 1e-9
}

// ----- the executor and its client ---------------------------------------------------------

/// The executor (in this process, own Context) and a cell controller watching it and the
/// driver. Fields drop in order: recorders and endpoints before their node, the executor
/// stopped in `Drop`.
struct Rig {
    commands: Recorder<JointState>,
    measured: Recorder<JointState>,
    joint_states: Recorder<JointState>,
    statuses: Recorder<TrajectoryStatus>,
    action: Fjt,
    validate: Client<ValidateTrajectoryRequest, ValidateTrajectoryResponse>,
    fault: Publisher<StringMsg>,
    client: KerfNode,
    stop: StopToken,
    executor: Option<JoinHandle<Result<(), String>>>,
}

impl Rig {
    /// The executor for `robot` with `params` (after its shipped parameter file), on `domain`.
    fn start(domain: u16, robot: &Robot, params: &[String]) -> Rig {
        let env = support::loopback(domain, ServiceMapping::Enhanced);
        let words = robot.executor_words(params);
        let (stop, executor) = support::spawn_node(&env, words, |a, e, s| {
            kerf_trajectory_executor::run(a, e, s).map_err(|e| e.to_string())
        });
        let mut client = support::client_node("cell_controller", &env);
        let action: Fjt = client
            .action_client(
                "/trajectory_executor/follow_joint_trajectory",
                "control_msgs/action/FollowJointTrajectory",
            )
            .unwrap();
        let validate = client
            .service_client(
                "/trajectory_executor/validate_trajectory",
                "kerf_msgs/srv/ValidateTrajectory",
            )
            .unwrap();
        let sub = |c: &mut KerfNode, topic: &str| -> Subscription<JointState> {
            c.subscription(topic, JointState::ROS_TYPE, qos::state())
                .unwrap()
        };
        let commands = Recorder::new(sub(&mut client, "/trajectory_executor/joint_command"));
        let measured = Recorder::new(sub(&mut client, "/driver/joint_states"));
        let joint_states = Recorder::new(sub(&mut client, "/joint_states"));
        let statuses = Recorder::new(
            client
                .subscription(
                    "/trajectory_executor/trajectory_status",
                    TrajectoryStatus::ROS_TYPE,
                    qos::latched(),
                )
                .unwrap(),
        );
        let fault = client
            .publisher("/driver/fault", StringMsg::ROS_TYPE, qos::commands())
            .unwrap();
        assert!(
            client.wait_for_action_server(&action, QUICK),
            "the executor's action server was not discovered"
        );
        assert!(
            client.wait_for_service(&validate, QUICK),
            "the validate service was not discovered"
        );
        Rig {
            commands,
            measured,
            joint_states,
            statuses,
            action,
            validate,
            fault,
            client,
            stop,
            executor: Some(executor),
        }
    }

    /// Waits until the executor republishes a joint state (it has the driver's first).
    fn wait_for_robot(&self) -> JointState {
        let deadline = Instant::now() + QUICK;
        loop {
            if let Some(s) = self.joint_states.last() {
                return s;
            }
            assert!(
                Instant::now() < deadline,
                "no joint state from the executor"
            );
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// The driver's newest measured positions.
    fn measured_now(&self) -> Vec<f64> {
        let deadline = Instant::now() + QUICK;
        loop {
            if let Some(s) = self.measured.last() {
                return s.position;
            }
            assert!(Instant::now() < deadline, "no joint state from the driver");
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// Tells the driver to show `fault` (on `/driver/fault`).
    fn fault(&self, fault: &str) {
        assert!(
            self.client.wait_for_subscriber(&self.fault, QUICK),
            "the driver's fault topic was not matched"
        );
        self.fault
            .publish(StringMsg { data: fault.into() })
            .expect("publish the fault");
    }

    fn send(&self, trajectory: JointTrajectory) -> GoalId {
        let goal = FollowJointTrajectoryGoal {
            trajectory,
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
                assert!(
                    resp.accepted,
                    "kerf accepts every goal, refusals are results"
                );
                return id;
            }
            assert!(Instant::now() < deadline, "no goal response");
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    fn result(&self, id: GoalId) -> (GoalStatusEnum, FollowJointTrajectoryResult) {
        let req = self.action.request_result(id).expect("request result");
        let deadline = Instant::now() + Duration::from_secs(60);
        loop {
            if let Some(r) = self.action.receive_result(req).expect("result") {
                return r;
            }
            assert!(Instant::now() < deadline, "no result for goal {id:?}");
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    fn validate(&self, trajectory: JointTrajectory) -> ValidateTrajectoryResponse {
        let req = self
            .validate
            .send_request(ValidateTrajectoryRequest { trajectory })
            .expect("validate request");
        let deadline = Instant::now() + QUICK;
        loop {
            if let Some((id, resp)) = self.validate.receive_response().expect("validate") {
                if id == req {
                    return resp;
                }
            }
            assert!(Instant::now() < deadline, "no validate answer");
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    /// The stamp (s) of the newest status with `status`, waiting for it.
    fn status_stamp(&self, status: u8) -> f64 {
        let deadline = Instant::now() + QUICK;
        loop {
            let found = self
                .statuses
                .seen
                .lock()
                .unwrap()
                .iter()
                .rev()
                .find(|s| s.status == status)
                .map(|s| s.header.stamp.as_nanos() as f64 * 1e-9);
            if let Some(t) = found {
                return t;
            }
            assert!(Instant::now() < deadline, "no status {status}");
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}

impl Drop for Rig {
    fn drop(&mut self) {
        support::stop_and_join(&self.stop, &mut self.executor);
    }
}

// ----- motions and checks ------------------------------------------------------------------

/// `trajectory` with a first point at `time_from_start` 0 at rest at `start` (a driver's
/// FollowJointTrajectory server starts goals from its current position, as JTC does).
fn from_rest_at(mut trajectory: JointTrajectory, start: &[f64]) -> JointTrajectory {
    let n = start.len();
    trajectory.points.insert(
        0,
        JointTrajectoryPoint {
            positions: start.to_vec(),
            velocities: vec![0.0; n],
            accelerations: vec![0.0; n],
            effort: vec![],
            time_from_start: RosDuration::ZERO,
        },
    );
    trajectory
}

/// Waits until the driver's newest state is within `tolerance` of `q`.
fn wait_measured_at(rig: &Rig, q: &[f64], tolerance: f64, what: &str) {
    let deadline = Instant::now() + QUICK;
    while max_diff(&rig.measured_now(), q) > tolerance {
        assert!(
            Instant::now() < deadline,
            "{what}: {:?} vs {q:?}",
            rig.measured_now()
        );
        std::thread::sleep(Duration::from_millis(10));
    }
}

fn offset(q: &[f64], d: &[f64]) -> Vec<f64> {
    q.iter().zip(d).map(|(a, b)| a + b).collect()
}

/// Every command of `cmds` within the velocity and acceleration limits (accelerations as the
/// velocity differences over the stamps' differences); returns the largest ratio to a limit.
fn assert_within_limits(cmds: &[JointState], limits: &[JointLimits], what: &str) -> f64 {
    let mut worst: f64 = 0.0;
    for w in cmds.windows(2) {
        // From the integer stamps: as f64 seconds since 1970 they carry ±256 ns, and after a
        // late cycle the loop catches up with cycles microseconds apart.
        let dt = (w[1].header.stamp.as_nanos() - w[0].header.stamp.as_nanos()) as f64 * 1e-9;
        assert!(dt > 0.0, "{what}: command stamps do not increase");
        for (j, l) in limits.iter().enumerate() {
            let v = w[1].velocity[j];
            let a = (w[1].velocity[j] - w[0].velocity[j]) / dt;
            assert!(
                v.abs() <= l.max_velocity * (1.0 + 1e-6),
                "{what}: joint {} commanded at {v} (limit {})",
                l.name,
                l.max_velocity
            );
            assert!(
                a.abs() <= l.max_acceleration * (1.0 + 1e-3) + 1e-6,
                "{what}: joint {} commanded an acceleration of {a} (limit {}) at {}: velocity {} \
                 at {} then {} at {}",
                l.name,
                l.max_acceleration,
                secs(&w[1]),
                w[0].velocity[j],
                secs(&w[0]),
                w[1].velocity[j],
                secs(&w[1])
            );
            worst = worst
                .max(v.abs() / l.max_velocity)
                .max(a.abs() / l.max_acceleration);
        }
    }
    worst
}

/// What the robot did after a fault.
#[derive(Debug)]
struct Stop {
    /// The largest joint speed when the stop began.
    speed: f64,
    /// The largest joint travel from the stop's first command to rest.
    travel: f64,
    /// From the stop's first command to the first command at rest (s).
    duration: f64,
}

/// A controlled stop, checked on the commands the executor sent (`~/joint_command`, from
/// index `from` on): all within the limits; after `fault_stamp` (the abort's status stamp)
/// every joint's speed never grows, the robot was moving when the stop began, and the last
/// commands are at rest.
fn assert_controlled_stop(
    rig: &Rig,
    from: usize,
    fault_stamp: f64,
    robot: &Robot,
    what: &str,
) -> Stop {
    // The stop lasts at most max |v| / a (well under 2 s for these motions).
    std::thread::sleep(Duration::from_millis(1500));
    let cmds = rig.commands.since(from);
    assert!(
        cmds.len() > 100,
        "{what}: only {} commands recorded",
        cmds.len()
    );
    assert_within_limits(&cmds, &robot.limits, what);
    // The stop starts at the fault's control cycle, before the status stamp: every command
    // after the stamp is part of it, and so are those before it back to where the speeds
    // stop falling (the faults come while the motion speeds up).
    let mut first = cmds
        .iter()
        .position(|c| secs(c) >= fault_stamp)
        .unwrap_or_else(|| panic!("{what}: no command after the fault"));
    let slower = |a: &JointState, b: &JointState| {
        a.velocity
            .iter()
            .zip(&b.velocity)
            .all(|(x, y)| y.abs() <= x.abs() + 1e-12)
    };
    while first > 0 && slower(&cmds[first - 1], &cmds[first]) {
        first -= 1;
    }
    let stop = &cmds[first..];
    let speed = stop[0].velocity.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(
        speed > 1e-3,
        "{what}: the robot was not moving at the fault ({speed})"
    );
    for w in stop.windows(2) {
        for j in 0..robot.limits.len() {
            assert!(
                w[1].velocity[j].abs() <= w[0].velocity[j].abs() + 1e-9,
                "{what}: joint {} speeds up after the fault: {} -> {}",
                robot.joints[j],
                w[0].velocity[j],
                w[1].velocity[j]
            );
        }
    }
    let last = stop.last().unwrap();
    assert!(
        last.velocity.iter().all(|v| *v == 0.0),
        "{what}: not at rest: {:?}",
        last.velocity
    );
    let rest = stop
        .iter()
        .position(|c| c.velocity.iter().all(|v| *v == 0.0))
        .unwrap();
    assert!(
        stop[rest..].iter().all(|c| c.position == last.position),
        "{what}: the held position moves"
    );
    Stop {
        speed,
        travel: max_diff(&stop[0].position, &last.position),
        duration: secs(&stop[rest]) - secs(&stop[0]),
    }
}

/// A fault mid-motion on topic hardware: a 3 s move of the IRB 6660, `fault()` 1.2 s into it,
/// a result ABORTED with PATH_TOLERANCE_VIOLATED naming the fault (`needle`), a controlled
/// stop; then a goal is refused with the reason while the fault lasts (when `lasting`), and
/// after `recover()` goals succeed again from the measured state.
fn fault_mid_motion(
    rig: &Rig,
    robot: &Robot,
    fault: impl FnOnce(&Rig),
    needle: &str,
    what: &str,
) -> (Stop, String) {
    let start = rig.measured_now();
    let target = offset(&start, &[0.6, 0.3, -0.3, 0.5, 0.4, 0.8]);
    let from = rig.commands.len();
    let t0 = Instant::now();
    let id = rig.send(min_jerk(&robot.joints, &start, &target, 3.0, 10));
    std::thread::sleep(Duration::from_millis(1200));
    fault(rig);
    let (status, result) = rig.result(id);
    let detected = t0.elapsed();
    assert_eq!(status, GoalStatusEnum::Aborted, "{what}: {result:?}");
    assert_eq!(
        result.error_code, PATH_TOLERANCE_VIOLATED,
        "{what}: {result:?}"
    );
    assert!(
        result.error_string.contains(needle),
        "{what}: {}",
        result.error_string
    );
    let stamp = rig.status_stamp(TrajectoryStatus::ABORTED);
    let stop = assert_controlled_stop(rig, from, stamp, robot, what);
    eprintln!(
        "{what}: aborted {:.3} s after the goal was sent ({}); stop from {:.3} rad/s over \
         {:.4} rad in {:.3} s",
        detected.as_secs_f64(),
        result.error_string,
        stop.speed,
        stop.travel,
        stop.duration
    );
    (stop, result.error_string)
}

/// A goal that must succeed: `robot` moves by `delta` from the measured state over `t` s; the
/// driver's measured end position is within `goal_tolerance` of the target.
fn move_and_succeed(
    rig: &Rig,
    robot: &Robot,
    delta: &[f64],
    t: f64,
    goal_tolerance: &[f64],
    what: &str,
) {
    let start = rig.measured_now();
    let target = offset(&start, delta);
    let from = rig.commands.len();
    let t0 = Instant::now();
    let id = rig.send(min_jerk(&robot.joints, &start, &target, t, 8));
    let (status, result) = rig.result(id);
    assert_eq!(status, GoalStatusEnum::Succeeded, "{what}: {result:?}");
    let took = t0.elapsed().as_secs_f64();
    std::thread::sleep(Duration::from_millis(100));
    let end = rig.measured_now();
    for (j, tol) in goal_tolerance.iter().enumerate() {
        assert!(
            (end[j] - target[j]).abs() <= *tol,
            "{what}: {} measured at {} after success, target {} (goal tolerance {tol})",
            robot.joints[j],
            end[j],
            target[j]
        );
    }
    let worst = assert_within_limits(&rig.commands.since(from), &robot.limits, what);
    eprintln!(
        "{what}: succeeded in {took:.3} s for a {t} s trajectory; end error {:.2e}; commands \
         at most {:.0} % of a limit",
        max_diff(&end, &target),
        worst * 100.0
    );
}

/// A goal refused with a reason containing `needle` (accepted, then aborted at once).
fn assert_refused(rig: &Rig, robot: &Robot, needle: &str, what: &str) -> String {
    let start = rig
        .measured
        .last()
        .map(|s| s.position)
        .unwrap_or_else(|| vec![0.0; robot.joints.len()]);
    let id = rig.send(min_jerk(&robot.joints, &start, &start, 1.0, 2));
    let (status, result) = rig.result(id);
    assert_eq!(status, GoalStatusEnum::Aborted, "{what}: {result:?}");
    assert_eq!(result.error_code, INVALID_GOAL, "{what}: {result:?}");
    assert!(
        result.error_string.contains(needle),
        "{what}: {}",
        result.error_string
    );
    result.error_string
}

/// Sends goals until one is accepted and succeeds (goals are refused, INVALID_GOAL, while the
/// feedback is bad and while the robot comes to rest after a fault).
fn until_accepted(rig: &Rig, robot: &Robot, what: &str) {
    let deadline = Instant::now() + QUICK;
    loop {
        let start = rig.measured_now();
        let target = offset(&start, &[0.05; 6]);
        let id = rig.send(min_jerk(&robot.joints, &start, &target, 0.8, 4));
        let (status, result) = rig.result(id);
        if status == GoalStatusEnum::Succeeded {
            return;
        }
        assert_eq!(result.error_code, INVALID_GOAL, "{what}: {result:?}");
        assert!(Instant::now() < deadline, "{what}: {result:?}");
        std::thread::sleep(Duration::from_millis(100));
    }
}

const IRB_START: [f64; 6] = [0.1, 0.2, 0.3, 0.0, 0.5, 0.0];
/// The shipped IRB 6660 goal tolerance (launch_scripts/params/irb6660.yaml).
const IRB_GOAL_TOLERANCE: [f64; 6] = [0.001; 6];

/// The IRB 6660 executor on topic hardware (feedback stale after `periods`) and a driver
/// started at [`IRB_START`].
fn irb_rig(domain: u16, periods: u32, driver_extra: &[&str]) -> (Robot, Driver, Rig) {
    let robot = Robot::load("irb6660");
    let driver = Driver::start(
        domain,
        &format!("irb_{domain}"),
        &driver_args(&robot, &IRB_START, driver_extra),
    );
    let rig = Rig::start(domain, &robot, &topic_params(periods));
    rig.wait_for_robot();
    (robot, driver, rig)
}

// ----- tests -------------------------------------------------------------------------------

/// The laser cutter on `hardware: topic` (Float64MultiArray commands): goals wait for the
/// driver, the robot starts where the driver says (not at the parameter file's
/// `initial_positions`), a goal succeeds on the measured state and ends within the shipped
/// goal tolerance, and the executor republishes the measured state on `/joint_states`.
#[test]
fn laser_cutter_goal_succeeds_on_the_measured_state() {
    let domain = 185;
    let robot = Robot::load("laser_cutter");
    let rig = Rig::start(domain, &robot, &topic_params(LENIENT));
    // No driver yet.
    let refusal = assert_refused(&rig, &robot, "waiting for the driver", "before the driver");
    assert!(refusal.contains("/driver/joint_states"), "{refusal}");
    // The parameter file says [0.8, 0.7, 1.5, 0, 0, -0.05]; the driver's robot is elsewhere.
    let initial = [0.75, 0.72, 1.45, 0.1, -0.05, -0.04];
    let _driver = Driver::start(domain, "laser", &driver_args(&robot, &initial, &[]));
    let first = rig.wait_for_robot();
    assert!(max_diff(&first.position, &initial) < 1e-12, "{first:?}");
    // 2 cm and 0.05 rad in 2.5 s (at most 12 mm/s): within the 2 mm path tolerance with the
    // driver's 8 ms delay and the loop's latencies, even on a loaded machine.
    move_and_succeed(
        &rig,
        &robot,
        &[0.02, -0.015, 0.01, 0.05, 0.03, 0.005],
        2.5,
        &[1e-4, 1e-4, 1e-4, 1e-3, 1e-3, 1e-4],
        "laser cutter",
    );
    // The executor's joint_states are the driver's states as received.
    let ours = rig.joint_states.last().unwrap();
    let theirs = rig.measured.since(0);
    assert!(
        theirs
            .iter()
            .any(|s| s.header.stamp == ours.header.stamp && s.position == ours.position),
        "the executor's joint state is not one of the driver's"
    );
}

/// The IRB 6660 on `hardware: topic` with `sensor_msgs/JointState` commands and measurement
/// noise: a goal succeeds, the measured end within the shipped goal tolerance.
#[test]
fn irb6660_goal_succeeds_with_joint_state_commands() {
    let domain = 186;
    let robot = Robot::load("irb6660");
    let _driver = Driver::start(
        domain,
        "irb_js",
        &driver_args(
            &robot,
            &IRB_START,
            &["--command-type", "joint_state", "--noise", "0.00005"],
        ),
    );
    let mut params = topic_params(LENIENT);
    params.push("hardware.command_type:=sensor_msgs/msg/JointState".into());
    let rig = Rig::start(domain, &robot, &params);
    let first = rig.wait_for_robot();
    assert!(max_diff(&first.position, &IRB_START) < 1e-3, "{first:?}");
    move_and_succeed(
        &rig,
        &robot,
        &[0.4, -0.2, 0.3, -0.5, 0.3, 1.0],
        2.5,
        &IRB_GOAL_TOLERANCE,
        "irb6660 (JointState commands)",
    );
}

/// Stale feedback: the driver stops publishing mid-motion; the goal is aborted naming the
/// topic and the silence, the robot stops under control; goals are refused while the
/// feedback is stale and accepted once it is back.
#[test]
fn stale_feedback_stops_the_robot_and_refuses_goals_until_it_returns() {
    let (robot, _driver, rig) = irb_rig(187, 5, &[]);
    let (_, stale) = fault_mid_motion(
        &rig,
        &robot,
        |r| r.fault("drop"),
        "feedback stale: no joint state on /driver/joint_states for",
        "stale feedback",
    );
    assert!(
        stale.contains("the motion was brought to a controlled stop"),
        "{stale}"
    );
    let refusal = assert_refused(&rig, &robot, "feedback stale", "while stale");
    assert!(refusal.contains("goals are refused until"), "{refusal}");
    rig.fault("resume");
    until_accepted(&rig, &robot, "after resume");
}

/// The driver is killed (SIGKILL) mid-motion: stale feedback, a controlled stop; a driver
/// restarted elsewhere becomes the robot's position and goals run from there.
#[test]
fn driver_death_stops_the_robot_and_a_restarted_driver_is_followed() {
    let domain = 188;
    let (robot, mut driver, rig) = irb_rig(domain, 5, &[]);
    fault_mid_motion(
        &rig,
        &robot,
        |_| driver.kill(),
        "feedback stale",
        "driver killed",
    );
    assert_refused(&rig, &robot, "feedback stale", "driver dead");
    let elsewhere = [0.0, 0.1, 0.2, 0.1, 0.3, -0.2];
    let _driver = Driver::start(
        domain,
        "irb_restarted",
        &driver_args(&robot, &elsewhere, &[]),
    );
    wait_measured_at(&rig, &elsewhere, 1e-12, "restarted driver");
    until_accepted(&rig, &robot, "restarted driver");
    std::thread::sleep(Duration::from_millis(200));
    let held = rig.commands.last().unwrap();
    let start = offset(&elsewhere, &[0.05; 6]);
    assert!(
        max_diff(&held.position, &start) < 1e-9,
        "the hold is not where the restarted driver's robot went: {:?}",
        held.position
    );
}

/// A state with NaN mid-motion: aborted naming the joint; good states follow at once.
#[test]
fn nan_feedback_stops_the_robot() {
    let (robot, _driver, rig) = irb_rig(189, LENIENT, &[]);
    fault_mid_motion(
        &rig,
        &robot,
        |r| r.fault("nan"),
        "bad joint state on /driver/joint_states: measured state: position of joint 'joint_1' is NaN",
        "NaN feedback",
    );
    until_accepted(&rig, &robot, "after NaN");
}

/// A state missing a joint mid-motion: aborted naming the joint.
#[test]
fn missing_joint_feedback_stops_the_robot() {
    let (robot, _driver, rig) = irb_rig(190, LENIENT, &[]);
    fault_mid_motion(
        &rig,
        &robot,
        |r| r.fault("fewer_joints"),
        "no value for joint(s) [joint_6]",
        "fewer joints",
    );
    until_accepted(&rig, &robot, "after fewer joints");
}

/// A state whose stamp goes back mid-motion: aborted naming both stamps.
#[test]
fn a_stamp_going_back_stops_the_robot() {
    let (robot, _driver, rig) = irb_rig(191, LENIENT, &[]);
    fault_mid_motion(
        &rig,
        &robot,
        |r| r.fault("stamp_back"),
        "feedback stamp went back on /driver/joint_states",
        "stamp back",
    );
    until_accepted(&rig, &robot, "after stamp back");
}

/// An axis that stops following (freeze): the measured state leaves the command by more than
/// the path tolerance and the goal is aborted, as JTC does, with a controlled stop.
#[test]
fn a_frozen_axis_violates_the_path_tolerance() {
    let (robot, _driver, rig) = irb_rig(192, LENIENT, &[]);
    fault_mid_motion(
        &rig,
        &robot,
        |r| r.fault("freeze"),
        "path tolerance violated",
        "frozen axis",
    );
    rig.fault("resume");
    until_accepted(&rig, &robot, "after freeze");
}

/// `hardware: jtc`: a goal is validated, forwarded to the driver's FollowJointTrajectory
/// server and succeeds with its feedback relayed and its measured state on `/joint_states`;
/// an invalid goal never reaches the server; a goal the server rejects is aborted naming it;
/// a server that dies mid-goal is reported after `hardware.jtc_timeout`.
#[test]
fn jtc_goals_are_forwarded_and_their_results_relayed() {
    let domain = 193;
    let robot = Robot::load("irb6660");
    let _driver = Driver::start(domain, "jtc", &driver_args(&robot, &IRB_START, &[]));
    let rig = Rig::start(
        domain,
        &robot,
        &[
            "hardware:=jtc".into(),
            "hardware.jtc_action:=/driver/follow_joint_trajectory".into(),
            "hardware.state_topic:=/driver/joint_states".into(),
            "hardware.jtc_timeout:=0.5".into(),
        ],
    );
    let first = rig.wait_for_robot();
    assert!(max_diff(&first.position, &IRB_START) < 1e-12, "{first:?}");
    // Succeeds, with feedback.
    let target = offset(&IRB_START, &[0.3, 0.2, -0.2, 0.4, 0.3, 0.5]);
    let id = rig.send(from_rest_at(
        min_jerk(&robot.joints, &IRB_START, &target, 1.5, 6),
        &IRB_START,
    ));
    let mut feedback = 0;
    let req = rig.action.request_result(id).unwrap();
    let deadline = Instant::now() + QUICK;
    let (status, result) = loop {
        while let Ok(Some(_)) = rig.action.receive_feedback(id) {
            feedback += 1;
        }
        if let Some(r) = rig.action.receive_result(req).unwrap() {
            break r;
        }
        assert!(Instant::now() < deadline, "no jtc result");
        std::thread::sleep(Duration::from_millis(5));
    };
    assert_eq!(status, GoalStatusEnum::Succeeded, "{result:?}");
    assert!(feedback > 0, "no feedback relayed");
    std::thread::sleep(Duration::from_millis(100));
    let end = rig.measured_now();
    assert!(max_diff(&end, &target) < 1e-3, "{end:?} vs {target:?}");
    // A trajectory over the velocity limit is refused by the executor itself.
    let too_fast = offset(&target, &[2.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    let id = rig.send(min_jerk(&robot.joints, &target, &too_fast, 0.5, 2));
    let (status, result) = rig.result(id);
    assert_eq!(status, GoalStatusEnum::Aborted);
    assert!(
        result.error_string.contains("exceeds the limit"),
        "{result:?}"
    );
    // The server rejects.
    rig.fault("reject_goals");
    std::thread::sleep(Duration::from_millis(200));
    let back = rig.send(from_rest_at(
        min_jerk(&robot.joints, &target, &IRB_START, 1.0, 4),
        &target,
    ));
    let (status, result) = rig.result(back);
    assert_eq!(status, GoalStatusEnum::Aborted, "{result:?}");
    assert_eq!(result.error_code, INVALID_GOAL);
    assert!(
        result
            .error_string
            .contains("external FollowJointTrajectory server /driver/follow_joint_trajectory: rejected the goal"),
        "{}",
        result.error_string
    );
    // A cancel is relayed: the server stops and the goal ends CANCELED.
    rig.fault("accept_goals");
    std::thread::sleep(Duration::from_millis(200));
    let id = rig.send(from_rest_at(
        min_jerk(&robot.joints, &target, &IRB_START, 2.0, 4),
        &target,
    ));
    std::thread::sleep(Duration::from_millis(500));
    rig.action.cancel_goal(id).expect("cancel");
    let (status, result) = rig.result(id);
    assert_eq!(status, GoalStatusEnum::Canceled, "{result:?}");
    std::thread::sleep(Duration::from_millis(200));
    let here = rig.measured_now();
    assert!(
        max_diff(&here, &target) > 1e-3 && max_diff(&here, &IRB_START) > 1e-3,
        "the cancel did not stop the motion midway: {here:?}"
    );
    // The server dies mid-goal.
    let id = rig.send(from_rest_at(
        min_jerk(&robot.joints, &here, &IRB_START, 2.0, 4),
        &here,
    ));
    std::thread::sleep(Duration::from_millis(700));
    rig.fault("die");
    let t0 = Instant::now();
    let (status, result) = rig.result(id);
    assert_eq!(status, GoalStatusEnum::Aborted, "{result:?}");
    assert!(
        result
            .error_string
            .contains("/driver/follow_joint_trajectory")
            && result.error_string.contains("gone"),
        "{}",
        result.error_string
    );
    eprintln!(
        "jtc: server death reported {:.3} s after the die fault: {}",
        t0.elapsed().as_secs_f64(),
        result.error_string
    );
}

/// A driver topic of the wrong type refuses goals naming the topic and both types: a
/// publisher of `std_msgs/String` on the state topic, and a driver subscribing
/// `sensor_msgs/JointState` commands while the executor sends `Float64MultiArray`. A state
/// topic that is the executor's own `joint_states` is refused at start-up.
#[test]
fn a_driver_topic_of_the_wrong_type_refuses_goals() {
    let domain = 194;
    let robot = Robot::load("irb6660");
    // Refused at start-up, naming the parameter.
    let env = support::loopback(domain, ServiceMapping::Enhanced);
    let words = robot.executor_words(&[
        "hardware:=topic".into(),
        "hardware.state_topic:=/joint_states".into(),
    ]);
    let (_stop, h) = support::spawn_node(&env, words, |a, e, s| {
        kerf_trajectory_executor::run(a, e, s).map_err(|e| e.to_string())
    });
    let e = h.join().unwrap().unwrap_err();
    assert!(
        e.contains("'hardware.state_topic'") && e.contains("a topic of the executor itself"),
        "{e}"
    );

    // The driver expects JointState commands; the executor sends Float64MultiArray.
    let _driver = Driver::start(
        domain,
        "wrong_type",
        &driver_args(&robot, &IRB_START, &["--command-type", "joint_state"]),
    );
    let rig = Rig::start(domain, &robot, &topic_params(LENIENT));
    rig.wait_for_robot();
    let trajectory = min_jerk(&robot.joints, &IRB_START, &IRB_START, 1.0, 2);
    let deadline = Instant::now() + QUICK;
    let refusal = loop {
        let answer = rig.validate(trajectory.clone());
        if !answer.valid && answer.message.contains("driver topic") {
            break answer.message;
        }
        assert!(Instant::now() < deadline, "never refused: {answer:?}");
        std::thread::sleep(Duration::from_millis(100));
    };
    assert!(
        refusal.contains(
            "driver topic /driver/commands has a subscription of type sensor_msgs/msg/JointState"
        ) && refusal.contains("publishes std_msgs/msg/Float64MultiArray"),
        "{refusal}"
    );
    assert_refused(
        &rig,
        &robot,
        "driver topic /driver/commands",
        "wrong command type",
    );

    // A String publisher on a second executor's state topic.
    drop(rig);
    let rig = Rig::start(
        domain,
        &robot,
        &[
            "hardware:=topic".into(),
            "hardware.command_topic:=/other/commands".into(),
            "hardware.state_topic:=/other/joint_states".into(),
        ],
    );
    let mut talker = support::client_node("talker", &env);
    let wrong = talker
        .publisher("/other/joint_states", StringMsg::ROS_TYPE, qos::commands())
        .unwrap();
    let deadline = Instant::now() + QUICK;
    let refusal = loop {
        let _ = wrong.publish(StringMsg {
            data: "not a joint state".into(),
        });
        let answer = rig.validate(trajectory.clone());
        if answer.message.contains("driver topic") {
            break answer.message;
        }
        assert!(Instant::now() < deadline, "never refused: {answer:?}");
        std::thread::sleep(Duration::from_millis(100));
    };
    assert!(
        refusal.contains(
            "driver topic /other/joint_states has a publisher of type std_msgs/msg/String"
        ) && refusal.contains("reads sensor_msgs/msg/JointState"),
        "{refusal}"
    );
    drop(wrong);
    drop(rig);
    drop(talker);
}

/// A second goal while one runs preempts it, as the executor documents (JTC): the first ends
/// CANCELED with INVALID_GOAL, the second continues from the commanded state without a jump
/// and succeeds on the measured state.
#[test]
fn a_second_goal_preempts_the_first_without_a_jump() {
    let (robot, _driver, rig) = irb_rig(195, LENIENT, &[]);
    let start = rig.measured_now();
    let a = offset(&start, &[0.6, 0.3, -0.3, 0.5, 0.4, 0.8]);
    let from = rig.commands.len();
    let first = rig.send(min_jerk(&robot.joints, &start, &a, 3.0, 10));
    std::thread::sleep(Duration::from_millis(1200));
    let b = offset(&start, &[-0.2, 0.1, 0.1, -0.3, 0.2, -0.4]);
    // Its first point 1.5 s ahead: it starts from wherever the first goal has brought the
    // reference.
    let second = rig.send(min_jerk(&robot.joints, &b, &b, 1.5, 1));
    let (status, result) = rig.result(first);
    assert_eq!(status, GoalStatusEnum::Canceled, "{result:?}");
    assert_eq!(result.error_code, INVALID_GOAL);
    assert!(result.error_string.contains("preempted"), "{result:?}");
    let (status, result) = rig.result(second);
    assert_eq!(status, GoalStatusEnum::Succeeded, "{result:?}");
    std::thread::sleep(Duration::from_millis(100));
    let end = rig.measured_now();
    assert!(max_diff(&end, &b) <= 1e-3, "{end:?} vs {b:?}");
    let worst = assert_within_limits(&rig.commands.since(from), &robot.limits, "preemption");
    eprintln!(
        "preemption: commands at most {:.0} % of a limit",
        worst * 100.0
    );
}
