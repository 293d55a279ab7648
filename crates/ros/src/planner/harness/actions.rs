//! The planning action in the node loop (issue 27, item 3): `~/plan_<noun>` goals join the
//! request queue, their answers end them (or start their execution), cancel requests stop
//! their plan or execution, feedback and statuses are published, result requests answered.
//!
//! * **Goals** are always accepted (a ROS 2 goal rejection cannot carry a reason) and their
//!   request then takes the topic path: numbers, conversion, budget and size checks, the one
//!   queue (arrival order), QUEUE_FULL when `queue_depth` requests wait or are planned. A goal
//!   whose request is refused ends ABORTED with the refusal as its plan. A goal that arrives
//!   while the node is stopping ends ABORTED at once ("the planner node is stopping").
//! * **Answers** of goals are published on the plan topics like every answer, but not on
//!   `~/joint_trajectory`: whether a goal's trajectory runs is its `execute` flag's decision.
//! * **Cancel**: a queued goal is taken out of the queue and answered at once
//!   ([`Failure::Canceled`]); a goal being planned is cancelled through its worker and
//!   answered when the worker answers, or, after [`ACTION_CANCEL_GRACE`], its worker is
//!   stopped and replaced; an executing goal is cancelled on the executor
//!   ([`super::super::execute`]).

use std::time::{Duration, Instant};

use kerf_msgs::numbers::NumberFields;
use ros2_client::{
    action::{ActionServer, GetResultResponse, GoalId, GoalStatusEnum, SendGoalResponse},
    builtin_interfaces::Time as RosTime,
};

use super::{PlannerNode, Queued, Running};
use crate::{
    planner::{
        action::{cancel_target, Origin, PlanGoals},
        execute::{ExecutionEnd, ExecutionEvent, Executions, FJT_TYPE},
        goal_msgs::{action_name, action_type, PlanFeedback, PlanGoal, PlanResult, Stage},
        result_fit::{fit_result, result_limit},
        Failure, PlanAnswer, PlanningService,
    },
    DiscoveryRange, KerfNode, RosError,
};

/// How long a plan whose goal was cancelled may take to answer before its worker process is
/// stopped (and replaced): with the DDS round trips, the goal is answered CANCELED within
/// 100 ms of the cancel request whatever the planner does.
pub const ACTION_CANCEL_GRACE: Duration = Duration::from_millis(80);

/// How often queued and planning goals get feedback (an executing goal gets one per executor
/// feedback).
pub const FEEDBACK_PERIOD: Duration = Duration::from_millis(100);

type Server<S> = ActionServer<
    PlanGoal<<S as PlanningService>::RequestMsg>,
    PlanResult<<S as PlanningService>::Answer>,
    PlanFeedback,
>;

/// The node's planning action: its server, goals and executions.
pub(super) struct ActionSide<S: PlanningService> {
    server: Server<S>,
    goals: PlanGoals<S::Answer>,
    executions: Executions,
    /// `~/plan_<noun>` resolved, for log lines.
    pub(super) name: String,
    /// The executor's action resolved, for log lines.
    pub(super) execute_action: String,
    /// The largest result sent whole ([`result_limit`]), and where the full answers are.
    result_limit: usize,
    plan_topic: String,
    next_feedback: Instant,
    /// The node is stopping: new goals end at once, no execution starts.
    stopping: bool,
}

impl<S: PlanningService> ActionSide<S> {
    /// The server of `~/plan_<noun>` and the client of the executor's action
    /// (`execute_action`, checked: a valid name).
    ///
    /// # Errors
    /// [`RosError::Param`] naming `execute_action` for a name that does not resolve; a DDS
    /// failure.
    pub(super) fn new(
        node: &mut KerfNode,
        noun: &str,
        execute_action: &str,
        range: DiscoveryRange,
        plan_topic: String,
    ) -> Result<Self, RosError> {
        let local = action_name(noun);
        let server = node.action_server(&local, &action_type(noun))?;
        let name = node.resolve(&local)?;
        let resolved = node.resolve(execute_action).map_err(|e| RosError::Param {
            name: "execute_action".into(),
            reason: format!("'{execute_action}' is not a valid action name: {e}"),
        })?;
        let client = node.action_client(&resolved, FJT_TYPE)?;
        Ok(Self {
            server,
            goals: PlanGoals::default(),
            executions: Executions::new(client, resolved.clone()),
            name,
            execute_action: resolved,
            result_limit: result_limit(range),
            plan_topic,
            next_feedback: Instant::now(),
            stopping: false,
        })
    }

