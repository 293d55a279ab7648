//! MoveIt `joint_limits.yaml` parsing and merging into URDF limits.
//!
//! Accepted format (a strict subset of MoveIt's, unknown keys are errors so
//! that typos cannot silently drop a limit):
//!
//! ```yaml
//! joint_limits:
//!   q1:
//!     has_position_limits: true   # optional
//!     min_position: 0.0           # optional; may only raise the URDF lower limit
//!     max_position: 1.6           # optional; may only lower the URDF upper limit
//!     has_velocity_limits: true   # optional
//!     max_velocity: 2.0           # optional; may only lower the URDF velocity
//!     has_acceleration_limits: true
//!     max_acceleration: 12.0
//!     has_jerk_limits: true
//!     max_jerk: 120.0
//! ```
//!
//! Merge rules: the URDF gives position and velocity limits, the YAML gives
//! acceleration and jerk limits and may tighten (never widen, never drop)
//! the URDF ones. As in MoveIt, `has_acceleration_limits: false` or
//! `has_jerk_limits: false` means "no such limit" and the value next to it
//! is ignored. `has_*_limits: true` without its value is an error.

use std::collections::BTreeMap;

use serde::Deserialize;

use crate::{JointSpec, RobotError};

/// Root of a `joint_limits.yaml` document.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct LimitsFile {
    joint_limits: BTreeMap<String, YamlJointLimits>,
}

/// Limits of one joint as written in the YAML (SI units).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct YamlJointLimits {
    has_position_limits: Option<bool>,
    min_position: Option<f64>,
    max_position: Option<f64>,
    has_velocity_limits: Option<bool>,
    max_velocity: Option<f64>,
    has_acceleration_limits: Option<bool>,
    max_acceleration: Option<f64>,
    has_jerk_limits: Option<bool>,
    max_jerk: Option<f64>,
}

/// Parses `yaml` and merges it into `joints` (which hold URDF limits).
///
/// # Arguments
/// * `joints` - the movable joints of the model, updated in place.
/// * `fixed_joints` - names of the URDF's fixed joints, to tell "fixed"
///   from "unknown" in errors.
/// * `yaml` - the `joint_limits.yaml` text.
///
/// # Returns
/// `Ok(())` with `joints` updated, or the first violated rule. On error
/// `joints` may be partly updated; callers discard it.
///
/// # Performance
/// O(entries · log entries + joints).
pub(crate) fn apply(
    joints: &mut [JointSpec],
    fixed_joints: &[&str],
    yaml: &str,
) -> Result<(), RobotError> {
    let file: LimitsFile =
        serde_yaml_ng::from_str(yaml).map_err(|source| RobotError::LimitsParse { source })?;
    for (name, entry) in &file.joint_limits {
        let Some(joint) = joints.iter_mut().find(|j| &j.name == name) else {
            return Err(if fixed_joints.contains(&name.as_str()) {
                RobotError::LimitsForFixedJoint {
                    joint: name.clone(),
                }
            } else {
                RobotError::UnknownJoint { name: name.clone() }
            });
        };
        merge(joint, entry)?;
    }
    Ok(())
}

/// Merges one YAML entry into one joint.
fn merge(joint: &mut JointSpec, entry: &YamlJointLimits) -> Result<(), RobotError> {
    let name = joint.name.clone();
    let removed = |field: &'static str| RobotError::LimitRemoved {
        joint: name.clone(),
        field,
    };
    let missing = |flag: &'static str, field: &'static str| RobotError::MissingLimitValue {
        joint: name.clone(),
        flag,
        field,
    };
    let widened = |field: &'static str, urdf: f64, yaml: f64| RobotError::LimitWidened {
        joint: name.clone(),
        field,
        urdf,
        yaml,
    };
    let invalid =
        |field: &'static str, value: f64, requirement: &'static str| RobotError::InvalidLimit {
            joint: name.clone(),
            field,
            value,
            requirement,
        };

    // Position: may only shrink [min_position, max_position].
    match entry.has_position_limits {
        Some(false) => return Err(removed("has_position_limits")),
        Some(true) if entry.min_position.is_none() => {
            return Err(missing("has_position_limits", "min_position"))
        }
        Some(true) if entry.max_position.is_none() => {
            return Err(missing("has_position_limits", "max_position"))
        }
        _ => {}
    }
    if let Some(min) = entry.min_position {
        if !min.is_finite() {
            return Err(invalid("min_position", min, "finite"));
        }
        if min < joint.min_position {
            return Err(widened("min_position", joint.min_position, min));
        }
        joint.min_position = min;
    }
    if let Some(max) = entry.max_position {
        if !max.is_finite() {
            return Err(invalid("max_position", max, "finite"));
        }
        if max > joint.max_position {
            return Err(widened("max_position", joint.max_position, max));
        }
        joint.max_position = max;
    }
    if joint.min_position >= joint.max_position {
        return Err(RobotError::EmptyRange {
            joint: name.clone(),
            min: joint.min_position,
            max: joint.max_position,
        });
    }

    // Velocity: may only decrease.
    match (entry.has_velocity_limits, entry.max_velocity) {
        (Some(false), _) => return Err(removed("has_velocity_limits")),
        (Some(true), None) => return Err(missing("has_velocity_limits", "max_velocity")),
        _ => {}
    }
    if let Some(v) = entry.max_velocity {
        if !(v.is_finite() && v > 0.0) {
            return Err(invalid("max_velocity", v, "finite and > 0"));
        }
        if v > joint.max_velocity {
            return Err(widened("max_velocity", joint.max_velocity, v));
        }
        joint.max_velocity = v;
    }

    // Acceleration and jerk: only the YAML defines them.
    let optional = |flag_name: &'static str,
                    flag: Option<bool>,
                    field: &'static str,
                    value: Option<f64>|
     -> Result<Option<f64>, RobotError> {
        match (flag, value) {
            (Some(false), _) | (None, None) => Ok(None),
            (Some(true), None) => Err(missing(flag_name, field)),
            (_, Some(v)) if v.is_finite() && v > 0.0 => Ok(Some(v)),
            (_, Some(v)) => Err(invalid(field, v, "finite and > 0")),
        }
    };
    joint.max_acceleration = optional(
        "has_acceleration_limits",
        entry.has_acceleration_limits,
        "max_acceleration",
        entry.max_acceleration,
    )?;
    joint.max_jerk = optional(
        "has_jerk_limits",
        entry.has_jerk_limits,
        "max_jerk",
        entry.max_jerk,
    )?;
    Ok(())
}
