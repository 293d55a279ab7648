//! The DP with the executed timing in the loop (issue 13, item 3: "the DP
//! with the executed timing in its cost, so its optimum holds as
//! executed").
//!
//! The DP of [`crate::dp`] maximizes seed 004's eq. 12 at the PLANNED
//! feeds: every segment at l / f. The robot runs the time-scaled trajectory
//! of [`crate::timing::time_scale`] instead, which slows the segments where
//! a g move asks a joint for more than its velocity, acceleration or jerk
//! limit (measured: the default DP plan, 16.18 s as planned, runs 21.95 s
//! and chatters at the slowed feeds). [`solve_executed`] closes that loop:
//!
//! 1. solve the DP ([`crate::dp::solve_holding`]) with g held on the moves
//!    found so far;
//! 2. evaluate the plan directly ([`Plan::evaluate_with_threads`]) and time
//!    it as the planner does ([`crate::execute`]);
//! 3. hold g on the moves around every segment the executed trajectory
//!    slowed by more than [`SLOWDOWN_TOLERANCE`] ([`HOLD_REACH`]), and go to 1,
//!    until no new move is held or after [`DP_EXECUTED_ROUNDS`] rounds.
//!
//! The answer is the round whose plan AS EXECUTED does not chatter
//! ([`Executed::chatters`]: the judge of every executed sample, issue 28) and
//! has the largest eq. 12 total (|μ|max and rewards re-evaluated at the
//! executed feeds, the objective of the DP as the robot runs it), else the
//! chattering round with the largest total; every round is reported. This is
//! the `dp` planner of [`crate::MillPlanner`] (issue 28, item 5).
//! What the rounds cannot express: a g move that is slowed only because of
//! its neighbours' moves (jerk over four midpoints) is held rather than
//! re-timed, so the result is the best plan among those whose slowed moves
//! are frozen, not the optimum of the executed-timing problem.

use kerf_budget::Budget;
use kerf_mill::MillCell;

use crate::cache::IndicatorCache;
use crate::dp::{solve_holding, DpResult, DpSpec};
use crate::error::MillPlanError;
use crate::executed::{execute, Executed};
use crate::plan::Plan;

/// The most DP solves of [`solve_executed`].
pub const DP_EXECUTED_ROUNDS: usize = 10;

/// A segment counts as slowed by the executed trajectory when its slowdown
/// ([`crate::timing::TimeScaling::segment_slowdown`]) exceeds this.
pub const SLOWDOWN_TOLERANCE: f64 = 1.005;

/// Moves held before a slowed segment i: from i − HOLD_REACH to i + 1 (the
/// executed g(s) is a cubic spline through the midpoints: a move changes its
/// slope and curvature over the neighbouring intervals too).
pub const HOLD_REACH: usize = 2;

/// One round of [`solve_executed`].
#[derive(Debug, Clone, PartialEq)]
pub struct ExecutedDpRound {
    /// The moves held in this round (`held[t]`: segment t → t + 1 keeps g).
    pub held: Vec<bool>,
    /// The DP's result.
    pub result: DpResult,
    /// Its plan evaluated directly (as planned).
    pub plan: Plan,
    /// What the robot runs of it.
    pub executed: Executed,
}

/// The rounds of [`solve_executed`] and the one answered.
#[derive(Debug, Clone, PartialEq)]
pub struct ExecutedDp {
    /// Every round, in order.
    pub rounds: Vec<ExecutedDpRound>,
    /// Index of the round whose executed eq. 12 total is the largest.
    pub best: usize,
}

impl ExecutedDp {
    /// The answered round.
    pub fn best(&self) -> Option<&ExecutedDpRound> {
        self.rounds.get(self.best)
    }
}

/// The DP with the executed timing in the loop (module documentation).
///
/// # Arguments
/// * `cell`, `cache`, `spec` — as [`crate::dp::solve_within`].
/// * `threads` — of the direct evaluation and the executed trajectory.
/// * `budget` — checked by every DP and between rounds.
///
/// # Returns
/// Every round and the best as executed.
///
/// # Errors
/// Those of [`crate::dp::solve_holding`], [`Plan::evaluate_with_threads`]
/// and [`crate::execute`] (a plan the executor would refuse is an error,
/// not a round).
///
/// # Performance
/// Each round: one DP (4–10 s on the default grid), N direct indicator
/// evaluations and one executed trajectory.
pub fn solve_executed(
    cell: &MillCell,
    cache: &IndicatorCache,
    spec: &DpSpec,
    threads: usize,
    budget: &Budget,
) -> Result<ExecutedDp, MillPlanError> {
    let n = cell.path().segments().len();
    let mut held = vec![false; n];
    let mut rounds: Vec<ExecutedDpRound> = Vec::new();
    for _ in 0..DP_EXECUTED_ROUNDS {
        budget.check("the executed DP's rounds")?;
        let result = solve_holding(cell, cache, spec, &held, budget)?;
        let plan = Plan::evaluate_with_threads(cell, &spec.weights, &result.states, "dp", threads)?;
        let executed = execute(cell, &plan, &spec.weights, threads)?;
        let mut next = held.clone();
        for (i, c) in executed.scaling.segment_slowdown.iter().enumerate() {
            if *c > SLOWDOWN_TOLERANCE {
                for t in i.saturating_sub(HOLD_REACH)..=i + 1 {
                    if let Some(slot) = next.get_mut(t) {
                        *slot = true;
                    }
                }
            }
        }
        let unchanged = next == held;
        rounds.push(ExecutedDpRound {
            held: std::mem::replace(&mut held, next),
            result,
            plan,
            executed,
        });
        if unchanged {
            break;
        }
    }
    let best = rounds
        .iter()
        .enumerate()
        .max_by(|(_, a), (_, b)| {
            (!a.executed.chatters()).cmp(&!b.executed.chatters()).then(
                a.executed
                    .plan
                    .total_reward
                    .total_cmp(&b.executed.plan.total_reward),
            )
        })
        .map_or(0, |(k, _)| k);
    Ok(ExecutedDp { rounds, best })
}
