//! The feed planner a caller picks (issue 14, item 3): the constant-speed
//! intervals of seed 003's planner ([`crate::plan_feed`]) or kerf's near
//! time-optimal one ([`crate::plan_feed_optimal`]), behind one call.

use kerf_budget::Budget;

use crate::constraints::FeedConstraints;
use crate::feed::{plan_feed_within, FeedPlan};
use crate::feed_optimal::plan_feed_optimal_within;
use crate::samples::PathSample;
use crate::ToolpathError;

/// A feed planner.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FeedMethod {
    /// Seed 003's planner (its reference 19, Jia et al. 2017): every
    /// feed-sensitive interval at its lowest limit ([`crate::plan_feed`]). Knows
    /// neither per-sample feeds nor axis limits.
    ConstantIntervals,
    /// The near time-optimal planner ([`crate::plan_feed_optimal`]).
    NearOptimal,
}

impl FeedMethod {
    /// Every method, in a fixed order.
    pub const ALL: [FeedMethod; 2] = [FeedMethod::ConstantIntervals, FeedMethod::NearOptimal];

    /// A short name for tables.
    pub fn name(self) -> &'static str {
        match self {
            FeedMethod::ConstantIntervals => "constant intervals",
            FeedMethod::NearOptimal => "near-optimal",
        }
    }

    /// Plans the feed along `samples` under `constraints`.
    ///
    /// # Errors
    /// The planner's errors; for [`FeedMethod::ConstantIntervals`] also
    /// [`ToolpathError::InvalidParameter`] when caps or axis limits are
    /// given (it would ignore them).
    pub fn plan(
        self,
        samples: &[PathSample],
        constraints: &FeedConstraints<'_>,
    ) -> Result<FeedPlan, ToolpathError> {
        self.plan_within(samples, constraints, &Budget::unlimited())
    }

    /// [`Self::plan`] under a budget ([`plan_feed_within`], [`plan_feed_optimal_within`]).
    ///
    /// # Errors
    /// As [`Self::plan`]; [`ToolpathError::Interrupted`] when the budget runs out.
    pub fn plan_within(
        self,
        samples: &[PathSample],
        constraints: &FeedConstraints<'_>,
        budget: &Budget,
    ) -> Result<FeedPlan, ToolpathError> {
        match self {
            FeedMethod::ConstantIntervals => {
                if constraints.caps.is_some() || constraints.axes.is_some() {
                    return Err(ToolpathError::InvalidParameter {
                        name: "feed method".to_string(),
                        value: 0.0,
                        reason: "the constant-interval planner takes neither per-sample \
                                 feeds nor axis limits"
                            .to_string(),
                    });
                }
                plan_feed_within(samples, &constraints.limits, budget)
            }
            FeedMethod::NearOptimal => plan_feed_optimal_within(samples, constraints, budget),
        }
    }
}
