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
    /// The time or memory budget ran out, or the work was cancelled (the `_within` variants).
    #[error("{0}")]
    Interrupted(#[from] kerf_budget::Interrupt),
}

/// Checks that each named value is finite and > 0.
///
/// # Errors
/// [`ToolpathError::InvalidParameter`] naming the first that is not.
pub(crate) fn check_positive(values: &[(&str, f64)]) -> Result<(), ToolpathError> {
    match values.iter().find(|(_, v)| !(v.is_finite() && *v > 0.0)) {
        Some((name, v)) => Err(ToolpathError::InvalidParameter {
            name: (*name).to_string(),
            value: *v,
            reason: "must be finite and > 0".to_string(),
        }),
        None => Ok(()),
    }
}
