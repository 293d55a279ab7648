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
//! * start-up (`queue_depth` from [`queue_depth`]) and clean shutdown: the plan in progress
//!   is finished and published, queued requests are answered [`Failure::Stopped`] without
//!   planning.

mod answers;
mod error;
mod executable;
mod harness;
mod main;
mod service;
mod text;

pub use error::NodeError;
pub use executable::{check_trajectory_msg, trajectory_msg, trajectory_request};
pub use harness::{answer_text, run, work, Job};
pub use main::node_main;
pub use service::{AnswerKey, Failure, PlanAnswer, PlanningService, Topics, TRAJECTORY_TOPIC};
pub use text::{check_text_size, yaml_field, TextRequestError, MAX_TEXT_REQUEST_BYTES};

use crate::{Params, RosError};

/// Default of the `queue_depth` parameter: requests waiting or being planned.
pub const DEFAULT_QUEUE_DEPTH: usize = 10;

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
