//! [`Budget`]: a deadline and a cancellation token, checked cooperatively.

use std::time::{Duration, Instant};

use crate::{memory::MemoryAccount, CancelToken, Interrupt};

/// The time a piece of work may take, from its creation, the token that cancels it, and the
/// memory its data may hold ([`Self::with_memory`]).
///
/// Cheap to check (an atomic load and a clock read): call [`Self::check`] between units of
/// work small enough that the overshoot past the deadline stays well under a second, and
/// [`Self::check_memory`] / [`Self::account`] before a stage allocates data that grows with
/// the request.
#[derive(Debug, Clone)]
pub struct Budget {
    start: Instant,
    limit: Option<Duration>,
    cancel: CancelToken,
    memory: MemoryAccount,
}

impl Budget {
    /// A budget of `limit` (none: unlimited) starting now, cancelled by `cancel`.
    pub fn new(limit: Option<Duration>, cancel: CancelToken) -> Self {
        Self {
            start: Instant::now(),
            limit,
            cancel,
            memory: MemoryAccount::default(),
        }
    }

    /// The same budget with a memory limit of `bytes` (none: unlimited) and an empty account.
    pub fn with_memory(mut self, bytes: Option<u64>) -> Self {
        self.memory = MemoryAccount::new(bytes);
        self
    }

    /// The memory limit (bytes; none: unlimited).
    pub fn memory_limit(&self) -> Option<u64> {
        self.memory.limit()
    }

    /// Bytes accounted so far ([`Self::account`]).
    pub fn memory_used(&self) -> u64 {
        self.memory.used()
    }

    /// Checks an estimate: whether a stage holding `bytes` more than what is accounted fits.
    ///
    /// # Arguments
    /// * `bytes` — the stage's estimated data (e.g. [`crate::bytes_of`] of its sample count).
    /// * `what` — what grows, with the request's figures, named in the error.
    ///
    /// # Errors
    /// [`Interrupt::OverMemory`] when it would not fit.
    pub fn check_memory(&self, bytes: u64, what: &str) -> Result<(), Interrupt> {
        self.memory.check(bytes, what)
    }

    /// Accounts `bytes` the plan now holds (until [`Self::release`]); clones share the account.
    ///
    /// # Errors
    /// [`Interrupt::OverMemory`] (nothing accounted) when they would not fit.
    pub fn account(&self, bytes: u64, what: &str) -> Result<(), Interrupt> {
        self.memory.account(bytes, what)
    }

    /// Gives back `bytes` accounted earlier.
    pub fn release(&self, bytes: u64) {
        self.memory.release(bytes)
    }

    /// No deadline and a token nobody holds: [`Self::check`] always passes.
    pub fn unlimited() -> Self {
        Self::new(None, CancelToken::new())
    }

    /// The same start and token, with the smaller of this budget's limit and `limit`
    /// (a request asking for less than its node allows).
    ///
    /// # Arguments
    /// * `limit` — the other limit, measured from this budget's start; `None` changes nothing.
    pub fn tightened(&self, limit: Option<Duration>) -> Self {
        let limit = match (self.limit, limit) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
        Self {
            start: self.start,
            limit,
            cancel: self.cancel.clone(),
            memory: self.memory.clone(),
        }
    }

    /// The limit (none: unlimited).
    pub fn limit(&self) -> Option<Duration> {
        self.limit
    }

    /// Time since the budget started.
    pub fn elapsed(&self) -> Duration {
        self.start.elapsed()
    }

    /// Time left before the deadline (`None`: unlimited; zero once it has passed).
    pub fn remaining(&self) -> Option<Duration> {
        self.limit.map(|l| l.saturating_sub(self.start.elapsed()))
    }

    /// Whether the work was cancelled.
    pub fn is_cancelled(&self) -> bool {
        self.cancel.is_cancelled()
    }

    /// Checks the token, then the deadline.
    ///
    /// # Arguments
    /// * `stage` — what is running, named in the error ("GFD construction", …).
    ///
    /// # Errors
    /// [`Interrupt::Cancelled`] once the token is cancelled; [`Interrupt::TimedOut`] once the
    /// deadline has passed.
    ///
    /// # Performance
    /// One relaxed atomic load and one monotonic clock read (tens of nanoseconds).
    pub fn check(&self, stage: &'static str) -> Result<(), Interrupt> {
        let elapsed = self.start.elapsed();
        if self.cancel.is_cancelled() {
            return Err(Interrupt::Cancelled { elapsed, stage });
        }
        match self.limit {
            Some(budget) if elapsed > budget => Err(Interrupt::TimedOut {
                budget,
                elapsed,
                stage,
            }),
            _ => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unlimited_always_passes() {
        let b = Budget::unlimited();
        assert!(b.check("x").is_ok());
        assert_eq!(b.remaining(), None);
    }

    #[test]
    fn deadline_ends_with_timed_out_naming_the_stage() {
        let b = Budget::new(Some(Duration::ZERO), CancelToken::new());
        std::thread::sleep(Duration::from_millis(2));
        let e = b.check("GFD construction").unwrap_err();
        assert!(e.is_timeout());
        let text = e.to_string();
        assert!(text.contains("GFD construction"), "{text}");
        assert!(text.contains("time budget of 0.000 s"), "{text}");
        assert_eq!(b.remaining(), Some(Duration::ZERO));
    }

    #[test]
    fn cancel_wins_over_the_deadline_and_reaches_clones() {
        let token = CancelToken::new();
        let b = Budget::new(Some(Duration::ZERO), token.clone());
        let c = b.tightened(None);
        token.cancel();
        assert!(matches!(c.check("s"), Err(Interrupt::Cancelled { .. })));
        assert!(b.is_cancelled());
    }

    #[test]
    fn memory_is_shared_by_clones_and_tightened_budgets() {
        let b = Budget::unlimited().with_memory(Some(100));
        let c = b.tightened(Some(Duration::from_secs(1)));
        assert!(c.account(80, "a").is_ok());
        assert_eq!(b.memory_used(), 80);
        assert!(b.check_memory(30, "b").unwrap_err().is_over_memory());
        b.release(80);
        assert!(c.check_memory(100, "c").is_ok());
        assert_eq!(Budget::unlimited().memory_limit(), None);
    }

    #[test]
    fn tightened_takes_the_smaller_limit() {
        let b = Budget::new(Some(Duration::from_secs(10)), CancelToken::new());
        assert_eq!(
            b.tightened(Some(Duration::from_secs(3))).limit(),
            Some(Duration::from_secs(3))
        );
        assert_eq!(
            b.tightened(Some(Duration::from_secs(30))).limit(),
            Some(Duration::from_secs(10))
        );
        assert_eq!(b.tightened(None).limit(), Some(Duration::from_secs(10)));
        assert_eq!(
            Budget::unlimited()
                .tightened(Some(Duration::from_secs(2)))
                .limit(),
            Some(Duration::from_secs(2))
        );
    }
}
