//! Plain input/output types: joint limits, trajectory requests, tolerances, joint samples.
//!
//! All quantities are SI: seconds, and joint units (rad for revolute, m for prismatic joints)
//! per second and per second squared.

use crate::error::ExecutorError;

/// Limits of one joint, in the robot model's joint order.
///
/// The ROS node fills these from `kerf_robot`; this crate does not depend on it.
#[derive(Debug, Clone, PartialEq)]
pub struct JointLimits {
    /// Joint name.
    pub name: String,
    /// Lower position limit (rad or m). `-inf` for an unbounded (continuous) joint.
    pub min_position: f64,
    /// Upper position limit (rad or m). `+inf` for an unbounded (continuous) joint.
    pub max_position: f64,
    /// Velocity limit, finite and > 0 (rad/s or m/s).
    pub max_velocity: f64,
    /// Acceleration limit, finite and > 0 (rad/s² or m/s²).
    pub max_acceleration: f64,
}

impl JointLimits {
    /// Checks one joint's limits.
    ///
    /// # Returns
    /// `Err(InvalidJointLimit)` when a position limit is NaN, `min_position >= max_position`,
    /// or a velocity/acceleration limit is not finite and > 0.
    pub fn check(&self) -> Result<(), ExecutorError> {
        let bad = |field, value, requirement| ExecutorError::InvalidJointLimit {
            joint: self.name.clone(),
            field,
            value,
            requirement,
        };
        if self.min_position.is_nan() || self.min_position == f64::INFINITY {
            return Err(bad(
                "min_position",
                self.min_position,
                "must be a number below +inf",
            ));
        }
        if self.max_position.is_nan() || self.max_position == f64::NEG_INFINITY {
            return Err(bad(
                "max_position",
                self.max_position,
                "must be a number above -inf",
            ));
        }
        if self.min_position >= self.max_position {
            return Err(bad(
                "min_position",
                self.min_position,
                "must be below max_position",
            ));
        }
        if !(self.max_velocity.is_finite() && self.max_velocity > 0.0) {
            return Err(bad(
                "max_velocity",
                self.max_velocity,
                "must be finite and > 0",
            ));
        }
        if !(self.max_acceleration.is_finite() && self.max_acceleration > 0.0) {
            return Err(bad(
                "max_acceleration",
                self.max_acceleration,
                "must be finite and > 0",
            ));
        }
        Ok(())
    }
}

/// Checks a whole robot model: at least one joint, unique names, valid limits.
pub(crate) fn check_limits(limits: &[JointLimits]) -> Result<(), ExecutorError> {
    if limits.is_empty() {
        return Err(ExecutorError::NoJoints);
    }
    for (i, l) in limits.iter().enumerate() {
        l.check()?;
        if limits[..i].iter().any(|o| o.name == l.name) {
            return Err(ExecutorError::DuplicateModelJoint {
                joint: l.name.clone(),
            });
        }
    }
    Ok(())
}

/// The robot's joint names, comma-separated, for error messages.
pub(crate) fn joint_list(limits: &[JointLimits]) -> String {
    limits
        .iter()
        .map(|l| l.name.as_str())
        .collect::<Vec<_>>()
        .join(", ")
}

/// One waypoint, as `trajectory_msgs/JointTrajectoryPoint`, in the request's joint order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TrajectoryPoint {
    /// One position per joint name.
    pub positions: Vec<f64>,
    /// Empty, or one velocity per joint name.
    pub velocities: Vec<f64>,
    /// Empty, or one acceleration per joint name (requires velocities).
    pub accelerations: Vec<f64>,
    /// Must be empty: there is no effort command interface.
    pub effort: Vec<f64>,
    /// Time of this point after the start time (s).
    pub time_from_start: f64,
}

/// A trajectory to execute, as `trajectory_msgs/JointTrajectory`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TrajectoryRequest {
    /// Joint names, in any order; every joint of the robot exactly once.
    pub joint_names: Vec<String>,
    /// The waypoints.
    pub points: Vec<TrajectoryPoint>,
    /// Absolute start time (s, `header.stamp`); `None` or `Some(0.0)` = start now.
    pub start_time: Option<f64>,
}