    /// Whether the goal at the head of the queue must wait: it executes, and an execution of
    /// an earlier goal runs (its plan starts where that execution leaves the robot).
    pub(super) fn must_wait(&self, origin: Origin) -> bool {
        match origin {
            Origin::Goal(id) => {
                self.executions.is_busy() && self.goals.get(&id).is_some_and(|g| g.execute)
            }
            Origin::Topic => false,
        }
    }

    /// Whether goals or executions are under way.
    pub(super) fn is_active(&self) -> bool {
        self.goals.active().next().is_some()
    }
}

impl<S: PlanningService> PlannerNode<S> {
    /// Serves the planning action for one turn of the loop; `true` if anything happened.
    pub(super) fn poll_action(&mut self) -> bool {
        let mut any = self.accept_goals();
        any |= self.poll_cancels();
        any |= self.poll_result_requests();
        any |= self.poll_executions();
        any |= self.stop_unanswered_cancel();
        self.send_feedback_when_due();
        self.answer_results();
        if self.actions.goals.take_changed() {
            let statuses = self.actions.goals.status_array();
            if let Err(e) = self.actions.server.send_goal_statuses(statuses) {
                self.log.warn(&format!(
                    "{}: goal statuses not published: {e:?}",
                    self.actions.name
                ));
            }
        }
        any
    }

    /// Accepts new goals and queues their requests; `true` if there were any.
    fn accept_goals(&mut self) -> bool {
        let mut any = false;
        loop {
            let (request_id, goal_id, goal) = match self.actions.server.receive_goal() {
                Ok(Some((r, g))) => (r, g.goal_id, g.goal),
                Ok(None) => break,
                Err(e) => {
                    self.log.error(&format!(
                        "{}: could not read a goal: {e:?}",
                        self.actions.name
                    ));
                    break;
                }
            };
            any = true;
            let accepted = RosTime::now();
            // A goal id already known is refused, as rcl_action does.
            let duplicate = self.actions.goals.get(&goal_id).is_some();
            let response = SendGoalResponse {
                accepted: !duplicate,
                stamp: accepted,
            };
            if let Err(e) = self.actions.server.send_goal_response(request_id, response) {
                self.log.error(&format!(
                    "{}: could not answer goal {goal_id:?}: {e:?}",
                    self.actions.name
                ));
            }
            if duplicate {
                self.log.warn(&format!(
                    "{}: goal {goal_id:?} refused: its id is already used by another goal",
                    self.actions.name
                ));
                continue;
            }
            self.actions.goals.add(goal_id, accepted, goal.execute);
            let origin = Origin::Goal(goal_id);
            if self.actions.stopping {
                let key = self.service.msg_key(&goal.request);
                let answer = self.service.failure(
                    &key,
                    Failure::Stopped,
                    "the planner node is stopping: the goal was not planned".into(),
                );
                self.publish_from(answer, origin);
                continue;
            }
            let ahead = u32::try_from(self.pending()).unwrap_or(u32::MAX);
            self.feedback(&goal_id, Stage::Queued, 0.0, ahead);
            let queued = self.queued_msg(goal.request, "goal");
            self.submit_from(queued, origin);
        }
        any
    }

