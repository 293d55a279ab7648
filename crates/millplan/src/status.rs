//! Status values of the planner's answer (the `MillPlan` message) and the
//! status category of an error ([`status_of`]).
//!
//! Reached as `kerf_millplan::planner::status` too (the constants' path
//! before this module was split out of [`crate::planner`]).

use kerf_mill::MillError;

use crate::error::MillPlanError;

/// The plan succeeded.
pub const SUCCESS: u8 = 0;
/// The request is malformed (field and index in the message).
pub const INVALID_REQUEST: u8 = 1;
/// A path point or segment is out of reach or beyond a joint limit.
pub const UNREACHABLE: u8 = 2;
/// The policy file is missing, unreadable or incompatible (issue 28: a
/// rollout that leaves the feasible set is INFEASIBLE).
pub const POLICY_ERROR: u8 = 3;
/// The chatter model failed (non-convergence, NaN).
pub const CHATTER_MODEL_ERROR: u8 = 4;
/// Anything else (I/O, learning backend, a numerical failure; planning
/// cancelled because the node is stopping).
pub const INTERNAL_ERROR: u8 = 6;
/// The request's time budget ran out before the plan was finished.
pub const TIMEOUT: u8 = 7;
/// The executed plan passes closer to a singularity than the request's minimum condition
/// indicator allows (value and arc length in the message).
pub const ILL_CONDITIONED: u8 = 8;
/// The plan would need more memory than its budget (the node's `plan_memory`) allows.
pub const RESOURCE_LIMIT: u8 = 9;
/// The plan chatters as executed: a control-period sample in the material reaches
/// |μ|max ≥ 1 (segment, |μ|max and the lowest |μ|max any planner reached in the message).
/// Value 10 is the planner node's NO_APPROACH.
pub const CHATTER: u8 = 11;
/// The planner cannot plan this valid path (the reason in the message).
pub const INFEASIBLE: u8 = 12;

/// The name of a status value, `None` for an unknown one.
pub fn status_name(value: u8) -> Option<&'static str> {
    match value {
        SUCCESS => Some("SUCCESS"),
        INVALID_REQUEST => Some("INVALID_REQUEST"),
        UNREACHABLE => Some("UNREACHABLE"),
        POLICY_ERROR => Some("POLICY_ERROR"),
        CHATTER_MODEL_ERROR => Some("CHATTER_MODEL_ERROR"),
        INTERNAL_ERROR => Some("INTERNAL_ERROR"),
        TIMEOUT => Some("TIMEOUT"),
        ILL_CONDITIONED => Some("ILL_CONDITIONED"),
        RESOURCE_LIMIT => Some("RESOURCE_LIMIT"),
        CHATTER => Some("CHATTER"),
        INFEASIBLE => Some("INFEASIBLE"),
        _ => None,
    }
}

/// The status category of an error:
///
/// | error | status |
/// |---|---|
/// | `InvalidParameter`, `InvalidConfig`; `Mill` of a bad parameter, configuration, non-coplanar points, a B-spline fit | INVALID_REQUEST 1 |
/// | `Mill` of `Unreachable`, `JointLimit`, `Singular` | UNREACHABLE 2 |
/// | `Policy` | POLICY_ERROR 3 |
/// | `Chatter`, `Mill(Chatter)` | CHATTER_MODEL_ERROR 4 |
/// | `Io`, `Backend`, `Mill` of a non-finite value, non-convergence, a file or robot-model failure; `Interrupted` by a cancellation | INTERNAL_ERROR 6 |
/// | `Interrupted` by the time budget | TIMEOUT 7 |
/// | `IllConditioned` | ILL_CONDITIONED 8 |
/// | `Interrupted` by the memory budget | RESOURCE_LIMIT 9 |
/// | `Chattering` | CHATTER 11 |
/// | `Infeasible` | INFEASIBLE 12 |
///
/// Value 5 (`QUEUE_FULL` of `kerf_msgs/msg/MillPlan`) belongs to the node
/// (its request queue) and is not produced here.
pub fn status_of(error: &MillPlanError) -> u8 {
    match error {
        MillPlanError::InvalidParameter { .. } | MillPlanError::InvalidConfig { .. } => {
            INVALID_REQUEST
        }
        MillPlanError::Mill(e) => match e {
            MillError::Unreachable { .. }
            | MillError::JointLimit { .. }
            | MillError::Singular { .. } => UNREACHABLE,
            MillError::InvalidParameter { .. }
            | MillError::InvalidConfig { .. }
            | MillError::NotCoplanar { .. }
            | MillError::Bspline(_) => INVALID_REQUEST,
            MillError::Chatter(_) => CHATTER_MODEL_ERROR,
            MillError::NonFinite { .. }
            | MillError::NotConverged { .. }
            | MillError::FileRead { .. }
            | MillError::Yaml { .. }
            | MillError::Robot(_) => INTERNAL_ERROR,
        },
        MillPlanError::Chatter(_) => CHATTER_MODEL_ERROR,
        MillPlanError::Policy { .. } => POLICY_ERROR,
        MillPlanError::Io { .. }
        | MillPlanError::Backend(_)
        | MillPlanError::NotExecutable { .. } => INTERNAL_ERROR,
        MillPlanError::Interrupted(i) if i.is_timeout() => TIMEOUT,
        MillPlanError::Interrupted(i) if i.is_over_memory() => RESOURCE_LIMIT,
        MillPlanError::IllConditioned { .. } => ILL_CONDITIONED,
        MillPlanError::Chattering { .. } => CHATTER,
        MillPlanError::Infeasible { .. } => INFEASIBLE,
        MillPlanError::Interrupted(_) => INTERNAL_ERROR,
    }
}
