//! The one error type of `kerf_chatter`.

use thiserror::Error;

/// Everything that can go wrong in a chatter computation.
///
/// Every variant names the offending quantity so that a planner can pass the
/// message on to its user unchanged.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ChatterError {
    /// A parameter is NaN, infinite or outside its physical range.
    #[error("invalid {name} = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name, with its unit (e.g. "spindle speed [rpm]").
        name: String,
        /// The value given.
        value: f64,
        /// Why it is refused (e.g. "must be > 0").
        reason: String,
    },
    /// An iterative method stopped at its iteration cap before converging.
    #[error("{what} did not converge in {iterations} iterations (residual {residual:e})")]
    NotConverged {
        /// What was being computed (e.g. "spectral radius (Arnoldi)").
        what: String,
        /// The iteration cap that was reached.
        iterations: usize,
        /// The last residual (NaN is reported as is, never passed on as a result).
        residual: f64,
    },
    /// A computation produced NaN or an infinity.
    #[error("non-finite result in {what}")]
    NonFinite {
        /// Where it appeared.
        what: String,
    },
    /// Inconsistent sizes or a model outside what the method supports.
    #[error("unsupported model: {reason}")]
    Unsupported {
        /// What is unsupported.
        reason: String,
    },
    /// A computation over a grid of spindle speeds (a lobe, a feed map,
    /// [`crate::lobe_map`]) failed: which one, at which speed when one
    /// speed failed, and why.
    #[error("{what}: {}{reason}", at_speed(.rpm))]
    Grid {
        /// The computation (e.g. "constant-delay lobes").
        what: String,
        /// The spindle speed [rpm] that failed, if one did.
        rpm: Option<f64>,
        /// The failure's message.
        reason: String,
    },
}

/// "3000 rpm: " or "" for [`ChatterError::Grid`].
fn at_speed(rpm: &Option<f64>) -> String {
    rpm.map_or(String::new(), |r| format!("{r} rpm: "))
}

impl ChatterError {
    /// [`ChatterError::InvalidParameter`] from borrowed parts.
    pub fn invalid(name: &str, value: f64, reason: &str) -> Self {
        Self::InvalidParameter {
            name: name.to_string(),
            value,
            reason: reason.to_string(),
        }
    }
}

/// Checks that `value` is finite and strictly positive.
///
/// # Errors
/// [`ChatterError::InvalidParameter`] naming `name`.
pub fn check_positive(name: &str, value: f64) -> Result<f64, ChatterError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(ChatterError::InvalidParameter {
            name: name.to_string(),
            value,
            reason: "must be finite and > 0".to_string(),
        })
    }
}

/// Checks that `value` is finite and ≥ 0.
///
/// # Errors
/// [`ChatterError::InvalidParameter`] naming `name`.
pub fn check_non_negative(name: &str, value: f64) -> Result<f64, ChatterError> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(ChatterError::InvalidParameter {
            name: name.to_string(),
            value,
            reason: "must be finite and >= 0".to_string(),
        })
    }
}
