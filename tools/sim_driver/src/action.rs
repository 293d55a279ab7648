//! The FollowJointTrajectory side of the loop: goals (checked, accepted or rejected,
//! preempting the running one), cancel requests, result requests and goal statuses.

use kerf_msgs::control_msgs::FollowJointTrajectoryResult;
use ros2_client::{
    action::{
        CancelGoalResponse, GetResultResponse, GoalInfo, GoalStatusEnum, SendGoalRequest,
        SendGoalResponse,
    },
    action_msgs::CancelGoalResponseEnum,
    builtin_interfaces::Time as RosTime,
};

use crate::{
    goals::cancel_target,
    serve::{log, wall_clock, Loop, MAX_PER_PASS},
    trajectory::Goal,
};

impl Loop<'_> {
    /// Answers new goals: rejects, or accepts, preempts the running goal and starts it.
    pub(crate) fn poll_goals(&mut self, now: f64) {
        for _ in 0..MAX_PER_PASS {
            let (req, SendGoalRequest { goal_id, goal }) = match self.ep.action.receive_goal() {
                Ok(Some(g)) => g,
                Ok(None) => break,
                Err(e) => {
                    log(&format!("unreadable goal request: {e:?}"));
                    continue;
                }
            };
            let verdict = if self.driver.rejects_goals() {
                Err("goals are rejected (fault reject_goals)".to_string())
            } else {
                Goal::check(&goal, self.driver.joints())
            };
            let checked = match verdict {
                Ok(c) => c,
                Err(reason) => {
                    self.driver.counters.goals_rejected += 1;
                    log(&format!("rejected goal {goal_id:?}: {reason}"));
                    let answer = SendGoalResponse {
                        accepted: false,
                        stamp: RosTime::ZERO,
                    };
                    if let Err(e) = self.ep.action.send_goal_response(req, answer) {
                        log(&format!("could not answer goal {goal_id:?}: {e:?}"));
                    }
                    continue;
                }
            };
            let accepted = RosTime::from_nanos(wall_clock().as_nanos());
            let answer = SendGoalResponse {
                accepted: true,
                stamp: accepted,
            };
            if let Err(e) = self.ep.action.send_goal_response(req, answer) {
                log(&format!("could not answer goal {goal_id:?}: {e:?}"));
            }
            self.book.add(goal_id, accepted);
            if let Some(old) = self.running.take() {
                self.driver.preempt();
                let message = "preempted by a newer goal".to_string();
                log(&format!("goal {old:?} {message}"));
                let result = FollowJointTrajectoryResult {
                    error_code: FollowJointTrajectoryResult::INVALID_GOAL,
                    error_string: message,
                };
                self.book.finish(&old, GoalStatusEnum::Aborted, result);
            }
            self.schedule.start(now);
            let points = goal.trajectory.points.len();
            match self.driver.start_goal(now, checked) {
                Ok(()) => {
                    log(&format!("accepted goal {goal_id:?}: {points} points"));
                    self.running = Some(goal_id);
                }
                Err(end) => {
                    log(&format!(
                        "aborted goal {goal_id:?}: {}",
                        end.result.error_string
                    ));
                    self.book
                        .finish(&goal_id, GoalStatusEnum::Aborted, end.result);
                }
            }
        }
    }

    /// Answers cancel requests.
    pub(crate) fn poll_cancels(&mut self) {
        for _ in 0..MAX_PER_PASS {
            let (req_id, req) = match self.ep.action.receive_cancel_request() {
                Ok(Some(r)) => r,
                Ok(None) => break,
                Err(e) => {
                    log(&format!("unreadable cancel request: {e:?}"));
                    continue;
                }
            };
            let response = match cancel_target(&req) {
                Err(e) => {
                    log(&format!("malformed cancel request: {e}"));
                    CancelGoalResponse {
                        return_code: CancelGoalResponseEnum::Rejected,
                        goals_canceling: Vec::new(),
                    }
                }
                Ok(info) => self.cancel(&info),
            };
            if let Err(e) = self.ep.action.send_cancel_response(req_id, response) {
                log(&format!("could not answer a cancel request: {e:?}"));
            }
        }
    }

    fn cancel(&mut self, info: &GoalInfo) -> CancelGoalResponse {
        let (executing, any) = self.book.select_for_cancel(info);
        for g in &executing {
            if self.running == Some(g.goal_id) {
                self.running = None;
                self.driver.cancel();
            }
            log(&format!(
                "goal {:?} canceled; holding the current position",
                g.goal_id
            ));
            let result = FollowJointTrajectoryResult {
                error_code: FollowJointTrajectoryResult::SUCCESSFUL,
                error_string: "canceled; holding the current position".into(),
            };
            self.book
                .finish(&g.goal_id, GoalStatusEnum::Canceled, result);
        }
        let return_code = if !executing.is_empty() {
            CancelGoalResponseEnum::None
        } else if any {
            CancelGoalResponseEnum::GoalTerminated
        } else {
            CancelGoalResponseEnum::UnknownGoal
        };
        CancelGoalResponse {
            return_code,
            goals_canceling: executing,
        }
    }

    /// Queues result requests until their goal ends.
    pub(crate) fn poll_result_requests(&mut self) {
        for _ in 0..MAX_PER_PASS {
            match self.ep.action.receive_result_request() {
                Ok(Some((req_id, req))) => self.book.wait_for_result(req.goal_id, req_id),
                Ok(None) => break,
                Err(e) => log(&format!("unreadable result request: {e:?}")),
            }
        }
    }

    /// Answers the result requests whose goal has ended.
    pub(crate) fn answer_results(&mut self) {
        for (req_id, status, result) in self.book.ready_results() {
            if let Err(e) = self
                .ep
                .action
                .send_result(req_id, GetResultResponse { status, result })
            {
                log(&format!("could not send a goal result: {e:?}"));
            }
        }
    }

    /// Publishes the goal statuses if they changed.
    pub(crate) fn publish_statuses(&mut self) {
        if std::mem::take(&mut self.book.changed) {
            if let Err(e) = self.ep.action.send_goal_statuses(self.book.status_array()) {
                log(&format!("goal statuses not published: {e:?}"));
            }
        }
    }
}
