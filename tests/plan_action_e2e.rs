//! Planning as a ROS 2 action (issue 27, item 3), end to end over loopback DDS with the MJTO
//! planner node and, where it executes, the laser cutter's trajectory executor:
//!
//! * a `kerf_msgs/action/PlanCut` goal with case 1 and `execute: false` SUCCEEDS with the plan
//!   (framed from the robot's state), its feedback goes through `queued` and `planning`, and
//!   the answer is also published on `~/cut_plan` (but not on `~/joint_trajectory`);
//! * with `execute: true` the plan runs on the executor's `FollowJointTrajectory` action and
//!   the goal SUCCEEDS with `executed`, error code 0, after `executing` feedback;
//! * a cancel takes a queued goal out of the queue and stops a plan in progress, each answered
//!   CANCELED (the latencies are printed, not asserted beyond a 1 s hang guard), and the next
//!   goal is planned;
//! * a goal with a NaN is ABORTED with INVALID_REQUEST naming the field; a goal over the queue
//!   is ABORTED with QUEUE_FULL; a goal sent while the node stops is ABORTED saying so;
//! * with a planning service that never checks its budget, a cancelled plan's worker process
//!   is stopped after the harness's 80 ms grace, the goal is CANCELED, and the next goal is
//!   planned by a fresh worker;
//! * a goal with `execute` and no executor is ABORTED after the 3 s discovery timeout, with its
//!   plan and a message naming the action.
//!
//! Each test runs its own nodes (in this process, own Contexts) on its own domain (200-206).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::{
    cell::RefCell,
    collections::BTreeMap,
    path::Path,
    time::{Duration, Instant},
};

use kerf_mjto::CutRequest;
use kerf_msgs::{
    action::{PlanCutFeedback, PlanCutGoal, PlanCutResult},
    geometry_msgs::{Point, Pose, Vector3},
    msg::{self, CutPlan, TrajectoryStatus},
};
use kerf_msgs::{msg::GcodePlan, std_msgs::StringMsg};
use kerf_ros::{
    planner::{
        self,
        goal_msgs::{PlanFeedback, PlanGoal, PlanResult},
        HarnessSettings,
    },
    KerfNode,
};
use ros2_client::{
    action::{ActionClient, GoalId, GoalStatusEnum},
    RmwRequestId, ServiceMapping,
};

#[allow(dead_code)] // shared with the other end-to-end tests
mod support;
use support::{expect, planner::mjto, PlannerClient, QUICK};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");
/// Waiting for an answer that runs the planner (debug builds are slow).
const PLANNING: Duration = Duration::from_secs(300);
/// Where the executor starts the laser cutter (as `tests/mjto_e2e.rs`).
const HOME: [f64; 6] = [0.8, 0.7, 1.5, 0.0, 0.0, -0.05];
/// A hang guard for a cancel (the design figure is 100 ms: BENCHMARKS.md).
const CANCEL_GUARD: Duration = Duration::from_secs(1);

type PlanCut = ActionClient<PlanCutGoal, PlanCutResult, PlanCutFeedback>;