/// Tolerance of one joint, with `control_msgs/JointTolerance` semantics.
///
/// In a goal: `0` = use the default, `-1` = no tolerance (unchecked), `> 0` = this tolerance.
/// In [`ExecutorConfig`]: `0` = unchecked, `> 0` = this tolerance.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct JointTolerance {
    /// Joint name.
    pub name: String,
    /// Position tolerance (rad or m).
    pub position: f64,
    /// Velocity tolerance (rad/s or m/s).
    pub velocity: f64,
    /// Acceleration tolerance (rad/s² or m/s²).
    pub acceleration: f64,
}

/// Tolerances of a goal, as in `control_msgs/FollowJointTrajectory` goals.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct GoalTolerances {
    /// Tolerances on the tracking error while the trajectory runs.
    pub path: Vec<JointTolerance>,
    /// Tolerances on the final error.
    pub goal: Vec<JointTolerance>,
    /// Time after the trajectory end to reach the goal tolerances (s); 0 = configured default.
    pub goal_time: f64,
}

/// Positions, velocities and accelerations of all joints, in the robot model's joint order.
///
/// For measured states, `velocities` and `accelerations` may be empty (no such state
/// interface); the corresponding tolerances are then not checked.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct JointSample {
    /// Positions (rad or m).
    pub positions: Vec<f64>,
    /// Velocities (rad/s or m/s), empty or one per joint.
    pub velocities: Vec<f64>,
    /// Accelerations (rad/s² or m/s²), empty or one per joint.
    pub accelerations: Vec<f64>,
}

impl JointSample {
    /// A state at rest at `positions` (zero velocities and accelerations).
    pub fn at_rest(positions: Vec<f64>) -> Self {
        let n = positions.len();
        Self {
            positions,
            velocities: vec![0.0; n],
            accelerations: vec![0.0; n],
        }
    }

    /// Resizes all three fields to `n` joints, for reuse as an output buffer.
    pub(crate) fn resize_full(&mut self, n: usize) {
        self.positions.resize(n, 0.0);
        self.velocities.resize(n, 0.0);
        self.accelerations.resize(n, 0.0);
    }

