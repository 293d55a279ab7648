//! Where a plan starts (issue 27, item 1): the robot's state as the node last received it, and
//! the request's [`StartSpec`] resolved against it.

use kerf_approach::StartSpec;
use kerf_executor::{measured_state, JointLimits, NamedState};
use serde::{Deserialize, Serialize};

/// The topic the harness reads the robot's joint state from, relative to the node's namespace
/// (the trajectory executor publishes its measured state there).
pub const JOINT_STATES_TOPIC: &str = "joint_states";

/// The oldest joint state (s) a default start (`start` left out) takes as the robot's current
/// state; an older one means no executor is running, and the plan starts at its first point.
/// An explicit `start: current` with an older state is refused.
pub const CURRENT_STATE_MAX_AGE: f64 = 1.0;

/// Largest joint speed (rad/s or m/s) of a robot counted as at rest: an approach starts at
/// rest, so a moving robot's state is refused as a start.
pub const AT_REST_SPEED: f64 = 1e-3;

/// The robot's joint state as the node last received it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CurrentState {
    /// The joint names of the message.
    pub names: Vec<String>,
    /// Positions, one per name.
    pub positions: Vec<f64>,
    /// Velocities, one per name, or empty.
    pub velocities: Vec<f64>,
    /// Seconds since the node received it, when the plan was handed to the worker.
    pub age: f64,
    /// The topic it came from (resolved), for messages.
    pub topic: String,
}

/// How a plan's start was decided.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StartKind {
    /// The robot's state.
    Current,
    /// The request's positions.
    Given,
}

impl StartKind {
    /// `"current"` or `"given"`.
    pub fn as_str(self) -> &'static str {
        match self {
            StartKind::Current => "current",
            StartKind::Given => "given",
        }
    }
}

/// Resolves a request's start.
///
/// # Arguments
/// * `spec` — what the request asks.
/// * `current` — the robot's latest joint state (none when the node has received none).
/// * `joints` — the robot's joints (names and position limits), the order of the result.
///
/// # Returns
/// `None` for a plan without approach and retract (`none`, or the default without a recent
/// state); the start kind and configuration otherwise.
///
/// # Errors
/// A message naming what is wrong: `current` without a joint state or with one older than
/// [`CURRENT_STATE_MAX_AGE`], a state with missing, duplicated or non-finite joints, a robot
/// that moves, given positions of the wrong count or outside a joint's limits.
pub fn resolve_start(
    spec: &StartSpec,
    current: Option<&CurrentState>,
    joints: &[JointLimits],
) -> Result<Option<(StartKind, Vec<f64>)>, String> {
    let state = match spec {
        StartSpec::None => return Ok(None),
        StartSpec::Given(q) => return given(q, joints).map(|q| Some((StartKind::Given, q))),
        StartSpec::Default => match current {
            Some(c) if c.age <= CURRENT_STATE_MAX_AGE => c,
            _ => return Ok(None),
        },
        StartSpec::Current => match current {
            None => {
                return Err(format!(
                    "start is \"current\" but no joint state of the robot was received on \
                     {JOINT_STATES_TOPIC} (is the trajectory executor running in this \
                     namespace?); give start \"given\" with start_positions, or \"none\""
                ))
            }
            Some(c) if c.age > CURRENT_STATE_MAX_AGE => {
                return Err(format!(
                    "start is \"current\" but the robot's latest joint state on {} is {:.3} s \
                     old (at most {CURRENT_STATE_MAX_AGE} s): the robot's driver or executor \
                     has stopped publishing",
                    c.topic, c.age
                ))
            }
            Some(c) => c,
        },
    };
    let named = NamedState {
        names: &state.names,
        positions: &state.positions,
        velocities: &state.velocities,
    };
    let measured = measured_state("start state", named, joints)
        .map_err(|e| format!("the robot's joint state on {}: {e}", state.topic))?;
    if let Some(v) = &measured.velocities {
        if let Some((j, speed)) = v.iter().enumerate().find(|(_, s)| s.abs() > AT_REST_SPEED) {
            return Err(format!(
                "the robot is moving (joint '{}' at {speed} per s on {}): a plan starts from \
                 rest; send it when the robot has stopped, or give start \"given\"",
                joints.get(j).map_or("?", |l| l.name.as_str()),
                state.topic
            ));
        }
    }
    within_limits("the robot's current", &measured.positions, joints)?;
    Ok(Some((StartKind::Current, measured.positions)))
}

