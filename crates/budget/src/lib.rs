//! Time budgets and cooperative cancellation of planning requests (issue 11, item 3).
//!
//! A planner takes a [`Budget`] and calls [`Budget::check`] between units of work (a GFD
//! candidate, a trajectory sample, a path segment, a QP solve), so that a request that runs
//! out of time ends with [`Interrupt::TimedOut`] and one whose node stops ends with
//! [`Interrupt::Cancelled`], freeing the planner's thread. Nothing is killed: the planner
//! returns from the check's error like from any other.
//!
//! ```
//! use std::time::Duration;
//! use kerf_budget::{Budget, CancelToken, Interrupt};
//!
//! let cancel = CancelToken::new();
//! let budget = Budget::new(Some(Duration::from_secs(60)), cancel.clone());
//! assert!(budget.check("setup").is_ok());
//! cancel.cancel();
//! assert!(matches!(budget.check("setup"), Err(Interrupt::Cancelled { .. })));
//! ```

mod budget;
mod cancel;
mod interrupt;
mod memory;
mod seconds;

pub use budget::Budget;
pub use cancel::CancelToken;
pub use interrupt::Interrupt;
pub use memory::{
    bytes_of, format_bytes, memory_from_bytes, DEFAULT_PLAN_MEMORY, MAX_PLAN_MEMORY,
    MIN_PLAN_MEMORY,
};
pub use seconds::{limit_from_seconds, MAX_BUDGET_SECONDS};
