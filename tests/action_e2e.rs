//! End to end over DDS (loopback only): a Rust cell controller drives the trajectory executor
//! through `control_msgs/action/FollowJointTrajectory`: success, rejection with reasons,
//! preemption, cancel, and the `~/validate_trajectory` dry-run service.
//!
//! Each test runs its own executor (in this process, own Context) on its own ROS domain.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::{
    thread::JoinHandle,
    time::{Duration, Instant},
};

use kerf_msgs::{
    builtin_interfaces::Duration as RosDuration,
    control_msgs::{
        FollowJointTrajectoryFeedback, FollowJointTrajectoryGoal, FollowJointTrajectoryResult,
        JointTolerance,
    },
    numbers::{
        probe::{refused_cases, with_value},
        NumberFields,
    },
    sensor_msgs::JointState,
    srv::{ValidateTrajectoryRequest, ValidateTrajectoryResponse},
    trajectory_msgs::JointTrajectory,
    RosType,
};
mod support;
use support::{max_diff, min_jerk};

use kerf_ros::{qos, KerfNode, StopToken};
use ros2_client::{
    action::{ActionClient, GoalId, GoalStatusEnum},
    Client, Publisher, ServiceMapping, Subscription,
};

const JOINTS: [&str; 6] = [
    "joint_1", "joint_2", "joint_3", "joint_4", "joint_5", "joint_6",
];
const TIMEOUT: Duration = Duration::from_secs(20);

type Fjt = ActionClient<
    FollowJointTrajectoryGoal,
    FollowJointTrajectoryResult,
    FollowJointTrajectoryFeedback,
>;

struct Cell {
    action: Fjt,
    validate: Client<ValidateTrajectoryRequest, ValidateTrajectoryResponse>,
    states: Subscription<JointState>,
    topic: Publisher<JointTrajectory>,
    last: Option<JointState>,
    /// Keeps the client node (and its Context) alive; dropped after the endpoints above.
    _client: KerfNode,
    stop: StopToken,
    executor: Option<JoinHandle<Result<(), String>>>,
}

impl Cell {
    fn start(domain: u16) -> Cell {
        Self::start_with(domain, ServiceMapping::Enhanced)
    }

    fn start_with(domain: u16, service_mapping: ServiceMapping) -> Cell {
        Self::start_full(domain, service_mapping, &[])
    }

    fn start_full(domain: u16, service_mapping: ServiceMapping, params: &[String]) -> Cell {
        let env = support::loopback(domain, service_mapping);
        let (stop, executor) = support::spawn_executor(&env, params);
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
        let states = client
            .subscription("/joint_states", JointState::ROS_TYPE, qos::state())
            .unwrap();
        let topic = support::executor_input(&mut client);
        assert!(
            client.wait_for_action_server(&action, TIMEOUT),
            "action server not discovered"
        );
        assert!(
            client.wait_for_service(&validate, TIMEOUT),
            "validate service not discovered"
        );
        let mut cell = Cell {
            action,
            validate,
            states,
            topic,
            last: None,
            _client: client,
            stop,
            executor: Some(executor),
        };
        cell.wait_state(|_| true, "first joint state");
        cell
    }

    /// Reads joint states until `pred` holds for one; returns every state read on the way.
    fn wait_state(
        &mut self,
        mut pred: impl FnMut(&JointState) -> bool,
        what: &str,
    ) -> Vec<JointState> {
        let deadline = Instant::now() + TIMEOUT;
        let mut seen = Vec::new();
        while Instant::now() < deadline {
            match self.states.take() {
                Ok(Some((s, _))) => {
                    self.last = Some(s.clone());
                    seen.push(s.clone());
                    if pred(&s) {
                        return seen;
                    }
                }
                Ok(None) => std::thread::sleep(Duration::from_millis(1)),
                Err(e) => panic!("reading joint states: {e:?}"),
            }
        }
        panic!("timed out waiting for {what}; last state {:?}", self.last);
    }

    fn position(&mut self) -> Vec<f64> {
        self.wait_state(|_| true, "a joint state");
        self.last.as_ref().map(|s| s.position.clone()).unwrap()
    }

