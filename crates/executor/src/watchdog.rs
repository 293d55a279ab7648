//! The feedback watchdog of a hardware driver (issue 27, item 2): a driver's joint states must
//! keep coming, and their stamps must not go back; otherwise the executor stops the robot in a
//! controlled way and aborts the goal.
//!
//! All times are seconds on one monotonic clock of the caller (arrival) and the driver's stamps
//! (which only need to be non-decreasing).

use crate::ExecutorError;

/// Watches the arrival and the stamps of a driver's feedback.
#[derive(Debug, Clone)]
pub struct FeedbackWatchdog {
    /// Largest gap between two states (s): `missed` control periods.
    limit: f64,
    missed: u32,
    /// When the watchdog started (s): the gap before the first state counts from here.
    started: f64,
    last_arrival: Option<f64>,
    last_stamp: Option<f64>,
}

impl FeedbackWatchdog {
    /// A watchdog allowing `missed` control periods of `period` seconds without a new state,
    /// started at `now`.
    ///
    /// # Errors
    /// [`ExecutorError::InvalidConfig`] when `period` is not finite and > 0, `missed` is 0, or
    /// `now` is not finite.
    pub fn new(period: f64, missed: u32, now: f64) -> Result<Self, ExecutorError> {
        let bad = |field: &str, value: f64, requirement| ExecutorError::InvalidConfig {
            field: field.into(),
            value,
            requirement,
        };
        if !(period.is_finite() && period > 0.0) {
            return Err(bad("feedback period", period, "must be finite and > 0"));
        }
        if missed == 0 {
            return Err(bad("feedback_missed_periods", 0.0, "must be at least 1"));
        }
        if !now.is_finite() {
            return Err(bad("watchdog start time", now, "must be finite"));
        }
        Ok(Self {
            limit: period * f64::from(missed),
            missed,
            started: now,
            last_arrival: None,
            last_stamp: None,
        })
    }

    /// A state stamped `stamp` arrived at `now`.
    ///
    /// # Errors
    /// [`ExecutorError::FeedbackStampBack`] when `stamp` is older than the previous one (the
    /// state is not taken), [`ExecutorError::NonFiniteTime`] for a non-finite time.
    pub fn receive(&mut self, stamp: f64, now: f64) -> Result<(), ExecutorError> {
        for (what, value) in [("feedback stamp", stamp), ("feedback arrival time", now)] {
            if !value.is_finite() {
                return Err(ExecutorError::NonFiniteTime { what, value });
            }
        }
        if let Some(previous) = self.last_stamp {
            if stamp < previous {
                return Err(ExecutorError::FeedbackStampBack {
                    previous,
                    got: stamp,
                });
            }
        }
        self.last_stamp = Some(stamp);
        self.last_arrival = Some(now);
        Ok(())
    }

    /// Checks the gap since the last state (or the start) at `now`.
    ///
    /// # Errors
    /// [`ExecutorError::FeedbackStale`] when it is longer than the allowed periods (a
    /// non-finite `now` is stale too: the robot must stop when time cannot be trusted).
    pub fn check(&self, now: f64) -> Result<(), ExecutorError> {
        let age = now - self.last_arrival.unwrap_or(self.started);
        if age.is_finite() && age <= self.limit {
            Ok(())
        } else {
            Err(ExecutorError::FeedbackStale {
                age,
                limit: self.limit,
                missed: self.missed,
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::FeedbackWatchdog;

    #[test]
    fn a_gap_over_the_allowed_periods_is_stale() {
        let mut w = FeedbackWatchdog::new(0.004, 5, 10.0).unwrap();
        assert!(w.check(10.02).is_ok());
        let e = w.check(10.021).unwrap_err().to_string();
        assert!(
            e.contains("feedback stale") && e.contains("5 control periods"),
            "{e}"
        );
        w.receive(1.0, 10.021).unwrap();
        assert!(w.check(10.04).is_ok());
        assert!(w.check(10.042).is_err());
        assert!(w.check(f64::NAN).is_err());
    }

    #[test]
    fn stamps_that_go_back_are_refused() {
        let mut w = FeedbackWatchdog::new(0.004, 3, 0.0).unwrap();
        w.receive(5.0, 0.001).unwrap();
        w.receive(5.0, 0.002).unwrap();
        let e = w.receive(4.999, 0.003).unwrap_err().to_string();
        assert!(e.contains("went back: 4.999 s after 5 s"), "{e}");
        // The refused state does not feed the watchdog.
        assert!(w.check(0.0141).is_err());
        assert!(w.receive(f64::NAN, 0.004).is_err());
    }

    #[test]
    fn settings_are_checked() {
        assert!(FeedbackWatchdog::new(0.0, 3, 0.0).is_err());
        assert!(FeedbackWatchdog::new(f64::NAN, 3, 0.0).is_err());
        assert!(FeedbackWatchdog::new(0.004, 0, 0.0).is_err());
        assert!(FeedbackWatchdog::new(0.004, 3, f64::INFINITY).is_err());
    }
}
