//! The one error type of `kerf_millplan`.

use kerf_chatter::ChatterError;
use kerf_mill::MillError;
use thiserror::Error;

/// Everything that can go wrong while planning a milling path.
#[derive(Debug, Error)]
pub enum MillPlanError {
    /// A parameter or input is NaN, infinite or out of its range.
    #[error("invalid {name} = {value}: {reason}")]
    InvalidParameter {
        /// Name with unit.
        name: String,
        /// The value given.
        value: f64,
        /// Why it is refused.
        reason: String,
    },
    /// A configuration or file content is inconsistent (not a single number).
    #[error("invalid {name}: {reason}")]
    InvalidConfig {
        /// What is wrong (field, file).
        name: String,
        /// Why.
        reason: String,
    },
    /// The robot/cell model failed (unreachable, joint limit, bad cell file).
    #[error(transparent)]
    Mill(#[from] MillError),
    /// The chatter model failed (non-convergence, bad parameters).
    #[error(transparent)]
    Chatter(#[from] ChatterError),
    /// A policy file is missing, unreadable or incompatible.
    #[error("policy {path}: {reason}")]
    Policy {
        /// File path.
        path: String,
        /// What is wrong (missing, wrong sizes, settings mismatch).
        reason: String,
    },
    /// File input/output failed.
    #[error("{path}: {message}")]
    Io {
        /// File path.
        path: String,
        /// The OS or parser message.
        message: String,
    },
    /// The learning backend (candle) failed.
    #[error("learning backend: {0}")]
    Backend(String),
    /// The executed trajectory fails the trajectory executor's own validation
    /// (`kerf_executor::check_executable`): a planner bug, or a cell whose robot the executor
    /// cannot model (a joint without an acceleration limit).
    #[error("the executed trajectory would be refused by the trajectory executor: {reason}")]
    NotExecutable {
        /// The executor's reason.
        reason: String,
    },
    /// The executed trajectory passes closer to a singularity than the request allows: its
    /// condition indicator 1/K (seed 004 eq. 14) falls below the requested minimum.
    #[error(
        "the plan's condition indicator 1/K falls to {value:.4} at arc length {arc_length:.4} m \
         (segment {segment}), below the requested minimum {minimum}"
    )]
    IllConditioned {
        /// The smallest 1/K along the executed trajectory.
        value: f64,
        /// Where \[m\].
        arc_length: f64,
        /// The plan segment there.
        segment: usize,
        /// The requested minimum.
        minimum: f64,
    },
    /// Planning stopped before its end: the request's time budget ran out (status TIMEOUT) or
    /// the planner was cancelled (the node is stopping; INTERNAL_ERROR).
    #[error("{0}")]
    Interrupted(#[from] kerf_budget::Interrupt),
}
