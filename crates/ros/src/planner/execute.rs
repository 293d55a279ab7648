//! Plan and execute (issue 27, item 3): a successful plan of a goal with `execute` is sent as a
//! goal to the executor's `control_msgs/action/FollowJointTrajectory` action (the node's
//! `execute_action` parameter), its feedback is relayed, and its result ends the plan goal.
//!
//! * **Sending**: the goal is sent once the executor's action server is discovered (a goal
//!   sent before would be lost); the trajectory is the plan's, unchanged, every other field of
//!   the goal its default (the executor's own tolerances).
//! * **No executor**: no server discovered, or no answer to the goal, within
//!   [`EXECUTOR_TIMEOUT`] (3 s) → the plan goal is ABORTED, not executed, the message naming
//!   the action. A goal the executor rejects is ABORTED the same way.
//! * **Running**: each `FollowJointTrajectory` feedback becomes a plan-goal feedback (stage
//!   `executing`, progress = desired `time_from_start` / the trajectory's duration).
//! * **Result**: the executor's status and result become the plan goal's: SUCCEEDED →
//!   SUCCEEDED; CANCELED after our cancel → CANCELED; anything else (ABORTED, or CANCELED by
//!   another client's goal preempting it) → ABORTED; `execution_error_code` is the executor's
//!   `error_code`.
//! * **A vanished executor**: no result [`RESULT_GRACE`] (5 s) after the trajectory's end, no
//!   feedback for [`EXECUTOR_TIMEOUT`] once it began, or no result [`EXECUTOR_TIMEOUT`] after a
//!   cancel → ABORTED (CANCELED after a cancel) with a message saying what was missing, and a
//!   cancel is sent in case the executor is only slow.
//! * **Cancel**: a cancel request to the executor for the goal; the result then comes from it.

use std::time::{Duration, Instant};

use kerf_msgs::{
    control_msgs::{
        FollowJointTrajectoryFeedback, FollowJointTrajectoryGoal, FollowJointTrajectoryResult,
    },
    trajectory_msgs::JointTrajectory,
};
use ros2_client::{
    action::{ActionClient, GoalId, GoalStatusEnum},
    RmwRequestId,
};

/// The executor's action client.
pub type FjtClient = ActionClient<
    FollowJointTrajectoryGoal,
    FollowJointTrajectoryResult,
    FollowJointTrajectoryFeedback,
>;

/// The executor's action type.
pub const FJT_TYPE: &str = "control_msgs/action/FollowJointTrajectory";

/// Default of the `execute_action` parameter: the trajectory executor's action.
pub const DEFAULT_EXECUTE_ACTION: &str = "/trajectory_executor/follow_joint_trajectory";

/// How long the executor may take to be discovered and answer a goal, to send feedback again
/// once it has, and to end a goal after a cancel.
pub const EXECUTOR_TIMEOUT: Duration = Duration::from_secs(3);

/// How long after the trajectory's end the executor may take to give its result (goal
/// tolerances settling).
pub const RESULT_GRACE: Duration = Duration::from_secs(5);

/// How often an undiscovered executor is looked for.
const DISCOVERY_POLL: Duration = Duration::from_millis(50);

/// How an execution ended, for the plan goal's result.
#[derive(Debug, Clone, PartialEq)]
pub struct ExecutionEnd {
    /// The plan goal's terminal status.
    pub status: GoalStatusEnum,
    /// The executor ended the goal and gave its result.
    pub executed: bool,
    /// The executor's `error_code` (0 when not executed).
    pub error_code: i32,
    /// The executor goal's status and `error_string`, or why there was no execution.
    pub message: String,
}

/// What the executions tell the node loop.
#[derive(Debug, Clone, PartialEq)]
pub enum ExecutionEvent {
    /// Progress of the execution of a plan goal.
    Progress {
        /// The plan goal.
        goal: GoalId,
        /// In [0, 1].
        progress: f64,
    },
    /// The execution of a plan goal ended.
    Finished {
        /// The plan goal.
        goal: GoalId,
        /// How.
        end: ExecutionEnd,
    },
}

