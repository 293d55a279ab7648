//! `builtin_interfaces/msg/Time`.

use std::time::{SystemTime, UNIX_EPOCH};

use serde::{Deserialize, Serialize};

use super::{nanos, secs_f64, split_nanos, split_secs_f64};
use crate::ros_type::impl_ros_type;
use crate::Error;

const WHAT: &str = "builtin_interfaces/Time";

/// A point in ROS time: `sec + nanosec * 1e-9` seconds since the clock's epoch
/// (the Unix epoch for the system clock), `nanosec` in `[0, 1e9)`.
///
/// Field order and types: `int32 sec`, `uint32 nanosec`
/// (rcl_interfaces, `builtin_interfaces/msg/Time.msg`). Zero means "no stamp"
/// in message headers. The constructors reject negative times, as rclcpp's
/// `Time` does; a negative `sec` received from another node is kept as is.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default, Serialize, Deserialize,
)]
pub struct Time {
    /// Whole seconds since the epoch, s.
    pub sec: i32,
    /// Nanoseconds added to `sec`, in `[0, 1e9)`, ns.
    pub nanosec: u32,
}

impl_ros_type!(Time, "builtin_interfaces", msg, "Time");

impl Time {
    /// The zero time, which ROS uses for "unset".
    pub const ZERO: Time = Time { sec: 0, nanosec: 0 };

    /// The time `seconds` after the epoch, at nanosecond resolution.
    ///
    /// # Errors
    /// [`Error::NonFiniteSeconds`], [`Error::NegativeTime`], or
    /// [`Error::SecondsOutOfRange`] beyond `i32::MAX` s (year 2038).
    pub fn from_secs_f64(seconds: f64) -> Result<Time, Error> {
        if seconds < 0.0 {
            return Err(Error::NegativeTime { value: seconds });
        }
        let (sec, nanosec) = split_secs_f64(seconds, WHAT)?;
        Ok(Time { sec, nanosec })
    }

    /// The time `nanoseconds` ns after the epoch.
    ///
    /// # Errors
    /// [`Error::NegativeTime`], or [`Error::SecondsOutOfRange`] beyond `i32::MAX` s.
    pub fn from_nanos(nanoseconds: i64) -> Result<Time, Error> {
        if nanoseconds < 0 {
            return Err(Error::NegativeTime {
                value: nanoseconds as f64 * 1e-9,
            });
        }
        let (sec, nanosec) = split_nanos(nanoseconds, WHAT)?;
        Ok(Time { sec, nanosec })
    }

    /// The current system time.
    ///
    /// # Errors
    /// As [`Time::try_from`] for [`SystemTime`].
    pub fn now() -> Result<Time, Error> {
        Time::try_from(SystemTime::now())
    }

    /// Seconds since the epoch, `sec + nanosec * 1e-9`.
    pub fn as_secs_f64(&self) -> f64 {
        secs_f64(self.sec, self.nanosec)
    }

    /// Nanoseconds since the epoch, `sec * 1e9 + nanosec` (exact).
    pub fn as_nanos(&self) -> i64 {
        nanos(self.sec, self.nanosec)
    }

    /// True for the zero ("unset") time.
    pub fn is_zero(&self) -> bool {
        self.sec == 0 && self.nanosec == 0
    }
}

impl TryFrom<SystemTime> for Time {
    type Error = Error;

    /// The ROS time of a system time, counted from the Unix epoch.
    /// Fails with [`Error::BeforeUnixEpoch`] before 1970 and
    /// [`Error::SecondsOutOfRange`] after 2038-01-19T03:14:07Z.
    fn try_from(value: SystemTime) -> Result<Self, Self::Error> {
        let since_epoch = value
            .duration_since(UNIX_EPOCH)
            .map_err(|e| Error::BeforeUnixEpoch {
                seconds_before: e.duration().as_secs_f64(),
            })?;
        let sec = i32::try_from(since_epoch.as_secs()).map_err(|_| Error::SecondsOutOfRange {
            what: WHAT,
            value: since_epoch.as_secs_f64(),
            min: 0.0,
            max: f64::from(i32::MAX) + 0.999_999_999,
        })?;
        Ok(Time {
            sec,
            nanosec: since_epoch.subsec_nanos(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration as StdDuration;

    #[test]
    fn from_system_time() {
        let t = UNIX_EPOCH + StdDuration::new(1_700_000_000, 123);
        assert_eq!(
            Time::try_from(t),
            Ok(Time {
                sec: 1_700_000_000,
                nanosec: 123
            })
        );
        let before = UNIX_EPOCH - StdDuration::from_secs(2);
        assert_eq!(
            Time::try_from(before),
            Err(Error::BeforeUnixEpoch {
                seconds_before: 2.0
            })
        );
        let after_2038 = UNIX_EPOCH + StdDuration::from_secs(1 << 31);
        assert!(matches!(
            Time::try_from(after_2038),
            Err(Error::SecondsOutOfRange { .. })
        ));
        assert!(Time::now().is_ok_and(|t| t.sec > 1_600_000_000));
    }

    #[test]
    fn seconds_conversions() {
        let t = Time::from_secs_f64(12.75).unwrap();
        assert_eq!(
            t,
            Time {
                sec: 12,
                nanosec: 750_000_000
            }
        );
        assert_eq!(t.as_secs_f64(), 12.75);
        assert_eq!(t.as_nanos(), 12_750_000_000);
        assert_eq!(Time::from_nanos(12_750_000_000), Ok(t));
        assert_eq!(
            Time::from_secs_f64(-0.5),
            Err(Error::NegativeTime { value: -0.5 })
        );
        assert!(Time::from_nanos(-1).is_err());
        assert!(Time::from_secs_f64(f64::INFINITY).is_err());
        assert!(Time::ZERO.is_zero() && Time::default().is_zero());
        assert!(!t.is_zero());
    }
}
