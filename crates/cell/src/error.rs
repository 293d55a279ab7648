//! The one error type of `kerf_cell`.

use std::path::PathBuf;

/// Everything that can go wrong building or stepping a simulated cell.
///
/// Every bad input is refused with one of these; nothing is clamped or dropped silently.
#[derive(Debug, thiserror::Error)]
pub enum CellError {
    /// A file could not be read.
    #[error("cannot read {path}: {reason}")]
    FileRead {
        /// The file.
        path: PathBuf,
        /// Why (the I/O error).
        reason: String,
    },
    /// The URDF or its joint limits could not be loaded by `kerf_robot`.
    #[error("robot model: {reason}")]
    Robot {
        /// `kerf_robot`'s message.
        reason: String,
    },
    /// A cell file or inertia sidecar is not valid YAML of the expected shape.
    #[error("{path}: not a valid {what}: {reason}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// What it should have been ("cell file", "inertia file").
        what: &'static str,
        /// The parser's message.
        reason: String,
    },
    /// A scene object names a mesh file that does not exist.
    #[error("scene object '{object}': mesh file {path} does not exist")]
    MissingMesh {
        /// The scene object.
        object: String,
        /// The resolved path of the mesh.
        path: PathBuf,
    },
    /// A mesh file exists but cannot be used.
    #[error("scene object '{object}': mesh {path}: {reason}")]
    BadMesh {
        /// The scene object.
        object: String,
        /// The mesh file.
        path: PathBuf,
        /// The parser's or parry's message.
        reason: String,
    },
    /// A movable joint's URDF `<limit effort>` is not finite and > 0.
    #[error("joint '{joint}': effort limit {effort} must be finite and > 0")]
    EffortLimit {
        /// The joint.
        joint: String,
        /// The effort limit found (N or N·m).
        effort: f64,
    },
    /// A link that moves has no mass in the inertia sidecar, or an invalid one.
    #[error("link '{link}': {reason}")]
    Inertia {
        /// The link.
        link: String,
        /// What is wrong.
        reason: String,
    },
    /// The physics rate is not a positive integer multiple of the control rate.
    #[error(
        "physics rate {physics_hz} Hz is not an integer multiple of the control rate \
         {control_hz} Hz (ratio {ratio})"
    )]
    RateRatio {
        /// Physics rate (Hz).
        physics_hz: f64,
        /// Control rate (Hz).
        control_hz: f64,
        /// `physics_hz / control_hz`.
        ratio: f64,
    },
    /// A numeric setting or cell-file value is out of its range.
    #[error("{field} = {value}: {requirement}")]
    InvalidValue {
        /// The setting or field.
        field: String,
        /// The value given.
        value: f64,
        /// What it must be.
        requirement: &'static str,
    },
    /// A cell file refers to something that does not exist or contradicts the robot.
    #[error("cell file {path}: {reason}")]
    CellFile {
        /// The cell file (or `<memory>`).
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// A command or joint-name list does not have the robot's joints.
    #[error("{what}: {reason} (the robot's joints are {expected})")]
    JointMismatch {
        /// What was checked ("command positions", "joint names").
        what: &'static str,
        /// The mismatch.
        reason: String,
        /// The URDF's movable joints, comma-separated.
        expected: String,
    },
    /// A command value is NaN or infinite.
    #[error("{what}[{joint}] = {value} is not finite")]
    NonFinite {
        /// The field ("command positions", ...).
        what: &'static str,
        /// The joint name.
        joint: String,
        /// The value.
        value: f64,
    },
    /// The control period passed to `step` is not the configured one.
    #[error("step dt {dt} s differs from the configured control period {expected} s")]
    ControlPeriod {
        /// The period given (s).
        dt: f64,
        /// The configured period (s).
        expected: f64,
    },
}
