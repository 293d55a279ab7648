//! What the robot runs of a plan (step 7 of
//! [`crate::MillPlanner::plan`]): the planned trajectory time-scaled to the
//! joints' velocity and acceleration limits ([`crate::timing::time_scale`])
//! and the plan at the feeds that result ([`Plan::as_executed`]).

use kerf_budget::Budget;
use kerf_executor::{check_executable, ExecutorConfig};
use kerf_mill::MillCell;

use crate::cache::IndicatorCache;
use crate::error::MillPlanError;
use crate::plan::{IndicatorProvenance, IndicatorSource, Plan};
use crate::planned::planned_trajectory;
use crate::reward::RewardWeights;
use crate::timing::{time_scale, JointLimit, TimeScaling};
use crate::trajectory::JointTrajectory;

/// The plan as the robot runs it (step 7 of [`crate::MillPlanner::plan`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Executed {
    /// The executable trajectory, its stretch per interval and the
    /// segment times and feeds it runs ([`crate::timing::time_scale`]).
    pub scaling: TimeScaling,
    /// The plan at those feeds and times ([`Plan::as_executed`]): |μ|max
    /// and reward re-evaluated directly where the feed changed; its
    /// `total_time` is the trajectory's duration from rest to rest.
    pub plan: Plan,
    /// Segments of `plan` whose |μ|max is the indicator cache's
    /// interpolation (only with [`IndicatorSource::Cache`]; the bound of
    /// [`crate::MillPlanOutput::indicator`] applies), ascending.
    pub cached_segments: Vec<usize>,
}

/// The plan's trajectory ([`crate::planned`]) and what the robot runs
/// of it (step 7 of [`crate::MillPlanner::plan`]), for a plan evaluated outside
/// the planner (e.g. the DP variants of the comparison), |μ|max direct.
///
/// # Errors
/// As [`crate::MillPlanner::plan`]'s steps 6–7.
pub fn execute(
    cell: &MillCell,
    plan: &Plan,
    weights: &RewardWeights,
    threads: usize,
) -> Result<Executed, MillPlanError> {
    let (trajectory, _) = planned_trajectory(cell, plan)?;
    let direct = IndicatorProvenance::direct(IndicatorSource::Direct, plan.segments.len(), "");
    executed(
        cell,
        plan,
        &trajectory,
        weights,
        threads,
        &direct,
        None,
        &Budget::unlimited(),
    )
}

/// Step 7: the executable trajectory and the plan it runs.
///
/// # Arguments
/// * `cell` — the request's cell (its robot's joint limits).
/// * `plan` — the plan as planned; `trajectory` — its planned trajectory.
/// * `weights`, `threads` — of the re-evaluation ([`Plan::as_executed_with`]).
/// * `indicator`, `cache` — where |μ|max comes from.
///
/// # Errors
/// A joint of `trajectory` the robot does not have; [`time_scale`] and
/// [`Plan::as_executed_with`] errors; [`MillPlanError::NotExecutable`] when
/// the scaled trajectory fails `kerf_executor::check_executable` (the
/// executor's own validation: the one executability check of kerf).
// The plan, its trajectory and the evaluation's settings, passed through from the planner.
#[allow(clippy::too_many_arguments)]
pub(crate) fn executed(
    cell: &MillCell,
    plan: &Plan,
    trajectory: &JointTrajectory,
    weights: &RewardWeights,
    threads: usize,
    indicator: &IndicatorProvenance,
    cache: Option<&IndicatorCache>,
    budget: &Budget,
) -> Result<Executed, MillPlanError> {
    let joints = cell.robot().joints();
    let limits = trajectory
        .joint_names()
        .iter()
        .map(|name| {
            joints
                .iter()
                .find(|j| &j.name == name)
                .map(|j| JointLimit {
                    max_velocity: j.max_velocity,
                    max_acceleration: j.max_acceleration,
                })
                .ok_or_else(|| MillPlanError::InvalidConfig {
                    name: "trajectory".to_string(),
                    reason: format!("joint '{name}' is not a joint of the cell's robot"),
                })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let times: Vec<f64> = plan.segments.iter().map(|s| s.time).collect();
    let feeds: Vec<f64> = plan.segments.iter().map(|s| s.feed).collect();
    budget.check("the time scaling")?;
    let scaling = time_scale(trajectory, &times, &feeds, &limits)?;
    budget.check("the executability check")?;
    // Judged by what the executor runs: its own validation, from rest at the first point.
    let not_executable = |reason: String| MillPlanError::NotExecutable { reason };
    let model = cell
        .robot()
        .executor_limits()
        .map_err(|e| not_executable(e.to_string()))?;
    check_executable(
        &model,
        &ExecutorConfig::default(),
        &scaling.trajectory.request,
    )
    .map_err(|e| not_executable(e.to_string()))?;
    let (plan, cached_segments) = plan.as_executed_with(
        cell,
        weights,
        &scaling.segment_feeds,
        &scaling.segment_times,
        threads,
        indicator,
        cache,
        budget,
    )?;
    Ok(Executed {
        scaling,
        plan,
        cached_segments,
    })
}
