//! [`Budget`]: a deadline and a cancellation token, checked cooperatively.

use std::time::{Duration, Instant};

use crate::{CancelToken, Interrupt};

/// The time a piece of work may take, from its creation, and the token that cancels it.
///
/// Cheap to check (an atomic load and a clock read): call [`Self::check`] between units of
/// work small enough that the overshoot past the deadline stays well under a second.
#[derive(Debug, Clone)]
pub struct Budget {
    start: Instant,
    limit: Option<Duration>,
    cancel: CancelToken,
}

impl Budget {
    /// A budget of `limit` (none: unlimited) starting now, cancelled by `cancel`.
    pub fn new(limit: Option<Duration>, cancel: CancelToken) -> Self {
        Self {
            start: Instant::now(),
            limit,
            cancel,
        }
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