    fn send(&self, goal: FollowJointTrajectoryGoal) -> GoalId {
        let (req, id) = self.action.send_goal(goal).expect("send goal");
        let deadline = Instant::now() + TIMEOUT;
        loop {
            if let Some(resp) = self
                .action
                .receive_goal_response(req)
                .expect("goal response")
            {
                assert!(
                    resp.accepted,
                    "kerf accepts every goal and reports problems in the result"
                );
                return id;
            }
            assert!(Instant::now() < deadline, "no goal response");
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    fn result(&self, id: GoalId) -> (GoalStatusEnum, FollowJointTrajectoryResult) {
        let req = self.action.request_result(id).expect("request result");
        let deadline = Instant::now() + TIMEOUT;
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
        let deadline = Instant::now() + TIMEOUT;
        loop {
            if let Some((id, resp)) = self.validate.receive_response().expect("validate response") {
                if id == req {
                    return resp;
                }
            }
            assert!(Instant::now() < deadline, "no validate response");
            std::thread::sleep(Duration::from_millis(2));
        }
    }
}

impl Drop for Cell {
    fn drop(&mut self) {
        support::stop_and_join(&self.stop, &mut self.executor);
    }
}

fn goal(trajectory: JointTrajectory) -> FollowJointTrajectoryGoal {
    FollowJointTrajectoryGoal {
        trajectory,
        ..Default::default()
    }
}

#[test]
fn follows_a_goal_and_reports_success() {
    let mut cell = Cell::start(41);
    let start = cell.position();
    let target = [0.3, -0.2, 0.25, 0.5, -0.4, 1.0];
    // Joints in another order than the model's: the executor maps them by name.
    let order = [5, 2, 0, 4, 1, 3];
    let names: Vec<&str> = order.iter().map(|&i| JOINTS[i]).collect();
    let from: Vec<f64> = order.iter().map(|&i| start[i]).collect();
    let to: Vec<f64> = order.iter().map(|&i| target[i]).collect();
    let id = cell.send(goal(min_jerk(&names, &from, &to, 1.5, 15)));
    let (status, result) = cell.result(id);
    assert_eq!(status, GoalStatusEnum::Succeeded, "{result:?}");
    assert_eq!(result.error_code, FollowJointTrajectoryResult::SUCCESSFUL);
    cell.wait_state(
        |s| max_diff(&s.position, &target) < 1e-6,
        "arrival at the target",
    );
}

/// `RMW_IMPLEMENTATION=rmw_cyclonedds_cpp` selects Cyclone's request/reply mapping for the
/// action's services; a client with the same mapping drives the executor.
#[test]
fn follows_a_goal_with_the_cyclone_rpc_mapping() {
    let mut cell = Cell::start_with(45, ServiceMapping::Cyclone);
    let start = cell.position();
    let target = [-0.2; 6];
    let id = cell.send(goal(min_jerk(&JOINTS, &start, &target, 1.0, 10)));
    let (status, result) = cell.result(id);
    assert_eq!(status, GoalStatusEnum::Succeeded, "{result:?}");
    cell.wait_state(
        |s| max_diff(&s.position, &target) < 1e-6,
        "arrival at the target",
    );
}

#[test]
fn refuses_bad_goals_with_code_and_reason_and_keeps_serving() {
    let mut cell = Cell::start(42);
    let start = cell.position();
    let target = [0.2; 6];

    let mut unknown = min_jerk(&JOINTS, &start, &target, 1.0, 5);
    unknown.joint_names[2] = "joint_7".into();
    let (status, r) = cell.result(cell.send(goal(unknown)));
    assert_eq!(status, GoalStatusEnum::Aborted);
    assert_eq!(r.error_code, FollowJointTrajectoryResult::INVALID_JOINTS);
    assert!(r.error_string.contains("joint_7"), "{}", r.error_string);

    let mut nan = min_jerk(&JOINTS, &start, &target, 1.0, 5);
    nan.points[2].positions[4] = f64::NAN;
    let (status, r) = cell.result(cell.send(goal(nan)));
    assert_eq!(status, GoalStatusEnum::Aborted);
    assert_eq!(r.error_code, FollowJointTrajectoryResult::INVALID_GOAL);
    assert!(r.error_string.contains("joint_5"), "{}", r.error_string);

    // 0.2 rad in 0.05 s: far over joint_1's 1.92 rad/s somewhere on the curve.
    let fast = min_jerk(&JOINTS, &start, &target, 0.05, 3);
    let (status, r) = cell.result(cell.send(goal(fast.clone())));
    assert_eq!(status, GoalStatusEnum::Aborted);
    assert!(
        r.error_string.contains("velocity") || r.error_string.contains("acceleration"),
        "{}",
        r.error_string
    );
    let v = cell.validate(fast);
    assert!(!v.valid);
    assert_eq!(v.error_code, FollowJointTrajectoryResult::INVALID_GOAL);

    // Nothing moved.
    assert!(max_diff(&cell.position(), &start) < 1e-12);

    // Still serving: a valid goal succeeds.
    let ok = min_jerk(&JOINTS, &start, &target, 1.0, 10);
    let v = cell.validate(ok.clone());
    assert!(v.valid, "{}", v.message);
    assert!((v.duration - 1.0).abs() < 1e-9);
    let (status, r) = cell.result(cell.send(goal(ok)));
    assert_eq!(status, GoalStatusEnum::Succeeded, "{r:?}");
    cell.wait_state(|s| max_diff(&s.position, &target) < 1e-6, "arrival");
}

/// Issue 33, item 1: NaN, infinite and huge numbers in a goal or a validate request are
/// refused by their declared rules (kerf_msgs::numbers), the field named, and the executor
/// keeps serving.
#[test]
fn refuses_bad_numbers_naming_the_field_and_keeps_serving() {
    let mut cell = Cell::start(47);
    let start = cell.position();
    let target = [0.2; 6];
    type Set = fn(&mut JointTrajectory);
    let cases: [(&str, Set); 4] = [
        ("points[1].velocities[0]", |t| {
            t.points[1].velocities[0] = f64::INFINITY
        }),
        ("points[2].positions[3]", |t| {
            t.points[2].positions[3] = 1e308
        }),
        ("points[0].accelerations[5]", |t| {
            t.points[0].accelerations[5] = f64::NEG_INFINITY
        }),
        ("points[4].time_from_start.sec", |t| {
            t.points[4].time_from_start.sec = i32::MAX
        }),
    ];
    for (field, set) in cases {
        let mut bad = min_jerk(&JOINTS, &start, &target, 1.0, 5);
        set(&mut bad);
        let (status, r) = cell.result(cell.send(goal(bad.clone())));
        assert_eq!(status, GoalStatusEnum::Aborted);
        assert_eq!(r.error_code, FollowJointTrajectoryResult::INVALID_GOAL);
        assert!(
            r.error_string.contains(&format!("`trajectory.{field}`")),
            "{}",
            r.error_string
        );
        let v = cell.validate(bad);
        assert!(!v.valid);
        assert_eq!(v.error_code, FollowJointTrajectoryResult::INVALID_GOAL);
        assert!(
            v.message.contains(&format!("`trajectory.{field}`")),
            "{}",
            v.message
        );
    }
    let mut late = goal(min_jerk(&JOINTS, &start, &target, 1.0, 5));
    late.goal_time_tolerance.nanosec = u32::MAX;
    let (status, r) = cell.result(cell.send(late));
    assert_eq!(status, GoalStatusEnum::Aborted);
    assert!(
        r.error_string.contains("`goal_time_tolerance.nanosec`"),
        "{}",
        r.error_string
    );
    // Nothing moved, and a valid goal still succeeds.
    assert!(max_diff(&cell.position(), &start) < 1e-12);
    let (status, r) = cell.result(cell.send(goal(min_jerk(&JOINTS, &start, &target, 1.0, 10))));
    assert_eq!(status, GoalStatusEnum::Succeeded, "{r:?}");
}

#[test]
fn a_new_goal_preempts_the_active_one_without_a_jump() {
    let mut cell = Cell::start(43);
    let start = cell.position();
    let far = [1.0, 0.5, 0.8, 1.5, 1.0, 2.0];
    let a = cell.send(goal(min_jerk(&JOINTS, &start, &far, 4.0, 20)));
    // Let it get under way, then replace it with a goal that starts where the robot is.
    let seen = cell.wait_state(|s| s.velocity.iter().any(|v| v.abs() > 0.2), "motion");
    let here = seen.last().unwrap().position.clone();
    let back = [0.1; 6];
    // First point 0.5 s ahead: the executor interpolates from its current state to it.
    let mut tr = min_jerk(&JOINTS, &here, &back, 3.0, 15);
    for p in &mut tr.points {
        let t = p.time_from_start.as_secs_f64() + 0.5;
        p.time_from_start = RosDuration::from_secs_f64(t).unwrap();
    }
    let b = cell.send(goal(tr));
    let (status_a, ra) = cell.result(a);
    assert_eq!(status_a, GoalStatusEnum::Canceled, "{ra:?}");
    assert!(ra.error_string.contains("preempted"), "{}", ra.error_string);
    let seen = cell.wait_state(
        |s| max_diff(&s.position, &back) < 1e-6,
        "arrival at the second target",
    );
    let (status_b, rb) = cell.result(b);
    assert_eq!(status_b, GoalStatusEnum::Succeeded, "{rb:?}");
    // Continuity across the switch: no sample-to-sample jump larger than joint_1's velocity
    // limit allows (1.92 rad/s), allowing for a dropped sample or two.
    for w in seen.windows(2) {
        let dt = (w[1].header.stamp.as_secs_f64() - w[0].header.stamp.as_secs_f64()).max(0.004);
        let step = max_diff(&w[0].position, &w[1].position);
        assert!(
            step <= 2.62 * dt * 1.01 + 1e-9,
            "jump of {step} rad in {dt} s"
        );
    }
}

#[test]
fn cancel_stops_the_motion_within_the_limits() {
    let mut cell = Cell::start(44);
    let start = cell.position();
    let far = [1.0, 0.5, 0.8, 1.5, 1.0, 2.0];
    let id = cell.send(goal(min_jerk(&JOINTS, &start, &far, 4.0, 20)));
    cell.wait_state(|s| s.velocity.iter().any(|v| v.abs() > 0.2), "motion");
    let req = cell.action.cancel_goal(id).expect("cancel");
    let deadline = Instant::now() + TIMEOUT;
    let resp = loop {
        if let Some(r) = cell
            .action
            .receive_cancel_response(req)
            .expect("cancel response")
        {
            break r;
        }
        assert!(Instant::now() < deadline, "no cancel response");
        std::thread::sleep(Duration::from_millis(2));
    };
    assert_eq!(resp.goals_canceling.len(), 1);
    let (status, r) = cell.result(id);
    assert_eq!(status, GoalStatusEnum::Canceled, "{r:?}");
    let stopped = cell.wait_state(|s| s.velocity.iter().all(|v| *v == 0.0), "standstill");
    let end = &stopped.last().unwrap().position;
    assert!(
        max_diff(end, &far) > 0.1,
        "the canceled motion must not reach its target"
    );
    // Velocity changes respect the largest acceleration limit (5 rad/s², joint_4). Measured
    // over windows of 10 samples (40 ms): a published state is the previous cycle's command,
    // as with ros2_control's mock hardware, so single-sample differences carry stamp jitter.
    for w in stopped.windows(11) {
        let dt = w[10].header.stamp.as_secs_f64() - w[0].header.stamp.as_secs_f64();
        let dv = max_diff(&w[0].velocity, &w[10].velocity);
        assert!(
            dv / dt <= 5.0 * 1.3,
            "velocity change {} rad/s² over {dt} s",
            dv / dt
        );
    }
}

/// As in JTC, an empty trajectory on the topic interface stops the current motion, here also
/// an action goal's: it ends CANCELED and the robot comes to rest short of its target.
#[test]
fn an_empty_topic_trajectory_stops_the_active_goal() {
    let mut cell = Cell::start(46);
    let start = cell.position();
    let far = [1.0, 0.5, 0.8, 1.5, 1.0, 2.0];
    let id = cell.send(goal(min_jerk(&JOINTS, &start, &far, 4.0, 20)));
    cell.wait_state(|s| s.velocity.iter().any(|v| v.abs() > 0.2), "motion");
    cell.topic
        .publish(JointTrajectory::default())
        .expect("publish");
    let (status, r) = cell.result(id);
    assert_eq!(status, GoalStatusEnum::Canceled, "{r:?}");
    let stopped = cell.wait_state(|s| s.velocity.iter().all(|v| *v == 0.0), "standstill");
    assert!(max_diff(&stopped.last().unwrap().position, &far) > 0.1);
}

/// Path and goal tolerances from the goal are honoured: with hardware that lags its commands
/// (first-order, 50 ms), a tight path tolerance aborts the goal with PATH_TOLERANCE_VIOLATED
/// and a loose one lets it succeed.
#[test]
fn path_tolerances_from_the_goal_are_honoured() {
    let mut cell = Cell::start_full(
        47,
        ServiceMapping::Enhanced,
        &["hardware.lag_time_constant:=0.05".to_string()],
    );
    let start = cell.position();
    let target = [0.4; 6];
    let tolerance = |position: f64| {
        JOINTS
            .iter()
            .map(|j| kerf_msgs::control_msgs::JointTolerance {
                name: j.to_string(),
                position,
                velocity: 0.0,
                acceleration: 0.0,
            })
            .collect::<Vec<_>>()
    };
    let mut tight = goal(min_jerk(&JOINTS, &start, &target, 1.0, 10));
    tight.path_tolerance = tolerance(0.001);
    let (status, r) = cell.result(cell.send(tight));
    assert_eq!(status, GoalStatusEnum::Aborted, "{r:?}");
    assert_eq!(
        r.error_code,
        FollowJointTrajectoryResult::PATH_TOLERANCE_VIOLATED
    );
    assert!(
        r.error_string.contains("path tolerance"),
        "{}",
        r.error_string
    );
    let here = cell
        .wait_state(|s| s.velocity.iter().all(|v| v.abs() < 1e-6), "standstill")
        .last()
        .unwrap()
        .position
        .clone();

    let mut loose = goal(min_jerk(&JOINTS, &here, &target, 1.0, 10));
    loose.path_tolerance = tolerance(0.5);
    loose.goal_tolerance = tolerance(0.01);
    loose.goal_time_tolerance = RosDuration::from_secs_f64(2.0).unwrap();
    let (status, r) = cell.result(cell.send(loose));
    assert_eq!(status, GoalStatusEnum::Succeeded, "{r:?}");
}

/// Issue 33, item 8 (the probe as a test): every numeric leaf of a goal with every group given
/// (of each array, its first and last element), set in turn to each of NaN, ±inf, ±0, 5e-324,
/// ±1e308 and the integer extremes that its declared rule refuses, is refused INVALID_GOAL
/// naming the field, through the action and (for the trajectory's) the validate service,
/// each within 15 s; nothing moves, and a valid goal right after succeeds.
#[test]
fn every_number_of_a_goal_is_refused_naming_it() {
    let mut cell = Cell::start(52);
    let start = cell.position();
    let target = [0.2; 6];
    let tolerance = |name: &str| JointTolerance {
        name: name.into(),
        position: 0.1,
        velocity: 0.5,
        acceleration: 1.0,
    };
    let mut base = goal(min_jerk(&JOINTS, &start, &target, 1.0, 5));
    base.path_tolerance = vec![tolerance("joint_1"), tolerance("joint_6")];
    base.goal_tolerance = vec![tolerance("joint_2"), tolerance("joint_5")];
    base.goal_time_tolerance = RosDuration { sec: 1, nanosec: 0 };
    base.check_numbers().expect("the base goal's numbers");
    let mut cases = 0;
    for (path, v) in refused_cases(&base) {
        let Ok(bad) = with_value(&base, &path, v) else {
            continue; // a value the field's type cannot hold
        };
        let needle = format!("`{path}`");
        let asked = Instant::now();
        let (status, r) = cell.result(cell.send(bad.clone()));
        assert_eq!(status, GoalStatusEnum::Aborted, "{path}: {r:?}");
        assert_eq!(r.error_code, FollowJointTrajectoryResult::INVALID_GOAL);
        assert!(r.error_string.contains(&needle), "{}", r.error_string);
        if path.starts_with("trajectory.") {
            let v = cell.validate(bad.trajectory);
            assert!(!v.valid);
            assert_eq!(v.error_code, FollowJointTrajectoryResult::INVALID_GOAL);
            assert!(v.message.contains(&needle), "{}", v.message);
        }
        assert!(asked.elapsed() < Duration::from_secs(15), "{path}");
        cases += 1;
    }
    assert!(cases > 40, "only {cases} cases");
    eprintln!("{cases} number cases refused naming the field");
    assert!(max_diff(&cell.position(), &start) < 1e-12, "nothing moved");
    let (status, r) = cell.result(cell.send(base));
    assert_eq!(status, GoalStatusEnum::Succeeded, "{r:?}");
    cell.wait_state(|s| max_diff(&s.position, &target) < 1e-6, "arrival");
}
