//! The one error type of `kerf_stepping`.

use thiserror::Error;

/// Everything that can go wrong when stepping through reference points.
///
/// Every variant names the offending quantity, so that a command or a node
/// can pass the message on unchanged.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum StepError {
    /// A parameter (limit, precision, period, setting) is NaN, infinite or
    /// outside its range.
    #[error("invalid {name} = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name with its unit (e.g. "precision [m]").
        name: String,
        /// The value given.
        value: f64,
        /// Why it is refused.
        reason: String,
    },
    /// A reference point is unusable (NaN, repeated, out of order, out of
    /// reach, wrong number of coordinates).
    #[error("reference point {index}: {reason}")]
    InvalidPoint {
        /// Index of the point (0 = the start).
        index: usize,
        /// Why it is refused.
        reason: String,
    },
    /// No action keeps the motion able to pass the next point within its
    /// precision: the controller's guarantee (module `rpro`) was broken by
    /// the state it was given.
    #[error("step {step}: no action can still pass point {point} within its precision ({reason})")]
    NoViableAction {
        /// The control step.
        step: usize,
        /// The next point to pass.
        point: usize,
        /// What was found.
        reason: String,
    },
    /// A controller asked for a motion outside the limits (an agent without
    /// a shield), or the motion passed a point outside its precision.
    #[error("step {step}: {reason}")]
    Violation {
        /// The control step.
        step: usize,
        /// The limit or point that was violated.
        reason: String,
    },
    /// The run reached its step cap before coming to rest on the last point.
    #[error("no rest on the last point within {max_steps} steps (point {point} of {points} next)")]
    StepCap {
        /// The cap.
        max_steps: usize,
        /// The next point to pass when the cap was reached.
        point: usize,
        /// Number of points.
        points: usize,
    },
    /// The Ruckig solver (module `ruckig_ref`) refused or failed a section
    /// of the reference trajectory.
    #[error("Ruckig reference, section {section} (toward point {}): {reason}", section + 1)]
    Ruckig {
        /// Index of the section (0 = from the start to point 1).
        section: usize,
        /// Ruckig's message or result code.
        reason: String,
    },
    /// A network file or a learned model cannot be used.
    #[error("network: {reason}")]
    Network {
        /// Why.
        reason: String,
    },
}

/// `Err(InvalidParameter)` unless `value` is finite and > 0.
pub(crate) fn check_positive(name: &str, value: f64) -> Result<(), StepError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(StepError::InvalidParameter {
            name: name.to_string(),
            value,
            reason: "must be finite and > 0".to_string(),
        })
    }
}
