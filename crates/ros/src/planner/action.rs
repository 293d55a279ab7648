//! Book-keeping of the planning action's goals (issue 27, item 3): their rcl_action status,
//! stage, results and pending result requests.
//!
//! A goal is ACCEPTED while it is queued and EXECUTING from the start of its plan (through its
//! execution, with `execute`); a cancel request moves it to CANCELING; it ends SUCCEEDED,
//! ABORTED or CANCELED with its result. Result requests wait for the goal to end (rcl_action's
//! semantics); finished goals are kept ([`KEEP_FINISHED`]) for late result requests.

use std::{collections::VecDeque, time::Instant};

use ros2_client::{
    action::{CancelGoalRequest, GoalId, GoalInfo, GoalStatusEnum},
    action_msgs::{CancelGoalResponse, CancelGoalResponseEnum, GoalStatus, GoalStatusArray},
    builtin_interfaces::Time as RosTime,
    RmwRequestId,
};

use super::goal_msgs::{PlanResult, Stage};

/// Finished goals kept for late result requests (rcl_action keeps them for `result_timeout`).
pub const KEEP_FINISHED: usize = 64;

/// Where a queued request came from: a request topic, or a goal of the planning action.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Origin {
    /// `~/<noun>_request` or `~/<noun>_request_text`.
    Topic,
    /// A goal of `~/plan_<noun>`.
    Goal(GoalId),
}

/// One goal of the planning action.
#[derive(Debug, Clone)]
pub struct PlanGoalEntry<A> {
    /// Goal id chosen by the client.
    pub id: GoalId,
    /// When it was accepted (ROS time, in the status array and cancel selections).
    pub accepted: RosTime,
    /// When it was accepted (for `elapsed` in the feedback).
    pub accepted_at: Instant,
    /// rcl_action status.
    pub status: GoalStatusEnum,
    /// Whether a successful plan is to be executed.
    pub execute: bool,
    /// What it is doing.
    pub stage: Stage,
    /// The successful plan while it executes (the result's `plan` when the execution ends).
    pub plan: Option<A>,
    /// The result, once terminal.
    pub result: Option<PlanResult<A>>,
}

impl<A> PlanGoalEntry<A> {
    /// Seconds since it was accepted.
    pub fn elapsed(&self) -> f64 {
        self.accepted_at.elapsed().as_secs_f64()
    }
}

/// Whether a status is terminal.
pub fn is_terminal(s: GoalStatusEnum) -> bool {
    matches!(
        s,
        GoalStatusEnum::Succeeded | GoalStatusEnum::Canceled | GoalStatusEnum::Aborted
    )
}

/// Every goal of the server, oldest first.
#[derive(Debug)]
pub struct PlanGoals<A> {
    goals: VecDeque<PlanGoalEntry<A>>,
    /// Result requests waiting for their goal to end.
    pending_results: Vec<(GoalId, RmwRequestId)>,
    /// A status changed since [`Self::take_changed`].
    changed: bool,
}

impl<A> Default for PlanGoals<A> {
    fn default() -> Self {
        Self {
            goals: VecDeque::new(),
            pending_results: Vec::new(),
            changed: false,
        }
    }
}

