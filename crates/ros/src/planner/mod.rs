//! The planner-node harness: every kerf planner node is a [`PlanningService`] run by [`run`].
//!
//! ```text
//! request (message or text) → service.request_from_msg / request_from_text (convert, validate)
//!   → queue (arrival order, `queue_depth`) → worker process (kerf_isolate): convert again,
//!     service.plan under the budget, executability check (check_trajectory_msg)
//!   → publish: answer (latched), answer as YAML text (latched), trajectory on success
//! ```
//!
//! The harness owns:
//! * the request topics (message and `std_msgs/String` text) and the answer topics, latched
//!   (reliable, transient-local, keep-last 10), and `~/joint_trajectory` (reliable, volatile);
//! * one **worker process** ([`kerf_isolate::Supervisor`], forked from the node with the
//!   service loaded): requests are planned there one at a time and answered in arrival order,
//!   each by exactly one answer with its request id, status and message: a request that cannot
//!   be read, converted or validated, a planner error, a planner panic ([`Failure::Panicked`])
//!   and a crashed worker all get one;
//! * the busy answer: when `queue_depth` requests are waiting or being planned, a new valid
//!   request is answered at once ([`Failure::Busy`], QUEUE_FULL) and a new invalid one at once
//!   with its own status;
//! * the executability check: a successful plan whose trajectory the trajectory executor
//!   would refuse is answered [`Failure::NotExecutable`] and its trajectory is not published;
//! * deadlines the planner cannot break (issue 33, item 2): every plan runs under a
//!   [`kerf_budget::Budget`] of the node's `plan_timeout` parameter, tightened by the request's
//!   own time budget ([`PlanningService::requested_budget`]; a request asking for more than
//!   `plan_timeout` is refused, [`Failure::OverBudget`]); the planner checks it cooperatively
//!   and answers TIMEOUT; a plan that has not answered 0.5 s after its deadline is stopped with
//!   its worker process (SIGKILL, reaped) and answered TIMEOUT by the harness
//!   ([`Failure::Timeout`]), and the next request is planned by a fresh worker;
//! * memory the request cannot grow (issue 33, item 3): the budget carries the node's
//!   `plan_memory` (default 1 GiB) for the planner's estimates ([`kerf_budget::Interrupt::OverMemory`],
//!   RESOURCE_LIMIT naming what grew), and a worker whose resident memory grows by more during
//!   a plan is stopped ([`Failure::ResourceLimit`]); the node process itself never plans, so it
//!   does not grow with the requests it serves;
//! * start-up ([`HarnessSettings`]) and clean shutdown: on Ctrl-C, SIGTERM or the stop token,
//!   the plan in progress is cancelled through its budget and answered (the planner's
//!   cancellation status; a plan that does not answer within 0.2 s is stopped and answered
//!   [`Failure::Stopped`]), queued requests are answered [`Failure::Stopped`] without planning,
//!   the answers are given [`SHUTDOWN_LINGER`] to be delivered, and the node returns within 2 s;
//! * the planning action (issue 27, item 3): `~/plan_<noun>` (`kerf_msgs/action/Plan<Noun>`,
//!   [`goal_msgs`]), whose goals are requests in the same queue, cancellable ([`action`]:
//!   queued goals leave the queue, a plan in progress is cancelled through its worker, which
//!   is stopped when it has not answered within 80 ms), and, with `execute`, executed on the
//!   executor's `FollowJointTrajectory` action (the `execute_action` parameter, [`execute`]).

pub mod action;
mod answers;
mod error;
mod executable;
pub mod execute;
pub mod framing;
pub mod goal_msgs;
mod harness;
mod main;
pub mod result_fit;
mod service;
mod size;
pub mod start;
mod text;
mod work;

