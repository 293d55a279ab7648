//! A named joint state (a `sensor_msgs/JointState`: a driver's feedback, or the robot's state
//! a planner starts from) in the robot model's joint order, every value checked (issue 27).
//!
//! Names not in the model are left out (a driver may also publish a gripper's joints); every
//! joint of the model must be named exactly once, with a finite position (and a finite
//! velocity when velocities are given).

use crate::{ExecutorError, JointLimits};

/// A state as a `sensor_msgs/JointState` carries it: names and, in the same order, positions
/// and (optionally: empty) velocities.
#[derive(Debug, Clone, Copy)]
pub struct NamedState<'a> {
    /// Joint names.
    pub names: &'a [String],
    /// Positions (rad or m), one per name.
    pub positions: &'a [f64],
    /// Velocities (rad/s or m/s), one per name, or empty.
    pub velocities: &'a [f64],
}

/// A state in the model's joint order.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredState {
    /// Positions, one per model joint.
    pub positions: Vec<f64>,
    /// Velocities, one per model joint, when the state gives them.
    pub velocities: Option<Vec<f64>>,
}

/// Reads `state` in the order of `joints`.
///
/// # Arguments
/// * `what` — the state in messages (`"measured state"`, `"start state"`).
/// * `state` — the named state.
/// * `joints` — the robot model's joints.
///
/// # Returns
/// The positions (and velocities) in model order.
///
/// # Errors
/// [`ExecutorError::StateLength`] when positions or velocities do not match the names in
/// number, [`ExecutorError::StateDuplicateJoint`], [`ExecutorError::StateMissingJoints`]
/// naming every joint of the model without a value, [`ExecutorError::NonFiniteState`] naming
/// the joint.
///
/// # Performance
/// O(names × joints) comparisons of short strings.
pub fn measured_state(
    what: &'static str,
    state: NamedState<'_>,
    joints: &[JointLimits],
) -> Result<MeasuredState, ExecutorError> {
    let n = state.names.len();
    if state.positions.len() != n {
        return Err(ExecutorError::StateLength {
            what,
            field: "positions",
            actual: state.positions.len(),
            expected: n,
            empty_note: "",
        });
    }
    if !state.velocities.is_empty() && state.velocities.len() != n {
        return Err(ExecutorError::StateLength {
            what,
            field: "velocities",
            actual: state.velocities.len(),
            expected: n,
            empty_note: ", or none",
        });
    }
    for (i, name) in state.names.iter().enumerate() {
        if state.names[..i].contains(name) {
            return Err(ExecutorError::StateDuplicateJoint {
                what,
                joint: name.clone(),
            });
        }
    }
    let index: Vec<Option<usize>> = joints
        .iter()
        .map(|j| state.names.iter().position(|n| *n == j.name))
        .collect();
    let missing: Vec<&str> = joints
        .iter()
        .zip(&index)
        .filter(|(_, i)| i.is_none())
        .map(|(j, _)| j.name.as_str())
        .collect();
    if !missing.is_empty() {
        return Err(ExecutorError::StateMissingJoints {
            what,
            missing: missing.join(", "),
        });
    }
    let pick = |field: &'static str, values: &[f64]| -> Result<Vec<f64>, ExecutorError> {
        joints
            .iter()
            .zip(&index)
            .map(|(j, i)| {
                let v = i.map_or(f64::NAN, |i| values[i]);
                if v.is_finite() {
                    Ok(v)
                } else {
                    Err(ExecutorError::NonFiniteState {
                        what,
                        field,
                        joint: j.name.clone(),
                        value: v,
                    })
                }
            })
            .collect()
    };
    let positions = pick("position", state.positions)?;
    let velocities = if state.velocities.is_empty() {
        None
    } else {
        Some(pick("velocity", state.velocities)?)
    };
    Ok(MeasuredState {
        positions,
        velocities,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn joints() -> Vec<JointLimits> {
        ["a", "b", "c"]
            .iter()
            .map(|n| JointLimits {
                name: (*n).into(),
                min_position: -1.0,
                max_position: 1.0,
                max_velocity: 1.0,
                max_acceleration: 1.0,
            })
            .collect()
    }

    fn names(n: &[&str]) -> Vec<String> {
        n.iter().map(|s| (*s).to_string()).collect()
    }

    #[test]
    fn a_state_is_read_in_model_order_extra_joints_left_out() {
        let n = names(&["c", "gripper", "a", "b"]);
        let s = measured_state(
            "measured state",
            NamedState {
                names: &n,
                positions: &[0.3, 9.0, 0.1, 0.2],
                velocities: &[],
            },
            &joints(),
        )
        .unwrap();
        assert_eq!(s.positions, [0.1, 0.2, 0.3]);
        assert_eq!(s.velocities, None);
        let s = measured_state(
            "measured state",
            NamedState {
                names: &n,
                positions: &[0.3, 9.0, 0.1, 0.2],
                velocities: &[3.0, f64::NAN, 1.0, 2.0],
            },
            &joints(),
        )
        .unwrap();
        // The gripper's NaN is not the robot's.
        assert_eq!(s.velocities, Some(vec![1.0, 2.0, 3.0]));
    }

    #[test]
    fn fewer_joints_nan_duplicates_and_lengths_are_refused_by_name() {
        let j = joints();
        let read = |n: &[&str], p: &[f64], v: &[f64]| {
            let n = names(n);
            measured_state(
                "start state",
                NamedState {
                    names: &n,
                    positions: p,
                    velocities: v,
                },
                &j,
            )
            .unwrap_err()
            .to_string()
        };
        let e = read(&["a", "c"], &[0.0, 0.0], &[]);
        assert!(e.contains("start state: no value for joint(s) [b]"), "{e}");
        let e = read(&["a", "b", "c"], &[0.0, f64::NAN, 0.0], &[]);
        assert!(e.contains("position of joint 'b' is NaN"), "{e}");
        let e = read(
            &["a", "b", "c"],
            &[0.0, 0.0, 0.0],
            &[0.0, f64::INFINITY, 0.0],
        );
        assert!(e.contains("velocity of joint 'b' is inf"), "{e}");
        let e = read(&["a", "b", "a", "c"], &[0.0; 4], &[]);
        assert!(e.contains("joint 'a' appears twice"), "{e}");
        let e = read(&["a", "b", "c"], &[0.0; 2], &[]);
        assert!(e.contains("positions has 2 values, expected 3"), "{e}");
        let e = read(&["a", "b", "c"], &[0.0; 3], &[0.0]);
        assert!(
            e.contains("velocities has 1 values, expected 3 (one per joint, or none)"),
            "{e}"
        );
    }
}
