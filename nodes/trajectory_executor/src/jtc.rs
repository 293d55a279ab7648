//! `hardware: jtc`: trajectories forwarded to an external `control_msgs/action/
//! FollowJointTrajectory` server (ros2_control's `joint_trajectory_controller`, a robot
//! vendor's driver) after the executor's own validation (issue 27, item 2).
//!
//! Each trajectory — an action goal or a topic trajectory — is validated as with any other
//! hardware (every number, the joints, the limits on the whole interpolated curve, and the
//! start from the robot's current state), then sent unchanged to the external server
//! (`hardware.jtc_action`), and the executor relays:
//! * **acceptance**: the goal counts as accepted (`~/trajectory_status` ACCEPTED) when the
//!   external server accepts it. A goal the external server rejects is aborted
//!   (INVALID_GOAL) with a message naming the server (a ROS 2 goal rejection carries no
//!   reason: its log has it).
//! * **feedback**: the external feedback goes to the executor's client unchanged, and its
//!   `actual` state is published on `joint_states` (with the good states of
//!   `hardware.state_topic`, when set).
//! * **result**: the external status and result become the goal's (SUCCEEDED; ABORTED with the
//!   external `error_code` and `error_string`, named as the server's; CANCELED when the
//!   executor's client canceled).
//! * **cancel** (the executor's action cancel, or an empty topic trajectory): a cancel request
//!   to the external server for the goal; the result then comes from there.
//! * **preemption**: a newer goal the external server accepts preempts the older ones, as in
//!   JTC (the older goal ends CANCELED with INVALID_GOAL, as with the executor's own
//!   preemption); the external server handles the motion.
//!
//! **The external server disappearing** is detected by time, `hardware.jtc_timeout` (T,
//! default 1 s; DDS only forgets a killed process's endpoints after its lease, up to 50 s):
//! no answer to a goal within T; no result within T after the trajectory's end plus its goal
//! time tolerance (the goal's, else `constraints.goal_time`); or, once the server has sent
//! feedback, no feedback for T. The goal is then aborted (PATH_TOLERANCE_VIOLATED) with a
//! message saying what was missing and for how long, and a cancel is sent in case the server
//! is only slow. The executor cannot stop a robot it does not command: what the robot does
//! then is the external controller's decision.
//!
//! **The start state** of validation is the latest state of `hardware.state_topic` when set
//! (then goals wait for its first state); without it, the external feedback's `desired` state
//! while a goal runs, the last trajectory's end after a success, and `initial_positions`
//! before the first goal. No `~/joint_command` and no `~/controller_state` are published: the
//! external controller commands the robot.

use std::collections::HashMap;

use kerf_executor::{
    measured_state, ExecutorConfig, GoalId as ExecGoalId, GoalTolerances, JointLimits, JointSample,
    NamedState, Outcome, PreparedTrajectory, INVALID_GOAL, PATH_TOLERANCE_VIOLATED, SUCCESSFUL,
};
use kerf_msgs::{
    control_msgs::{
        FollowJointTrajectoryFeedback, FollowJointTrajectoryGoal, FollowJointTrajectoryResult,
    },
    sensor_msgs::JointState,
    trajectory_msgs::JointTrajectoryPoint,
};
use kerf_ros::{Inbox, LogLevel, Streamer};
use ros2_client::{
    action::{ActionClient, GoalId, GoalStatusEnum},
    RmwRequestId,
};

use crate::{convert::Rejection, NodeError};

/// The external server's client.
pub type FjtClient = ActionClient<
    FollowJointTrajectoryGoal,
    FollowJointTrajectoryResult,
    FollowJointTrajectoryFeedback,
>;

/// What the forwarder tells the request thread.
#[derive(Debug)]
pub enum JtcEvent {
    /// The external server accepted the forwarded goal.
    Accepted {
        /// The executor goal.
        exec_id: ExecGoalId,
    },
    /// A forwarded goal ended.
    Finished {
        /// The executor goal.
        exec_id: ExecGoalId,
        /// How.
        outcome: Outcome,
    },
    /// External feedback for a forwarded goal.
    Feedback {
        /// The executor goal.
        exec_id: ExecGoalId,
        /// The feedback, as the external server sent it.
        feedback: Box<FollowJointTrajectoryFeedback>,
    },
    /// A line for the node's log.
    Log {
        /// Level.
        level: LogLevel,
        /// Text.
        message: String,
    },
}

