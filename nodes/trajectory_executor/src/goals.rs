//! The `FollowJointTrajectory` action side of the request thread: goals (accepted, then
//! prepared and started like topic trajectories), cancel requests and result requests.

use ros2_client::{
    action::{
        CancelGoalRequest, CancelGoalResponse, GetResultResponse, GoalInfo, GoalStatusEnum,
        SendGoalRequest, SendGoalResponse,
    },
    action_msgs::CancelGoalResponseEnum,
};

use crate::{action, control, drain, ExecutorNode, Incoming, Job, Source};

impl ExecutorNode {
    pub(crate) fn poll_goals(&mut self) {
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
                ticket: None,
                result: None,
            });
            self.statuses_changed = true;
            self.enqueue(Job::Run(source), Incoming::Goal(Box::new(goal)));
        }
    }

    pub(crate) fn poll_cancels(&mut self) {
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

    pub(crate) fn cancel(&mut self, info: &GoalInfo) -> CancelGoalResponse {
        let selected = self.goals.select_for_cancel(info);
        let mut canceling = Vec::new();
        let mut to_control = Vec::new();
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
            // A goal still being prepared ends when its preparation comes back; one handed to
            // the control thread is canceled there (after its start, if that is still queued);
            // one forwarded to an external server (`hardware: jtc`) is canceled there.
            if let Some(ticket) = g.ticket {
                to_control.push((ticket, g.exec_id));
            }
        }
        for (ticket, exec_id) in to_control {
            if self.jobs.contains_key(&ticket) {
                continue;
            }
            match (self.jtc.as_mut(), exec_id) {
                (Some(f), Some(exec_id)) => {
                    f.cancel(exec_id);
                }
                (Some(_), None) => {}
                (None, _) => {
                    let _ = self.commands.send(control::Command::Cancel { tag: ticket });
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

    pub(crate) fn poll_result_requests(&mut self) {
        let (requests, error) = drain(|| self.action.receive_result_request());
        if let Some(e) = error {
            self.log
                .error(&format!("could not read a result request: {e}"));
        }
        for (req_id, req) in requests {
            self.goals.pending_results.push((req.goal_id, req_id));
        }
    }

    /// Answers the result requests whose goal has ended.
    pub(crate) fn answer_results(&mut self) {
        if self.goals.pending_results.is_empty() {
            return;
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
