//! The kerf trajectory executor node.
//!
//! Validates, interpolates and streams joint trajectories for one robot (URDF + limits YAML
//! given as parameters), with ros2_control's `joint_trajectory_controller` as the reference
//! semantics (see `kerf_executor` for the differences).
//!
//! | endpoint | type | |
//! |---|---|---|
//! | `~/joint_trajectory` | `trajectory_msgs/msg/JointTrajectory` | subscription |
//! | `~/follow_joint_trajectory` | `control_msgs/action/FollowJointTrajectory` | action server |
//! | `~/validate_trajectory` | `kerf_msgs/srv/ValidateTrajectory` | service (dry run) |
//! | `joint_states` | `sensor_msgs/msg/JointState` | measured state, every control cycle |
//! | `~/controller_state` | `control_msgs/msg/JointTrajectoryControllerState` | every control cycle |
//! | `~/joint_command` | `sensor_msgs/msg/JointState` | command stream for a hardware driver |
//! | `~/trajectory_status` | `kerf_msgs/msg/TrajectoryStatus` | accepted / rejected / finished |
//!
//! Validating a trajectory costs O(points · joints) (about 3 ms for 1000 six-joint quintic
//! points in a release build), more than a control period. The request-only part
//! (`kerf_executor::prepare`) therefore runs on a worker thread (`kerf_ros::Worker`), in
//! arrival order; the control loop finishes it against the current state in O(joints) and
//! never misses a cycle for it.
//!
//! As in JTC, an empty `JointTrajectory` (no points) on `~/joint_trajectory` stops the current
//! motion (here: a controlled stop within the acceleration limits) and the robot holds.
//!
//! Every cycle follows ros2_control's read → update → write order: the measured state is read
//! from the (mock) hardware, the executor computes the reference, the reference is written to
//! the hardware and published on `~/joint_command`.

pub mod action;
pub mod config;
pub mod convert;

use std::{
    collections::HashMap,
    time::{Duration as StdDuration, Instant},
};

use kerf_executor::{
    prepare, Cycle, Executor, ExecutorError, GoalId as ExecGoalId, GoalTolerances, JointSample,
    MockHardware, Outcome, PreparedTrajectory, TrajectoryRequest, ValidatedTrajectory,
    INVALID_GOAL, SUCCESSFUL,
};
use kerf_msgs::{
    builtin_interfaces::Time,
    control_msgs::{
        FollowJointTrajectoryFeedback, FollowJointTrajectoryGoal, FollowJointTrajectoryResult,
        JointTrajectoryControllerState,
    },
    msg::TrajectoryStatus,
    sensor_msgs::JointState,
    srv::{ValidateTrajectoryRequest, ValidateTrajectoryResponse},
    std_msgs::Header,
    trajectory_msgs::JointTrajectory,
    RosType,
};
use kerf_robot::RobotError;
use kerf_ros::{
    qos, Inbox, KerfNode, Logger, NodeSpec, RosArgs, RosEnv, RosError, StopToken, Streamer, Worker,
};
use ros2_client::{
    action::{
        ActionServer, CancelGoalRequest, CancelGoalResponse, GetResultResponse, GoalId, GoalInfo,
        GoalStatusEnum, SendGoalRequest, SendGoalResponse,
    },
    action_msgs::CancelGoalResponseEnum,
    builtin_interfaces::Time as RosTime,
    RmwRequestId, Server,
};

pub use config::{NodeConfig, KNOWN_PARAMS};
use convert::{Clock, Rejection};

/// Default node name.
pub const DEFAULT_NAME: &str = "trajectory_executor";

/// Samples each outgoing stream may queue before new ones are dropped (0.25 s at 250 Hz).
const STREAM_QUEUE: usize = 64;

