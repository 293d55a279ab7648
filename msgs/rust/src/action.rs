//! kerf's own actions (`kerf_msgs/action`, defined in `msgs/action/`): planning as ROS 2
//! actions (issue 27, item 3), one per planner node — [`PlanCutGoal`] … of
//! `kerf_msgs/action/PlanCut` (`~/plan_cut` of the MJTO planner), `PlanMill` (`~/plan_mill`)
//! and `PlanGcode` (`~/plan_gcode`).
//!
//! Each action is mirrored as its three parts (`<Action>Goal`, `<Action>Result`,
//! `<Action>Feedback`), as [`crate::control_msgs`] mirrors `FollowJointTrajectory`; the action
//! protocol wrappers (goal id, status) are ros2-client's. The three actions have the same shape
//! (the request message and its answer, `execute`, the execution's outcome, the same feedback),
//! so their mirrors are made by one macro.

use serde::{Deserialize, Serialize};

use crate::msg::{CutPlan, CutRequest, GcodePlan, GcodeRequest, MillPlan, MillRequest};
use crate::ros_type::impl_ros_type;

/// Defines the goal, result and feedback mirrors of one planning action.
macro_rules! plan_action {
    (
        $action:literal, $noun:literal,
        $goal:ident = $goal_name:literal,
        $result:ident = $result_name:literal,
        $feedback:ident = $feedback_name:literal,
        $request:ty, $plan:ty
    ) => {
        #[doc = concat!("Goal of `kerf_msgs/action/", $action, "` (`~/plan_", $noun, "`): the \
                         request, as on `~/", $noun, "_request`, and whether to execute the plan.")]
        #[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
        pub struct $goal {
            /// The request, checked and planned exactly as one on the request topic.
            pub request: $request,
            /// Run a successful plan on the executor's `FollowJointTrajectory` action (the
            /// planner node's `execute_action` parameter) and wait for its result.
            pub execute: bool,
        }
        impl_ros_type!($goal, "kerf_msgs", action, $goal_name);

        #[doc = concat!("Result of `kerf_msgs/action/", $action, "`: the answer (also published on \
                         `~/", $noun, "_plan`) and the execution's outcome.")]
        #[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
        pub struct $result {
            /// The answer, as published on the plan topic.
            pub plan: $plan,
            /// The trajectory was sent to the executor and the executor reported how its goal
            /// ended; the two fields below are then its result.
            pub executed: bool,
            /// The executor's `FollowJointTrajectory` result `error_code` when executed, else 0.
            pub execution_error_code: i32,
            /// The executor goal's final status and `error_string` when executed (`"SUCCEEDED"`,
            /// `"ABORTED: …"`); otherwise why nothing was executed.
            pub execution_message: String,
        }
        impl_ros_type!($result, "kerf_msgs", action, $result_name);

        #[doc = concat!("Feedback of `kerf_msgs/action/", $action, "`: the goal's stage and \
                         progress.")]
        #[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
        pub struct $feedback {
            /// [`STAGE_QUEUED`](Self::STAGE_QUEUED), [`STAGE_PLANNING`](Self::STAGE_PLANNING)
            /// or [`STAGE_EXECUTING`](Self::STAGE_EXECUTING).
            pub stage: String,
            /// Queued: 0. Planning: the fraction of the plan's time budget used, in [0, 1] (the
            /// planner reports no finer progress). Executing: the executor's desired
            /// `time_from_start` over the trajectory's duration, in [0, 1].
            pub progress: f64,
            /// Requests ahead of the goal (queued or being planned); 0 once it is planned.
            pub queue_position: u32,
            /// Seconds since the goal was accepted.
            pub elapsed: f64,
        }
        impl_ros_type!($feedback, "kerf_msgs", action, $feedback_name);

        impl $feedback {
            /// `stage`: waiting behind other requests (or for an earlier execution to end).
            pub const STAGE_QUEUED: &'static str = "queued";
            /// `stage`: being planned.
            pub const STAGE_PLANNING: &'static str = "planning";
            /// `stage`: the plan runs on the executor.
            pub const STAGE_EXECUTING: &'static str = "executing";
        }
    };
}

plan_action!(
    "PlanCut",
    "cut",
    PlanCutGoal = "PlanCut_Goal",
    PlanCutResult = "PlanCut_Result",
    PlanCutFeedback = "PlanCut_Feedback",
    CutRequest,
    CutPlan
);
plan_action!(
    "PlanMill",
    "mill",
    PlanMillGoal = "PlanMill_Goal",
    PlanMillResult = "PlanMill_Result",
    PlanMillFeedback = "PlanMill_Feedback",
    MillRequest,
    MillPlan
);
plan_action!(
    "PlanGcode",
    "gcode",
    PlanGcodeGoal = "PlanGcode_Goal",
    PlanGcodeResult = "PlanGcode_Result",
    PlanGcodeFeedback = "PlanGcode_Feedback",
    GcodeRequest,
    GcodePlan
);
