//! [`Interrupt`]: why a [`crate::Budget`] stopped the work.

use std::time::Duration;

use thiserror::Error;

/// Why planning stopped before its end.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum Interrupt {
    /// The request's time budget ran out.
    #[error(
        "time budget of {budget:.3} s exhausted after {elapsed:.3} s, during {stage}; \
         the request was not planned (simplify it, or ask for a larger budget up to the \
         node's plan_timeout)",
        budget = .budget.as_secs_f64(),
        elapsed = .elapsed.as_secs_f64()
    )]
    TimedOut {
        /// The budget the request ran under.
        budget: Duration,
        /// Time from the budget's start to the check that stopped it.
        elapsed: Duration,
        /// The stage of the planner that was running.
        stage: &'static str,
    },
    /// The work was cancelled (the node is stopping).
    #[error(
        "planning cancelled after {elapsed:.3} s, during {stage}: the planner is stopping",
        elapsed = .elapsed.as_secs_f64()
    )]
    Cancelled {
        /// Time from the budget's start to the check that stopped it.
        elapsed: Duration,
        /// The stage of the planner that was running.
        stage: &'static str,
    },
}

impl Interrupt {
    /// Whether the budget ran out (as opposed to a cancellation).
    pub fn is_timeout(&self) -> bool {
        matches!(self, Interrupt::TimedOut { .. })
    }
}
