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
    /// The plan chatters as executed (issue 28, item 1): a control-period sample in the
    /// material reaches |μ|max ≥ 1 ([`crate::chatter_judge`]). Status CHATTER.
    #[error("{}", chattering_message(planner, worst, lowest.as_ref(), reason))]
    Chattering {
        /// The planner whose plan chatters (`best`: every candidate).
        planner: String,
        /// The worst executed sample of that plan.
        worst: Box<crate::chatter_judge::JudgedSample>,
        /// The lowest executed |μ|max any planner reached on the path, and that planner.
        lowest: Option<(String, f64)>,
        /// Why no chatter-free plan exists, or which planner has one.
        reason: String,
    },
    /// The planner cannot plan this valid path (issue 28, item 2): e.g. `fixed_g` or `greedy`
    /// where g = g0 leaves a joint's limit or the reach on some segment. Status INFEASIBLE.
    #[error("{planner}: no plan on this path: {reason}")]
    Infeasible {
        /// The planner.
        planner: String,
        /// Why (segment, joint or reach, and what another planner can do).
        reason: String,
    },
    /// Planning stopped before its end: the request's time budget ran out (status TIMEOUT) or
    /// the planner was cancelled (the node is stopping; INTERNAL_ERROR).
    #[error("{0}")]
    Interrupted(#[from] kerf_budget::Interrupt),
}

/// The message of [`MillPlanError::Chattering`].
fn chattering_message(
    planner: &str,
    worst: &crate::chatter_judge::JudgedSample,
    lowest: Option<&(String, f64)>,
    reason: &str,
) -> String {
    let mu = if worst.spectral_radius.is_finite() {
        format!("{:.4}", worst.spectral_radius)
    } else {
        "undefined (no equilibrium of the chatter model)".to_string()
    };
    let lowest = lowest.map_or(String::new(), |(p, v)| {
        format!("; the lowest |μ|max any planner reached on this path is {v:.4} ({p})")
    });
    let reason = if reason.is_empty() {
        String::new()
    } else {
        format!("; {reason}")
    };
    format!(
        "{planner}: the plan chatters as executed: |μ|max {mu} at segment {} (arc length {:.4} m, \
         t = {:.3} s, {:.2} mm/s, {:.0} rpm, g = {:.4} rad){lowest}{reason}",
        worst.segment,
        worst.arc_length,
        worst.time,
        worst.feed * 1e3,
        worst.rpm,
        worst.g
    )
}
