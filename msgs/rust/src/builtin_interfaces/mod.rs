//! Mirrors of `builtin_interfaces` (ros2/rcl_interfaces, Jazzy): [`Time`] and [`Duration`].
//!
//! Both store a point or span of ROS time as `int32 sec` plus `uint32 nanosec`
//! with `nanosec` in `[0, 1e9)`. A negative value keeps `nanosec` non-negative:
//! -0.5 s is `sec = -1, nanosec = 500_000_000`, the normalization of rclcpp's
//! `Duration`/`Time` `to_msg` (ROS 2 design article "Clock and Time").

mod duration;
mod time;

pub use duration::Duration;
pub use time::Time;

use crate::Error;

/// Nanoseconds per second.
pub(crate) const NANOS_PER_SEC: i64 = 1_000_000_000;

/// Splits `value` seconds into `(sec, nanosec)` with `nanosec` in `[0, 1e9)`:
/// `sec = floor(value)`, `nanosec = round((value - sec) * 1e9)`, carried into
/// `sec` when it rounds to 1e9. `what` names the value in errors.
pub(crate) fn split_secs_f64(value: f64, what: &'static str) -> Result<(i32, u32), Error> {
    if !value.is_finite() {
        return Err(Error::NonFiniteSeconds { what, value });
    }
    let whole = value.floor();
    // `value - floor(value)` is exact in IEEE 754 for every finite value.
    let mut nanos = ((value - whole) * 1e9).round();
    let mut sec = whole;
    if nanos >= 1e9 {
        sec += 1.0;
        nanos -= 1e9;
    }
    let (min, max) = (f64::from(i32::MIN), f64::from(i32::MAX));
    if sec < min || sec > max {
        return Err(Error::SecondsOutOfRange {
            what,
            value,
            min,
            max: max + 0.999_999_999,
        });
    }
    // Both casts are exact: range checked above, nanos in [0, 1e9).
    Ok((sec as i32, nanos as u32))
}

/// Splits `nanos` nanoseconds into `(sec, nanosec)` with `nanosec` in `[0, 1e9)`
/// (Euclidean division). `what` names the value in errors.
pub(crate) fn split_nanos(nanos: i64, what: &'static str) -> Result<(i32, u32), Error> {
    let sec = nanos.div_euclid(NANOS_PER_SEC);
    let nanosec = nanos.rem_euclid(NANOS_PER_SEC);
    match (i32::try_from(sec), u32::try_from(nanosec)) {
        (Ok(sec), Ok(nanosec)) => Ok((sec, nanosec)),
        _ => Err(Error::SecondsOutOfRange {
            what,
            value: nanos as f64 * 1e-9,
            min: f64::from(i32::MIN),
            max: f64::from(i32::MAX) + 0.999_999_999,
        }),
    }
}

/// `sec + nanosec * 1e-9` seconds. Also correct for a non-normalized `nanosec`
/// (>= 1e9) received from another node.
pub(crate) fn secs_f64(sec: i32, nanosec: u32) -> f64 {
    f64::from(sec) + f64::from(nanosec) * 1e-9
}

/// `sec * 1e9 + nanosec` nanoseconds; cannot overflow an `i64` for any field values.
pub(crate) fn nanos(sec: i32, nanosec: u32) -> i64 {
    i64::from(sec) * NANOS_PER_SEC + i64::from(nanosec)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_rounds_and_carries() {
        assert_eq!(split_secs_f64(1.5, "x"), Ok((1, 500_000_000)));
        assert_eq!(split_secs_f64(-0.25, "x"), Ok((-1, 750_000_000)));
        // 1.9999999999 s rounds to 2 s exactly: nanosec carries into sec.
        assert_eq!(split_secs_f64(1.999_999_999_9, "x"), Ok((2, 0)));
        assert_eq!(split_secs_f64(-1e-12, "x"), Ok((0, 0)));
    }

    #[test]
    fn split_rejects_non_finite_and_out_of_range() {
        assert!(matches!(
            split_secs_f64(f64::NAN, "x"),
            Err(Error::NonFiniteSeconds { .. })
        ));
        assert!(matches!(
            split_secs_f64(3e9, "x"),
            Err(Error::SecondsOutOfRange { .. })
        ));
        assert!(matches!(
            split_secs_f64(-2_147_483_649.0, "x"),
            Err(Error::SecondsOutOfRange { .. })
        ));
        assert_eq!(split_secs_f64(-2_147_483_648.0, "x"), Ok((i32::MIN, 0)));
    }

    #[test]
    fn split_nanos_is_euclidean() {
        assert_eq!(split_nanos(-1, "x"), Ok((-1, 999_999_999)));
        assert_eq!(split_nanos(2_000_000_001, "x"), Ok((2, 1)));
        assert!(split_nanos(i64::MAX, "x").is_err());
        assert_eq!(nanos(-1, 999_999_999), -1);
    }
}