#[derive(Debug, Clone, Copy)]
enum Phase {
    /// Waiting for the executor's server to be discovered.
    Discovering { next_check: Instant },
    /// Sent; waiting for the answer.
    Sent { request: RmwRequestId, at: Instant },
    /// Accepted; waiting for the result.
    Running {
        result_request: Option<RmwRequestId>,
        accepted_at: Instant,
        last_feedback: Option<Instant>,
    },
}

#[derive(Debug)]
struct Execution {
    goal: GoalId,
    external: Option<GoalId>,
    trajectory: Option<JointTrajectory>,
    duration: f64,
    phase: Phase,
    started: Instant,
    canceled_at: Option<Instant>,
}

/// The executions of plan goals, one executor client.
pub struct Executions {
    client: FjtClient,
    action: String,
    runs: Vec<Execution>,
}

impl Executions {
    /// Executions through `client`, the action named `action` (resolved, for messages).
    pub fn new(client: FjtClient, action: String) -> Self {
        Self {
            client,
            action,
            runs: Vec::new(),
        }
    }

    /// The executor's client (to look for its server).
    pub fn client(&self) -> &FjtClient {
        &self.client
    }

    /// Whether an execution is under way.
    pub fn is_busy(&self) -> bool {
        !self.runs.is_empty()
    }

    /// Starts executing `trajectory` for the plan goal `goal`: sent once the executor is
    /// discovered ([`Self::poll`]).
    pub fn start(&mut self, goal: GoalId, trajectory: JointTrajectory) {
        let duration = trajectory
            .points
            .last()
            .map_or(0.0, |p| p.time_from_start.as_secs_f64());
        let now = Instant::now();
        self.runs.push(Execution {
            goal,
            external: None,
            trajectory: Some(trajectory),
            duration,
            phase: Phase::Discovering { next_check: now },
            started: now,
            canceled_at: None,
        });
    }

    /// Cancels the execution of `goal`: a cancel request to the executor once its goal is
    /// sent (an unsent one ends at once).
    ///
    /// # Returns
    /// The end, when the execution ended at once (it was not sent yet).
    pub fn cancel(&mut self, goal: &GoalId) -> Option<ExecutionEnd> {
        let i = self.runs.iter().position(|r| &r.goal == goal)?;
        let run = self.runs.get_mut(i)?;
        if run.canceled_at.is_none() {
            run.canceled_at = Some(Instant::now());
        }
        match (run.phase, run.external) {
            (Phase::Discovering { .. }, _) => {
                self.runs.remove(i);
                Some(ExecutionEnd {
                    status: GoalStatusEnum::Canceled,
                    executed: false,
                    error_code: 0,
                    message: "canceled before the trajectory was sent to the executor".into(),
                })
            }
            (_, Some(external)) => {
                // Best effort: an unanswered cancel still ends by the result or the timeout.
                let _ = self.client.cancel_goal(external);
                None
            }
            (_, None) => None,
        }
    }

    /// Cancels every execution (the node is stopping).
    pub fn cancel_all(&mut self) -> Vec<(GoalId, ExecutionEnd)> {
        let goals: Vec<GoalId> = self.runs.iter().map(|r| r.goal).collect();
        goals
            .into_iter()
            .filter_map(|g| self.cancel(&g).map(|end| (g, end)))
            .collect()
    }

    /// Ends every execution still under way (the node is leaving): the executor's goals keep
    /// the cancel sent by [`Self::cancel_all`].
    pub fn abandon(&mut self) -> Vec<(GoalId, ExecutionEnd)> {
        let action = self.action.clone();
        self.runs
            .drain(..)
            .map(|r| {
                (
                    r.goal,
                    ExecutionEnd {
                        status: GoalStatusEnum::Aborted,
                        executed: false,
                        error_code: 0,
                        message: format!(
                            "the planner node stopped before the executor ({action}) confirmed \
                             the end of the execution; a cancel was sent to it"
                        ),
                    },
                )
            })
            .collect()
    }

    /// Sends discovered goals, takes the executor's answers, feedback and results, and checks
    /// the timeouts. `discovered` says whether the executor's server is matched now (it is
    /// asked at most every [`DISCOVERY_POLL`] per waiting execution).
    pub fn poll(
        &mut self,
        discovered: impl Fn(&FjtClient) -> bool,
        events: &mut Vec<ExecutionEvent>,
    ) {
        self.send_discovered(&discovered, events);
        self.poll_goal_responses(events);
        self.poll_results(events);
        self.poll_feedback(events);
        // Cancel answers carry nothing the result does not; drained so they do not pile up.
        while let Ok(Some(_)) = self.client.cancel_client().receive_response() {}
        self.check_timeouts(events);
    }