    /// The queue entry of a request message (numbers, conversion, budget, size), as for the
    /// request topic.
    pub(super) fn queued_msg(
        &self,
        m: S::RequestMsg,
        source: &str,
    ) -> Queued<S::RequestMsg, S::Answer> {
        match m.check_numbers() {
            Err(e) => Queued::Answer(Box::new(self.service.failure(
                &self.service.msg_key(&m),
                Failure::BadNumber,
                format!("invalid request: {e}"),
            ))),
            Ok(()) => match self.service.request_from_msg(&m) {
                Ok(r) => self.plan_job(r, crate::planner::RawRequest::Msg(m), source),
                Err(answer) => Queued::Answer(answer),
            },
        }
    }

    /// The answer of a goal's request: it ends the goal, or starts its execution.
    pub(super) fn goal_answered(&mut self, id: GoalId, answer: S::Answer) {
        let Some(goal) = self.actions.goals.get(&id) else {
            return;
        };
        let (status, message) = if self.actions.goals.is_canceling(&id) {
            (
                GoalStatusEnum::Canceled,
                "not executed: the goal was canceled",
            )
        } else if !answer.is_success() {
            (GoalStatusEnum::Aborted, "not executed: the plan failed")
        } else if !goal.execute {
            (GoalStatusEnum::Succeeded, "not executed: execute is false")
        } else if self.actions.stopping {
            (
                GoalStatusEnum::Aborted,
                "not executed: the planner node is stopping",
            )
        } else {
            self.log.info(&format!(
                "goal {id:?} ('{}'): planned; executing on {}",
                answer.request_id(),
                self.actions.execute_action
            ));
            self.actions
                .executions
                .start(id, answer.trajectory().clone());
            self.actions.goals.set_stage(&id, Stage::Executing);
            if let Some(g) = self.actions.goals.get_mut(&id) {
                g.plan = Some(answer);
            }
            self.feedback(&id, Stage::Executing, 0.0, 0);
            return;
        };
        let result = PlanResult {
            plan: answer,
            executed: false,
            execution_error_code: 0,
            execution_message: message.into(),
        };
        self.actions.goals.finish(&id, status, result);
    }

    /// A goal's plan was handed to the worker.
    pub(super) fn goal_planning(&mut self, origin: Origin) {
        if let Origin::Goal(id) = origin {
            self.feedback(&id, Stage::Planning, 0.0, 0);
        }
    }

    /// Ends a goal's execution.
    fn execution_ended(&mut self, id: GoalId, end: ExecutionEnd) {
        let Some(plan) = self.actions.goals.get_mut(&id).and_then(|g| g.plan.take()) else {
            return;
        };
        let level_warn = end.status != GoalStatusEnum::Succeeded;
        let line = format!(
            "goal {id:?} ('{}'): execution {}: {}",
            plan.request_id(),
            if end.executed { "ended" } else { "not done" },
            end.message
        );
        if level_warn {
            self.log.warn(&line);
        } else {
            self.log.info(&line);
        }
        let result = PlanResult {
            plan,
            executed: end.executed,
            execution_error_code: end.error_code,
            execution_message: end.message,
        };
        self.actions.goals.finish(&id, end.status, result);
    }

    fn poll_executions(&mut self) -> bool {
        let mut events = Vec::new();
        let node = &self.node;
        self.actions.executions.poll(
            |c| node.wait_for_action_server(c, Duration::ZERO),
            &mut events,
        );
        let any = !events.is_empty();
        for event in events {
            match event {
                ExecutionEvent::Progress { goal, progress } => {
                    self.feedback(&goal, Stage::Executing, progress, 0)
                }
                ExecutionEvent::Finished { goal, end } => self.execution_ended(goal, end),
            }
        }
        any
    }

