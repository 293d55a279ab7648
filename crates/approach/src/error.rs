//! The one error type of `kerf_approach`.

use crate::{Boundary, Role, Route, Violation};

/// Everything that can go wrong building, checking or stitching an approach or a retract.
///
/// Every bad input is refused with one of these; nothing is clamped or dropped silently, and
/// no input makes the crate panic.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ApproachError {
    /// A setting is out of its range.
    #[error("setting {field} = {value}: {requirement}")]
    InvalidSetting {
        /// The setting (with an index for a list, e.g. `lipschitz[2]`).
        field: String,
        /// The value given.
        value: f64,
        /// What it must be.
        requirement: &'static str,
    },
    /// A required setting was not given to the builder.
    #[error("setting {field} is required")]
    MissingSetting {
        /// The setting.
        field: &'static str,
    },
    /// The robot has no joints.
    #[error("the robot needs at least one joint")]
    NoJoints,
    /// A joint limit is not valid.
    #[error("joint '{joint}': {field} = {value} {requirement}")]
    InvalidJointLimit {
        /// The joint.
        joint: String,
        /// The limit field.
        field: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        requirement: &'static str,
    },
    /// A list has a different length than the robot has joints.
    #[error("{what}: {found} values for {expected} joints")]
    JointCount {
        /// The list (a configuration, a setting).
        what: String,
        /// The robot's joint count.
        expected: usize,
        /// The list's length.
        found: usize,
    },
    /// A joint position is NaN or infinite.
    #[error("{role}: joint '{joint}' position {value} is not finite")]
    NonFinitePosition {
        /// Which configuration.
        role: Role,
        /// The joint.
        joint: String,
        /// The position.
        value: f64,
    },
    /// A joint position is outside the joint's position limits.
    #[error("{role}: joint '{joint}' position {value} is outside its limits [{min}, {max}]")]
    OutOfLimits {
        /// Which configuration.
        role: Role,
        /// The joint.
        joint: String,
        /// The position.
        value: f64,
        /// The lower limit.
        min: f64,
        /// The upper limit.
        max: f64,
    },
    /// The start (or the goal, or the retract start) is already closer to an obstacle than
    /// the clearance.
    #[error("{role} is {distance} m from '{obstacle}', inside the clearance {clearance} m")]
    InCollision {
        /// Which configuration.
        role: Role,
        /// The nearest obstacle.
        obstacle: String,
        /// Its distance (m).
        distance: f64,
        /// The clearance (m).
        clearance: f64,
    },
    /// The clearance function answered NaN.
    #[error(
        "the clearance function returned NaN (obstacle '{obstacle}') at q = {configuration:?}"
    )]
    InvalidClearance {
        /// The obstacle it named.
        obstacle: String,
        /// The configuration asked about.
        configuration: Vec<f64>,
    },
    /// Neither the direct move nor any move via a safe pose is clear.
    #[error("no collision-free approach: {direct}{}", via_list(.via))]
    NoApproach {
        /// Why the direct move failed.
        direct: Box<Violation>,
        /// Why each move via a safe pose failed, in the order tried.
        via: Vec<Violation>,
    },
    /// The retract is not clear.
    #[error("retract blocked: {violation}")]
    RetractBlocked {
        /// Where and why.
        violation: Box<Violation>,
    },
    /// A move is longer than the settings allow.
    #[error("{route}: duration {duration} s exceeds max_duration {max} s")]
    MoveTooLong {
        /// The move.
        route: Route,
        /// Its duration (s).
        duration: f64,
        /// `max_duration` (s).
        max: f64,
    },
    /// A move's displacement gives an infinite duration (positions far apart on unbounded
    /// joints).
    #[error("{role}: the move to it has a duration that is not finite")]
    NonFiniteDuration {
        /// The move's end.
        role: Role,
    },
    /// A duration asked for is not finite or shorter than the limits allow.
    #[error(
        "duration {duration} s: must be finite and >= the minimum {min} s of the joint limits"
    )]
    InvalidDuration {
        /// The duration asked for (s).
        duration: f64,
        /// The shortest duration meeting every joint's limits (s).
        min: f64,
    },
    /// A sampling period is not finite and > 0.
    #[error("sampling period {period} s must be finite and > 0")]
    InvalidPeriod {
        /// The period (s).
        period: f64,
    },
    /// Sampling a move would take too many samples.
    #[error(
        "sampling {duration} s every {period} s takes about {samples} samples, more than {max}"
    )]
    TooManySamples {
        /// The move's duration (s).
        duration: f64,
        /// The period (s).
        period: f64,
        /// The sample count it would take.
        samples: f64,
        /// [`crate::MAX_SAMPLES`].
        max: usize,
    },
    /// A waypoint move needs a start and an end.
    #[error("a waypoint move needs at least 2 waypoints, got {found}")]
    TooFewWaypoints {
        /// The waypoints given.
        found: usize,
    },
    /// A leg does not start where the previous one ends.
    #[error("leg {leg} does not start where leg {previous} ends")]
    DisconnectedLegs {
        /// The leg (0-based).
        leg: usize,
        /// The leg before it.
        previous: usize,
    },
    /// The tool-axis retract distance is not finite and non-zero.
    #[error("tool-axis retract distance {distance} m must be finite and non-zero")]
    InvalidRetractDistance {
        /// The distance (m).
        distance: f64,
    },
    /// The forward kinematics closure returned a pose that is not finite.
    #[error("forward kinematics returned a pose that is not finite at q = {configuration:?}")]
    NonFinitePose {
        /// The configuration.
        configuration: Vec<f64>,
    },
    /// The inverse kinematics closure found no configuration for the retract pose.
    #[error("inverse kinematics found no configuration {distance} m along the tool axis")]
    IkFailed {
        /// The retract distance (m).
        distance: f64,
    },
    /// The inverse kinematics answer does not reach the retract pose.
    #[error(
        "inverse kinematics answer misses the retract pose by {position_error} m and \
         {rotation_error} rad (tolerances {position_tolerance} m, {rotation_tolerance} rad)"
    )]
    IkMismatch {
        /// Position error of FK(answer) (m).
        position_error: f64,
        /// Rotation error of FK(answer) (rad).
        rotation_error: f64,
        /// [`crate::IK_POSITION_TOLERANCE`].
        position_tolerance: f64,
        /// [`crate::IK_ROTATION_TOLERANCE`].
        rotation_tolerance: f64,
    },
    /// The process has no samples.
    #[error("the process has no samples")]
    EmptyProcess,
    /// A process sample is malformed.
    #[error("process sample {index}: {reason}")]
    InvalidProcess {
        /// The sample (0-based).
        index: usize,
        /// What is wrong.
        reason: String,
    },
    /// The approach, process and retract do not meet.
    #[error("{boundary}: joint {joint} {quantity} jumps by {gap} (tolerance {tolerance})")]
    Discontinuity {
        /// Where.
        boundary: Boundary,
        /// The joint (0-based).
        joint: usize,
        /// `position`, `velocity` or `acceleration`.
        quantity: &'static str,
        /// The jump.
        gap: f64,
        /// The tolerance it exceeds.
        tolerance: f64,
    },
    /// One move of a framed process failed ([`crate::frame`]).
    #[error("{stage}: {source}")]
    InStage {
        /// The move.
        stage: crate::Stage,
        /// Why.
        source: Box<ApproachError>,
    },
}

/// The violations of the moves via safe poses, for [`ApproachError::NoApproach`].
impl ApproachError {
    /// This error, as the failure of `stage` of a framed process.
    pub fn in_stage(self, stage: crate::Stage) -> Self {
        ApproachError::InStage {
            stage,
            source: Box::new(self),
        }
    }

    /// The innermost error (under every [`ApproachError::InStage`]).
    pub fn root(&self) -> &ApproachError {
        match self {
            ApproachError::InStage { source, .. } => source.root(),
            e => e,
        }
    }
}

fn via_list(via: &[Violation]) -> String {
    if via.is_empty() {
        return "; no safe pose configured".into();
    }
    via.iter().map(|v| format!("; {v}")).collect()
}
