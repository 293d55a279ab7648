//! [`GcodePlanError`]: every way a program can fail to become a trajectory.

use kerf_budget::Interrupt;
use kerf_gcode::GcodeError;
use kerf_toolpath::ToolpathError;
use thiserror::Error;

/// Why a program was not planned.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum GcodePlanError {
    /// The program is not valid G-code, or uses what the reader refuses
    /// (its line and column are in the message).
    #[error("program: {0}")]
    Program(#[from] GcodeError),
    /// A setting of the plan is out of range.
    #[error("setting {name} = {value}: {reason}")]
    InvalidSetting {
        /// The setting, with its unit.
        name: String,
        /// Its value.
        value: f64,
        /// The rule it breaks.
        reason: String,
    },
    /// A field of a request is bad (not a number: a name, a file, a machine).
    #[error("{field}: {reason}")]
    InvalidRequest {
        /// The field.
        field: String,
        /// What is wrong.
        reason: String,
    },
    /// The path of a run could not be smoothed or timed.
    #[error("line {line}: {error}")]
    Path {
        /// First source line of the run.
        line: usize,
        /// What the tool path library said.
        error: ToolpathError,
    },
    /// A point of the program is outside what the machine reaches.
    #[error("line {line}: the machine cannot reach [{x:.6}, {y:.6}, {z:.6}] m (program frame): {reason}")]
    Unreachable {
        /// Source line of the motion.
        line: usize,
        /// x \[m\].
        x: f64,
        /// y \[m\].
        y: f64,
        /// z \[m\].
        z: f64,
        /// The kinematics' reason.
        reason: String,
    },
    /// An arc of the program cannot be approximated by chords within the plan's settings:
    /// it needs more chords than the points allowed, or the settings leave no tolerance for
    /// them.
    #[error("line {line}: {reason}")]
    Arc {
        /// Source line of the arc.
        line: usize,
        /// What is wrong, with the numbers.
        reason: String,
    },
    /// The program has no motion to plan.
    #[error("no motion: {reason}")]
    Empty {
        /// Why.
        reason: String,
    },
    /// The trajectory needs more points than allowed.
    #[error("the trajectory needs more than {max} points (raise max_points or split the program)")]
    TooManyPoints {
        /// The most allowed.
        max: usize,
    },
    /// The time budget ran out or the planner is stopping.
    #[error("{0}")]
    Interrupted(#[from] Interrupt),
    /// The executor would refuse the trajectory, or it leaves the tolerance
    /// as executed: a defect of the planner, reported rather than published.
    #[error("the trajectory is not executable: {reason}")]
    NotExecutable {
        /// The first source line of the run at fault (0 when no run is named).
        line: usize,
        /// Why.
        reason: String,
    },
}

impl GcodePlanError {
    /// The program line the error is tied to (1-based; 0 when none): the reader's line for
    /// [`GcodePlanError::Program`] (lexer, interpreter, arc, line limit), the motion's for
    /// [`GcodePlanError::Arc`] and [`GcodePlanError::Unreachable`], the run's first line for
    /// [`GcodePlanError::Path`] and [`GcodePlanError::NotExecutable`].
    pub fn line(&self) -> usize {
        match self {
            Self::Program(e) => e.line(),
            Self::Path { line, .. }
            | Self::Unreachable { line, .. }
            | Self::Arc { line, .. }
            | Self::NotExecutable { line, .. } => *line,
            Self::InvalidSetting { .. }
            | Self::InvalidRequest { .. }
            | Self::Empty { .. }
            | Self::TooManyPoints { .. }
            | Self::Interrupted(_) => 0,
        }
    }
}

/// Checks that each named value is finite and > 0.
///
/// # Errors
/// [`GcodePlanError::InvalidSetting`] naming the first that is not.
pub(crate) fn check_positive(values: &[(&str, f64)]) -> Result<(), GcodePlanError> {
    match values.iter().find(|(_, v)| !(v.is_finite() && *v > 0.0)) {
        Some((name, v)) => Err(GcodePlanError::InvalidSetting {
            name: (*name).to_string(),
            value: *v,
            reason: "must be finite and > 0".to_string(),
        }),
        None => Ok(()),
    }
}

/// A tool path error of the run starting at `line`: the budget's interruption as itself
/// ([`GcodePlanError::Interrupted`], whose status is TIMEOUT or RESOURCE_LIMIT), anything else
/// as [`GcodePlanError::Path`].
pub(crate) fn path(line: usize, error: ToolpathError) -> GcodePlanError {
    match error {
        // What grew is named with the run it grew in.
        ToolpathError::Interrupted(Interrupt::OverMemory {
            limit,
            needed,
            what,
        }) if line > 0 => GcodePlanError::Interrupted(Interrupt::OverMemory {
            limit,
            needed,
            what: format!("the run from line {line}: {what}"),
        }),
        ToolpathError::Interrupted(i) => GcodePlanError::Interrupted(i),
        error => GcodePlanError::Path { line, error },
    }
}

/// A limit the tool path library refused, as a setting.
pub(crate) fn setting(error: ToolpathError) -> GcodePlanError {
    match error {
        ToolpathError::InvalidParameter {
            name,
            value,
            reason,
        } => GcodePlanError::InvalidSetting {
            name: format!("limits: {name}"),
            value,
            reason,
        },
        other => path(0, other),
    }
}
