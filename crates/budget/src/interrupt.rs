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
    /// The plan's data would not fit in its memory budget (the node's `plan_memory`).
    #[error(
        "memory budget of {limit_text} exceeded: {what} needs {needed_text}; the request was \
         not planned (simplify it, or raise the node's plan_memory)",
        limit_text = crate::format_bytes(*.limit),
        needed_text = crate::format_bytes(*.needed)
    )]
    OverMemory {
        /// The budget (bytes).
        limit: u64,
        /// What the stage would have held in all (bytes, an estimate or the account).
        needed: u64,
        /// What grew, with the request's figures ("arc samples: 10000 helix turns × …").
        what: String,
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

    /// Whether the memory budget ran out.
    pub fn is_over_memory(&self) -> bool {
        matches!(self, Interrupt::OverMemory { .. })
    }
}