    fn not_executed(status: GoalStatusEnum, message: String) -> ExecutionEnd {
        ExecutionEnd {
            status,
            executed: false,
            error_code: 0,
            message,
        }
    }

    fn end(&mut self, i: usize, end: ExecutionEnd, events: &mut Vec<ExecutionEvent>) {
        if i < self.runs.len() {
            let run = self.runs.remove(i);
            events.push(ExecutionEvent::Finished {
                goal: run.goal,
                end,
            });
        }
    }

    fn send_discovered(
        &mut self,
        discovered: &impl Fn(&FjtClient) -> bool,
        events: &mut Vec<ExecutionEvent>,
    ) {
        let now = Instant::now();
        let mut i = 0;
        while i < self.runs.len() {
            let Some(run) = self.runs.get_mut(i) else {
                break;
            };
            let Phase::Discovering { next_check } = run.phase else {
                i += 1;
                continue;
            };
            if now < next_check {
                i += 1;
                continue;
            }
            if !discovered(&self.client) {
                if now.duration_since(run.started) > EXECUTOR_TIMEOUT {
                    let message = format!(
                        "not executed: no FollowJointTrajectory server was discovered on {} \
                         within {:.1} s (is the trajectory executor running? the planner's \
                         execute_action parameter names its action)",
                        self.action,
                        EXECUTOR_TIMEOUT.as_secs_f64()
                    );
                    self.end(
                        i,
                        Self::not_executed(GoalStatusEnum::Aborted, message),
                        events,
                    );
                } else {
                    run.phase = Phase::Discovering {
                        next_check: now + DISCOVERY_POLL,
                    };
                    i += 1;
                }
                continue;
            }
            let goal = FollowJointTrajectoryGoal {
                trajectory: run.trajectory.take().unwrap_or_default(),
                ..FollowJointTrajectoryGoal::default()
            };
            match self.client.send_goal(goal) {
                Ok((request, external)) => {
                    run.external = Some(external);
                    run.phase = Phase::Sent { request, at: now };
                    i += 1;
                }
                Err(e) => {
                    let message = format!(
                        "not executed: the goal could not be sent to {}: {e:?}",
                        self.action
                    );
                    self.end(
                        i,
                        Self::not_executed(GoalStatusEnum::Aborted, message),
                        events,
                    );
                }
            }
        }
    }

    fn poll_goal_responses(&mut self, events: &mut Vec<ExecutionEvent>) {
        while let Ok(Some((request, response))) = self.client.goal_client().receive_response() {
            let Some(i) = self
                .runs
                .iter()
                .position(|r| matches!(r.phase, Phase::Sent { request: q, .. } if q == request))
            else {
                continue;
            };
            if !response.accepted {
                let message = format!(
                    "not executed: the executor ({}) rejected the goal (a ROS 2 goal rejection \
                     carries no reason; the executor's log has it)",
                    self.action
                );
                self.end(
                    i,
                    Self::not_executed(GoalStatusEnum::Aborted, message),
                    events,
                );
                continue;
            }
            let Some(run) = self.runs.get_mut(i) else {
                continue;
            };
            let result_request = run
                .external
                .and_then(|external| self.client.request_result(external).ok());
            run.phase = Phase::Running {
                result_request,
                accepted_at: Instant::now(),
                last_feedback: None,
            };
            // A cancel that came while the goal was being sent.
            if let (Some(_), Some(external)) = (run.canceled_at, run.external) {
                let _ = self.client.cancel_goal(external);
            }
        }
    }