impl<A: Clone> PlanGoals<A> {
    /// Adds an accepted goal (ACCEPTED, queued).
    pub fn add(&mut self, id: GoalId, accepted: RosTime, execute: bool) {
        self.goals.push_back(PlanGoalEntry {
            id,
            accepted,
            accepted_at: Instant::now(),
            status: GoalStatusEnum::Accepted,
            execute,
            stage: Stage::Queued,
            plan: None,
            result: None,
        });
        self.changed = true;
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
    pub fn get(&self, id: &GoalId) -> Option<&PlanGoalEntry<A>> {
        self.goals.iter().find(|g| &g.id == id)
    }

    /// The goal with this id, mutable.
    pub fn get_mut(&mut self, id: &GoalId) -> Option<&mut PlanGoalEntry<A>> {
        self.goals.iter_mut().find(|g| &g.id == id)
    }

    /// The goals that have not ended.
    pub fn active(&self) -> impl Iterator<Item = &PlanGoalEntry<A>> {
        self.goals.iter().filter(|g| !is_terminal(g.status))
    }

    /// Moves a goal to `stage` (EXECUTING once it is planned, unless it is being canceled).
    pub fn set_stage(&mut self, id: &GoalId, stage: Stage) {
        let mut changed = false;
        if let Some(g) = self.get_mut(id) {
            g.stage = stage;
            if stage != Stage::Queued && g.status == GoalStatusEnum::Accepted {
                g.status = GoalStatusEnum::Executing;
                changed = true;
            }
        }
        self.changed |= changed;
    }

    /// Ends a goal with `status` and `result` (a goal that has ended keeps its first end).
    pub fn finish(&mut self, id: &GoalId, status: GoalStatusEnum, result: PlanResult<A>) {
        let mut changed = false;
        if let Some(g) = self.get_mut(id) {
            if !is_terminal(g.status) {
                g.status = status;
                g.plan = None;
                g.result = Some(result);
                changed = true;
            }
        }
        self.changed |= changed;
    }

    /// Handles a CancelGoal request: the goals it selects (as `action_msgs/srv/CancelGoal`
    /// defines: zero id and zero stamp = all goals; zero id = all accepted at or before the
    /// stamp; an id = that goal, plus all accepted at or before a non-zero stamp) that have not
    /// ended move to CANCELING.
    ///
    /// # Returns
    /// The response, and the goals that moved to CANCELING (the caller cancels their work).
    pub fn begin_cancel(&mut self, info: &GoalInfo) -> (CancelGoalResponse, Vec<GoalId>) {
        let zero_id = info.goal_id == GoalId::ZERO;
        let zero_stamp = info.stamp == RosTime::ZERO;
        let mut selected = 0;
        let mut canceling = Vec::new();
        for g in self.goals.iter_mut() {
            let chosen = (zero_id && zero_stamp)
                || g.id == info.goal_id
                || (!zero_stamp && g.accepted <= info.stamp);
            if !chosen {
                continue;
            }
            selected += 1;
            if matches!(
                g.status,
                GoalStatusEnum::Accepted | GoalStatusEnum::Executing
            ) {
                g.status = GoalStatusEnum::Canceling;
                canceling.push(GoalInfo {
                    goal_id: g.id,
                    stamp: g.accepted,
                });
            }
        }
        self.changed |= !canceling.is_empty();
        let return_code = if !canceling.is_empty() {
            CancelGoalResponseEnum::None
        } else if selected == 0 {
            CancelGoalResponseEnum::UnknownGoal
        } else {
            CancelGoalResponseEnum::GoalTerminated
        };
        let ids = canceling.iter().map(|i| i.goal_id).collect();
        (
            CancelGoalResponse {
                return_code,
                goals_canceling: canceling,
            },
            ids,
        )
    }

    /// Whether the goal is being canceled.
    pub fn is_canceling(&self, id: &GoalId) -> bool {
        self.get(id)
            .is_some_and(|g| g.status == GoalStatusEnum::Canceling)
    }

    /// Keeps a result request until its goal ends.
    pub fn wait_for_result(&mut self, id: GoalId, request: RmwRequestId) {
        self.pending_results.push((id, request));
    }

    /// Takes the pending result requests whose goal has ended, with its status and result;
    /// a goal this server does not know is answered STATUS_UNKNOWN (`None`: the caller gives
    /// an empty result), as rcl_action does.
    pub fn take_ready_results(
        &mut self,
    ) -> Vec<(RmwRequestId, GoalStatusEnum, Option<PlanResult<A>>)> {
        let mut ready = Vec::new();
        let mut waiting = Vec::new();
        for (id, request) in self.pending_results.drain(..) {
            match self.goals.iter().find(|g| g.id == id) {
                Some(g) if is_terminal(g.status) => {
                    ready.push((request, g.status, g.result.clone()))
                }
                Some(_) => waiting.push((id, request)),
                None => ready.push((request, GoalStatusEnum::Unknown, None)),
            }
        }
        self.pending_results = waiting;
        ready
    }

    /// Whether a status changed since the last call.
    pub fn take_changed(&mut self) -> bool {
        std::mem::take(&mut self.changed)
    }

    /// The `action_msgs/GoalStatusArray` of every known goal.
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
/// request is read back through a serde value into a mirror of `action_msgs/srv/CancelGoal`.
///
/// # Errors
/// The serde error, as text.
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

    /// Ten distinct goal ids, the same on every call of one test thread.
    fn id(n: usize) -> GoalId {
        thread_local! {
            static IDS: Vec<GoalId> = (0..10).map(|_| GoalId::new_random()).collect();
        }
        IDS.with(|ids| ids[n])
    }

    fn result() -> PlanResult<u8> {
        PlanResult {
            plan: 1,
            ..PlanResult::default()
        }
    }

    #[test]
    fn goals_move_through_the_rcl_action_states() {
        let mut goals = PlanGoals::<u8>::default();
        let (a, b) = (id(1), id(2));
        assert_ne!(a, b);
        goals.add(a, RosTime::from_nanos(10), false);
        goals.add(b, RosTime::from_nanos(20), true);
        assert!(goals.take_changed());
        assert!(!goals.take_changed());
        assert_eq!(
            goals.get(&a).map(|g| g.status),
            Some(GoalStatusEnum::Accepted)
        );
        goals.set_stage(&a, Stage::Planning);
        assert_eq!(
            goals.get(&a).map(|g| g.status),
            Some(GoalStatusEnum::Executing)
        );
        // A result request waits for the end; an unknown goal is answered at once.
        goals.wait_for_result(a, RmwRequestId::default());
        goals.wait_for_result(id(9), RmwRequestId::default());
        let ready = goals.take_ready_results();
        assert_eq!(ready.len(), 1);
        assert_eq!(ready[0].1, GoalStatusEnum::Unknown);
        goals.finish(&a, GoalStatusEnum::Succeeded, result());
        goals.finish(&a, GoalStatusEnum::Aborted, result());
        let ready = goals.take_ready_results();
        assert_eq!(ready.len(), 1);
        assert_eq!(ready[0].1, GoalStatusEnum::Succeeded, "the first end stays");
        assert_eq!(goals.active().count(), 1);
        let statuses = goals.status_array();
        assert_eq!(statuses.status_list.len(), 2);
    }

    #[test]
    fn cancel_selection_follows_action_msgs() {
        let mut goals = PlanGoals::<u8>::default();
        goals.add(id(1), RosTime::from_nanos(10), false);
        goals.add(id(2), RosTime::from_nanos(20), false);
        goals.add(id(3), RosTime::from_nanos(30), false);
        goals.finish(&id(1), GoalStatusEnum::Succeeded, result());
        // One id: that goal.
        let (r, ids) = goals.begin_cancel(&GoalInfo {
            goal_id: id(2),
            stamp: RosTime::ZERO,
        });
        assert_eq!(r.return_code, CancelGoalResponseEnum::None);
        assert_eq!(ids, vec![id(2)]);
        assert!(goals.is_canceling(&id(2)));
        // A finished goal cannot be canceled; an unknown one is unknown.
        let (r, _) = goals.begin_cancel(&GoalInfo {
            goal_id: id(1),
            stamp: RosTime::ZERO,
        });
        assert_eq!(r.return_code, CancelGoalResponseEnum::GoalTerminated);
        let (r, _) = goals.begin_cancel(&GoalInfo {
            goal_id: id(7),
            stamp: RosTime::ZERO,
        });
        assert_eq!(r.return_code, CancelGoalResponseEnum::UnknownGoal);
        // Zero id, zero stamp: every goal that has not ended.
        let (r, ids) = goals.begin_cancel(&GoalInfo {
            goal_id: GoalId::ZERO,
            stamp: RosTime::ZERO,
        });
        assert_eq!(r.return_code, CancelGoalResponseEnum::None);
        assert_eq!(ids, vec![id(3)]);
    }
}
