//! [`Held`]: the memory a plan holds while it runs (the program's runs, each run's path,
//! samples, feed plan and joint points), accounted against the plan's memory budget
//! ([`kerf_budget::Budget::account`]) and given back when the plan ends.
//!
//! Data a stage makes and drops (the feed plan at the interpolation period, the limit curve)
//! is checked by estimate before it is made ([`kerf_budget::Budget::check_memory`], in the
//! stages of `kerf_toolpath` and here), against the budget less what is held.

use kerf_budget::{Budget, Interrupt};

/// Bytes accounted on a budget, released when this is dropped (the plan's end, whatever way
/// it ends).
#[derive(Debug)]
pub(crate) struct Held<'a> {
    budget: &'a Budget,
    bytes: u64,
}

impl<'a> Held<'a> {
    /// Nothing held yet.
    pub(crate) fn new(budget: &'a Budget) -> Self {
        Self { budget, bytes: 0 }
    }

    /// The budget.
    pub(crate) fn budget(&self) -> &'a Budget {
        self.budget
    }

    /// Accounts `bytes` more, named by `what` (formatted only when they do not fit).
    ///
    /// # Errors
    /// [`Interrupt::OverMemory`] naming `what()` (nothing accounted).
    pub(crate) fn add(
        &mut self,
        bytes: u64,
        what: impl FnOnce() -> String,
    ) -> Result<(), Interrupt> {
        match self.budget.account(bytes, "") {
            Ok(()) => {
                self.bytes = self.bytes.saturating_add(bytes);
                Ok(())
            }
            Err(Interrupt::OverMemory { limit, needed, .. }) => Err(Interrupt::OverMemory {
                limit,
                needed,
                what: what(),
            }),
            Err(other) => Err(other),
        }
    }

    /// Checks that `bytes` more would fit, named by `what` (formatted only when they do not).
    ///
    /// # Errors
    /// [`Interrupt::OverMemory`] naming `what()`.
    pub(crate) fn check(&self, bytes: u64, what: impl FnOnce() -> String) -> Result<(), Interrupt> {
        match self.budget.check_memory(bytes, "") {
            Err(Interrupt::OverMemory { limit, needed, .. }) => Err(Interrupt::OverMemory {
                limit,
                needed,
                what: what(),
            }),
            other => other,
        }
    }
}

impl Drop for Held<'_> {
    fn drop(&mut self) {
        self.budget.release(self.bytes);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn held_bytes_are_released_at_the_end_and_refusals_name_what_grew() {
        let budget = Budget::unlimited().with_memory(Some(1000));
        {
            let mut held = Held::new(&budget);
            held.add(600, || "runs".to_string()).unwrap();
            assert_eq!(budget.memory_used(), 600);
            let e = held
                .add(500, || "path samples: 9 pieces".to_string())
                .unwrap_err();
            assert!(e.to_string().contains("path samples: 9 pieces"), "{e}");
            assert!(held.check(400, || "x".to_string()).is_ok());
            assert!(held
                .check(401, || "knots".to_string())
                .unwrap_err()
                .to_string()
                .contains("knots"));
        }
        assert_eq!(budget.memory_used(), 0);
    }
}