    /// The plan goal's end for the executor's `status` and `result`.
    fn outcome(
        &self,
        status: GoalStatusEnum,
        result: FollowJointTrajectoryResult,
        canceled: bool,
    ) -> ExecutionEnd {
        let name = match status {
            GoalStatusEnum::Succeeded => "SUCCEEDED",
            GoalStatusEnum::Canceled => "CANCELED",
            GoalStatusEnum::Aborted => "ABORTED",
            _ => "UNKNOWN",
        };
        let message = if result.error_string.is_empty() {
            name.to_string()
        } else {
            format!("{name}: {}", result.error_string)
        };
        let plan_status = match status {
            GoalStatusEnum::Succeeded => GoalStatusEnum::Succeeded,
            GoalStatusEnum::Canceled if canceled => GoalStatusEnum::Canceled,
            _ => GoalStatusEnum::Aborted,
        };
        ExecutionEnd {
            status: plan_status,
            executed: true,
            error_code: result.error_code,
            message,
        }
    }

    fn poll_results(&mut self, events: &mut Vec<ExecutionEvent>) {
        while let Ok(Some((request, response))) = self.client.result_client().receive_response() {
            let Some(i) = self.runs.iter().position(|r| {
                matches!(r.phase, Phase::Running { result_request: Some(q), .. } if q == request)
            }) else {
                continue;
            };
            let canceled = self.runs.get(i).is_some_and(|r| r.canceled_at.is_some());
            let end = self.outcome(response.status, response.result, canceled);
            self.end(i, end, events);
        }
    }

    fn poll_feedback(&mut self, events: &mut Vec<ExecutionEvent>) {
        while let Ok(Some((message, _))) = self.client.feedback_subscription().take() {
            let Some(run) = self
                .runs
                .iter_mut()
                .find(|r| r.external == Some(message.goal_id))
            else {
                continue;
            };
            if let Phase::Running { last_feedback, .. } = &mut run.phase {
                *last_feedback = Some(Instant::now());
            }
            let t = message.feedback.desired.time_from_start.as_secs_f64();
            let progress = if run.duration > 0.0 {
                (t / run.duration).clamp(0.0, 1.0)
            } else {
                1.0
            };
            events.push(ExecutionEvent::Progress {
                goal: run.goal,
                progress,
            });
        }
    }

    fn check_timeouts(&mut self, events: &mut Vec<ExecutionEvent>) {
        let now = Instant::now();
        let mut i = 0;
        while i < self.runs.len() {
            let Some(run) = self.runs.get(i) else {
                break;
            };
            let since = |t: Instant| now.saturating_duration_since(t);
            let missing = match run.phase {
                Phase::Discovering { .. } => None,
                Phase::Sent { at, .. } if since(at) > EXECUTOR_TIMEOUT => Some((
                    false,
                    format!(
                        "not executed: the executor ({}) did not answer the goal within {:.1} s",
                        self.action,
                        EXECUTOR_TIMEOUT.as_secs_f64()
                    ),
                )),
                Phase::Sent { .. } => None,
                Phase::Running {
                    accepted_at,
                    last_feedback,
                    ..
                } => {
                    let due = Duration::from_secs_f64(run.duration.max(0.0)) + RESULT_GRACE;
                    match (run.canceled_at, last_feedback) {
                        (Some(c), _) if since(c) > EXECUTOR_TIMEOUT => Some((
                            true,
                            format!(
                                "the executor ({}) did not end the goal within {:.1} s of the \
                                 cancel; the robot's state is unknown",
                                self.action,
                                EXECUTOR_TIMEOUT.as_secs_f64()
                            ),
                        )),
                        (_, Some(f)) if since(f) > EXECUTOR_TIMEOUT => Some((
                            false,
                            format!(
                                "the executor ({}) sent no feedback for {:.1} s while the \
                                 trajectory ran: it is gone; the robot's state is unknown",
                                self.action,
                                since(f).as_secs_f64()
                            ),
                        )),
                        _ if since(accepted_at) > due => Some((
                            false,
                            format!(
                                "the executor ({}) gave no result {:.1} s after the \
                                 trajectory's end: it is gone or stuck; the robot's state is \
                                 unknown",
                                self.action,
                                RESULT_GRACE.as_secs_f64()
                            ),
                        )),
                        _ => None,
                    }
                }
            };
            let Some((after_cancel, message)) = missing else {
                i += 1;
                continue;
            };
            if let Some(external) = run.external {
                let _ = self.client.cancel_goal(external);
            }
            let status = if after_cancel || run.canceled_at.is_some() {
                GoalStatusEnum::Canceled
            } else {
                GoalStatusEnum::Aborted
            };
            self.end(i, Self::not_executed(status, message), events);
        }
    }
}