pub use error::NodeError;
pub use executable::{check_trajectory_msg, trajectory_msg, trajectory_request};
pub use harness::{answer_text, run, MAX_REQUEST_ID_BYTES, SHUTDOWN_LINGER};
pub use main::node_main;
pub use service::{AnswerKey, Failure, PlanAnswer, PlanningService, Topics, TRAJECTORY_TOPIC};
pub use size::{
    cdr_bytes, check_answer, check_points, max_answer_points, AnswerSize, MAX_ANSWER_BYTES,
    TEXT_BYTES_PER_JOINT_POINT,
};
pub use text::{
    check_text_size, leading_request_id, yaml_field, TextRequestError, LEADING_BYTES,
    MAX_TEXT_REQUEST_BYTES,
};
pub use work::{plan_checked, work, HarnessWork, Job, PlanJob, RawRequest};

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
pub const HARNESS_PARAMS: &[&str] = &[
    "queue_depth",
    "plan_timeout",
    "plan_memory",
    "execute_action",
    "approach.clearance",
    "approach.lead_distance",
    "approach.lead_clearance",
    "approach.safe_pose",
    "approach.control_period",
    "retract.distance",
    "retract.safe_pose",
];

/// The harness's settings, from the node's parameters ([`HarnessSettings::from_params`]).
#[derive(Debug, Clone, PartialEq)]
pub struct HarnessSettings {
    /// Requests waiting or being planned before new ones are answered [`Failure::Busy`] (≥ 1).
    pub queue_depth: usize,
    /// The time budget of every plan; a request may ask for less, not more.
    pub plan_timeout: std::time::Duration,
    /// The memory budget of every plan (bytes): the planner's estimates are checked against
    /// it, and the worker process running the plan is stopped when its memory grows by more.
    pub plan_memory: u64,
    /// How a plan with a start is framed by its approach and retract (issue 27).
    pub framing: kerf_approach::FrameSettings,
    /// The executor's `control_msgs/action/FollowJointTrajectory` action that runs the plans
    /// of goals with `execute` (issue 27, item 3); resolved against the node's namespace.
    pub execute_action: String,
}

impl Default for HarnessSettings {
    fn default() -> Self {
        Self {
            queue_depth: DEFAULT_QUEUE_DEPTH,
            plan_timeout: std::time::Duration::from_secs_f64(DEFAULT_PLAN_TIMEOUT),
            plan_memory: kerf_budget::DEFAULT_PLAN_MEMORY,
            framing: kerf_approach::FrameSettings::default(),
            execute_action: execute::DEFAULT_EXECUTE_ACTION.into(),
        }
    }
}

impl HarnessSettings {
    /// Reads `queue_depth` ([`queue_depth`]), `plan_timeout` (seconds, a number in
    /// (0, [`kerf_budget::MAX_BUDGET_SECONDS`]], default [`DEFAULT_PLAN_TIMEOUT`]) and
    /// `plan_memory` (bytes, an integer in [[`kerf_budget::MIN_PLAN_MEMORY`],
    /// [`kerf_budget::MAX_PLAN_MEMORY`]], default [`kerf_budget::DEFAULT_PLAN_MEMORY`], 1 GiB),
    /// the framing of plans with a start ([`framing_from_params`]), and `execute_action` (the
    /// executor's `FollowJointTrajectory` action; a non-empty ROS name, default
    /// [`execute::DEFAULT_EXECUTE_ACTION`]; checked again when the node resolves it).
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
        let memory = params.i64_or("plan_memory", kerf_budget::DEFAULT_PLAN_MEMORY as i64)?;
        let plan_memory =
            kerf_budget::memory_from_bytes(memory).map_err(|reason| RosError::Param {
                name: "plan_memory".into(),
                reason,
            })?;
        let execute_action = params
            .string("execute_action")?
            .unwrap_or_else(|| execute::DEFAULT_EXECUTE_ACTION.into());
        crate::names::expand(&execute_action, "/", "node").map_err(|e| RosError::Param {
            name: "execute_action".into(),
            reason: format!(
                "'{execute_action}' is not a valid action name ({e}); it names the executor's \
                 FollowJointTrajectory action (default {})",
                execute::DEFAULT_EXECUTE_ACTION
            ),
        })?;
        Ok(Self {
            queue_depth,
            plan_timeout,
            plan_memory,
            framing: framing_from_params(params)?,
            execute_action,
        })
    }
}