#[derive(Debug, Clone, Copy)]
enum Phase {
    /// Sent; waiting for the external server's answer.
    Sent { request: RmwRequestId, at: f64 },
    /// Accepted; waiting for the result.
    Running {
        result_request: Option<RmwRequestId>,
        last_feedback: Option<f64>,
    },
}

#[derive(Debug)]
struct Forwarded {
    exec_id: ExecGoalId,
    external: GoalId,
    phase: Phase,
    /// When the result is due at the latest (s): the trajectory's end, its goal time and
    /// the timeout.
    due: f64,
    final_positions: Vec<f64>,
    canceled: bool,
}

/// The external server and what was forwarded to it; lives on the request thread.
pub struct Forwarder {
    client: FjtClient,
    action: String,
    timeout: f64,
    limits: Vec<JointLimits>,
    cfg: ExecutorConfig,
    states: Option<(Inbox<JointState>, String)>,
    joint_states: Streamer<JointState>,
    /// The start state of the next validation (see the module docs).
    start: Option<JointSample>,
    /// Goal messages kept for forwarding while their trajectories are validated, by ticket.
    waiting: HashMap<u64, FollowJointTrajectoryGoal>,
    goals: Vec<Forwarded>,
    next_id: u64,
    publish_failures: u64,
}

impl Forwarder {
    /// A forwarder to the external server behind `client` (named `action`).
    ///
    /// # Arguments
    /// * `states` — the driver's joint states and their topic (`hardware.state_topic`).
    /// * `joint_states` — the executor's own `joint_states`.
    /// * `initial` — the start state before the first goal without a state topic.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        client: FjtClient,
        action: String,
        timeout: f64,
        limits: Vec<JointLimits>,
        cfg: ExecutorConfig,
        states: Option<(Inbox<JointState>, String)>,
        joint_states: Streamer<JointState>,
        initial: Vec<f64>,
    ) -> Self {
        let start = states.is_none().then(|| JointSample::at_rest(initial));
        Self {
            client,
            action,
            timeout,
            limits,
            cfg,
            states,
            joint_states,
            start,
            waiting: HashMap::new(),
            goals: Vec::new(),
            next_id: 1,
            publish_failures: 0,
        }
    }

    /// The external server's client (to wait for it).
    pub fn client(&self) -> &FjtClient {
        &self.client
    }

    /// The external action's name.
    pub fn action(&self) -> &str {
        &self.action
    }

    fn rejection(&self, code: i32, reason: String) -> Rejection {
        Rejection {
            code,
            message: NodeError::ExternalServer {
                action: self.action.clone(),
                reason,
            }
            .to_string(),
        }
    }

    /// Keeps the message of a goal (or topic trajectory) being validated under `ticket`.
    pub fn keep(&mut self, ticket: u64, goal: FollowJointTrajectoryGoal) {
        self.waiting.insert(ticket, goal);
    }

    /// Forgets the message kept under `ticket` (its request ended otherwise).
    pub fn forget(&mut self, ticket: u64) {
        self.waiting.remove(&ticket);
    }

    /// Finishes the validation of `prepared` against the start state at `now` (see the module
    /// docs).
    ///
    /// # Returns
    /// The trajectory's end (s on the executor's clock) and final positions.
    ///
    /// # Errors
    /// No start state yet (waiting for `hardware.state_topic`), or the executor's refusal.
    fn finish(
        &self,
        prepared: &PreparedTrajectory,
        tolerances: &GoalTolerances,
        now: f64,
    ) -> Result<(f64, Vec<f64>), Rejection> {
        let start = self.start.as_ref().ok_or_else(|| Rejection {
            code: INVALID_GOAL,
            message: match &self.states {
                Some((_, topic)) => NodeError::WaitingForDriver {
                    topic: topic.clone(),
                }
                .to_string(),
                None => "no start state".into(),
            },
        })?;
        kerf_executor::resolve_tolerances(&self.limits, &self.cfg, tolerances)?;
        let traj = prepared.finish(&self.limits, &self.cfg, start, now)?;
        Ok((traj.end_time(), traj.final_positions().to_vec()))
    }

    /// The dry run of `hardware: jtc` (ValidateTrajectory): the executor's validation from the
    /// start state at `now`.
    ///
    /// # Returns
    /// The trajectory's duration (s), or why it would be refused.
    pub fn validate(
        &self,
        prepared: &PreparedTrajectory,
        tolerances: &GoalTolerances,
        now: f64,
    ) -> Result<f64, Rejection> {
        self.finish(prepared, tolerances, now)?;
        Ok(prepared.duration())
    }

    /// Validates `prepared` (kept under `ticket`) from the start state at `now` and sends its
    /// goal to the external server.
    ///
    /// # Returns
    /// The executor goal that follows it; the goal counts as started when the external
    /// server accepts it ([`JtcEvent::Accepted`]).
    ///
    /// # Errors
    /// The validation's refusal, or a goal that could not be sent.
    pub fn start(
        &mut self,
        ticket: u64,
        prepared: &PreparedTrajectory,
        tolerances: &GoalTolerances,
        now: f64,
    ) -> Result<ExecGoalId, Rejection> {
        let goal = self.waiting.remove(&ticket).ok_or_else(|| Rejection {
            code: INVALID_GOAL,
            message: "internal error: the goal to forward was not kept".into(),
        })?;
        let (end, final_positions) = self.finish(prepared, tolerances, now)?;
        let goal_time = if tolerances.goal_time > 0.0 {
            tolerances.goal_time
        } else {
            self.cfg.goal_time_tolerance
        };
        let (request, external) = self.client.send_goal(goal).map_err(|e| {
            self.rejection(INVALID_GOAL, format!("the goal could not be sent: {e:?}"))
        })?;
        let exec_id = ExecGoalId(self.next_id);
        self.next_id += 1;
        self.goals.push(Forwarded {
            exec_id,
            external,
            phase: Phase::Sent { request, at: now },
            due: end + goal_time + self.timeout,
            final_positions,
            canceled: false,
        });
        Ok(exec_id)
    }

    /// Asks the external server to cancel the forwarded goal `exec_id`.
    ///
    /// # Returns
    /// Whether the goal is one of the forwarded ones still running.
    pub fn cancel(&mut self, exec_id: ExecGoalId) -> bool {
        let Some(g) = self.goals.iter_mut().find(|g| g.exec_id == exec_id) else {
            return false;
        };
        g.canceled = true;
        let external = g.external;
        // Best effort: an unanswered cancel still ends by the result or the timeout.
        let _ = self.client.cancel_goal(external);
        true
    }

    /// Cancels every forwarded goal (an empty topic trajectory).
    ///
    /// # Returns
    /// How many were running.
    pub fn cancel_all(&mut self) -> usize {
        let ids: Vec<ExecGoalId> = self.goals.iter().map(|g| g.exec_id).collect();
        ids.into_iter().filter(|id| self.cancel(*id)).count()
    }

    fn end(&mut self, i: usize, outcome: Outcome, events: &mut Vec<JtcEvent>) {
        let g = self.goals.remove(i);
        if outcome == Outcome::Succeeded && self.states.is_none() {
            self.start = Some(JointSample::at_rest(g.final_positions));
        }
        events.push(JtcEvent::Finished {
            exec_id: g.exec_id,
            outcome,
        });
    }

    /// The outcome of an external result.
    fn outcome(
        &self,
        status: GoalStatusEnum,
        result: &FollowJointTrajectoryResult,
        canceled: bool,
    ) -> Outcome {
        let named = |what: &str| {
            let reason = if result.error_string.is_empty() {
                format!("{what} the goal (error_code {})", result.error_code)
            } else {
                format!(
                    "{what} the goal (error_code {}): {}",
                    result.error_code, result.error_string
                )
            };
            NodeError::ExternalServer {
                action: self.action.clone(),
                reason,
            }
            .to_string()
        };
        let code = if result.error_code == SUCCESSFUL {
            INVALID_GOAL
        } else {
            result.error_code
        };
        match status {
            GoalStatusEnum::Succeeded => Outcome::Succeeded,
            GoalStatusEnum::Canceled if canceled => Outcome::Canceled,
            GoalStatusEnum::Canceled => Outcome::Aborted {
                error_code: code,
                message: named("canceled (another client's goal may have preempted it)"),
            },
            GoalStatusEnum::Aborted => Outcome::Aborted {
                error_code: code,
                message: named("aborted"),
            },
            other => Outcome::Aborted {
                error_code: code,
                message: named(&format!("answered status {other:?} for")),
            },
        }
    }

    /// Takes the external server's answers, results and feedback and the driver's joint
    /// states, and checks the timeouts, at `now`.
    pub fn poll(&mut self, now: f64, events: &mut Vec<JtcEvent>) {
        self.poll_states(events);
        self.poll_goal_responses(events);
        self.poll_results(events);
        self.poll_feedback(now, events);
        // Cancel answers carry nothing the result does not; drained so they do not pile up.
        while let Ok(Some(_)) = self.client.cancel_client().receive_response() {}
        self.check_timeouts(now, events);
    }

    fn publish_state(&mut self, js: JointState, events: &mut Vec<JtcEvent>) {
        if let Some(message) = crate::control::publish_counted(
            &self.joint_states,
            js,
            &mut self.publish_failures,
            "joint states",
        ) {
            events.push(JtcEvent::Log {
                level: LogLevel::Warn,
                message,
            });
        }
    }

    fn poll_states(&mut self, events: &mut Vec<JtcEvent>) {
        let mut good = Vec::new();
        if let Some((inbox, topic)) = &self.states {
            while let Some(received) = inbox.try_recv() {
                match received {
                    Ok(msg) => {
                        let named = NamedState {
                            names: &msg.name,
                            positions: &msg.position,
                            velocities: &msg.velocity,
                        };
                        match measured_state("measured state", named, &self.limits) {
                            Ok(s) => {
                                let mut sample = JointSample::at_rest(s.positions);
                                if let Some(v) = s.velocities {
                                    sample.velocities = v;
                                }
                                good.push((sample, msg));
                            }
                            Err(e) => events.push(JtcEvent::Log {
                                level: LogLevel::Warn,
                                message: NodeError::BadFeedback {
                                    topic: topic.clone(),
                                    reason: e.to_string(),
                                }
                                .to_string(),
                            }),
                        }
                    }
                    Err(reason) => events.push(JtcEvent::Log {
                        level: LogLevel::Warn,
                        message: NodeError::UnreadableFeedback {
                            topic: topic.clone(),
                            expected: "sensor_msgs/msg/JointState",
                            reason,
                        }
                        .to_string(),
                    }),
                }
            }
        }
        for (sample, msg) in good {
            self.start = Some(sample);
            self.publish_state(msg, events);
        }
    }

    fn poll_goal_responses(&mut self, events: &mut Vec<JtcEvent>) {
        loop {
            let (request, response) = match self.client.goal_client().receive_response() {
                Ok(Some(r)) => r,
                Ok(None) => break,
                Err(e) => {
                    events.push(JtcEvent::Log {
                        level: LogLevel::Error,
                        message: format!("{}: could not read a goal response: {e:?}", self.action),
                    });
                    break;
                }
            };
            let Some(i) = self
                .goals
                .iter()
                .position(|g| matches!(g.phase, Phase::Sent { request: r, .. } if r == request))
            else {
                continue;
            };
            if !response.accepted {
                let message = NodeError::ExternalServer {
                    action: self.action.clone(),
                    reason: "rejected the goal (a ROS 2 goal rejection carries no reason; the \
                             server's log has it)"
                        .into(),
                }
                .to_string();
                self.end(
                    i,
                    Outcome::Aborted {
                        error_code: INVALID_GOAL,
                        message,
                    },
                    events,
                );
                continue;
            }
            let external = self.goals[i].external;
            let result_request = self.client.request_result(external).ok();
            if result_request.is_none() {
                events.push(JtcEvent::Log {
                    level: LogLevel::Error,
                    message: format!(
                        "{}: the result request could not be sent; the goal ends by its timeout",
                        self.action
                    ),
                });
            }
            self.goals[i].phase = Phase::Running {
                result_request,
                last_feedback: None,
            };
            let exec_id = self.goals[i].exec_id;
            events.push(JtcEvent::Accepted { exec_id });
            // A newer accepted goal preempts the older running ones (the external server
            // preempts its own, as JTC does).
            let older: Vec<ExecGoalId> = self.goals[..i]
                .iter()
                .filter(|g| matches!(g.phase, Phase::Running { .. }))
                .map(|g| g.exec_id)
                .collect();
            for id in older {
                if let Some(k) = self.goals.iter().position(|g| g.exec_id == id) {
                    self.end(k, Outcome::Preempted, events);
                }
            }
        }
    }

    fn poll_results(&mut self, events: &mut Vec<JtcEvent>) {
        loop {
            let (request, response) = match self.client.result_client().receive_response() {
                Ok(Some(r)) => r,
                Ok(None) => break,
                Err(e) => {
                    events.push(JtcEvent::Log {
                        level: LogLevel::Error,
                        message: format!("{}: could not read a result: {e:?}", self.action),
                    });
                    break;
                }
            };
            let Some(i) = self.goals.iter().position(|g| {
                matches!(g.phase, Phase::Running { result_request: Some(r), .. } if r == request)
            }) else {
                continue;
            };
            let outcome = self.outcome(response.status, &response.result, self.goals[i].canceled);
            self.end(i, outcome, events);
        }
    }

    fn poll_feedback(&mut self, now: f64, events: &mut Vec<JtcEvent>) {
        loop {
            let message = match self.client.feedback_subscription().take() {
                Ok(Some((m, _))) => m,
                Ok(None) => break,
                Err(e) => {
                    events.push(JtcEvent::Log {
                        level: LogLevel::Warn,
                        message: format!("{}: could not read feedback: {e:?}", self.action),
                    });
                    break;
                }
            };
            let Some(g) = self
                .goals
                .iter_mut()
                .find(|g| g.external == message.goal_id)
            else {
                continue;
            };
            if let Phase::Running { last_feedback, .. } = &mut g.phase {
                *last_feedback = Some(now);
            }
            let exec_id = g.exec_id;
            let fb = message.feedback;
            if self.states.is_none() {
                if let Some(s) = self.sample(&fb.joint_names, &fb.desired) {
                    self.start = Some(s);
                }
            }
            let js = JointState {
                header: fb.header.clone(),
                name: fb.joint_names.clone(),
                position: fb.actual.positions.clone(),
                velocity: fb.actual.velocities.clone(),
                effort: fb.actual.effort.clone(),
            };
            self.publish_state(js, events);
            events.push(JtcEvent::Feedback {
                exec_id,
                feedback: Box::new(fb),
            });
        }
    }

    /// A state of the external feedback in model order (positions, and velocities and
    /// accelerations when given for every joint); `None` when it is not a valid state.
    fn sample(&self, names: &[String], point: &JointTrajectoryPoint) -> Option<JointSample> {
        let named = NamedState {
            names,
            positions: &point.positions,
            velocities: &point.velocities,
        };
        let s = measured_state("external desired state", named, &self.limits).ok()?;
        let mut sample = JointSample::at_rest(s.positions);
        if let Some(v) = s.velocities {
            sample.velocities = v;
        }
        if point.accelerations.len() == names.len() {
            let named = NamedState {
                names,
                positions: &point.accelerations,
                velocities: &[],
            };
            if let Ok(a) = measured_state("external desired state", named, &self.limits) {
                sample.accelerations = a.positions;
            }
        }
        Some(sample)
    }

    fn check_timeouts(&mut self, now: f64, events: &mut Vec<JtcEvent>) {
        let mut i = 0;
        while i < self.goals.len() {
            let g = &self.goals[i];
            let missing = match g.phase {
                Phase::Sent { at, .. } if now - at > self.timeout => Some(format!(
                    "no answer to the goal within {:.3} s (hardware.jtc_timeout): the server is \
                     not running or not reachable",
                    now - at
                )),
                Phase::Running {
                    last_feedback: Some(t),
                    ..
                } if now - t > self.timeout => Some(format!(
                    "no feedback for {:.3} s (hardware.jtc_timeout) while the goal runs: the \
                     server is gone; the robot's state is unknown",
                    now - t
                )),
                Phase::Running { .. } if now > g.due => Some(format!(
                    "no result {:.3} s after the trajectory's end and its goal time \
                     (hardware.jtc_timeout): the server is gone or stuck; the robot's state is \
                     unknown",
                    self.timeout
                )),
                _ => None,
            };
            let Some(reason) = missing else {
                i += 1;
                continue;
            };
            let _ = self.client.cancel_goal(g.external);
            let message = NodeError::ExternalServer {
                action: self.action.clone(),
                reason,
            }
            .to_string();
            self.end(
                i,
                Outcome::Aborted {
                    error_code: PATH_TOLERANCE_VIOLATED,
                    message,
                },
                events,
            );
        }
    }
}