    /// Checks lengths and finiteness against the robot model.
    ///
    /// # Arguments
    /// * `what` — name of the state for messages ("measured state", ...).
    /// * `limits` — the robot model.
    /// * `derivatives_required` — whether velocities and accelerations must be present.
    pub(crate) fn check(
        &self,
        what: &'static str,
        limits: &[JointLimits],
        derivatives_required: bool,
    ) -> Result<(), ExecutorError> {
        let n = limits.len();
        let fields: [(&'static str, &Vec<f64>, bool); 3] = [
            ("positions", &self.positions, false),
            ("velocities", &self.velocities, !derivatives_required),
            ("accelerations", &self.accelerations, !derivatives_required),
        ];
        for (field, values, may_be_empty) in fields {
            if values.len() != n && !(may_be_empty && values.is_empty()) {
                return Err(ExecutorError::StateLength {
                    what,
                    field,
                    actual: values.len(),
                    expected: n,
                    empty_note: if may_be_empty { ", or none" } else { "" },
                });
            }
            for (value, l) in values.iter().zip(limits) {
                if !value.is_finite() {
                    return Err(ExecutorError::NonFiniteState {
                        what,
                        field,
                        joint: l.name.clone(),
                        value: *value,
                    });
                }
            }
        }
        Ok(())
    }

    /// Checks that every position is within its joint's limits (with [`crate::LIMIT_SLACK`]).
    pub(crate) fn check_in_limits(
        &self,
        what: &'static str,
        limits: &[JointLimits],
    ) -> Result<(), ExecutorError> {
        for (p, l) in self.positions.iter().zip(limits) {
            if !crate::slack::position_ok(*p, l) {
                return Err(ExecutorError::StateOutOfLimits {
                    what,
                    joint: l.name.clone(),
                    value: *p,
                    min: l.min_position,
                    max: l.max_position,
                });
            }
        }
        Ok(())
    }
}

/// Configuration of the executor (JTC parameters of the same meaning in parentheses).
#[derive(Debug, Clone, PartialEq)]
pub struct ExecutorConfig {
    /// Control period (s); velocity steps are commanded within one period. Default 0.004
    /// (250 Hz); JTC `update_rate`.
    pub control_period: f64,
    /// Default path tolerances by joint name; joints not listed are unchecked. Values: 0 =
    /// unchecked, > 0 = tolerance [`constraints.<joint>.trajectory` (position only)].
    pub path_tolerances: Vec<JointTolerance>,
    /// Default goal tolerances by joint name; joints not listed are unchecked (except the
    /// velocity, see `stopped_velocity_tolerance`) (JTC `constraints.<joint>.goal`).
    pub goal_tolerances: Vec<JointTolerance>,
    /// Default goal velocity tolerance of every joint whose `goal_tolerances` entry gives no
    /// velocity; default 0.01 (JTC `constraints.stopped_velocity_tolerance`).
    pub stopped_velocity_tolerance: f64,
    /// Default time after the trajectory end to reach the goal tolerances (s); 0 = wait
    /// forever. Default 0 (JTC `constraints.goal_time`).
    pub goal_time_tolerance: f64,
    /// Largest position difference (joint units) between the current commanded position and a
    /// first point due at the start time (`time_from_start` 0). Default 1e-3. No JTC equivalent.
    pub start_tolerance: f64,
}

impl Default for ExecutorConfig {
    fn default() -> Self {
        Self {
            control_period: 0.004,
            path_tolerances: Vec::new(),
            goal_tolerances: Vec::new(),
            stopped_velocity_tolerance: 0.01,
            goal_time_tolerance: 0.0,
            start_tolerance: 1e-3,
        }
    }
}

impl ExecutorConfig {
    /// Checks the configuration against the robot model.
    ///
    /// # Returns
    /// `Err(InvalidConfig)` for a non-finite or out-of-range value, `Err(UnknownToleranceJoint)`
    /// / `Err(DuplicateToleranceJoint)` for tolerances of unknown or repeated joints.
    pub fn check(&self, limits: &[JointLimits]) -> Result<(), ExecutorError> {
        let bad = |field: &str, value, requirement| ExecutorError::InvalidConfig {
            field: field.to_string(),
            value,
            requirement,
        };
        if !(self.control_period.is_finite() && self.control_period > 0.0) {
            return Err(bad(
                "control_period",
                self.control_period,
                "must be finite and > 0",
            ));
        }
        for (field, value) in [
            (
                "stopped_velocity_tolerance",
                self.stopped_velocity_tolerance,
            ),
            ("goal_time_tolerance", self.goal_time_tolerance),
            ("start_tolerance", self.start_tolerance),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(bad(field, value, "must be finite and >= 0"));
            }
        }
        for (kind, list) in [
            ("path", &self.path_tolerances),
            ("goal", &self.goal_tolerances),
        ] {
            for (i, t) in list.iter().enumerate() {
                if !limits.iter().any(|l| l.name == t.name) {
                    return Err(ExecutorError::UnknownToleranceJoint {
                        kind,
                        joint: t.name.clone(),
                        known: joint_list(limits),
                    });
                }
                if list[..i].iter().any(|o| o.name == t.name) {
                    return Err(ExecutorError::DuplicateToleranceJoint {
                        kind,
                        joint: t.name.clone(),
                    });
                }
                for (field, value) in [
                    ("position", t.position),
                    ("velocity", t.velocity),
                    ("acceleration", t.acceleration),
                ] {
                    if !(value.is_finite() && value >= 0.0) {
                        return Err(bad(
                            &format!("{kind}_tolerances['{}'].{field}", t.name),
                            value,
                            "must be finite and >= 0 (0 = unchecked)",
                        ));
                    }
                }
            }
        }
        Ok(())
    }
}
