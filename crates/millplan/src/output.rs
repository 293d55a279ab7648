//! The planner's answer to a request ([`MillPlanOutput`]) and the wall
//! time of its steps ([`PlanningPhases`]).

use std::path::PathBuf;

use kerf_mill::BranchJump;

use crate::executed::Executed;
use crate::plan::{IndicatorProvenance, Plan};
use crate::request::PlannerKind;
use crate::trajectory::JointTrajectory;

/// The answer to a request.
#[derive(Debug, Clone, PartialEq)]
pub struct MillPlanOutput {
    /// The request's id.
    pub request_id: String,
    /// The planner that answered.
    pub planner: PlannerKind,
    /// The policy file used (`ddpg`, `fixed_g`).
    pub policy_file: Option<PathBuf>,
    /// Per-segment Ω, f, g, |μ|max, K, 1/K, joints, time, reward (direct
    /// evaluation) and the totals.
    pub plan: Plan,
    /// The joint trajectory as planned: timed by the planned feeds, not
    /// from rest ([`crate::planned`]).
    pub trajectory: JointTrajectory,
    /// What the robot runs: [`JointTrajectory`] from rest to rest,
    /// time-scaled to the joint velocity and acceleration limits, and the
    /// plan at the feeds that result ([`Executed`]).
    pub executed: Executed,
    /// Joint steps above the branch-jump threshold between trajectory
    /// points (index = the later point).
    pub branch_jumps: Vec<BranchJump>,
    /// Whether the default cell's indicator cache applied to the request.
    pub cache_used: bool,
    /// Wall-clock planning time \[s\].
    pub planning_seconds: f64,
    /// Wall-clock time of each step of [`crate::MillPlanner::plan`] \[s\].
    pub phases: PlanningPhases,
    /// Where the plan's |μ|max values come from: all direct (the default),
    /// or partly the indicator cache with its stated error bound
    /// ([`crate::MillPlanner::with_indicator_source`]); its `note` belongs in the
    /// answer's message.
    pub indicator: IndicatorProvenance,
}

/// Wall-clock seconds of the steps of [`crate::MillPlanner::plan`] (module
/// documentation); their sum is at most
/// [`MillPlanOutput::planning_seconds`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlanningPhases {
    /// Steps 1–3: request validation, the request's cell, reachability.
    pub setup: f64,
    /// Step 4: the planner (policy rollout, DP or naive), including the
    /// policy's loading when not already loaded.
    pub planner: f64,
    /// Step 5: [`Plan::evaluate`] (direct |μ|max of every segment).
    pub evaluation: f64,
    /// Step 6: the joint trajectory.
    pub trajectory: f64,
}
