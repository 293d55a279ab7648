//! The planning actions on the wire (issue 27, item 3): `kerf_msgs/action/Plan<Noun>` served
//! on `~/plan_<noun>` by every planner node.
//!
//! The three actions (`PlanCut`, `PlanMill`, `PlanGcode`) have one shape — the node's request
//! message and `execute`; its answer message and the execution's outcome; the same feedback —
//! so the harness serves them with the generic forms below, CDR-identical to the mirrors of
//! `kerf_msgs::action` (tested here). ros2-client puts the action's type name on the wire from
//! [`action_type`], not from the Rust type.

use serde::{Deserialize, Serialize};

/// The goal: the request (as on `~/<noun>_request`) and whether to execute the plan.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PlanGoal<M> {
    /// The request message.
    pub request: M,
    /// Run a successful plan on the executor's `FollowJointTrajectory` action.
    pub execute: bool,
}

/// The result: the answer (as on `~/<noun>_plan`) and the execution's outcome.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PlanResult<A> {
    /// The answer message.
    pub plan: A,
    /// The trajectory was sent to the executor and the executor reported how its goal ended.
    pub executed: bool,
    /// The executor's `FollowJointTrajectory` result code when executed, else 0.
    pub execution_error_code: i32,
    /// The executor goal's final status and message when executed; else why nothing ran.
    pub execution_message: String,
}

/// The feedback (see [`Stage`] for what `progress` is at each stage).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PlanFeedback {
    /// [`Stage::as_str`].
    pub stage: String,
    /// In [0, 1]: 0 while queued; the fraction of the plan's time budget used while planning;
    /// the executor's desired `time_from_start` over the trajectory's duration while executing.
    pub progress: f64,
    /// Requests ahead of the goal (queued or being planned); 0 once it is planned.
    pub queue_position: u32,
    /// Seconds since the goal was accepted.
    pub elapsed: f64,
}

impl<M: Serialize + serde::de::DeserializeOwned> ros2_client::Message for PlanGoal<M> {}
impl<A: Serialize + serde::de::DeserializeOwned> ros2_client::Message for PlanResult<A> {}
impl ros2_client::Message for PlanFeedback {}

/// What a goal is doing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Waiting behind other requests, or (an execute goal) for an earlier execution to end.
    Queued,
    /// Being planned.
    Planning,
    /// Running on the executor.
    Executing,
}

impl Stage {
    /// `"queued"`, `"planning"` or `"executing"` (the `STAGE_*` constants of the feedback).
    pub fn as_str(self) -> &'static str {
        match self {
            Stage::Queued => "queued",
            Stage::Planning => "planning",
            Stage::Executing => "executing",
        }
    }
}

/// The action's ROS type for a node planning `noun`s: `kerf_msgs/action/Plan<Noun>` (`cut` →
/// `PlanCut`, `gcode` → `PlanGcode`).
pub fn action_type(noun: &str) -> String {
    let mut chars = noun.chars();
    let capitalized: String = match chars.next() {
        Some(first) => first.to_uppercase().chain(chars).collect(),
        None => String::new(),
    };
    format!("kerf_msgs/action/Plan{capitalized}")
}

/// The action's name, relative to the node: `~/plan_<noun>`.
pub fn action_name(noun: &str) -> String {
    format!("~/plan_{noun}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use kerf_msgs::{action, msg};
    use serde::Serialize;

    fn cdr<T: Serialize>(v: &T) -> Vec<u8> {
        cdr_encoding::to_vec::<_, byteorder::LittleEndian>(v).unwrap_or_default()
    }

    #[test]
    fn names_follow_the_noun() {
        assert_eq!(action_type("cut"), "kerf_msgs/action/PlanCut");
        assert_eq!(action_type("gcode"), "kerf_msgs/action/PlanGcode");
        assert_eq!(action_type("mill"), "kerf_msgs/action/PlanMill");
        assert_eq!(action_name("mill"), "~/plan_mill");
    }

    #[test]
    fn the_generic_forms_are_the_mirrors_on_the_wire() {
        let mut request = msg::CutRequest {
            request_id: "job-1".into(),
            feedrate: 0.3,
            ..msg::CutRequest::default()
        };
        request.start_positions = vec![1.0, 2.0];
        let generic = PlanGoal {
            request: request.clone(),
            execute: true,
        };
        let mirror = action::PlanCutGoal {
            request,
            execute: true,
        };
        assert!(!cdr(&generic).is_empty());
        assert_eq!(cdr(&generic), cdr(&mirror));

        let plan = msg::MillPlan {
            request_id: "m".into(),
            status: 3,
            message: "why".into(),
            ..msg::MillPlan::default()
        };
        let generic = PlanResult {
            plan: plan.clone(),
            executed: true,
            execution_error_code: -4,
            execution_message: "ABORTED: x".into(),
        };
        let mirror = action::PlanMillResult {
            plan,
            executed: true,
            execution_error_code: -4,
            execution_message: "ABORTED: x".into(),
        };
        assert_eq!(cdr(&generic), cdr(&mirror));

        let generic = PlanFeedback {
            stage: Stage::Planning.as_str().into(),
            progress: 0.25,
            queue_position: 3,
            elapsed: 1.5,
        };
        let mirror = action::PlanGcodeFeedback {
            stage: action::PlanGcodeFeedback::STAGE_PLANNING.into(),
            progress: 0.25,
            queue_position: 3,
            elapsed: 1.5,
        };
        assert_eq!(cdr(&generic), cdr(&mirror));
        assert_eq!(
            Stage::Queued.as_str(),
            action::PlanCutFeedback::STAGE_QUEUED
        );
        assert_eq!(
            Stage::Executing.as_str(),
            action::PlanCutFeedback::STAGE_EXECUTING
        );
    }
}