/// Why the node could not start.
#[derive(Debug, thiserror::Error)]
pub enum NodeError {
    /// Environment, arguments, names or DDS.
    #[error(transparent)]
    Ros(#[from] RosError),
    /// The robot description could not be loaded.
    #[error("robot description: {0}")]
    Robot(#[from] RobotError),
    /// The executor refused the configuration.
    #[error("executor configuration: {0}")]
    Executor(#[from] ExecutorError),
    /// A parameter is inconsistent with the robot.
    #[error("parameter '{name}': {reason}")]
    Config {
        /// Parameter.
        name: String,
        /// What is wrong.
        reason: String,
    },
}

type FjtServer = ActionServer<
    FollowJointTrajectoryGoal,
    FollowJointTrajectoryResult,
    FollowJointTrajectoryFeedback,
>;

/// A request for the preparation worker: converted from its message and checked against the
/// robot there, off the control thread.
enum Incoming {
    /// A topic trajectory or a ValidateTrajectory request's trajectory.
    Trajectory(JointTrajectory),
    /// A FollowJointTrajectory goal.
    Goal(Box<FollowJointTrajectoryGoal>),
    /// An empty topic trajectory: nothing to prepare, kept in order with the others.
    Stop,
}

/// What the worker returns: `None` for [`Incoming::Stop`].
type Prepared = Result<(PreparedTrajectory, GoalTolerances), Rejection>;

/// What to do with a prepared request.
#[derive(Debug, Clone)]
enum Job {
    /// Start it (topic trajectory or action goal).
    Run(Source),
    /// Answer a ValidateTrajectory request.
    Validate(RmwRequestId),
    /// An empty topic trajectory: stop the current motion.
    Stop(Source),
}

/// Where an executor goal came from.
#[derive(Debug, Clone)]
enum Source {
    Topic { stamp: Time },
    Action { id: GoalId, stamp: Time },
}

impl Source {
    /// "trajectory from topic" or "goal <id>", for log lines.
    fn describe(&self) -> String {
        match self {
            Source::Topic { .. } => "trajectory from topic".to_string(),
            Source::Action { id, .. } => format!("goal {id:?}"),
        }
    }
}

/// Runs the node until its stop token (or Ctrl-C) stops it.
///
/// # Returns
/// `Ok` after a clean shutdown; an error if the node could not start (bad parameter,
/// unreadable robot description, DDS failure). Request errors never end the node.
pub fn run(args: &RosArgs, env: &RosEnv, stop: StopToken) -> Result<(), NodeError> {
    let node = KerfNode::new(
        NodeSpec {
            default_name: DEFAULT_NAME,
            default_namespace: "/",
            known_params: KNOWN_PARAMS,
        },
        args,
        env,
        stop,
    )?;
    let log = node.logger();
    let cfg = match NodeConfig::from_params(node.params()) {
        Ok(c) => c,
        Err(e) => {
            log.error(&format!("cannot start: {e}"));
            return Err(e);
        }
    };
    let priority = cfg.realtime_priority;
    let mut n = ExecutorNode::new(node, cfg)?;
    if priority > 0 {
        // The control loop runs on this thread.
        kerf_ros::set_realtime_priority(priority).map_err(|reason| {
            log.error(&format!("cannot start: {reason}"));
            NodeError::Config {
                name: "realtime_priority".into(),
                reason,
            }
        })?;
        log.info(&format!(
            "control thread runs SCHED_FIFO at priority {priority}"
        ));
    }
    n.spin();
    Ok(())
}

/// The node's state. Fields drop in declaration order: DDS endpoints first, `node` (and its
/// Context) last.
struct ExecutorNode {
    traj_sub: Inbox<JointTrajectory>,
    action: FjtServer,
    validate_srv: Server<ValidateTrajectoryRequest, ValidateTrajectoryResponse>,
    joint_states: Streamer<JointState>,
    controller_state: Streamer<JointTrajectoryControllerState>,
    command: Streamer<JointState>,
    status: Streamer<TrajectoryStatus>,
    goals: action::ActionGoals,
    sources: HashMap<ExecGoalId, Source>,
    /// Validation of incoming trajectories (O(points · joints)) runs here, off the control
    /// thread; one thread, so results come back in arrival order.
    prep: Worker<Incoming, Option<Prepared>>,
    jobs: HashMap<u64, Job>,
    exec: Executor,
    hw: MockHardware,
    cfg: NodeConfig,
    names: Vec<String>,
    cycle: Cycle,
    next_feedback: f64,
    statuses_changed: bool,
    publish_failures: u64,
    clock: Clock,
    log: Logger,
    node: KerfNode,
}

impl ExecutorNode {
    fn new(mut node: KerfNode, cfg: NodeConfig) -> Result<Self, NodeError> {
        let exec = Executor::new(
            cfg.limits.clone(),
            cfg.executor.clone(),
            cfg.initial_positions.clone(),
        )?;
        let hw = MockHardware::with_lag(cfg.initial_positions.clone(), cfg.lag_time_constant)?;
        // Read on its own thread: deserializing a large trajectory takes milliseconds.
        let traj_sub = node.inbox(
            "~/joint_trajectory",
            JointTrajectory::ROS_TYPE,
            qos::commands(),
        )?;
        let action = node.action_server(
            "~/follow_joint_trajectory",
            "control_msgs/action/FollowJointTrajectory",
        )?;
        let validate_srv =
            node.service_server("~/validate_trajectory", "kerf_msgs/srv/ValidateTrajectory")?;
        // Outgoing streams leave the control thread through bounded queues: a stalled
        // subscriber can cost samples but never blocks the control loop.
        let q = STREAM_QUEUE;
        let joint_states = node.streamer("joint_states", JointState::ROS_TYPE, qos::state(), q)?;
        let controller_state = node.streamer(
            "~/controller_state",
            JointTrajectoryControllerState::ROS_TYPE,
            qos::state(),
            q,
        )?;
        let command = node.streamer("~/joint_command", JointState::ROS_TYPE, qos::state(), q)?;
        let status = node.streamer(
            "~/trajectory_status",
            TrajectoryStatus::ROS_TYPE,
            qos::latched(),
            q,
        )?;
        let names = cfg
            .limits
            .iter()
            .map(|l| l.name.clone())
            .collect::<Vec<_>>();
        let log = node.logger();
        log.info(&format!(
            "ready: robot '{}', joints [{}], {} Hz; trajectories on {}, action {}",
            cfg.robot.name(),
            names.join(", "),
            cfg.control_rate,
            node.resolve("~/joint_trajectory")?,
            node.resolve("~/follow_joint_trajectory")?,
        ));
        let clock = Clock::start();
        let (limits, exec_cfg) = (cfg.limits.clone(), cfg.executor.clone());
        let prep = Worker::spawn("prepare", 1, move |incoming: Incoming| {
            let prepared = |req: TrajectoryRequest, tol: GoalTolerances| -> Prepared {
                Ok((prepare(&limits, &exec_cfg, &req)?, tol))
            };
            match incoming {
                Incoming::Stop => None,
                Incoming::Trajectory(msg) => Some(
                    convert::trajectory_request(&msg, &clock)
                        .and_then(|req| prepared(req, GoalTolerances::default())),
                ),
                Incoming::Goal(goal) => Some(
                    convert::goal_request(&goal, &clock).and_then(|(req, tol)| prepared(req, tol)),
                ),
            }
        })
        .map_err(|e| RosError::Dds {
            what: "trajectory preparation thread".into(),
            reason: e.to_string(),
        })?;
        Ok(Self {
            traj_sub,
            action,
            validate_srv,
            joint_states,
            controller_state,
            command,
            status,
            goals: action::ActionGoals::default(),
            sources: HashMap::new(),
            prep,
            jobs: HashMap::new(),
            exec,
            hw,
            cfg,
            names,
            cycle: Cycle::default(),
            next_feedback: 0.0,
            statuses_changed: false,
            publish_failures: 0,
            clock,
            log,
            node,
        })
    }

    fn spin(&mut self) {
        let period = StdDuration::from_secs_f64(1.0 / self.cfg.control_rate);
        let mut next = Instant::now();
        let mut overruns = 0u64;
        while !self.node.should_stop() {
            self.poll_trajectories();
            self.poll_goals();
            self.poll_cancels();
            self.poll_result_requests();
            self.poll_validate();
            self.poll_prepared();
            self.control_cycle();
            next += period;
            let now = Instant::now();
            if next > now {
                std::thread::sleep(next - now);
            } else if now - next > period * 10 {
                overruns += 1;
                if overruns.is_power_of_two() {
                    self.log.warn(&format!(
                        "control loop fell {:.1} ms behind; skipping ahead ({overruns} times so far)",
                        (now - next).as_secs_f64() * 1e3
                    ));
                }
                next = now;
            }
        }
        self.log.info("shutting down");
    }

    fn publish<M: serde::Serialize + Send + 'static>(
        stream: &Streamer<M>,
        msg: M,
        failures: &mut u64,
        log: &Logger,
        what: &str,
    ) {
        if !stream.publish(msg) {
            *failures += 1;
            if failures.is_power_of_two() {
                log.warn(&format!(
                    "{what}: sample dropped, a subscriber is not keeping up ({failures} drops so far)"
                ));
            }
        }
    }

    fn header(&self, t: f64) -> Header {
        Header {
            stamp: self.clock.stamp(t),
            frame_id: String::new(),
        }
    }

    fn trajectory_status(&mut self, source: &Source, status: u8, code: i32, message: &str) {
        let (src, goal_id, stamp) = match source {
            Source::Topic { stamp } => (TrajectoryStatus::SOURCE_TOPIC, String::new(), *stamp),
            Source::Action { id, stamp } => (
                TrajectoryStatus::SOURCE_ACTION,
                action::goal_id_hex(id),
                *stamp,
            ),
        };
        let msg = TrajectoryStatus {
            header: self.header(self.clock.now()),
            trajectory_stamp: stamp,
            source: src.to_string(),
            goal_id,
            status,
            error_code: code,
            message: message.to_string(),
        };
        Self::publish(
            &self.status,
            msg,
            &mut self.publish_failures,
            &self.log,
            "trajectory status",
        );
    }

    fn ros_now(&self) -> RosTime {
        RosTime::from_nanos(self.clock.stamp(self.clock.now()).as_nanos())
    }

    fn poll_trajectories(&mut self) {
        while let Some(received) = self.traj_sub.try_recv() {
            match received {
                Ok(msg) => self.on_trajectory(msg),
                Err(e) => {
                    let msg = format!("could not read a JointTrajectory sample: {e}");
                    self.log.error(&msg);
                    let source = Source::Topic { stamp: Time::ZERO };
                    self.trajectory_status(&source, TrajectoryStatus::REJECTED, INVALID_GOAL, &msg);
                }
            }
        }
    }

    fn on_trajectory(&mut self, msg: JointTrajectory) {
        let source = Source::Topic {
            stamp: msg.header.stamp,
        };
        if msg.points.is_empty() {
            // Queued behind the trajectories still being prepared, so it stops whatever was
            // sent before it.
            self.enqueue(Job::Stop(source), Incoming::Stop);
        } else {
            self.enqueue(Job::Run(source), Incoming::Trajectory(msg));
        }
    }

    /// Hands a request to the preparation worker; results come back in order.
    fn enqueue(&mut self, job: Job, incoming: Incoming) {
        let ticket = self.prep.submit(incoming);
        self.jobs.insert(ticket, job);
    }

    fn rejected(&mut self, source: &Source, rej: Rejection) {
        self.log
            .warn(&format!("rejected {}: {}", source.describe(), rej.message));
        self.trajectory_status(source, TrajectoryStatus::REJECTED, rej.code, &rej.message);
        if let Source::Action { id, .. } = source {
            self.goals.finish(
                id,
                GoalStatusEnum::Aborted,
                FollowJointTrajectoryResult {
                    error_code: rej.code,
                    error_string: rej.message,
                },
            );
            self.statuses_changed = true;
        }
    }

    /// Finishes the requests the worker has prepared, in the order they arrived.
    fn poll_prepared(&mut self) {
        while let Some((ticket, result)) = self.prep.try_recv() {
            let Some(job) = self.jobs.remove(&ticket) else {
                continue;
            };
            let missing = || Rejection {
                code: INVALID_GOAL,
                message: "no trajectory in the request".into(),
            };
            let prepared = match result {
                Ok(p) => p,
                Err(e) => Some(Err(Rejection {
                    code: INVALID_GOAL,
                    message: format!("internal error while validating: {e}"),
                })),
            };
            let now = self.clock.now();
            match job {
                Job::Stop(source) => self.stop_on_empty_trajectory(&source),
                Job::Validate(req_id) => {
                    let checked = prepared
                        .unwrap_or_else(|| Err(missing()))
                        .and_then(|(p, tol)| Ok(self.exec.validate_prepared(&p, &tol, now)?));
                    self.answer_validate(req_id, checked);
                }
                Job::Run(source) => {
                    self.start(source, prepared.unwrap_or_else(|| Err(missing())), now);
                }
            }
        }
    }

    fn start(&mut self, source: Source, prepared: Prepared, now: f64) {
        if let Source::Action { id, .. } = &source {
            if self
                .goals
                .get(id)
                .is_some_and(|g| g.status == GoalStatusEnum::Canceling)
            {
                let message = "canceled before it started".to_string();
                self.log.info(&format!("goal {id:?} {message}"));
                self.trajectory_status(&source, TrajectoryStatus::CANCELED, SUCCESSFUL, &message);
                self.goals.finish(
                    id,
                    GoalStatusEnum::Canceled,
                    FollowJointTrajectoryResult {
                        error_code: SUCCESSFUL,
                        error_string: message,
                    },
                );
                self.statuses_changed = true;
                return;
            }
        }
        let submitted = prepared.and_then(|(p, tol)| {
            let id = self.exec.submit_prepared(&p, &tol, now)?;
            Ok((id, p.point_count(), p.duration()))
        });
        match submitted {
            Ok((exec_id, points, duration)) => {
                let what = source.describe();
                self.log.info(&format!(
                    "accepted {what}: {points} points over {duration:.3} s"
                ));
                self.trajectory_status(&source, TrajectoryStatus::ACCEPTED, SUCCESSFUL, "accepted");
                if let Source::Action { id, .. } = &source {
                    if let Some(g) = self.goals.get_mut(id) {
                        g.exec_id = Some(exec_id);
                    }
                }
                self.sources.insert(exec_id, source);
            }
            Err(rej) => self.rejected(&source, rej),
        }
    }

    /// JTC: an empty trajectory on the topic interface stops the current motion and holds.
    /// Here the stop is the executor's controlled stop within the acceleration limits; the
    /// stopped goal (topic or action) ends CANCELED.
    fn stop_on_empty_trajectory(&mut self, source: &Source) {
        let message = match self.exec.active_goal() {
            Some(id) => match self.exec.cancel(id, self.clock.now()) {
                Ok(()) => "empty trajectory: stopping the current motion".to_string(),
                Err(e) => format!("empty trajectory: {e}"),
            },
            None => "empty trajectory: no active motion to stop".to_string(),
        };
        self.log.info(&message);
        self.trajectory_status(source, TrajectoryStatus::ACCEPTED, SUCCESSFUL, &message);
    }

    fn poll_goals(&mut self) {
        let (goals, error) = drain(|| self.action.receive_goal());
        if let Some(e) = error {
            self.log
                .error(&format!("could not read a FollowJointTrajectory goal: {e}"));
        }
        for (req_id, SendGoalRequest { goal_id, goal }) in goals {
            let accepted = self.ros_now();
            let source = Source::Action {
                id: goal_id,
                stamp: goal.trajectory.header.stamp,
            };
            // A ROS 2 goal rejection carries no reason, so every goal is accepted; an invalid
            // one is then aborted with its error code and message (JTC rejects without a
            // reason).
            if let Err(e) = self.action.send_goal_response(
                req_id,
                SendGoalResponse {
                    accepted: true,
                    stamp: accepted,
                },
            ) {
                self.log
                    .error(&format!("could not answer goal {goal_id:?}: {e:?}"));
            }
            self.goals.add(action::ActionGoal {
                id: goal_id,
                accepted,
                status: GoalStatusEnum::Executing,
                exec_id: None,
                result: None,
            });
            self.statuses_changed = true;
            self.enqueue(Job::Run(source), Incoming::Goal(Box::new(goal)));
        }
    }

    fn poll_cancels(&mut self) {
        let (requests, error) = drain(|| self.action.receive_cancel_request());
        if let Some(e) = error {
            self.log
                .error(&format!("could not read a cancel request: {e}"));
        }
        for (req_id, req) in requests {
            let response = match cancel_target(&req) {
                Ok(info) => self.cancel(&info),
                Err(reason) => {
                    self.log
                        .error(&format!("malformed cancel request: {reason}"));
                    CancelGoalResponse {
                        return_code: CancelGoalResponseEnum::Rejected,
                        goals_canceling: Vec::new(),
                    }
                }
            };
            if let Err(e) = self.action.send_cancel_response(req_id, response) {
                self.log
                    .error(&format!("could not answer a cancel request: {e:?}"));
            }
        }
    }

    fn cancel(&mut self, info: &GoalInfo) -> CancelGoalResponse {
        let selected = self.goals.select_for_cancel(info);
        let now = self.clock.now();
        let mut canceling = Vec::new();
        for id in &selected {
            let Some(g) = self.goals.get_mut(id) else {
                continue;
            };
            if g.status != GoalStatusEnum::Executing {
                continue;
            }
            g.status = GoalStatusEnum::Canceling;
            canceling.push(GoalInfo {
                goal_id: g.id,
                stamp: g.accepted,
            });
            // A goal still being prepared ends when its preparation comes back.
            if let Some(exec_id) = g.exec_id {
                if let Err(e) = self.exec.cancel(exec_id, now) {
                    self.log.warn(&format!("cancel of goal {id:?}: {e}"));
                }
            }
        }
        if !canceling.is_empty() {
            self.log.info(&format!(
                "canceling {} goal(s); the motion stops within the acceleration limits",
                canceling.len()
            ));
            self.statuses_changed = true;
        }
        let return_code = if !canceling.is_empty() {
            CancelGoalResponseEnum::None
        } else if selected.is_empty() {
            CancelGoalResponseEnum::UnknownGoal
        } else {
            CancelGoalResponseEnum::GoalTerminated
        };
        CancelGoalResponse {
            return_code,
            goals_canceling: canceling,
        }
    }

    fn poll_result_requests(&mut self) {
        let (requests, error) = drain(|| self.action.receive_result_request());
        if let Some(e) = error {
            self.log
                .error(&format!("could not read a result request: {e}"));
        }
        for (req_id, req) in requests {
            self.goals.pending_results.push((req.goal_id, req_id));
        }
        for (req_id, status, result) in self.goals.take_ready_results() {
            if let Err(e) = self
                .action
                .send_result(req_id, GetResultResponse { status, result })
            {
                self.log
                    .error(&format!("could not send a goal result: {e:?}"));
            }
        }
    }

    fn poll_validate(&mut self) {
        let (requests, error) = drain(|| self.validate_srv.receive_request());
        if let Some(e) = error {
            self.log
                .error(&format!("could not read a validate request: {e}"));
        }
        for (req_id, req) in requests {
            self.enqueue(Job::Validate(req_id), Incoming::Trajectory(req.trajectory));
        }
    }

    fn answer_validate(
        &mut self,
        req_id: RmwRequestId,
        checked: Result<ValidatedTrajectory, Rejection>,
    ) {
        let resp = match checked {
            Ok(traj) => ValidateTrajectoryResponse {
                valid: true,
                error_code: SUCCESSFUL,
                message: "valid".into(),
                duration: traj.duration(),
            },
            Err(rej) => ValidateTrajectoryResponse {
                valid: false,
                error_code: rej.code,
                message: rej.message,
                duration: 0.0,
            },
        };
        if let Err(e) = self.validate_srv.send_response(req_id, resp) {
            self.log
                .error(&format!("could not answer a validate request: {e:?}"));
        }
    }

    fn control_cycle(&mut self) {
        let now = self.clock.now();
        let measured = self.hw.state().clone();
        let mut cycle = std::mem::take(&mut self.cycle);
        if let Err(e) = self.exec.update_into(now, &measured, &mut cycle) {
            self.log.error(&format!("control cycle failed: {e}"));
            self.cycle = cycle;
            return;
        }
        if let Err(e) = self.hw.write(
            &self.cfg.limits,
            &cycle.reference,
            self.cfg.executor.control_period,
        ) {
            self.log
                .error(&format!("hardware refused the command: {e}"));
        }
        let header = self.header(now);
        let joint_state = |s: &JointSample| JointState {
            header: header.clone(),
            name: self.names.clone(),
            position: s.positions.clone(),
            velocity: s.velocities.clone(),
            effort: Vec::new(),
        };
        let js = joint_state(&measured);
        let cmd = joint_state(&cycle.reference);
        let tfs = cycle.feedback.map_or(0.0, |f| f.time_from_start.max(0.0));
        let state = JointTrajectoryControllerState {
            header: header.clone(),
            joint_names: self.names.clone(),
            reference: convert::point(&cycle.reference, tfs),
            feedback: convert::point(&measured, tfs),
            error: convert::point(&cycle.error, tfs),
            output: convert::point(&cycle.reference, tfs),
            ..Default::default()
        };
        Self::publish(
            &self.joint_states,
            js,
            &mut self.publish_failures,
            &self.log,
            "joint states",
        );
        Self::publish(
            &self.command,
            cmd,
            &mut self.publish_failures,
            &self.log,
            "joint command",
        );
        Self::publish(
            &self.controller_state,
            state,
            &mut self.publish_failures,
            &self.log,
            "controller state",
        );

        for ev in std::mem::take(&mut cycle.events) {
            self.finish(ev.id, ev.outcome);
        }
        if let Some(fb) = cycle.feedback {
            if now >= self.next_feedback {
                self.next_feedback = now + 1.0 / self.cfg.action_monitor_rate;
                if let Some(Source::Action { id, .. }) = self.sources.get(&fb.id) {
                    let feedback = FollowJointTrajectoryFeedback {
                        header,
                        joint_names: self.names.clone(),
                        desired: convert::point(&cycle.reference, tfs),
                        actual: convert::point(&measured, tfs),
                        error: convert::point(&cycle.error, tfs),
                        ..Default::default()
                    };
                    if let Err(e) = self.action.send_feedback(*id, feedback) {
                        self.log.debug(&format!("feedback not sent: {e:?}"));
                    }
                }
            }
        }
        if self.statuses_changed {
            self.statuses_changed = false;
            if let Err(e) = self.action.send_goal_statuses(self.goals.status_array()) {
                self.log.warn(&format!("goal status not published: {e:?}"));
            }
        }
        self.cycle = cycle;
    }

    fn finish(&mut self, id: ExecGoalId, outcome: Outcome) {
        let Some(source) = self.sources.remove(&id) else {
            return;
        };
        let (status, action_status, code, message) = match outcome {
            Outcome::Succeeded => (
                TrajectoryStatus::SUCCEEDED,
                GoalStatusEnum::Succeeded,
                SUCCESSFUL,
                String::new(),
            ),
            Outcome::Aborted {
                error_code,
                message,
            } => (
                TrajectoryStatus::ABORTED,
                GoalStatusEnum::Aborted,
                error_code,
                message,
            ),
            // JTC ends a preempted goal as CANCELED with INVALID_GOAL and this kind of message.
            Outcome::Preempted => (
                TrajectoryStatus::PREEMPTED,
                GoalStatusEnum::Canceled,
                INVALID_GOAL,
                "preempted by a newer trajectory, which continues from the current commanded state"
                    .to_string(),
            ),
            Outcome::Canceled => (
                TrajectoryStatus::CANCELED,
                GoalStatusEnum::Canceled,
                SUCCESSFUL,
                "canceled; the motion was brought to a controlled stop".to_string(),
            ),
        };
        let name = TrajectoryStatus::status_name(status).unwrap_or("?");
        if message.is_empty() {
            self.log.info(&format!("trajectory {name}"));
        } else if code == SUCCESSFUL {
            self.log.info(&format!("trajectory {name}: {message}"));
        } else {
            self.log.warn(&format!("trajectory {name}: {message}"));
        }
        self.trajectory_status(&source, status, code, &message);
        if let Source::Action { id: goal_id, .. } = source {
            self.goals.finish(
                &goal_id,
                action_status,
                FollowJointTrajectoryResult {
                    error_code: code,
                    error_string: message,
                },
            );
            self.statuses_changed = true;
        }
    }
}

/// Takes every sample or request available now, in arrival order.
///
/// # Returns
/// The items, and the read error that ended the drain early, if any (e.g. a sample that does
/// not deserialize); items read before it are kept.
fn drain<T, E: std::fmt::Debug>(
    mut read: impl FnMut() -> Result<Option<T>, E>,
) -> (Vec<T>, Option<String>) {
    let mut items = Vec::new();
    loop {
        match read() {
            Ok(Some(x)) => items.push(x),
            Ok(None) => return (items, None),
            Err(e) => return (items, Some(format!("{e:?}"))),
        }
    }
}

/// The goal selector of a CancelGoal request.
///
/// ros2-client keeps `CancelGoalRequest::goal_info` private; its serde form is public, so the
/// request is read back through a serde value into a mirror of `action_msgs/srv/CancelGoal`.
fn cancel_target(req: &CancelGoalRequest) -> Result<GoalInfo, String> {
    #[derive(serde::Deserialize)]
    struct Mirror {
        goal_info: GoalInfo,
    }
    let v = serde_yaml_ng::to_value(req).map_err(|e| e.to_string())?;
    serde_yaml_ng::from_value::<Mirror>(v)
        .map(|m| m.goal_info)
        .map_err(|e| e.to_string())
}