fn case1() -> CutRequest {
    let path = Path::new(ROOT).join("crates/mjto/cases/case1.yaml");
    CutRequest::from_yaml(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Case 1 with the largest GFD grid and an RTO every 2 cm: plans for over a minute (as in
/// `tests/deadline_e2e.rs`).
fn long_request(id: &str) -> msg::CutRequest {
    let mut r = case1();
    r.request_id = id.into();
    r.options.gfd.q4_steps = 25;
    r.options.gfd.q5_steps = 25;
    r.options.gfd.q6_steps = 15;
    r.options.rto_indices.clear();
    r.options.rto_spacing = 0.02;
    support::requests::cut_msg(&r)
}

/// Nine CL points 5 mm apart on the B-pillar's flange, in case 1's workpiece pose: planned in
/// milliseconds (the README's `ros2 action send_goal` example).
fn short_request(id: &str) -> msg::CutRequest {
    let n = 9;
    msg::CutRequest {
        request_id: id.into(),
        points: (0..n)
            .map(|i| Point {
                x: 0.6 + 0.005 * i as f64,
                y: -0.1776,
                z: 0.0,
            })
            .collect(),
        axes: vec![
            Vector3 {
                x: 0.0,
                y: 0.0,
                z: 1.0
            };
            n
        ],
        feedrate: 0.3333,
        sample_period: 0.004,
        max_lead_angle: 0.087,
        max_tilt_angle: 0.087,
        mesh: "package://kerf/urdf/meshes/bpillar.obj".into(),
        workpiece_pose: case1_pose(),
        ..msg::CutRequest::default()
    }
}

fn case1_pose() -> Pose {
    support::requests::cut_msg(&case1()).workpiece_pose
}

/// A goal sent: its id and its result request.
struct Sent {
    id: GoalId,
    result: RmwRequestId,
}

/// A client of `/mjto_planner/plan_cut` keeping every result and feedback it reads (ros2-client's
/// own `receive_result` drops the answers of other requests).
struct Goals {
    client: PlanCut,
    results: RefCell<BTreeMap<RmwRequestId, (Instant, GoalStatusEnum, PlanCutResult)>>,
    feedback: RefCell<BTreeMap<GoalId, Vec<PlanCutFeedback>>>,
    /// Keeps the client node (and its Context) alive; dropped after the client.
    _node: KerfNode,
}

impl Goals {
    fn connect(env: &kerf_ros::RosEnv) -> Goals {
        let mut node = support::client_node("plan_cut_client", env);
        let client: PlanCut = node
            .action_client("/mjto_planner/plan_cut", "kerf_msgs/action/PlanCut")
            .unwrap();
        assert!(
            node.wait_for_action_server(&client, 3 * QUICK),
            "the planner's plan_cut action was not discovered"
        );
        Goals {
            client,
            results: RefCell::default(),
            feedback: RefCell::default(),
            _node: node,
        }
    }

    /// Sends a goal, waits for its acceptance and asks for its result.
    fn send(&self, request: msg::CutRequest, execute: bool) -> Sent {
        let (req, id) = self
            .client
            .send_goal(PlanCutGoal { request, execute })
            .expect("send goal");
        let deadline = Instant::now() + QUICK;
        loop {
            if let Some(resp) = self
                .client
                .receive_goal_response(req)
                .expect("goal response")
            {
                assert!(resp.accepted, "the planner accepts every goal");
                break;
            }
            assert!(Instant::now() < deadline, "no goal response");
            std::thread::sleep(Duration::from_millis(1));
        }
        let result = self.client.request_result(id).expect("request result");
        Sent { id, result }
    }

    /// Reads what has arrived.
    fn pump(&self) {
        while let Ok(Some((m, _))) = self.client.feedback_subscription().take() {
            self.feedback
                .borrow_mut()
                .entry(m.goal_id)
                .or_default()
                .push(m.feedback);
        }
        while let Ok(Some((req, r))) = self.client.result_client().receive_response() {
            self.results
                .borrow_mut()
                .insert(req, (Instant::now(), r.status, r.result));
        }
    }

    /// The result of a goal, waiting up to `timeout`, and when it arrived.
    fn result(&self, sent: &Sent, timeout: Duration) -> (Instant, GoalStatusEnum, PlanCutResult) {
        let deadline = Instant::now() + timeout;
        loop {
            self.pump();
            if let Some(r) = self.results.borrow_mut().remove(&sent.result) {
                return r;
            }
            assert!(
                Instant::now() < deadline,
                "no result for goal {:?} within {timeout:?}",
                sent.id
            );
            std::thread::sleep(Duration::from_millis(1));
        }
    }

    /// Whether the goal's result has arrived (without taking it).
    fn has_result(&self, sent: &Sent) -> bool {
        self.pump();
        self.results.borrow().contains_key(&sent.result)
    }

    /// Waits for a feedback of the goal at `stage`.
    fn wait_stage(&self, sent: &Sent, stage: &str, timeout: Duration) -> PlanCutFeedback {
        let deadline = Instant::now() + timeout;
        loop {
            self.pump();
            if let Some(f) = self
                .feedback
                .borrow()
                .get(&sent.id)
                .and_then(|v| v.iter().rev().find(|f| f.stage == stage).cloned())
            {
                return f;
            }
            assert!(
                Instant::now() < deadline,
                "no '{stage}' feedback for goal {:?}",
                sent.id
            );
            std::thread::sleep(Duration::from_millis(1));
        }
    }

    /// Every feedback of the goal read so far.
    fn feedback_of(&self, sent: &Sent) -> Vec<PlanCutFeedback> {
        self.pump();
        self.feedback
            .borrow()
            .get(&sent.id)
            .cloned()
            .unwrap_or_default()
    }

    /// Cancels a goal: the time from the cancel request to its CANCELED result.
    fn cancel(&self, sent: &Sent) -> (Duration, PlanCutResult) {
        let at = Instant::now();
        self.client.cancel_goal(sent.id).expect("cancel request");
        let (when, status, result) = self.result(sent, CANCEL_GUARD);
        assert_eq!(status, GoalStatusEnum::Canceled, "{}", result.plan.message);
        (when - at, result)
    }
}

/// The stages of a goal's feedback in order, repeats removed.
fn stages(feedback: &[PlanCutFeedback]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for f in feedback {
        if out.last() != Some(&f.stage) {
            out.push(f.stage.clone());
        }
    }
    out
}

fn assert_starts_at_home(plan: &CutPlan) {
    let first = &plan.trajectory.points[0].positions;
    for (got, want) in first.iter().zip(HOME) {
        assert!((got - want).abs() < 1e-9, "the plan starts at {first:?}");
    }
}

#[test]
fn a_goal_is_planned_with_feedback_and_published() {
    let env = support::loopback(200, ServiceMapping::Enhanced);
    let (exec_stop, executor) =
        support::spawn_robot_executor(&env, "laser_cutter", &[support::initial_positions(&HOME)]);
    let planner = PlannerClient::start(&mjto(), &env, &[]);
    let goals = Goals::connect(&env);
    // The planner frames plans from the robot's state: let it receive one.
    std::thread::sleep(Duration::from_millis(500));

    let t = Instant::now();
    let mut request = support::requests::cut_msg(&case1());
    request.request_id = "action-case1".into();
    let sent = goals.send(request, false);
    let (_, status, result) = goals.result(&sent, PLANNING);
    println!(
        "case 1 planned by action in {:.2} s",
        t.elapsed().as_secs_f64()
    );
    assert_eq!(status, GoalStatusEnum::Succeeded, "{}", result.plan.message);
    expect(&result.plan, "action-case1", CutPlan::SUCCESS, &["planned"]);
    assert!(!result.executed);
    assert_eq!(result.execution_error_code, 0);
    assert!(
        result.execution_message.contains("execute is false"),
        "{}",
        result.execution_message
    );
    let feedback = goals.feedback_of(&sent);
    assert_eq!(
        stages(&feedback),
        [
            PlanCutFeedback::STAGE_QUEUED,
            PlanCutFeedback::STAGE_PLANNING
        ],
        "{feedback:?}"
    );
    for f in &feedback {
        assert!((0.0..=1.0).contains(&f.progress), "{f:?}");
        assert!(f.elapsed >= 0.0, "{f:?}");
        if f.stage == PlanCutFeedback::STAGE_PLANNING {
            assert_eq!(f.queue_position, 0, "{f:?}");
        }
    }
    // The answer on the plan topic, whole: framed from the robot's state. The result carries
    // all of it but the trajectory's points (over the 60 000 bytes one loopback datagram
    // carries: kerf_ros::planner::result_fit), and says so.
    let on_topic = planner.next_plan(QUICK);
    assert_starts_at_home(&on_topic);
    assert!(result.plan.trajectory.points.is_empty());
    assert!(
        result
            .plan
            .message
            .contains("trajectory's points left out of this action result")
            && result
                .plan
                .message
                .contains("the full answer is on /mjto_planner/cut_plan"),
        "{}",
        result.plan.message
    );
    let mut without_points = on_topic.clone();
    without_points.trajectory.points.clear();
    without_points.message = result.plan.message.clone();
    assert_eq!(without_points, result.plan);
    assert!(result.plan.message.starts_with(&on_topic.message));

    // A plan that fits one datagram (no approach: start "none") comes whole.
    let mut request = short_request("action-short");
    request.start = msg::CutRequest::START_NONE.into();
    let sent = goals.send(request, false);
    let (_, status, result) = goals.result(&sent, PLANNING);
    assert_eq!(status, GoalStatusEnum::Succeeded, "{}", result.plan.message);
    assert!(!result.plan.trajectory.points.is_empty());
    assert_eq!(planner.next_plan(QUICK), result.plan);

    // No trajectory on ~/joint_trajectory: a goal executes only by its execute flag.
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(planner.trajectories_received(), 0);

    drop(goals);
    planner.finish();
    exec_stop.stop();
    executor.join().unwrap().unwrap();
}

#[test]
fn a_goal_with_execute_runs_on_the_executor() {
    let env = support::loopback(201, ServiceMapping::Enhanced);
    let (exec_stop, executor) =
        support::spawn_robot_executor(&env, "laser_cutter", &[support::initial_positions(&HOME)]);
    let planner = PlannerClient::start(&mjto(), &env, &[]);
    let goals = Goals::connect(&env);
    let mut watch = support::client_node("plan_cut_watch", &env);
    let (_states, statuses) = support::watch_executor(&mut watch);
    std::thread::sleep(Duration::from_millis(500));

    let t = Instant::now();
    let mut request = support::requests::cut_msg(&case1());
    request.request_id = "action-case1-execute".into();
    let sent = goals.send(request, true);
    let (_, status, result) = goals.result(&sent, PLANNING);
    println!(
        "case 1 planned and executed by action in {:.2} s",
        t.elapsed().as_secs_f64()
    );
    assert_eq!(
        status,
        GoalStatusEnum::Succeeded,
        "{} / {}",
        result.plan.message,
        result.execution_message
    );
    expect(
        &result.plan,
        "action-case1-execute",
        CutPlan::SUCCESS,
        &["planned"],
    );
    // What ran: the plan framed from where the robot stood.
    let on_topic = planner.next_plan(QUICK);
    assert_eq!(on_topic.request_id, "action-case1-execute");
    assert_starts_at_home(&on_topic);
    assert!(result.executed, "{}", result.execution_message);
    assert_eq!(result.execution_error_code, 0);
    assert!(
        result.execution_message.starts_with("SUCCEEDED"),
        "{}",
        result.execution_message
    );
    let feedback = goals.feedback_of(&sent);
    assert_eq!(
        stages(&feedback),
        [
            PlanCutFeedback::STAGE_QUEUED,
            PlanCutFeedback::STAGE_PLANNING,
            PlanCutFeedback::STAGE_EXECUTING
        ],
    );
    let executed = feedback
        .iter()
        .filter(|f| f.stage == PlanCutFeedback::STAGE_EXECUTING)
        .map(|f| f.progress)
        .fold(0.0, f64::max);
    assert!(executed > 0.9, "executing progress reached {executed}");
    // The executor ran it as an action goal, to its end.
    let mut seen = Vec::new();
    let deadline = Instant::now() + QUICK;
    while !seen.contains(&TrajectoryStatus::SUCCEEDED) && Instant::now() < deadline {
        while let Ok(Some((s, _))) = statuses.take() {
            assert_eq!(s.source, TrajectoryStatus::SOURCE_ACTION, "{s:?}");
            seen.push(s.status);
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(
        seen.contains(&TrajectoryStatus::SUCCEEDED),
        "executor statuses {seen:?}"
    );

    drop((goals, statuses, _states, watch));
    planner.finish();
    exec_stop.stop();
    executor.join().unwrap().unwrap();
}

#[test]
fn cancel_stops_a_queued_goal_and_a_plan_in_progress() {
    let env = support::loopback(202, ServiceMapping::Enhanced);
    let planner = PlannerClient::start(&mjto(), &env, &[]);
    let goals = Goals::connect(&env);

    let long = goals.send(long_request("long"), false);
    goals.wait_stage(&long, PlanCutFeedback::STAGE_PLANNING, QUICK);
    // Deep in the plan (GFDs and RTO selection).
    std::thread::sleep(Duration::from_millis(500));
    let queued = goals.send(short_request("queued"), false);
    let f = goals.wait_stage(&queued, PlanCutFeedback::STAGE_QUEUED, QUICK);
    assert_eq!(f.queue_position, 1, "{f:?}");
    assert_eq!(f.progress, 0.0);

    let (queued_latency, result) = goals.cancel(&queued);
    expect(
        &result.plan,
        "queued",
        CutPlan::INTERNAL_ERROR,
        &["canceled", "while queued"],
    );
    assert!(!result.executed);
    assert!(!goals.has_result(&long), "the plan in progress goes on");

    let (running_latency, result) = goals.cancel(&long);
    expect(&result.plan, "long", CutPlan::INTERNAL_ERROR, &["canceled"]);
    println!(
        "cancel → CANCELED: queued goal {:.1} ms, plan in progress {:.1} ms ({})",
        queued_latency.as_secs_f64() * 1e3,
        running_latency.as_secs_f64() * 1e3,
        result.plan.message
    );
    // Both answers are on the plan topic too.
    let mut answered: Vec<String> = (0..2)
        .map(|_| planner.next_plan(QUICK).request_id)
        .collect();
    answered.sort();
    assert_eq!(answered, ["long", "queued"]);

    // The node plans the next goal.
    let next = goals.send(short_request("next"), false);
    let (_, status, result) = goals.result(&next, PLANNING);
    assert_eq!(status, GoalStatusEnum::Succeeded, "{}", result.plan.message);
    expect(&result.plan, "next", CutPlan::SUCCESS, &[]);

    drop(goals);
    planner.finish();
}

#[test]
fn a_goal_with_a_nan_is_aborted_naming_the_field() {
    let env = support::loopback(203, ServiceMapping::Enhanced);
    let planner = PlannerClient::start(&mjto(), &env, &[]);
    let goals = Goals::connect(&env);

    let mut request = short_request("nan-feedrate");
    request.feedrate = f64::NAN;
    let sent = goals.send(request, true);
    let (_, status, result) = goals.result(&sent, QUICK);
    assert_eq!(status, GoalStatusEnum::Aborted);
    expect(
        &result.plan,
        "nan-feedrate",
        CutPlan::INVALID_REQUEST,
        &["feedrate", "NaN"],
    );
    assert!(!result.executed);
    assert!(
        result.execution_message.contains("the plan failed"),
        "{}",
        result.execution_message
    );

    let mut request = short_request("nan-point");
    request.points[3].y = f64::NAN;
    let sent = goals.send(request, false);
    let (_, status, result) = goals.result(&sent, QUICK);
    assert_eq!(status, GoalStatusEnum::Aborted);
    expect(
        &result.plan,
        "nan-point",
        CutPlan::INVALID_REQUEST,
        &["points[3].y"],
    );
    // As on the topic: the same answers on ~/cut_plan, in arrival order.
    assert_eq!(planner.next_plan(QUICK).request_id, "nan-feedrate");
    assert_eq!(planner.next_plan(QUICK).request_id, "nan-point");

    drop(goals);
    planner.finish();
}

#[test]
fn execute_without_an_executor_is_aborted() {
    let env = support::loopback(206, ServiceMapping::Enhanced);
    let planner = PlannerClient::start(&mjto(), &env, &[]);
    let goals = Goals::connect(&env);

    let mut request = short_request("no-executor");
    request.start = msg::CutRequest::START_NONE.into();
    let t = Instant::now();
    let sent = goals.send(request, true);
    let (_, status, result) = goals.result(&sent, QUICK);
    println!(
        "no executor: ABORTED {:.2} s after the goal",
        t.elapsed().as_secs_f64()
    );
    assert_eq!(
        status,
        GoalStatusEnum::Aborted,
        "{}",
        result.execution_message
    );
    expect(&result.plan, "no-executor", CutPlan::SUCCESS, &["planned"]);
    assert!(!result.executed);
    assert!(
        result.execution_message.contains(
            "no FollowJointTrajectory server was discovered on \
             /trajectory_executor/follow_joint_trajectory within 3.0 s"
        ),
        "{}",
        result.execution_message
    );
    assert!(t.elapsed() >= Duration::from_secs(3));

    drop(goals);
    planner.finish();
}

#[test]
fn goals_over_the_queue_or_while_stopping_are_aborted() {
    let env = support::loopback(204, ServiceMapping::Enhanced);
    let planner = PlannerClient::start(&mjto(), &env, &["-p", "queue_depth:=1"]);
    let goals = Goals::connect(&env);

    let long = goals.send(long_request("long"), false);
    goals.wait_stage(&long, PlanCutFeedback::STAGE_PLANNING, QUICK);
    // The queue (depth 1) is full: topic requests and goals count together.
    let busy = goals.send(short_request("busy"), false);
    let (_, status, result) = goals.result(&busy, QUICK);
    assert_eq!(status, GoalStatusEnum::Aborted);
    expect(
        &result.plan,
        "busy",
        CutPlan::QUEUE_FULL,
        &["planner busy", "queue_depth 1"],
    );

    // The node stops (Ctrl-C): the plan in progress is answered, a new goal is ended at once.
    planner.request_stop();
    // Past the node's next turn: it is stopping (answering the plan, then lingering).
    std::thread::sleep(Duration::from_millis(100));
    let late = goals.send(short_request("late"), false);
    let (_, status, result) = goals.result(&late, QUICK);
    assert_eq!(status, GoalStatusEnum::Aborted);
    expect(&result.plan, "late", CutPlan::INTERNAL_ERROR, &["stopp"]);
    let (_, status, result) = goals.result(&long, QUICK);
    assert_eq!(status, GoalStatusEnum::Aborted);
    expect(&result.plan, "long", CutPlan::INTERNAL_ERROR, &["stopping"]);

    drop(goals);
    planner.finish();
}

type PlanFake = ActionClient<PlanGoal<StringMsg>, PlanResult<GcodePlan>, PlanFeedback>;

/// Sends a goal to the stubborn planner and waits for its result.
fn fake_goal(
    client: &PlanFake,
    data: &str,
    cancel_after: Option<Duration>,
) -> (GoalStatusEnum, GcodePlan, Duration) {
    let goal = PlanGoal {
        request: StringMsg { data: data.into() },
        execute: false,
    };
    let (req, id) = client.send_goal(goal).expect("send goal");
    let deadline = Instant::now() + QUICK;
    while client
        .receive_goal_response(req)
        .expect("goal response")
        .is_none()
    {
        assert!(Instant::now() < deadline, "no goal response");
        std::thread::sleep(Duration::from_millis(1));
    }
    let result = client.request_result(id).expect("request result");
    let mut canceled_at = None;
    if let Some(after) = cancel_after {
        std::thread::sleep(after);
        canceled_at = Some(Instant::now());
        client.cancel_goal(id).expect("cancel");
    }
    loop {
        if let Some((status, r)) = client.receive_result(result).expect("result") {
            let latency = canceled_at.map_or(Duration::ZERO, |t| t.elapsed());
            return (status, r.plan, latency);
        }
        let guard = canceled_at.map_or(deadline, |t| t + CANCEL_GUARD);
        assert!(Instant::now() < guard, "no result for {data}");
        std::thread::sleep(Duration::from_millis(1));
    }
}

fn pid_of(plan: &GcodePlan) -> u32 {
    plan.message
        .rsplit(' ')
        .next()
        .and_then(|p| p.parse().ok())
        .unwrap_or_else(|| panic!("no pid in {:?}", plan.message))
}

#[test]
fn cancel_stops_a_plan_that_never_checks_its_budget() {
    let env = support::loopback(205, ServiceMapping::Enhanced);
    let words = vec!["--ros-args".to_string(), "--disable-rosout-logs".into()];
    let (stop, node) = support::spawn_node(&env, words, |args, env, stop| {
        planner::run("stubborn_planner", &[], args, env, stop, |node| {
            let settings = HarnessSettings::from_params(node.params())?;
            Ok::<_, kerf_ros::RosError>((support::stubborn::Stubborn, settings))
        })
        .map_err(|e| e.to_string())
    });
    let mut client_node = support::client_node("fake_client", &env);
    let client: PlanFake = client_node
        .action_client("/stubborn_planner/plan_fake", "kerf_msgs/action/PlanFake")
        .unwrap();
    assert!(client_node.wait_for_action_server(&client, 3 * QUICK));

    let (status, first, _) = fake_goal(&client, "ok-1", None);
    assert_eq!(status, GoalStatusEnum::Aborted, "{}", first.message);
    assert_eq!(first.status, GcodePlan::PROGRAM_ERROR, "{}", first.message);
    let (status, spun, latency) = fake_goal(&client, "spin-2", Some(Duration::from_millis(300)));
    assert_eq!(status, GoalStatusEnum::Canceled, "{}", spun.message);
    assert_eq!(spun.status, GcodePlan::INTERNAL_ERROR);
    assert!(
        spun.message.contains("canceled") && spun.message.contains("worker process was stopped"),
        "{}",
        spun.message
    );
    println!(
        "cancel → CANCELED of a plan that never checks its budget: {:.1} ms",
        latency.as_secs_f64() * 1e3
    );
    let (status, next, _) = fake_goal(&client, "ok-3", None);
    assert_eq!(status, GoalStatusEnum::Aborted, "{}", next.message);
    assert_ne!(
        pid_of(&next),
        pid_of(&first),
        "a fresh worker plans the next goal"
    );

    drop(client);
    drop(client_node);
    stop.stop();
    node.join().unwrap().unwrap();
}
