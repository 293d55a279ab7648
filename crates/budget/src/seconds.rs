//! [`limit_from_seconds`]: a request's time budget field, read and checked.

use std::time::Duration;

/// Largest time budget a request may give (s): one day.
pub const MAX_BUDGET_SECONDS: f64 = 86_400.0;

/// Reads a request's time budget in seconds: 0 = none of its own.
///
/// # Returns
/// `None` for 0, else the duration.
///
/// # Errors
/// A message (without the field name) for a negative, non-finite or too large value
/// (over [`MAX_BUDGET_SECONDS`]); nothing is clamped.
pub fn limit_from_seconds(seconds: f64) -> Result<Option<Duration>, String> {
    if seconds == 0.0 {
        return Ok(None);
    }
    if !(seconds > 0.0 && seconds <= MAX_BUDGET_SECONDS) {
        return Err(format!(
            "{seconds} s must be in (0, {MAX_BUDGET_SECONDS}] s, or 0 for none"
        ));
    }
    Ok(Some(Duration::from_secs_f64(seconds)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_is_none_and_bad_values_are_refused() {
        assert_eq!(limit_from_seconds(0.0), Ok(None));
        assert_eq!(
            limit_from_seconds(2.5),
            Ok(Some(Duration::from_millis(2500)))
        );
        for bad in [
            -1.0,
            f64::NAN,
            f64::INFINITY,
            1e300,
            MAX_BUDGET_SECONDS * 2.0,
        ] {
            let e = limit_from_seconds(bad).unwrap_err();
            assert!(e.contains("must be in (0, 86400] s"), "{bad}: {e}");
        }
    }
}
