//! The one error type of the crate.

use thiserror::Error;

/// Everything that can go wrong when building or using a B-spline.
///
/// Every variant names the offending quantity so that a caller (e.g. the MJTO
/// planner) can turn it into a message for the cell engineer.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum BsplineError {
    /// A clamped B-spline of degree `degree` needs at least `degree + 1`
    /// coefficients.
    #[error("{n_coeffs} coefficients are too few for a B-spline of degree {degree} (at least degree + 1 = {} are needed)", degree + 1)]
    TooFewCoefficients {
        /// Number of coefficients asked for.
        n_coeffs: usize,
        /// Degree k of the spline.
        degree: usize,
    },
    /// A parameter lies outside the normalized domain [0, 1] (by more than
    /// 1e-12).
    #[error("parameter u = {u} is outside [0, 1]")]
    ParameterOutOfRange {
        /// The offending parameter.
        u: f64,
    },
    /// A NaN or an infinity where a finite number is required.
    #[error("{what} is not finite")]
    NotFinite {
        /// Which value, with its index where it applies.
        what: String,
    },
    /// A linear system has no (unique) solution.
    #[error("singular system: {detail}")]
    Singular {
        /// Which matrix, which pivot, and the likely cause.
        detail: String,
    },
    /// Two inputs that must have the same length do not.
    #[error("{what}: expected length {expected}, got {got}")]
    LengthMismatch {
        /// Which input.
        what: String,
        /// The required length.
        expected: usize,
        /// The length given.
        got: usize,
    },
    /// Interior knots are not strictly increasing inside (0, 1).
    #[error("invalid knot vector: {detail}")]
    InvalidKnots {
        /// Which knot and why.
        detail: String,
    },
    /// A derivative order above the degree was asked for where it has no
    /// meaning (e.g. a derivative operator of order r > k).
    #[error("derivative order {order} exceeds the degree {degree}")]
    DerivativeOrderTooHigh {
        /// Requested order r.
        order: usize,
        /// Degree k of the spline.
        degree: usize,
    },
    /// The degree is too low for the requested quantity (e.g. a jerk
    /// Hessian needs k >= 3).
    #[error("degree {degree} is too low: at least {required} is needed")]
    DegreeTooLow {
        /// Degree k of the spline.
        degree: usize,
        /// Minimum degree required.
        required: usize,
    },
    /// A least-squares fit needs at least as many points as coefficients.
    #[error("{n_points} data points are too few to fit {n_coeffs} coefficients")]
    TooFewPoints {
        /// Number of data points.
        n_points: usize,
        /// Number of coefficients.
        n_coeffs: usize,
    },
}

/// Tolerance by which a parameter may leave [0, 1] and still be accepted
/// (it is then clamped).
pub const PARAM_TOLERANCE: f64 = 1e-12;

/// Check that `u` is finite and in [0, 1] (within [`PARAM_TOLERANCE`]);
/// return it clamped to [0, 1].
///
/// # Errors
/// [`BsplineError::NotFinite`] for NaN or infinity,
/// [`BsplineError::ParameterOutOfRange`] outside [-1e-12, 1 + 1e-12].
pub fn check_param(u: f64) -> Result<f64, BsplineError> {
    if !u.is_finite() {
        return Err(BsplineError::NotFinite {
            what: format!("parameter u = {u}"),
        });
    }
    if !(-PARAM_TOLERANCE..=1.0 + PARAM_TOLERANCE).contains(&u) {
        return Err(BsplineError::ParameterOutOfRange { u });
    }
    Ok(u.clamp(0.0, 1.0))
}

/// Check that every value of `values` is finite.
///
/// # Errors
/// [`BsplineError::NotFinite`] naming `what` and the first bad index.
pub fn check_finite(what: &str, values: &[f64]) -> Result<(), BsplineError> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(BsplineError::NotFinite {
            what: format!(
                "{what}[{i}] = {}",
                values.get(i).copied().unwrap_or(f64::NAN)
            ),
        }),
        None => Ok(()),
    }
}