/// Checks given start positions: one per joint, inside the limits.
fn given(q: &[f64], joints: &[JointLimits]) -> Result<Vec<f64>, String> {
    if q.len() != joints.len() {
        let names: Vec<&str> = joints.iter().map(|j| j.name.as_str()).collect();
        return Err(format!(
            "start_positions has {} value(s) for {} joints ({})",
            q.len(),
            joints.len(),
            names.join(", ")
        ));
    }
    within_limits("start_positions", q, joints)?;
    Ok(q.to_vec())
}

fn within_limits(what: &str, q: &[f64], joints: &[JointLimits]) -> Result<(), String> {
    for (i, (v, j)) in q.iter().zip(joints).enumerate() {
        if !v.is_finite() {
            return Err(format!(
                "{what} position of joint '{}' ([{i}]) is {v}: not finite",
                j.name
            ));
        }
        if *v < j.min_position || *v > j.max_position {
            return Err(format!(
                "{what} position of joint '{}' ([{i}]) is {v}, outside its limits [{}, {}]",
                j.name, j.min_position, j.max_position
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn joints() -> Vec<JointLimits> {
        ["a", "b"]
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

    fn state(age: f64) -> CurrentState {
        CurrentState {
            names: vec!["b".into(), "a".into(), "extra".into()],
            positions: vec![0.2, 0.1, 9.0],
            velocities: vec![],
            age,
            topic: "/joint_states".into(),
        }
    }

    #[test]
    fn the_default_is_current_when_recent_else_none() {
        let j = joints();
        assert_eq!(
            resolve_start(&StartSpec::Default, Some(&state(0.01)), &j),
            Ok(Some((StartKind::Current, vec![0.1, 0.2])))
        );
        assert_eq!(
            resolve_start(&StartSpec::Default, Some(&state(5.0)), &j),
            Ok(None)
        );
        assert_eq!(resolve_start(&StartSpec::Default, None, &j), Ok(None));
        assert_eq!(
            resolve_start(&StartSpec::None, Some(&state(0.0)), &j),
            Ok(None)
        );
    }

    #[test]
    fn bad_starts_are_refused_by_name() {
        let j = joints();
        let e = |spec: StartSpec, s: Option<CurrentState>| {
            resolve_start(&spec, s.as_ref(), &j).unwrap_err()
        };
        assert!(e(StartSpec::Current, None).contains("no joint state"));
        assert!(e(StartSpec::Current, Some(state(2.0))).contains("2.000 s old"));
        let mut missing = state(0.0);
        missing.names = vec!["a".into(), "c".into(), "d".into()];
        // Named as kerf_executor::measured_state names it ('b', or [b] in a list).
        let m = e(StartSpec::Current, Some(missing));
        assert!(m.contains("'b'") || m.contains("[b]"), "{m}");
        let mut nan = state(0.0);
        nan.positions[0] = f64::NAN;
        assert!(e(StartSpec::Current, Some(nan)).contains("'b'"));
        let mut moving = state(0.0);
        moving.velocities = vec![0.0, 0.5, 0.0];
        assert!(e(StartSpec::Current, Some(moving)).contains("moving (joint 'a'"));
        assert!(e(StartSpec::Given(vec![0.0]), None).contains("1 value(s) for 2 joints"));
        assert!(e(StartSpec::Given(vec![0.0, 1.5]), None).contains("'b' ([1]) is 1.5, outside"));
        let mut out = state(0.0);
        out.positions[1] = -3.0;
        assert!(e(StartSpec::Current, Some(out)).contains("joint 'a'"));
    }
}