impl HarnessSettings {
    /// Checks the safe poses of [`Self::framing`] against the robot's limits (the service's
    /// [`PlanningService::approach_limits`]): a safe pose the robot cannot reach stops the node
    /// at start-up.
    ///
    /// # Errors
    /// [`RosError::Param`] naming `approach.safe_pose` or `retract.safe_pose`.
    pub fn check_reach(&self, limits: &[kerf_approach::JointLimit]) -> Result<(), RosError> {
        use kerf_approach::{ApproachError as E, Role};
        self.framing.check_reach(limits).map_err(|e| {
            let role = match &e {
                E::OutOfLimits { role, .. } | E::NonFinitePosition { role, .. } => Some(*role),
                _ => None,
            };
            let name = match role {
                Some(Role::RetractTarget(_)) => "retract.safe_pose",
                Some(_) => "approach.safe_pose",
                None if self
                    .framing
                    .safe_poses()
                    .iter()
                    .any(|p| p.len() != limits.len()) =>
                {
                    "approach.safe_pose"
                }
                None => "retract.safe_pose",
            };
            RosError::Param {
                name: name.into(),
                reason: format!("{e} (the robot cannot reach it)"),
            }
        })
    }
}

/// Reads how plans with a start are framed (issue 27): `approach.clearance` (m, default
/// 0.01), `approach.lead_distance` (m along the tool axis, default 0.03),
/// `approach.lead_clearance` (m, default 0.0005), `approach.safe_pose` (one position per
/// joint: the approach passes through it when the direct move is not clear; default none),
/// `approach.control_period` (s, default 0.004: the executor's), `retract.distance` (m along
/// the tool axis, default 0.05), `retract.safe_pose` (the retract ends there; default none).
/// Each number must be finite and > 0. The safe poses are checked against the robot's limits
/// when the node starts.
///
/// # Errors
/// [`RosError::Param`] naming the parameter.
pub fn framing_from_params(params: &Params) -> Result<kerf_approach::FrameSettings, RosError> {
    use kerf_approach::FrameSettings as F;
    let number = |name: &str, default: f64| params.f64_or(name, default);
    let b = F::builder()
        .clearance(number(
            "approach.clearance",
            kerf_approach::frame::DEFAULT_CLEARANCE,
        )?)
        .lead_distance(number(
            "approach.lead_distance",
            kerf_approach::frame::DEFAULT_LEAD_DISTANCE,
        )?)
        .lead_clearance(number(
            "approach.lead_clearance",
            kerf_approach::frame::DEFAULT_LEAD_CLEARANCE,
        )?)
        .control_period(number(
            "approach.control_period",
            kerf_approach::settings::DEFAULT_CONTROL_PERIOD,
        )?)
        .retract_distance(number(
            "retract.distance",
            kerf_approach::frame::DEFAULT_RETRACT_DISTANCE,
        )?)
        .safe_poses(
            params
                .f64_array("approach.safe_pose")?
                .into_iter()
                .collect(),
        )
        .retract_safe_pose(params.f64_array("retract.safe_pose")?);
    b.build().map_err(|e| {
        let name = match &e {
            kerf_approach::ApproachError::InvalidSetting { field, .. } => match field.as_str() {
                "clearance" => "approach.clearance",
                "lead_distance" => "approach.lead_distance",
                "lead_clearance" => "approach.lead_clearance",
                "control_period" => "approach.control_period",
                "retract_distance" => "retract.distance",
                f if f.starts_with("safe_poses") => "approach.safe_pose",
                f if f.starts_with("retract_safe_pose") => "retract.safe_pose",
                _ => "approach",
            },
            _ => "approach",
        };
        RosError::Param {
            name: name.into(),
            reason: e.to_string(),
        }
    })
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
