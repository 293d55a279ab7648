//! The action server's book of goals: status (rcl_action's state machine), results, result
//! requests waiting for their goal, and which goals a CancelGoal request selects.

use std::collections::VecDeque;

use kerf_msgs::control_msgs::FollowJointTrajectoryResult;
use ros2_client::{
    action::{CancelGoalRequest, GoalId, GoalInfo, GoalStatusEnum},
    action_msgs::{GoalStatus, GoalStatusArray},
    builtin_interfaces::Time as RosTime,
    RmwRequestId,
};

/// Finished goals kept for late result requests.
const KEEP_FINISHED: usize = 64;

#[derive(Debug, Clone)]
struct Entry {
    id: GoalId,
    accepted: RosTime,
    status: GoalStatusEnum,
    result: Option<FollowJointTrajectoryResult>,
}

fn terminal(s: GoalStatusEnum) -> bool {
    matches!(
        s,
        GoalStatusEnum::Succeeded | GoalStatusEnum::Canceled | GoalStatusEnum::Aborted
    )
}

/// Every accepted goal (the newest [`KEEP_FINISHED`] finished ones), oldest first.
#[derive(Debug, Default)]
pub struct GoalBook {
    goals: VecDeque<Entry>,
    waiting: Vec<(GoalId, RmwRequestId)>,
    /// The status array changed since it was last published.
    pub changed: bool,
}

impl GoalBook {
    /// Adds an accepted goal, executing.
    pub fn add(&mut self, id: GoalId, accepted: RosTime) {
        self.goals.push_back(Entry {
            id,
            accepted,
            status: GoalStatusEnum::Executing,
            result: None,
        });
        while self.goals.len() > KEEP_FINISHED {
            match self.goals.iter().position(|g| terminal(g.status)) {
                Some(i) => drop(self.goals.remove(i)),
                None => break,
            }
        }
        self.changed = true;
    }

    /// Ends goal `id` with `status` and `result` (nothing if it has ended already).
    pub fn finish(
        &mut self,
        id: &GoalId,
        status: GoalStatusEnum,
        result: FollowJointTrajectoryResult,
    ) {
        if let Some(g) = self
            .goals
            .iter_mut()
            .find(|g| &g.id == id && !terminal(g.status))
        {
            g.status = status;
            g.result = Some(result);
            self.changed = true;
        }
    }

    /// The goals a cancel request selects among those still executing, as
    /// `action_msgs/srv/CancelGoal` defines it (zero id and stamp: all; zero id: accepted at or
    /// before the stamp; an id: that goal, plus those at or before a non-zero stamp), and
    /// whether it selected any goal at all (executing or not).
    pub fn select_for_cancel(&self, info: &GoalInfo) -> (Vec<GoalInfo>, bool) {
        let zero_id = info.goal_id == GoalId::ZERO;
        let zero_stamp = info.stamp == RosTime::ZERO;
        let selected: Vec<&Entry> = self
            .goals
            .iter()
            .filter(|g| {
                (zero_id && zero_stamp)
                    || g.id == info.goal_id
                    || (!zero_stamp && g.accepted <= info.stamp)
            })
            .collect();
        let any = !selected.is_empty();
        let executing = selected
            .into_iter()
            .filter(|g| !terminal(g.status))
            .map(|g| GoalInfo {
                goal_id: g.id,
                stamp: g.accepted,
            })
            .collect();
        (executing, any)
    }

    /// Queues a result request until its goal ends.
    pub fn wait_for_result(&mut self, id: GoalId, request: RmwRequestId) {
        self.waiting.push((id, request));
    }

    /// The result requests that can be answered now, with status and result; a goal the book
    /// does not know is answered UNKNOWN, as rcl_action does.
    pub fn ready_results(
        &mut self,
    ) -> Vec<(RmwRequestId, GoalStatusEnum, FollowJointTrajectoryResult)> {
        let mut ready = Vec::new();
        let goals = &self.goals;
        self.waiting
            .retain(|(id, req)| match goals.iter().find(|g| &g.id == id) {
                Some(g) if !terminal(g.status) => true,
                Some(g) => {
                    ready.push((*req, g.status, g.result.clone().unwrap_or_default()));
                    false
                }
                None => {
                    let unknown = FollowJointTrajectoryResult::default();
                    ready.push((*req, GoalStatusEnum::Unknown, unknown));
                    false
                }
            });
        ready
    }

    /// The `action_msgs/msg/GoalStatusArray` of every goal in the book.
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
}

/// The goal selector of a CancelGoal request.
///
/// ros2-client keeps `CancelGoalRequest::goal_info` private; its serde form is public, so the
/// request is read back through a YAML value into a mirror of `action_msgs/srv/CancelGoal`.
///
/// # Errors
/// A message if the serde round trip fails.
pub fn cancel_target(req: &CancelGoalRequest) -> Result<GoalInfo, String> {
    #[derive(serde::Deserialize)]
    struct Mirror {
        goal_info: GoalInfo,
    }
    let v = serde_yaml_ng::to_value(req).map_err(|e| e.to_string())?;
    serde_yaml_ng::from_value::<Mirror>(v)
        .map(|m| m.goal_info)
        .map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn info(goal_id: GoalId, stamp: i64) -> GoalInfo {
        GoalInfo {
            goal_id,
            stamp: RosTime::from_nanos(stamp),
        }
    }

    #[test]
    fn cancel_selection_and_results() {
        let mut book = GoalBook::default();
        let (a, b) = (GoalId::new_random(), GoalId::new_random());
        book.add(a, RosTime::from_nanos(10));
        book.add(b, RosTime::from_nanos(20));
        let aborted = FollowJointTrajectoryResult {
            error_code: -4,
            error_string: "far".into(),
        };
        book.finish(&a, GoalStatusEnum::Aborted, aborted.clone());
        let (executing, any) = book.select_for_cancel(&info(GoalId::ZERO, 0));
        assert!(any);
        assert_eq!(executing.len(), 1);
        assert_eq!(executing[0].goal_id, b);
        let (executing, any) = book.select_for_cancel(&info(a, 0));
        assert!(any && executing.is_empty(), "a has ended");
        let (executing, any) = book.select_for_cancel(&info(GoalId::new_random(), 0));
        assert!(!any && executing.is_empty());
        assert_eq!(book.select_for_cancel(&info(GoalId::ZERO, 15)).0.len(), 0);

        let req = |n: i64| RmwRequestId {
            sequence_number: n,
            ..RmwRequestId::default()
        };
        book.wait_for_result(a, req(1));
        book.wait_for_result(b, req(2));
        book.wait_for_result(GoalId::new_random(), req(3));
        let ready = book.ready_results();
        assert_eq!(ready.len(), 2);
        assert_eq!(ready[0].1, GoalStatusEnum::Aborted);
        assert_eq!(ready[0].2, aborted);
        assert_eq!(ready[1].1, GoalStatusEnum::Unknown);
        book.finish(
            &b,
            GoalStatusEnum::Succeeded,
            FollowJointTrajectoryResult::default(),
        );
        let ready = book.ready_results();
        assert_eq!(ready.len(), 1);
        assert_eq!(ready[0].1, GoalStatusEnum::Succeeded);
        assert_eq!(book.status_array().status_list.len(), 2);
    }
}
