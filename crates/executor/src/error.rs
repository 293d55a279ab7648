//! The one error type of this crate and the `control_msgs/FollowJointTrajectory` result codes.

use thiserror::Error;

/// `control_msgs/action/FollowJointTrajectory` result code: the goal succeeded.
pub const SUCCESSFUL: i32 = 0;
/// `control_msgs/action/FollowJointTrajectory` result code: the goal is malformed or infeasible.
pub const INVALID_GOAL: i32 = -1;
/// `control_msgs/action/FollowJointTrajectory` result code: unknown, duplicated or missing joints.
pub const INVALID_JOINTS: i32 = -2;
/// `control_msgs/action/FollowJointTrajectory` result code: the header stamp is too old.
pub const OLD_HEADER_TIMESTAMP: i32 = -3;
/// `control_msgs/action/FollowJointTrajectory` result code: a path tolerance was violated.
pub const PATH_TOLERANCE_VIOLATED: i32 = -4;
/// `control_msgs/action/FollowJointTrajectory` result code: the goal tolerance was not reached.
pub const GOAL_TOLERANCE_VIOLATED: i32 = -5;

/// Everything that can go wrong in this crate.
///
/// Every message names what is wrong: the joint, the point index, the time and the value
/// against its limit. [`ExecutorError::error_code`] maps each variant to a
/// `control_msgs/FollowJointTrajectory` result code.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ExecutorError {
    // ----- robot model and configuration -------------------------------------------------
    /// The robot model has no joints.
    #[error("the robot model has no joints")]
    NoJoints,
    /// A joint limit is invalid (NaN, non-positive velocity/acceleration limit, empty range).
    #[error("joint '{joint}': invalid limit {field} = {value}: {requirement}")]
    InvalidJointLimit {
        /// Joint name.
        joint: String,
        /// Name of the offending [`crate::JointLimits`] field.
        field: &'static str,
        /// The offending value.
        value: f64,
        /// What the value must satisfy.
        requirement: &'static str,
    },
    /// Two joints of the robot model have the same name.
    #[error("joint '{joint}' appears twice in the robot model")]
    DuplicateModelJoint {
        /// Joint name.
        joint: String,
    },
    /// An [`crate::ExecutorConfig`] value is invalid.
    #[error("invalid executor configuration: {field} = {value}: {requirement}")]
    InvalidConfig {
        /// Name of the offending field.
        field: String,
        /// The offending value.
        value: f64,
        /// What the value must satisfy.
        requirement: &'static str,
    },
    /// A joint sample (initial, current or measured state) has the wrong number of values.
    #[error(
        "{what}: {field} has {actual} values, expected {expected} (one per joint{empty_note})"
    )]
    StateLength {
        /// Which state ("initial positions", "measured state", ...).
        what: &'static str,
        /// Which field ("positions", "velocities", "accelerations").
        field: &'static str,
        /// Number of values given.
        actual: usize,
        /// Number of joints.
        expected: usize,
        /// ", or none" when the field may be empty.
        empty_note: &'static str,
    },
    /// A joint sample contains NaN or an infinity.
    #[error("{what}: {field} of joint '{joint}' is {value}, must be finite")]
    NonFiniteState {
        /// Which state.
        what: &'static str,
        /// Which field.
        field: &'static str,
        /// Joint name.
        joint: String,
        /// The offending value.
        value: f64,
    },
    /// A joint of a state is outside its position limits.
    #[error("{what}: position of joint '{joint}' is {value}, outside its limits [{min}, {max}]")]
    StateOutOfLimits {
        /// Which state.
        what: &'static str,
        /// Joint name.
        joint: String,
        /// The position.
        value: f64,
        /// Lower position limit.
        min: f64,
        /// Upper position limit.
        max: f64,
    },
    /// A joint name appears twice in a named state (a `sensor_msgs/JointState`).
    #[error("{what}: joint '{joint}' appears twice in the joint names")]
    StateDuplicateJoint {
        /// Which state.
        what: &'static str,
        /// The duplicated name.
        joint: String,
    },
    /// Joints of the robot are missing from a named state.
    #[error("{what}: no value for joint(s) [{missing}]; every joint of the robot is required")]
    StateMissingJoints {
        /// Which state.
        what: &'static str,
        /// The missing joint names, comma-separated.
        missing: String,
    },
    /// The driver's feedback is stale: no new state for longer than the watchdog allows.
    #[error(
        "feedback stale: no new joint state for {age} s (the watchdog allows {limit} s: {missed} control periods)"
    )]
    FeedbackStale {
        /// Time since the last state (s), or since the watchdog started when none came.
        age: f64,
        /// The allowed gap (s).
        limit: f64,
        /// The allowed number of missed periods.
        missed: u32,
    },
    /// The driver's feedback went back in time (its stamp is older than the previous one).
    #[error("feedback stamp went back: {got} s after {previous} s")]
    FeedbackStampBack {
        /// The previous stamp (s).
        previous: f64,
        /// The new stamp (s).
        got: f64,
    },
    /// The hold cannot move to a measured state while a goal is active or the reference moves.
    #[error(
        "cannot hold at the measured state at t = {time} s: a goal is active or the reference is still moving"
    )]
    HoldWhileMoving {
        /// The time of the request (s).
        time: f64,
    },
    /// A time argument is NaN or infinite.
    #[error("{what} is {value} s, must be finite")]
    NonFiniteTime {
        /// Which time argument.
        what: &'static str,
        /// The value.
        value: f64,
    },
    /// [`crate::Executor::update`] was called with a time earlier than the previous call.
    #[error("time went backwards: update at t = {now} s after an update at t = {last} s")]
    TimeWentBackwards {
        /// Time of this call.
        now: f64,
        /// Time of the previous update.
        last: f64,
    },

    // ----- trajectory structure ---------------------------------------------------------
    /// The trajectory names no joints.
    #[error("the trajectory has no joint names")]
    NoJointNames,
    /// The trajectory has no points.
    #[error("the trajectory has no points")]
    EmptyTrajectory,
    /// A joint name of the trajectory is not a joint of the robot.
    #[error("unknown joint '{joint}' in the trajectory; the robot's joints are [{known}]")]
    UnknownJoint {
        /// The unknown name.
        joint: String,
        /// The robot's joint names, comma-separated.
        known: String,
    },
    /// A joint name appears twice in the trajectory.
    #[error("joint '{joint}' appears twice in the trajectory's joint names")]
    DuplicateJoint {
        /// The duplicated name.
        joint: String,
    },
    /// Joints of the robot are missing from the trajectory (partial goals are not allowed).
    #[error(
        "the trajectory does not command joint(s) [{missing}]; all joints of the robot are required (partial goals are not allowed)"
    )]
    MissingJoints {
        /// The missing joint names, comma-separated.
        missing: String,
    },
    /// `time_from_start` of a point is negative or not finite.
    #[error("point {index}: time_from_start = {time} s, must be finite and >= 0")]
    InvalidTimeFromStart {
        /// Point index.
        index: usize,
        /// The value.
        time: f64,
    },
    /// `time_from_start` is not strictly increasing.
    #[error(
        "point {index}: time_from_start = {time} s is not after point {previous_index} at {previous} s; times must strictly increase"
    )]
    NonIncreasingTime {
        /// Point index.
        index: usize,
        /// Its time_from_start.
        time: f64,
        /// Index of the previous point.
        previous_index: usize,
        /// Time_from_start of the previous point.
        previous: f64,
    },
    /// An array of a point has the wrong length.
    #[error("point {index}: {field} has {actual} values, expected {expected}{empty_note}")]
    WrongLength {
        /// Point index.
        index: usize,
        /// Field name.
        field: &'static str,
        /// Given length.
        actual: usize,
        /// Number of joint names.
        expected: usize,
        /// " or none" when the field may be empty.
        empty_note: &'static str,
    },
    /// A point gives accelerations but no velocities.
    #[error("point {index}: accelerations are given without velocities")]
    AccelerationsWithoutVelocities {
        /// Point index.
        index: usize,
    },
    /// A point commands effort, which this executor cannot.
    #[error(
        "point {index}: effort is given, but the executor has no effort command interface (position/velocity/acceleration only)"
    )]
    EffortNotSupported {
        /// Point index.
        index: usize,
    },
    /// A value of a point is NaN or infinite.
    #[error("point {index}: {field} of joint '{joint}' is {value}, must be finite")]
    NonFiniteValue {
        /// Point index.
        index: usize,
        /// Field name.
        field: &'static str,
        /// Joint name.
        joint: String,
        /// The value.
        value: f64,
    },
    /// The last point has a non-zero velocity or acceleration.
    #[error(
        "last point {index}: {field} of joint '{joint}' is {value}, must be 0 (a trajectory must end at rest)"
    )]
    NonZeroFinalState {
        /// Point index.
        index: usize,
        /// "velocity" or "acceleration".
        field: &'static str,
        /// Joint name.
        joint: String,
        /// The value.
        value: f64,
    },

    // ----- timing -----------------------------------------------------------------------
    /// The start time (header stamp) is not finite.
    #[error("start time (header stamp) is {value} s, must be finite")]
    InvalidStartTime {
        /// The value.
        value: f64,
    },
    /// The start time lies so far in the past that the first point is already due.
    #[error(
        "start time {start_time} s is in the past and the first point was due at {first_point_time} s, not after now = {now} s"
    )]
    OldHeaderTimestamp {
        /// Requested start time.
        start_time: f64,
        /// Absolute time of the first point.
        first_point_time: f64,
        /// Current time.
        now: f64,
    },
    /// The first point is due at the start time but is not at the current commanded position.
    #[error(
        "point 0 is due at the start time but joint '{joint}' is at {current}, the point at {first} (difference {difference} > start tolerance {tolerance}); give the first point a time_from_start > 0 to move there"
    )]
    StartMismatch {
        /// Joint name.
        joint: String,
        /// Current commanded position.
        current: f64,
        /// Position of the first point.
        first: f64,
        /// |first − current|.
        difference: f64,
        /// The configured start tolerance.
        tolerance: f64,
    },

    // ----- limits on the interpolated curve -------------------------------------------
    /// A position limit is exceeded on the interpolated curve.
    #[error(
        "joint '{joint}': position {value} at t = {time} s ({location}) is outside the limits [{min}, {max}]"
    )]
    PositionLimit {
        /// Joint name.
        joint: String,
        /// Where: "point 3", "between point 2 and point 3", "start segment (current state → point 0)".
        location: String,
        /// Absolute time of the worst value.
        time: f64,
        /// Worst position.
        value: f64,
        /// Lower limit.
        min: f64,
        /// Upper limit.
        max: f64,
    },
    /// The velocity limit is exceeded on the interpolated curve.
    #[error(
        "joint '{joint}': velocity {value} at t = {time} s ({location}) exceeds the limit {limit}"
    )]
    VelocityLimit {
        /// Joint name.
        joint: String,
        /// Where.
        location: String,
        /// Absolute time of the worst value.
        time: f64,
        /// Worst velocity (signed).
        value: f64,
        /// Velocity limit.
        limit: f64,
    },
    /// The acceleration limit is exceeded on the interpolated curve.
    #[error(
        "joint '{joint}': acceleration {value} at t = {time} s ({location}) exceeds the limit {limit}"
    )]
    AccelerationLimit {
        /// Joint name.
        joint: String,
        /// Where.
        location: String,
        /// Absolute time of the worst value.
        time: f64,
        /// Worst acceleration (signed).
        value: f64,
        /// Acceleration limit.
        limit: f64,
    },
    /// A velocity discontinuity, commanded within one control period, exceeds the acceleration limit.
    #[error(
        "joint '{joint}': velocity steps from {from} to {to} at t = {time} s ({location}); commanded within one control period of {period} s that is an acceleration of {acceleration}, over the limit {limit}"
    )]
    VelocityStep {
        /// Joint name.
        joint: String,
        /// Where.
        location: String,
        /// Absolute time of the step.
        time: f64,
        /// Velocity before the step.
        from: f64,
        /// Velocity after the step.
        to: f64,
        /// Control period (s).
        period: f64,
        /// |to − from| / period.
        acceleration: f64,
        /// Acceleration limit.
        limit: f64,
    },

    // ----- tolerances -------------------------------------------------------------------
    /// A tolerance names a joint the robot does not have.
    #[error("{kind} tolerance for unknown joint '{joint}'; the robot's joints are [{known}]")]
    UnknownToleranceJoint {
        /// "path" or "goal".
        kind: &'static str,
        /// The unknown name.
        joint: String,
        /// The robot's joint names, comma-separated.
        known: String,
    },
    /// A joint appears twice in one tolerance list.
    #[error("{kind} tolerance for joint '{joint}' is given twice")]
    DuplicateToleranceJoint {
        /// "path" or "goal".
        kind: &'static str,
        /// Joint name.
        joint: String,
    },
    /// A tolerance value is invalid.
    #[error(
        "{kind} tolerance of joint '{joint}': {field} = {value} is invalid (0 = default, -1 = no tolerance, > 0 = tolerance)"
    )]
    InvalidTolerance {
        /// "path" or "goal".
        kind: &'static str,
        /// Joint name.
        joint: String,
        /// "position", "velocity" or "acceleration".
        field: &'static str,
        /// The value.
        value: f64,
    },
    /// The goal time tolerance is negative or not finite.
    #[error("goal_time_tolerance = {value} s is invalid, must be finite and >= 0 (0 = default)")]
    InvalidGoalTime {
        /// The value.
        value: f64,
    },

    // ----- execution --------------------------------------------------------------------
    /// The goal to cancel is not the active goal (unknown or already finished).
    #[error("goal {id} is not active (unknown or already finished)")]
    UnknownGoal {
        /// Goal id.
        id: u64,
    },
    /// A path tolerance was violated while the trajectory ran.
    #[error(
        "path tolerance violated at t = {time} s: joint '{joint}' {quantity} error {error} exceeds tolerance {tolerance}"
    )]
    PathToleranceViolated {
        /// Joint name.
        joint: String,
        /// "position", "velocity" or "acceleration".
        quantity: &'static str,
        /// Reference − measured.
        error: f64,
        /// The tolerance.
        tolerance: f64,
        /// Absolute time.
        time: f64,
    },
    /// The goal tolerance was not reached within the goal time tolerance.
    #[error(
        "goal tolerance not reached {goal_time} s after the trajectory end at {end_time} s (now t = {time} s): joint '{joint}' {quantity} error {error} exceeds tolerance {tolerance}"
    )]
    GoalToleranceViolated {
        /// Joint name.
        joint: String,
        /// "position", "velocity" or "acceleration".
        quantity: &'static str,
        /// Reference − measured.
        error: f64,
        /// The tolerance.
        tolerance: f64,
        /// Absolute time of the check.
        time: f64,
        /// Absolute end time of the trajectory.
        end_time: f64,
        /// Goal time tolerance (s).
        goal_time: f64,
    },
}

impl ExecutorError {
    /// The `control_msgs/FollowJointTrajectory` result code of this error.
    ///
    /// # Returns
    /// [`INVALID_JOINTS`] for unknown, duplicated or missing joints (also in tolerances),
    /// [`OLD_HEADER_TIMESTAMP`], [`PATH_TOLERANCE_VIOLATED`], [`GOAL_TOLERANCE_VIOLATED`] for
    /// those conditions, and [`INVALID_GOAL`] for everything else.
    pub fn error_code(&self) -> i32 {
        match self {
            Self::UnknownJoint { .. }
            | Self::DuplicateJoint { .. }
            | Self::MissingJoints { .. }
            | Self::NoJointNames
            | Self::UnknownToleranceJoint { .. }
            | Self::DuplicateToleranceJoint { .. } => INVALID_JOINTS,
            Self::OldHeaderTimestamp { .. } => OLD_HEADER_TIMESTAMP,
            Self::PathToleranceViolated { .. } => PATH_TOLERANCE_VIOLATED,
            Self::GoalToleranceViolated { .. } => GOAL_TOLERANCE_VIOLATED,
            _ => INVALID_GOAL,
        }
    }
}