    fn poll_cancels(&mut self) -> bool {
        let mut any = false;
        loop {
            let (request_id, request) = match self.actions.server.receive_cancel_request() {
                Ok(Some(r)) => r,
                Ok(None) => break,
                Err(e) => {
                    self.log.error(&format!(
                        "{}: could not read a cancel request: {e:?}",
                        self.actions.name
                    ));
                    break;
                }
            };
            any = true;
            let (response, canceling) = match cancel_target(&request) {
                Ok(info) => self.actions.goals.begin_cancel(&info),
                Err(reason) => {
                    self.log.error(&format!(
                        "{}: malformed cancel request: {reason}",
                        self.actions.name
                    ));
                    (
                        ros2_client::action::CancelGoalResponse {
                            return_code: ros2_client::action_msgs::CancelGoalResponseEnum::Rejected,
                            goals_canceling: Vec::new(),
                        },
                        Vec::new(),
                    )
                }
            };
            if let Err(e) = self
                .actions
                .server
                .send_cancel_response(request_id, response)
            {
                self.log.error(&format!(
                    "{}: could not answer a cancel request: {e:?}",
                    self.actions.name
                ));
            }
            for id in canceling {
                self.cancel_work(id);
            }
        }
        any
    }

    /// Stops the work of a goal being canceled: its queue entry, its plan or its execution.
    fn cancel_work(&mut self, id: GoalId) {
        let origin = Origin::Goal(id);
        if let Some(i) = self.queue.iter().position(|(_, o)| *o == origin) {
            if let Some((entry, _)) = self.queue.remove(i) {
                let answer = match entry {
                    Queued::Answer(a) => *a,
                    Queued::Plan { key, .. } => self.service.failure(
                        &key,
                        Failure::Canceled,
                        "canceled by the action client while queued; not planned".into(),
                    ),
                };
                self.log
                    .info(&format!("goal {id:?}: canceled while queued"));
                self.publish_from(answer, origin);
            }
            return;
        }
        if let Some(r) = self.running.as_mut().filter(|r| r.origin == origin) {
            if r.canceled_at.is_none() {
                r.canceled_at = Some(Instant::now());
                self.supervisor.cancel();
                self.log
                    .info(&format!("goal {id:?}: canceling its plan in progress"));
            }
            return;
        }
        if let Some(end) = self.actions.executions.cancel(&id) {
            self.execution_ended(id, end);
        } else {
            self.log.info(&format!(
                "goal {id:?}: canceling its execution on {}",
                self.actions.execute_action
            ));
        }
    }

    /// The answer of a plan cancelled by its goal's client: CANCELED, whatever the worker
    /// answered (or after its worker was stopped).
    pub(super) fn canceled_answer(&self, running: &Running, stopped_worker: bool) -> S::Answer {
        let after = running
            .canceled_at
            .map_or(0.0, |t| t.elapsed().as_secs_f64() * 1e3);
        let how = if stopped_worker {
            format!(
                "the plan did not stop within {} ms, so its worker process was stopped (and \
                 replaced)",
                ACTION_CANCEL_GRACE.as_millis()
            )
        } else {
            format!("the plan stopped {after:.0} ms after the cancel")
        };
        self.service.failure(
            &running.key,
            Failure::Canceled,
            format!(
                "canceled by the action client after {:.3} s of planning; {how}",
                running.started.elapsed().as_secs_f64() - after * 1e-3
            ),
        )
    }

    /// Stops the worker of a cancelled plan that has not answered within
    /// [`ACTION_CANCEL_GRACE`], and answers the plan; `true` if it did.
    fn stop_unanswered_cancel(&mut self) -> bool {
        let overdue = self
            .running
            .as_ref()
            .and_then(|r| r.canceled_at)
            .is_some_and(|t| t.elapsed() > ACTION_CANCEL_GRACE);
        if !overdue {
            return false;
        }
        // One last look: the answer may be there.
        if self.poll_worker() {
            return true;
        }
        let Some(running) = self.running.take() else {
            return false;
        };
        self.replace_worker();
        let answer = self.canceled_answer(&running, true);
        self.publish_from(answer, running.origin);
        // The result first, then the fork of the next worker.
        self.answer_results();
        if let Err(e) = self.supervisor.warm() {
            self.log
                .error(&format!("no new planner worker process yet: {e}"));
        }
        true
    }

