//! The one error type of `kerf_mill`.

use std::path::PathBuf;

use kerf_bspline::BsplineError;
use kerf_chatter::ChatterError;
use kerf_robot::RobotError;
use thiserror::Error;

/// Everything that can go wrong in the robotic milling model.
///
/// Every variant names the offending quantity (field, joint, segment,
/// redundancy angle) and, where it applies, by how much a bound is exceeded,
/// so that a planner can pass the message on unchanged.
#[derive(Debug, Error)]
pub enum MillError {
    /// A numeric parameter is NaN, infinite or outside its range.
    #[error("invalid {name} = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name with its unit (e.g. "path.segments").
        name: String,
        /// The value given.
        value: f64,
        /// Why it is refused.
        reason: String,
    },
    /// A non-numeric configuration problem (missing field, bad shape).
    #[error("invalid {name}: {reason}")]
    InvalidConfig {
        /// The field at fault.
        name: String,
        /// What is wrong with it.
        reason: String,
    },
    /// The path points do not lie in one plane.
    #[error(
        "path points are not coplanar: point {worst_point} is {distance:.3e} m from the \
         best-fit plane (tolerance {tolerance:.1e} m)"
    )]
    NotCoplanar {
        /// Index of the point farthest from the best-fit plane.
        worst_point: usize,
        /// Its distance from the plane \[m\].
        distance: f64,
        /// The tolerance \[m\].
        tolerance: f64,
    },
    /// The wrist centre of a target lies outside the arm's reach.
    #[error(
        "target unreachable{}: the wrist centre is {distance_beyond_reach:.6} m beyond the \
         reach of the arm",
        context(.segment, .g)
    )]
    Unreachable {
        /// Path segment index, when the target belongs to a path.
        segment: Option<usize>,
        /// Redundancy angle \[rad\], when the target was built from one.
        g: Option<f64>,
        /// Distance \[m\] from the wrist centre to the nearest reachable
        /// wrist-centre position of the shoulder/elbow chain (> 0).
        distance_beyond_reach: f64,
    },
    /// Every inverse-kinematics solution violates a joint limit; the one
    /// closest to being valid is reported.
    #[error(
        "joint limit{}: {joint} = {value:.6} rad is outside [{lower:.6}, {upper:.6}] by \
         {excess:.6} rad",
        context(.segment, .g)
    )]
    JointLimit {
        /// Path segment index, when the target belongs to a path.
        segment: Option<usize>,
        /// Redundancy angle \[rad\], when the target was built from one.
        g: Option<f64>,
        /// Joint name (URDF).
        joint: String,
        /// The joint value of the best solution \[rad\].
        value: f64,
        /// Lower limit \[rad\].
        lower: f64,
        /// Upper limit \[rad\].
        upper: f64,
        /// How far the value lies outside the limits \[rad\] (> 0).
        excess: f64,
    },
    /// A computation produced NaN or an infinity.
    #[error("non-finite value in {what}")]
    NonFinite {
        /// Where it appeared.
        what: String,
    },
    /// A matrix that must be invertible is (numerically) singular.
    #[error("singular matrix: {what}")]
    Singular {
        /// What was being inverted and why it failed.
        what: String,
    },
    /// An iterative method hit its iteration cap.
    #[error("{what} did not converge in {iterations} iterations (residual {residual:e})")]
    NotConverged {
        /// What was being computed.
        what: String,
        /// The cap that was reached.
        iterations: usize,
        /// The last residual.
        residual: f64,
    },
    /// A file could not be read.
    #[error("cannot read {}: {message}", path.display())]
    FileRead {
        /// The file.
        path: PathBuf,
        /// The I/O error message.
        message: String,
    },
    /// The cell YAML is not valid YAML of the expected shape.
    #[error("invalid cell YAML {}: {message}", path.display())]
    Yaml {
        /// The file.
        path: PathBuf,
        /// The parser message (with line and column).
        message: String,
    },
    /// The robot model could not be loaded or evaluated.
    #[error("robot model: {0}")]
    Robot(#[from] RobotError),
    /// The B-spline fit failed.
    #[error("milling path B-spline: {0}")]
    Bspline(#[from] BsplineError),
    /// A chatter-model type rejected its parameters.
    #[error("chatter model: {0}")]
    Chatter(#[from] ChatterError),
}

/// " (segment 3, g = 0.500 rad)" or "" for the error messages.
fn context(segment: &Option<usize>, g: &Option<f64>) -> String {
    match (segment, g) {
        (Some(s), Some(g)) => format!(" (segment {s}, g = {g:.4} rad)"),
        (Some(s), None) => format!(" (segment {s})"),
        (None, Some(g)) => format!(" (g = {g:.4} rad)"),
        (None, None) => String::new(),
    }
}

/// Checks that `value` is finite (and returns it).
///
/// # Errors
/// [`MillError::InvalidParameter`] naming `name`.
pub(crate) fn check_finite(name: &str, value: f64) -> Result<f64, MillError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(MillError::InvalidParameter {
            name: name.to_string(),
            value,
            reason: "must be finite".to_string(),
        })
    }
}

/// Checks that `value` is finite and > 0 (and returns it).
///
/// # Errors
/// [`MillError::InvalidParameter`] naming `name`.
pub(crate) fn check_positive(name: &str, value: f64) -> Result<f64, MillError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(MillError::InvalidParameter {
            name: name.to_string(),
            value,
            reason: "must be finite and > 0".to_string(),
        })
    }
}

impl MillError {
    /// Attaches a path segment index and a redundancy angle to an
    /// [`MillError::Unreachable`] or [`MillError::JointLimit`] error (other
    /// variants are returned unchanged).
    pub fn with_context(self, segment: Option<usize>, g: Option<f64>) -> Self {
        match self {
            MillError::Unreachable {
                distance_beyond_reach,
                ..
            } => MillError::Unreachable {
                segment,
                g,
                distance_beyond_reach,
            },
            MillError::JointLimit {
                joint,
                value,
                lower,
                upper,
                excess,
                ..
            } => MillError::JointLimit {
                segment,
                g,
                joint,
                value,
                lower,
                upper,
                excess,
            },
            other => other,
        }
    }
}
