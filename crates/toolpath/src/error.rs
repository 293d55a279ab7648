//! [`ToolpathError`].

use thiserror::Error;

/// Why a tool path could not be smoothed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ToolpathError {
    /// A parameter is out of range.
    #[error("{name} = {value}: {reason}")]
    InvalidParameter {
        /// The parameter, with its unit.
        name: String,
        /// Its value.
        value: f64,
        /// The rule it breaks.
        reason: String,
    },
    /// A point of the path is not finite, or two consecutive points
    /// coincide.
    #[error("point {index}: {reason}")]
    BadPoint {
        /// Index of the point.
        index: usize,
        /// What is wrong.
        reason: String,
    },
}
