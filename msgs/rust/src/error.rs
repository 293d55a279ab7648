//! The crate's error type.

/// Everything that can go wrong in kerf_msgs: building time values and parsing
/// interface definition files.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A time value in seconds was NaN or infinite.
    #[error("{what} must be a finite number of seconds, got {value}")]
    NonFiniteSeconds {
        /// Which value (e.g. "builtin_interfaces/Duration").
        what: &'static str,
        /// The offending value, s.
        value: f64,
    },
    /// A time value does not fit the `int32 sec` field.
    #[error(
        "{what} of {value} s does not fit its int32 seconds field \
         (representable range {min} s to {max} s)"
    )]
    SecondsOutOfRange {
        /// Which value (e.g. "builtin_interfaces/Time").
        what: &'static str,
        /// The offending value, s.
        value: f64,
        /// Smallest representable value, s.
        min: f64,
        /// Largest representable value, s.
        max: f64,
    },
    /// A negative value was given for a point in ROS time.
    #[error("builtin_interfaces/Time cannot be negative (ROS time starts at 0), got {value} s")]
    NegativeTime {
        /// The offending value, s.
        value: f64,
    },
    /// A system time before 1970-01-01T00:00:00Z.
    #[error(
        "system time is {seconds_before} s before the Unix epoch; \
         builtin_interfaces/Time cannot represent it"
    )]
    BeforeUnixEpoch {
        /// How far before the epoch, s.
        seconds_before: f64,
    },
    /// A negative duration cannot become a `std::time::Duration`.
    #[error(
        "builtin_interfaces/Duration of {sec} s + {nanosec} ns is negative; \
         std::time::Duration cannot represent it"
    )]
    NegativeDuration {
        /// The `sec` field.
        sec: i32,
        /// The `nanosec` field.
        nanosec: u32,
    },
    /// A line of an interface definition file is invalid.
    #[error("{file}:{line}: {reason} (line: `{text}`)")]
    Idl {
        /// Name of the file or text being parsed.
        file: String,
        /// 1-based line number; 0 when the package or interface name is wrong.
        line: usize,
        /// The offending line as written.
        text: String,
        /// What is wrong with it.
        reason: String,
    },
    /// The `---` separators of a service or action file are wrong.
    #[error("{file}: a {kind} definition needs exactly {expected} `---` separator line(s), found {found}")]
    IdlSeparators {
        /// Name of the file or text being parsed.
        file: String,
        /// `"srv"` or `"action"`.
        kind: &'static str,
        /// Separators required.
        expected: usize,
        /// Separators found.
        found: usize,
    },
}