    /// Result requests wait for their goal's end.
    fn poll_result_requests(&mut self) -> bool {
        let mut any = false;
        loop {
            match self.actions.server.receive_result_request() {
                Ok(Some((request_id, request))) => {
                    any = true;
                    self.actions
                        .goals
                        .wait_for_result(request.goal_id, request_id);
                }
                Ok(None) => break,
                Err(e) => {
                    self.log.error(&format!(
                        "{}: could not read a result request: {e:?}",
                        self.actions.name
                    ));
                    break;
                }
            }
        }
        any
    }

    /// Answers the result requests whose goal has ended.
    fn answer_results(&mut self) {
        for (request_id, status, result) in self.actions.goals.take_ready_results() {
            let result =
                result.map(|r| fit_result(r, self.actions.result_limit, &self.actions.plan_topic));
            let result = result.unwrap_or_else(|| PlanResult {
                plan: self.service.failure(
                    &Default::default(),
                    Failure::Unreadable,
                    format!("unknown goal: {} does not know it", self.actions.name),
                ),
                executed: false,
                execution_error_code: 0,
                execution_message: String::new(),
            });
            if let Err(e) = self
                .actions
                .server
                .send_result(request_id, GetResultResponse { status, result })
            {
                self.log.error(&format!(
                    "{}: could not send a goal result: {e:?}",
                    self.actions.name
                ));
            }
        }
    }

    /// Publishes one feedback of a goal.
    fn feedback(&mut self, id: &GoalId, stage: Stage, progress: f64, queue_position: u32) {
        self.actions.goals.set_stage(id, stage);
        let Some(goal) = self.actions.goals.get(id) else {
            return;
        };
        let feedback = PlanFeedback {
            stage: stage.as_str().into(),
            progress: progress.clamp(0.0, 1.0),
            queue_position,
            elapsed: goal.elapsed(),
        };
        // Feedback is periodic: a lost one is replaced by the next.
        let _ = self.actions.server.send_feedback(*id, feedback);
    }

    /// The periodic feedback of queued and planning goals.
    fn send_feedback_when_due(&mut self) {
        if Instant::now() < self.actions.next_feedback {
            return;
        }
        self.actions.next_feedback = Instant::now() + FEEDBACK_PERIOD;
        let ahead = usize::from(self.running.is_some());
        let queued: Vec<(GoalId, u32)> = self
            .queue
            .iter()
            .enumerate()
            .filter_map(|(i, (_, o))| match o {
                Origin::Goal(id) => Some((*id, u32::try_from(i + ahead).unwrap_or(u32::MAX))),
                Origin::Topic => None,
            })
            .collect();
        for (id, position) in queued {
            self.feedback(&id, Stage::Queued, 0.0, position);
        }
        if let Some((Origin::Goal(id), progress)) = self.running.as_ref().map(|r| {
            let used = r.started.elapsed().as_secs_f64() / r.limit.as_secs_f64().max(1e-9);
            (r.origin, used)
        }) {
            self.feedback(&id, Stage::Planning, progress, 0);
        }
    }

    /// The node is stopping: new goals end at once, executions are cancelled on the executor.
    pub(super) fn stop_actions(&mut self) {
        self.actions.stopping = true;
        for (id, end) in self.actions.executions.cancel_all() {
            self.execution_ended(id, end);
        }
    }

    /// Whether goals or executions are under way (the node lingers for them when stopping).
    pub(super) fn actions_active(&self) -> bool {
        self.actions.is_active()
    }

    /// Serves the action for `linger` (results, cancels, new goals ended at once, the
    /// executions' ends), then ends every goal still under way.
    pub(super) fn linger_actions(&mut self, linger: Duration) {
        let until = Instant::now() + linger;
        while Instant::now() < until {
            if !self.poll_action() {
                std::thread::sleep(super::POLL);
            }
        }
        for (id, end) in self.actions.executions.abandon() {
            self.execution_ended(id, end);
        }
        self.answer_results();
        if self.actions.goals.take_changed() {
            let statuses = self.actions.goals.status_array();
            let _ = self.actions.server.send_goal_statuses(statuses);
        }
    }
}
