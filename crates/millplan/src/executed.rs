//! What the robot runs of a plan (step 7 of
//! [`crate::MillPlanner::plan`]): the dense trajectory of
//! [`crate::timing::time_scale`] (smooth states along the path, within the
//! joints' velocity, acceleration and jerk limits and the path tolerance),
//! checked by the executor's own validation, its tool path measured at the
//! control period ([`crate::deviation::executed_deviation`]), and the plan
//! at the feeds that result ([`Plan::as_executed`]).

use kerf_budget::Budget;
use kerf_mill::MillCell;

use crate::cache::IndicatorCache;
use crate::chatter_judge::{judge, ChatterVerdict, Known};
use crate::error::MillPlanError;
use crate::plan::{IndicatorProvenance, IndicatorSource, Plan};
use crate::reward::RewardWeights;
use crate::timing::{joint_limits, time_scale, TimeScaling, TrajectorySettings};

/// The plan as the robot runs it (step 7 of [`crate::MillPlanner::plan`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Executed {
    /// The executable trajectory, the slowdown per segment and the
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
    /// The settings the trajectory was built with (tolerance, control period).
    pub settings: TrajectorySettings,
    /// |μ|max at every control-period sample in the material, at the executed feed, speed and
    /// g ([`crate::chatter_judge`]); `plan.chatter_free` and `plan.max_spectral_radius` include
    /// it.
    pub chatter: ChatterVerdict,
}

impl Executed {
    /// Whether the plan chatters as executed: a sample in the material at |μ|max ≥ 1
    /// ([`Executed::chatter`]) or a segment's |μ|max ≥ 1. A plan whose cached segments are
    /// only not proven chatter-free (|μ|max + the cache's bound ≥ 1, `plan.chatter_free`
    /// false) does not chatter here: the judge evaluated its samples directly.
    pub fn chatters(&self) -> bool {
        !self.chatter.chatter_free || self.plan.segments.iter().any(|s| s.spectral_radius >= 1.0)
    }

    /// The executed plan with the chatter judge of its trajectory
    /// ([`crate::chatter_judge::judge`]) folded into its totals.
    ///
    /// # Errors
    /// As [`crate::chatter_judge::judge`].
    pub(crate) fn assemble(
        cell: &MillCell,
        (scaling, mut plan): (TimeScaling, Plan),
        cached_segments: Vec<usize>,
        settings: TrajectorySettings,
        threads: usize,
        budget: &Budget,
    ) -> Result<Self, MillPlanError> {
        // The segments' values are direct unless the indicator cache gave them.
        let known: Vec<Known> = plan
            .segments
            .iter()
            .map(|s| Known {
                joints: s.joints,
                direct: cached_segments
                    .binary_search(&s.segment)
                    .is_err()
                    .then_some([s.rpm, s.feed, s.g, s.spectral_radius]),
            })
            .collect();
        let chatter = judge(
            cell,
            &scaling,
            &known,
            settings.control_period,
            threads,
            budget,
        )?;
        plan.chatter_free &= chatter.chatter_free;
        plan.max_spectral_radius = plan.max_spectral_radius.max(chatter.max_spectral_radius);
        Ok(Self {
            scaling,
            plan,
            cached_segments,
            settings,
            chatter,
        })
    }
}

/// What the robot runs of a plan evaluated outside the planner (e.g. the DP
/// variants of the comparison), |μ|max direct, default trajectory settings.
///
/// # Errors
/// As [`crate::MillPlanner::plan`]'s step 7.
pub fn execute(
    cell: &MillCell,
    plan: &Plan,
    weights: &RewardWeights,
    threads: usize,
) -> Result<Executed, MillPlanError> {
    let direct = IndicatorProvenance::direct(IndicatorSource::Direct, plan.segments.len(), "");
    executed(
        cell,
        plan,
        &TrajectorySettings::default(),
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
/// * `plan` — the plan as planned; `settings` — of the trajectory.
/// * `weights`, `threads` — of the re-evaluation ([`Plan::as_executed_with`]).
/// * `indicator`, `cache` — where |μ|max comes from.
///
/// # Errors
/// [`time_scale`] errors (among them [`MillPlanError::NotExecutable`] when the
/// trajectory fails `kerf_executor::check_executable`, the executor's own
/// validation, which its step 7 runs before measuring the tool path) and
/// [`Plan::as_executed_with`] errors.
// The plan, its settings and the evaluation's settings, passed through from the planner.
#[allow(clippy::too_many_arguments)]
pub(crate) fn executed(
    cell: &MillCell,
    plan: &Plan,
    settings: &TrajectorySettings,
    weights: &RewardWeights,
    threads: usize,
    indicator: &IndicatorProvenance,
    cache: Option<&IndicatorCache>,
    budget: &Budget,
) -> Result<Executed, MillPlanError> {
    let limits = joint_limits(cell)?;
    budget.check("the executed trajectory")?;
    let scaling = time_scale(cell, plan, &limits, settings, budget)?;
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
    Executed::assemble(
        cell,
        (scaling, plan),
        cached_segments,
        *settings,
        threads,
        budget,
    )
}
