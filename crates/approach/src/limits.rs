//! Joint limits (position, velocity, acceleration, jerk) and the checks of configurations
//! against them.

use crate::{ApproachError, Role};

/// Limits of one joint, in the robot model's joint order. SI units: rad for a revolute joint,
/// m for a prismatic one, per s, s², s³.
///
/// The ROS node fills these from `kerf_robot` (URDF position and velocity limits, the
/// executor's acceleration and jerk limits); this crate does not depend on it.
#[derive(Debug, Clone, PartialEq)]
pub struct JointLimit {
    /// Joint name, used in errors.
    pub name: String,
    /// Lower position limit. `-inf` for an unbounded (continuous) joint.
    pub min_position: f64,
    /// Upper position limit. `+inf` for an unbounded (continuous) joint.
    pub max_position: f64,
    /// Velocity limit, finite and > 0.
    pub max_velocity: f64,
    /// Acceleration limit, finite and > 0.
    pub max_acceleration: f64,
    /// Jerk limit, finite and > 0.
    pub max_jerk: f64,
}

impl JointLimit {
    /// Checks one joint's limits.
    ///
    /// # Returns
    /// [`ApproachError::InvalidJointLimit`] naming the field when a position limit is NaN,
    /// `min_position` is `+inf`, `max_position` is `-inf`, `min_position >= max_position`, or
    /// a velocity, acceleration or jerk limit is not finite and > 0.
    pub fn check(&self) -> Result<(), ApproachError> {
        // Position, velocity and acceleration as the executor checks its own limits.
        let executor = kerf_executor::JointLimits {
            name: self.name.clone(),
            min_position: self.min_position,
            max_position: self.max_position,
            max_velocity: self.max_velocity,
            max_acceleration: self.max_acceleration,
        };
        match executor.check() {
            Ok(()) => {}
            Err(kerf_executor::ExecutorError::InvalidJointLimit {
                joint,
                field,
                value,
                requirement,
            }) => {
                return Err(ApproachError::InvalidJointLimit {
                    joint,
                    field,
                    value,
                    requirement,
                })
            }
            Err(other) => {
                return Err(ApproachError::InvalidJointLimit {
                    joint: self.name.clone(),
                    field: "limits",
                    value: f64::NAN,
                    requirement: other_limit_error(&other),
                })
            }
        }
        if !(self.max_jerk.is_finite() && self.max_jerk > 0.0) {
            return Err(ApproachError::InvalidJointLimit {
                joint: self.name.clone(),
                field: "max_jerk",
                value: self.max_jerk,
                requirement: "must be finite and > 0",
            });
        }
        Ok(())
    }
}

/// A requirement text for an executor error other than an invalid limit (none is expected
/// from a single joint's check).
fn other_limit_error(_e: &kerf_executor::ExecutorError) -> &'static str {
    "rejected by the executor's joint-limit check"
}

/// Checks a robot's limits: at least one joint, every joint valid.
///
/// # Returns
/// [`ApproachError::NoJoints`] or the first joint's [`JointLimit::check`] error.
pub fn check_limits(limits: &[JointLimit]) -> Result<(), ApproachError> {
    if limits.is_empty() {
        return Err(ApproachError::NoJoints);
    }
    limits.iter().try_for_each(JointLimit::check)
}

/// Checks a configuration: one finite position per joint, each inside its position limits
/// (bounds included).
///
/// # Arguments
/// * `role` – what `q` is, for the error.
/// * `q` – the configuration.
/// * `limits` – the robot's limits (assumed checked by [`check_limits`]).
///
/// # Returns
/// [`ApproachError::JointCount`], [`ApproachError::NonFinitePosition`] or
/// [`ApproachError::OutOfLimits`] naming the joint and its value.
pub fn check_configuration(
    role: Role,
    q: &[f64],
    limits: &[JointLimit],
) -> Result<(), ApproachError> {
    if q.len() != limits.len() {
        return Err(ApproachError::JointCount {
            what: role.to_string(),
            expected: limits.len(),
            found: q.len(),
        });
    }
    for (&value, l) in q.iter().zip(limits) {
        if !value.is_finite() {
            return Err(ApproachError::NonFinitePosition {
                role,
                joint: l.name.clone(),
                value,
            });
        }
        if value < l.min_position || value > l.max_position {
            return Err(ApproachError::OutOfLimits {
                role,
                joint: l.name.clone(),
                value,
                min: l.min_position,
                max: l.max_position,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn joint() -> JointLimit {
        JointLimit {
            name: "a1".into(),
            min_position: -1.0,
            max_position: 1.0,
            max_velocity: 1.0,
            max_acceleration: 2.0,
            max_jerk: 10.0,
        }
    }

    #[test]
    fn bad_numbers_are_named() {
        assert!(joint().check().is_ok());
        let unbounded = JointLimit {
            min_position: f64::NEG_INFINITY,
            max_position: f64::INFINITY,
            ..joint()
        };
        assert!(unbounded.check().is_ok());
        let cases: [(JointLimit, &str); 7] = [
            (
                JointLimit {
                    min_position: f64::NAN,
                    ..joint()
                },
                "min_position",
            ),
            (
                JointLimit {
                    max_position: f64::NEG_INFINITY,
                    ..joint()
                },
                "max_position",
            ),
            (
                JointLimit {
                    min_position: 1.0,
                    ..joint()
                },
                "min_position",
            ),
            (
                JointLimit {
                    max_velocity: 0.0,
                    ..joint()
                },
                "max_velocity",
            ),
            (
                JointLimit {
                    max_acceleration: -1.0,
                    ..joint()
                },
                "max_acceleration",
            ),
            (
                JointLimit {
                    max_jerk: f64::INFINITY,
                    ..joint()
                },
                "max_jerk",
            ),
            (
                JointLimit {
                    max_jerk: f64::NAN,
                    ..joint()
                },
                "max_jerk",
            ),
        ];
        for (l, field) in cases {
            let e = l.check().unwrap_err();
            assert!(
                matches!(&e, ApproachError::InvalidJointLimit { field: f, joint, .. } if *f == field && joint == "a1"),
                "{e}"
            );
        }
        assert_eq!(check_limits(&[]), Err(ApproachError::NoJoints));
    }

    #[test]
    fn configurations_are_checked() {
        let l = [joint()];
        assert!(check_configuration(Role::Start, &[1.0], &l).is_ok());
        let e = check_configuration(Role::Goal, &[1.5], &l).unwrap_err();
        assert!(
            e.to_string().contains("'a1'") && e.to_string().contains("1.5"),
            "{e}"
        );
        assert!(matches!(
            check_configuration(Role::Start, &[f64::NAN], &l),
            Err(ApproachError::NonFinitePosition { .. })
        ));
        assert!(matches!(
            check_configuration(Role::Start, &[0.0, 0.0], &l),
            Err(ApproachError::JointCount {
                expected: 1,
                found: 2,
                ..
            })
        ));
    }
}
