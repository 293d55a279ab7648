//! The planner-node harness: every kerf planner node is a [`PlanningService`] run by [`run`].
//!
//! ```text
//! request (message or text) → service.request_from_msg / request_from_text (convert, validate)
//!   → queue (arrival order, `queue_depth`) → worker: service.plan
//!   → executability check (the executor's own validation, check_trajectory_msg)
//!   → publish: answer (latched), answer as YAML text (latched), trajectory on success
//! ```
//!
//! The harness owns:
//! * the request topics (message and `std_msgs/String` text) and the answer topics, latched
//!   (reliable, transient-local, keep-last 10), and `~/joint_trajectory` (reliable, volatile);
//! * one worker thread; requests are answered in arrival order, each by exactly one answer
//!   with its request id, status and message: a request that cannot be read, converted or
//!   validated, a planner error and a planner panic ([`Failure::Panicked`]) all get one;
//! * the busy answer: when `queue_depth` requests are waiting or being planned, a new valid
//!   request is answered at once ([`Failure::Busy`]) and a new invalid one at once with its
//!   own status;
//! * the executability check: a successful plan whose trajectory the trajectory executor
//!   would refuse is answered [`Failure::NotExecutable`] and its trajectory is not published;
//! * deadlines and cancellation (issue 11, item 3): every plan runs under a
//!   [`kerf_budget::Budget`] of the node's `plan_timeout` parameter, tightened by the request's
//!   own time budget ([`PlanningService::requested_budget`]; a request asking for more than
//!   `plan_timeout` is refused, [`Failure::OverBudget`]); the planner checks it cooperatively
//!   and a plan that runs out of it is answered TIMEOUT, freeing the worker;
//! * start-up ([`HarnessSettings`]) and clean shutdown: on Ctrl-C, SIGTERM or the stop token,
//!   the plan in progress is cancelled through its budget and answered (the planner's
//!   cancellation status), queued requests are answered [`Failure::Stopped`] without planning,
//!   and the node returns within a second.

mod answers;
mod error;
mod executable;
mod harness;
mod main;
mod service;
mod size;
mod text;

pub use error::NodeError;
pub use executable::{check_trajectory_msg, trajectory_msg, trajectory_request};
pub use harness::{answer_text, run, work, Job, MAX_REQUEST_ID_BYTES, SHUTDOWN_LINGER};
pub use main::node_main;
pub use service::{AnswerKey, Failure, PlanAnswer, PlanningService, Topics, TRAJECTORY_TOPIC};
pub use size::{
    cdr_bytes, check_answer, check_points, max_answer_points, AnswerSize, MAX_ANSWER_BYTES,
    TEXT_BYTES_PER_JOINT_POINT,
};
pub use text::{check_text_size, yaml_field, TextRequestError, MAX_TEXT_REQUEST_BYTES};

use crate::{Params, RosError};

/// Default of the `queue_depth` parameter: requests waiting or being planned.
pub const DEFAULT_QUEUE_DEPTH: usize = 10;

/// Default of the `plan_timeout` parameter (s): the time budget of every plan.
pub const DEFAULT_PLAN_TIMEOUT: f64 = 60.0;

/// Reads the `allowed_file_roots` parameter (string array of directories): files named by
/// requests (meshes, policies, programs) must resolve under one of them or under the shipped
/// data. Unset or empty: any path.
///
/// # Errors
/// [`RosError::Param`] naming `allowed_file_roots` for a wrong type, or a root that does not
/// exist or is not a directory.
pub fn allowed_roots(params: &Params) -> Result<kerf_robot::roots::AllowedRoots, RosError> {
    match params.string_array("allowed_file_roots")? {
        None => Ok(kerf_robot::roots::AllowedRoots::any()),
        Some(list) if list.is_empty() => Ok(kerf_robot::roots::AllowedRoots::any()),
        Some(list) => {
            let dirs: Vec<std::path::PathBuf> = list.iter().map(Into::into).collect();
            kerf_robot::roots::AllowedRoots::only(&dirs).map_err(|reason| RosError::Param {
                name: "allowed_file_roots".into(),
                reason,
            })
        }
    }
}

/// The parameters the harness reads (every planner node lists them among its known ones).
pub const HARNESS_PARAMS: &[&str] = &["queue_depth", "plan_timeout"];

/// The harness's settings, from the node's parameters ([`HarnessSettings::from_params`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HarnessSettings {
    /// Requests waiting or being planned before new ones are answered [`Failure::Busy`] (≥ 1).
    pub queue_depth: usize,
    /// The time budget of every plan; a request may ask for less, not more.
    pub plan_timeout: std::time::Duration,
}

impl Default for HarnessSettings {
    fn default() -> Self {
        Self {
            queue_depth: DEFAULT_QUEUE_DEPTH,
            plan_timeout: std::time::Duration::from_secs_f64(DEFAULT_PLAN_TIMEOUT),
        }
    }
}

impl HarnessSettings {
    /// Reads `queue_depth` ([`queue_depth`]) and `plan_timeout` (seconds, a number in
    /// (0, [`kerf_budget::MAX_BUDGET_SECONDS`]], default [`DEFAULT_PLAN_TIMEOUT`]).
    ///
    /// # Errors
    /// [`RosError::Param`] naming the parameter for a wrong type or a value out of range.
    pub fn from_params(params: &Params) -> Result<Self, RosError> {
        let queue_depth = queue_depth(params)?;
        let seconds = params.f64_or("plan_timeout", DEFAULT_PLAN_TIMEOUT)?;
        let plan_timeout = match kerf_budget::limit_from_seconds(seconds) {
            Ok(Some(limit)) => limit,
            Ok(None) => {
                return Err(RosError::Param {
                    name: "plan_timeout".into(),
                    reason: "must be > 0 s (every plan has a time budget)".into(),
                })
            }
            Err(reason) => {
                return Err(RosError::Param {
                    name: "plan_timeout".into(),
                    reason,
                })
            }
        };
        Ok(Self {
            queue_depth,
            plan_timeout,
        })
    }
}

/// Reads the `queue_depth` parameter (integer ≥ 1, default [`DEFAULT_QUEUE_DEPTH`]).
///
/// # Errors
/// [`RosError::Param`] naming `queue_depth` for a wrong type or a value below 1.
pub fn queue_depth(params: &Params) -> Result<usize, RosError> {
    let depth = params.i64_or("queue_depth", DEFAULT_QUEUE_DEPTH as i64)?;
    usize::try_from(depth)
        .ok()
        .filter(|d| *d >= 1)
        .ok_or_else(|| RosError::Param {
            name: "queue_depth".into(),
            reason: format!("must be >= 1, got {depth}"),
        })
}
