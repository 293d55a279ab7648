//! Path and goal tolerances: resolution of goal values against defaults, and checks.
//!
//! Semantics of `control_msgs/JointTolerance` as resolved by JTC (`tolerances.hpp`,
//! `get_segment_tolerances`, Jazzy): a goal value > 0 replaces the default, 0 keeps the
//! default, −1 removes the tolerance; a resolved tolerance of 0 is not checked. The default
//! goal velocity tolerance is `stopped_velocity_tolerance`.

use crate::error::ExecutorError;
use crate::types::{joint_list, ExecutorConfig, GoalTolerances, JointLimits, JointTolerance};

/// Resolved tolerances of one joint; 0 = unchecked.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Tolerance {
    /// Position tolerance.
    pub position: f64,
    /// Velocity tolerance.
    pub velocity: f64,
    /// Acceleration tolerance.
    pub acceleration: f64,
}

/// Tolerances of a goal, resolved per joint in model order.
#[derive(Debug, Clone, PartialEq)]
pub struct ResolvedTolerances {
    /// Path tolerance per joint.
    pub path: Vec<Tolerance>,
    /// Goal tolerance per joint.
    pub goal: Vec<Tolerance>,
    /// Goal time tolerance (s); 0 = wait forever.
    pub goal_time: f64,
}

/// A tolerance violation found by [`check`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Violation {
    /// Model index of the joint.
    pub joint: usize,
    /// "position", "velocity" or "acceleration".
    pub quantity: &'static str,
    /// Reference − measured.
    pub error: f64,
    /// The tolerance.
    pub tolerance: f64,
}

/// Resolves a goal's tolerances against the configured defaults.
///
/// # Returns
/// `Err(UnknownToleranceJoint)` / `Err(DuplicateToleranceJoint)` (INVALID_JOINTS) for names;
/// `Err(InvalidTolerance)` / `Err(InvalidGoalTime)` (INVALID_GOAL) for values. JTC logs such
/// problems and falls back to the defaults; this crate rejects the goal instead.
pub fn resolve(
    limits: &[JointLimits],
    cfg: &ExecutorConfig,
    goal: &GoalTolerances,
) -> Result<ResolvedTolerances, ExecutorError> {
    let defaults = |list: &[JointTolerance], stopped: f64| -> Vec<Tolerance> {
        limits
            .iter()
            .map(|l| {
                let t = list.iter().find(|t| t.name == l.name);
                Tolerance {
                    position: t.map_or(0.0, |t| t.position),
                    velocity: match t {
                        Some(t) if t.velocity > 0.0 => t.velocity,
                        _ => stopped,
                    },
                    acceleration: t.map_or(0.0, |t| t.acceleration),
                }
            })
            .collect()
    };
    let mut path = defaults(&cfg.path_tolerances, 0.0);
    let mut goal_tol = defaults(&cfg.goal_tolerances, cfg.stopped_velocity_tolerance);
    apply(limits, "path", &goal.path, &mut path)?;
    apply(limits, "goal", &goal.goal, &mut goal_tol)?;
    let goal_time = if !(goal.goal_time.is_finite() && goal.goal_time >= 0.0) {
        return Err(ExecutorError::InvalidGoalTime {
            value: goal.goal_time,
        });
    } else if goal.goal_time > 0.0 {
        goal.goal_time
    } else {
        cfg.goal_time_tolerance
    };
    Ok(ResolvedTolerances {
        path,
        goal: goal_tol,
        goal_time,
    })
}

fn apply(
    limits: &[JointLimits],
    kind: &'static str,
    list: &[JointTolerance],
    out: &mut [Tolerance],
) -> Result<(), ExecutorError> {
    for (i, t) in list.iter().enumerate() {
        let Some(j) = limits.iter().position(|l| l.name == t.name) else {
            return Err(ExecutorError::UnknownToleranceJoint {
                kind,
                joint: t.name.clone(),
                known: joint_list(limits),
            });
        };
        if list[..i].iter().any(|o| o.name == t.name) {
            return Err(ExecutorError::DuplicateToleranceJoint {
                kind,
                joint: t.name.clone(),
            });
        }
        let resolve_one = |field: &'static str, value: f64, default: f64| {
            if value > 0.0 && value.is_finite() {
                Ok(value)
            } else if value == 0.0 {
                Ok(default)
            } else if value == -1.0 {
                Ok(0.0)
            } else {
                Err(ExecutorError::InvalidTolerance {
                    kind,
                    joint: t.name.clone(),
                    field,
                    value,
                })
            }
        };
        let d = out[j];
        out[j] = Tolerance {
            position: resolve_one("position", t.position, d.position)?,
            velocity: resolve_one("velocity", t.velocity, d.velocity)?,
            acceleration: resolve_one("acceleration", t.acceleration, d.acceleration)?,
        };
    }
    Ok(())
}

/// First joint whose error exceeds its tolerance (JTC `check_state_tolerance_per_joint`).
///
/// # Arguments
/// * `tolerances` — per joint, model order; 0 = unchecked.
/// * `position_error`, `velocity_error`, `acceleration_error` — reference − measured; the
///   velocity/acceleration slices may be empty (no such state), then unchecked.
pub fn check(
    tolerances: &[Tolerance],
    position_error: &[f64],
    velocity_error: &[f64],
    acceleration_error: &[f64],
) -> Option<Violation> {
    for (joint, tol) in tolerances.iter().enumerate() {
        let quantities = [
            ("position", tol.position, position_error.get(joint)),
            ("velocity", tol.velocity, velocity_error.get(joint)),
            (
                "acceleration",
                tol.acceleration,
                acceleration_error.get(joint),
            ),
        ];
        for (quantity, tolerance, error) in quantities {
            if let Some(&error) = error {
                if tolerance > 0.0 && error.abs() > tolerance {
                    return Some(Violation {
                        joint,
                        quantity,
                        error,
                        tolerance,
                    });
                }
            }
        }
    }
    None
}
