//! `builtin_interfaces/msg/Duration`.

use serde::{Deserialize, Serialize};

use super::{nanos, secs_f64, split_nanos, split_secs_f64};
use crate::ros_type::impl_ros_type;
use crate::Error;

const WHAT: &str = "builtin_interfaces/Duration";

/// A span of ROS time, possibly negative: `sec + nanosec * 1e-9` seconds with
/// `nanosec` in `[0, 1e9)`.
///
/// Field order and types: `int32 sec`, `uint32 nanosec`
/// (rcl_interfaces, `builtin_interfaces/msg/Duration.msg`). The derived
/// ordering compares `sec` then `nanosec`, which is chronological for
/// normalized values.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default, Serialize, Deserialize,
)]
pub struct Duration {
    /// Whole seconds (floor of the value), s.
    pub sec: i32,
    /// Nanoseconds added to `sec`, in `[0, 1e9)`, ns.
    pub nanosec: u32,
}

impl_ros_type!(Duration, "builtin_interfaces", msg, "Duration");

impl Duration {
    /// Zero duration.
    pub const ZERO: Duration = Duration { sec: 0, nanosec: 0 };

    /// The duration nearest to `seconds` at nanosecond resolution, normalized
    /// so that `nanosec` is in `[0, 1e9)` (-0.5 s is `sec -1, nanosec 5e8`).
    ///
    /// # Errors
    /// [`Error::NonFiniteSeconds`] for NaN or infinity,
    /// [`Error::SecondsOutOfRange`] when `sec` would not fit an `i32`.
    pub fn from_secs_f64(seconds: f64) -> Result<Duration, Error> {
        let (sec, nanosec) = split_secs_f64(seconds, WHAT)?;
        Ok(Duration { sec, nanosec })
    }

    /// The duration of `nanoseconds` ns, normalized.
    ///
    /// # Errors
    /// [`Error::SecondsOutOfRange`] when `sec` would not fit an `i32`.
    pub fn from_nanos(nanoseconds: i64) -> Result<Duration, Error> {
        let (sec, nanosec) = split_nanos(nanoseconds, WHAT)?;
        Ok(Duration { sec, nanosec })
    }

    /// The duration in seconds, `sec + nanosec * 1e-9`.
    pub fn as_secs_f64(&self) -> f64 {
        secs_f64(self.sec, self.nanosec)
    }

    /// The duration in nanoseconds, `sec * 1e9 + nanosec` (exact).
    pub fn as_nanos(&self) -> i64 {
        nanos(self.sec, self.nanosec)
    }

    /// True when both fields are zero.
    pub fn is_zero(&self) -> bool {
        self.sec == 0 && self.nanosec == 0
    }

    /// True when the duration is below zero.
    pub fn is_negative(&self) -> bool {
        self.as_nanos() < 0
    }
}

impl TryFrom<std::time::Duration> for Duration {
    type Error = Error;

    /// Converts a non-negative std duration; fails with
    /// [`Error::SecondsOutOfRange`] beyond `i32::MAX` seconds.
    fn try_from(value: std::time::Duration) -> Result<Self, Self::Error> {
        let sec = i32::try_from(value.as_secs()).map_err(|_| Error::SecondsOutOfRange {
            what: WHAT,
            value: value.as_secs_f64(),
            min: f64::from(i32::MIN),
            max: f64::from(i32::MAX) + 0.999_999_999,
        })?;
        Ok(Duration {
            sec,
            nanosec: value.subsec_nanos(),
        })
    }
}

impl TryFrom<Duration> for std::time::Duration {
    type Error = Error;

    /// Converts a non-negative duration; fails with [`Error::NegativeDuration`].
    fn try_from(value: Duration) -> Result<Self, Self::Error> {
        let nanos = u64::try_from(value.as_nanos()).map_err(|_| Error::NegativeDuration {
            sec: value.sec,
            nanosec: value.nanosec,
        })?;
        Ok(std::time::Duration::from_nanos(nanos))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn negative_durations_are_normalized() {
        let d = Duration::from_secs_f64(-1.25).unwrap();
        assert_eq!(
            d,
            Duration {
                sec: -2,
                nanosec: 750_000_000
            }
        );
        assert_eq!(d.as_secs_f64(), -1.25);
        assert_eq!(d.as_nanos(), -1_250_000_000);
        assert!(d.is_negative());
        assert_eq!(Duration::from_nanos(-1_250_000_000), Ok(d));
    }

    #[test]
    fn seconds_round_trip_at_nanosecond_resolution() {
        for s in [0.0, 1e-9, 0.1, 2.5, 3.123_456_789, 1_000_000.000_000_001] {
            let d = Duration::from_secs_f64(s).unwrap();
            assert!(
                (d.as_secs_f64() - s).abs() <= 0.5e-9 + s * f64::EPSILON,
                "{s}"
            );
        }
        assert!(Duration::from_secs_f64(0.0).unwrap().is_zero());
        assert!(!Duration::from_secs_f64(1e-9).unwrap().is_zero());
    }

    #[test]
    fn std_conversions() {
        let std = std::time::Duration::new(3, 7);
        let d = Duration::try_from(std).unwrap();
        assert_eq!(d, Duration { sec: 3, nanosec: 7 });
        assert_eq!(std::time::Duration::try_from(d), Ok(std));
        let negative = Duration {
            sec: -1,
            nanosec: 0,
        };
        assert_eq!(
            std::time::Duration::try_from(negative),
            Err(Error::NegativeDuration {
                sec: -1,
                nanosec: 0
            })
        );
        assert!(Duration::try_from(std::time::Duration::from_secs(1 << 32)).is_err());
    }

    #[test]
    fn ordering_is_chronological() {
        let a = Duration::from_secs_f64(-0.5).unwrap();
        let b = Duration::from_secs_f64(0.25).unwrap();
        assert!(a < b);
    }
}
