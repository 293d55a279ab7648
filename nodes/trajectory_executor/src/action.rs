//! Book-keeping of FollowJointTrajectory goals: their status, results and pending result
//! requests, following the rcl_action goal state machine.

use std::collections::VecDeque;

use kerf_executor::GoalId as ExecGoalId;
use kerf_msgs::control_msgs::FollowJointTrajectoryResult;
use ros2_client::{
    action::{GoalId, GoalInfo, GoalStatusEnum},
    action_msgs::{GoalStatus, GoalStatusArray},
    builtin_interfaces::Time as RosTime,
    RmwRequestId,
};

/// Finished goals kept for late result requests (rcl_action keeps them for `result_timeout`).
pub const KEEP_FINISHED: usize = 64;

/// One goal known to the action server.
#[derive(Debug, Clone)]
pub struct ActionGoal {
    /// Goal id chosen by the client.
    pub id: GoalId,
    /// When it was accepted.
    pub accepted: RosTime,
    /// rcl_action status.
    pub status: GoalStatusEnum,
    /// The executor goal that runs it, while it runs.
    pub exec_id: Option<ExecGoalId>,
    /// Ticket of the goal's request (preparation, then the control thread).
    pub ticket: Option<u64>,
    /// The result, once terminal.
    pub result: Option<FollowJointTrajectoryResult>,
}

/// All goals of the server, newest last.
#[derive(Debug, Default)]
pub struct ActionGoals {
    goals: VecDeque<ActionGoal>,
    /// Result requests waiting for their goal to end.
    pub pending_results: Vec<(GoalId, RmwRequestId)>,
}

fn is_terminal(s: GoalStatusEnum) -> bool {
    matches!(
        s,
        GoalStatusEnum::Succeeded | GoalStatusEnum::Canceled | GoalStatusEnum::Aborted
    )
}

impl ActionGoals {
    /// Adds a goal in EXECUTING (or, with a result, terminal) state.
    pub fn add(&mut self, goal: ActionGoal) {
        self.goals.push_back(goal);
        while self.goals.len() > KEEP_FINISHED {
            match self.goals.iter().position(|g| is_terminal(g.status)) {
                Some(i) => {
                    self.goals.remove(i);
                }
                None => break,
            }
        }
    }

    /// The goal with this id.
    pub fn get(&self, id: &GoalId) -> Option<&ActionGoal> {
        self.goals.iter().find(|g| &g.id == id)
    }

    /// The action goal run by an executor goal.
    pub fn by_exec(&mut self, exec: ExecGoalId) -> Option<&mut ActionGoal> {
        self.goals.iter_mut().find(|g| g.exec_id == Some(exec))
    }

    /// The goal with this id, mutable.
    pub fn get_mut(&mut self, id: &GoalId) -> Option<&mut ActionGoal> {
        self.goals.iter_mut().find(|g| &g.id == id)
    }

    /// Ends a goal with `status` and `result`.
    pub fn finish(
        &mut self,
        id: &GoalId,
        status: GoalStatusEnum,
        result: FollowJointTrajectoryResult,
    ) {
        if let Some(g) = self.get_mut(id) {
            g.status = status;
            g.exec_id = None;
            g.result = Some(result);
        }
    }

    /// Goals selected by a CancelGoal request, as `action_msgs/srv/CancelGoal` defines:
    /// zero id and zero stamp = all goals; zero id = all accepted at or before the stamp;
    /// an id = that goal, plus all accepted at or before a non-zero stamp.
    pub fn select_for_cancel(&self, info: &GoalInfo) -> Vec<GoalId> {
        let zero_id = info.goal_id == GoalId::ZERO;
        let zero_stamp = info.stamp == RosTime::ZERO;
        self.goals
            .iter()
            .filter(|g| {
                (zero_id && zero_stamp)
                    || g.id == info.goal_id
                    || (!zero_stamp && g.accepted <= info.stamp)
            })
            .map(|g| g.id)
            .collect()
    }

    /// Whether the goal has ended.
    pub fn is_terminal(&self, id: &GoalId) -> bool {
        self.get(id).is_some_and(|g| is_terminal(g.status))
    }

    /// The `action_msgs/GoalStatusArray` of all known goals.
    pub fn status_array(&self) -> GoalStatusArray {
        GoalStatusArray {
            status_list: self
                .goals
                .iter()
                .map(|g| GoalStatus {
                    goal_info: GoalInfo {
                        goal_id: g.id,
                        stamp: g.accepted,
                    },
                    status: g.status,
                })
                .collect(),
        }
    }

    /// Takes the pending result requests whose goal has ended, with status and result.
    pub fn take_ready_results(
        &mut self,
    ) -> Vec<(RmwRequestId, GoalStatusEnum, FollowJointTrajectoryResult)> {
        let mut ready = Vec::new();
        let mut waiting = Vec::new();
        for (id, req) in self.pending_results.drain(..) {
            match self.goals.iter().find(|g| g.id == id) {
                Some(g) if is_terminal(g.status) => {
                    ready.push((req, g.status, g.result.clone().unwrap_or_default()))
                }
                Some(_) => waiting.push((id, req)),
                // rcl_action answers STATUS_UNKNOWN for a goal it does not know.
                None => ready.push((
                    req,
                    GoalStatusEnum::Unknown,
                    FollowJointTrajectoryResult::default(),
                )),
            }
        }
        self.pending_results = waiting;
        ready
    }
}

/// Hex form of a goal id (32 lowercase digits), as in `TrajectoryStatus.goal_id`.
pub fn goal_id_hex(id: &GoalId) -> String {
    format!("{id:?}")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn goal(n: u8, status: GoalStatusEnum, t: i64) -> ActionGoal {
        ActionGoal {
            id: GoalId {
                uuid: uuid::Uuid::from_bytes([n; 16]),
            },
            accepted: RosTime::from_nanos(t),
            status,
            exec_id: None,
            ticket: None,
            result: None,
        }
    }

    #[test]
    fn cancel_selection_follows_action_msgs() {
        let mut goals = ActionGoals::default();
        goals.add(goal(1, GoalStatusEnum::Succeeded, 10));
        goals.add(goal(2, GoalStatusEnum::Executing, 20));
        let second = goals.goals[1].id;
        let all = GoalInfo {
            goal_id: GoalId::ZERO,
            stamp: RosTime::ZERO,
        };
        assert_eq!(goals.select_for_cancel(&all).len(), 2);
        let before_15 = GoalInfo {
            goal_id: GoalId::ZERO,
            stamp: RosTime::from_nanos(15),
        };
        assert_eq!(goals.select_for_cancel(&before_15).len(), 1);
        let one = GoalInfo {
            goal_id: second,
            stamp: RosTime::ZERO,
        };
        assert_eq!(goals.select_for_cancel(&one), vec![second]);
    }
}
