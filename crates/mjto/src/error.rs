//! The one error type of the planner.
//!
//! Every variant maps to a status code of `kerf_msgs/msg/CutPlan`
//! ([`PlanError::status`]) and carries what a cell engineer needs to fix the
//! request: which field, which point, which joint, by how much.

use thiserror::Error;

/// Which group of constraints of a QP is at fault when it has no solution.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConstraintFamily {
    /// Joint position bounds (eq. 15 first row, eq. 39).
    Position,
    /// Velocity bounds on the first derivative coefficients (eq. 15, 40).
    Velocity,
    /// Acceleration bounds on the second derivative coefficients (eq. 15, 41).
    Acceleration,
    /// Jerk bounds on the third derivative coefficients (eq. 15, 42).
    Jerk,
    /// Boundary equalities at u = 0 and u = 1 (eq. 45).
    Boundary,
    /// RTO via-point equalities (eq. 58-60, 62-64).
    Rto,
    /// The standoff stroke of the M-path QP (eq. 54, 62).
    Stroke,
    /// The lead/tilt allowance corridor of the q5 QP at the CL points (kerf, issue 16 item 3;
    /// `options.orientation_corridor: allowance`).
    Allowance,
}

impl std::fmt::Display for ConstraintFamily {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let s = match self {
            ConstraintFamily::Position => "position bounds",
            ConstraintFamily::Velocity => "velocity bounds",
            ConstraintFamily::Acceleration => "acceleration bounds",
            ConstraintFamily::Jerk => "jerk bounds",
            ConstraintFamily::Boundary => "boundary equalities",
            ConstraintFamily::Rto => "RTO equalities",
            ConstraintFamily::Stroke => "standoff stroke",
            ConstraintFamily::Allowance => "lead/tilt allowance corridor",
        };
        f.write_str(s)
    }
}

/// One collision (or orientation-tolerance violation) found on the dense
/// trajectory samples.
#[derive(Debug, Clone, PartialEq)]
pub struct CollisionReport {
    /// Normalized arc length u in [0, 1] of the sample.
    pub u: f64,
    /// Time from the start of the trajectory (s).
    pub time: f64,
    /// Index of the nearest CL point.
    pub cl_index: usize,
    /// Links of the cutting head in contact with the workpiece (empty when
    /// the violation is an orientation tolerance, not a contact).
    pub links: Vec<String>,
    /// Why this sample is rejected, in words.
    pub reason: String,
}

/// One limit violation on the dense samples.
#[derive(Debug, Clone, PartialEq)]
pub struct LimitViolation {
    /// Joint name (q1..q6).
    pub joint: String,
    /// "position", "velocity", "acceleration" or "jerk".
    pub quantity: &'static str,
    /// The sampled value (SI).
    pub value: f64,
    /// The limit it exceeds (SI, positive for magnitudes).
    pub limit: f64,
    /// Time of the sample (s).
    pub time: f64,
}

/// Everything that can make a cut request fail.
#[derive(Debug, Error)]
pub enum PlanError {
    /// A field of the request is malformed (NaN, wrong length, non-unit
    /// axis, repeated point, ...).
    #[error("invalid request: {field}: {reason}")]
    InvalidRequest {
        /// Field name as in `CutRequest`, with an index where it applies.
        field: String,
        /// What is wrong.
        reason: String,
    },
    /// The workpiece mesh cannot be found, read or used.
    #[error("workpiece mesh '{source_name}': {reason}")]
    Mesh {
        /// The mesh reference as given in the request.
        source_name: String,
        /// What went wrong.
        reason: String,
    },
    /// A CL point cannot be reached by the machine.
    #[error("CL point {index} is unreachable: {reason}")]
    Unreachable {
        /// Index of the CL point.
        index: usize,
        /// Which joint leaves its stroke and by how much.
        reason: String,
    },
    /// No feasible candidate in the GFD of a CL point: every sampled
    /// (q4, q5, q6) collides or leaves the lead/tilt limits.
    #[error("no collision-free tool orientation at CL point {index} (u = {u:.4}): {reason}")]
    NoFeasibleOrientation {
        /// Index of the CL point.
        index: usize,
        /// Its normalized arc length.
        u: f64,
        /// Candidate counts and causes.
        reason: String,
    },
    /// A QP has no solution.
    #[error("{problem} QP infeasible ({family}): {detail}{}", max_feasible_feedrate.map(|f| format!("; largest feasible feedrate {:.4} m/s ({:.2} m/min)", f, f * 60.0)).unwrap_or_default())]
    Infeasible {
        /// Which QP: "q4", "q5" or "M path".
        problem: String,
        /// The constraint family whose removal makes it feasible.
        family: ConstraintFamily,
        /// Details (solver status, values).
        detail: String,
        /// When the feedrate is the cause: the largest feasible one (m/s).
        max_feasible_feedrate: Option<f64>,
    },
    /// The solver stopped without an optimal or infeasibility certificate.
    #[error("{problem} QP solver failed: {detail}")]
    Solver {
        /// Which QP.
        problem: String,
        /// Solver status and iteration count.
        detail: String,
    },
    /// The loop ended with collisions left on the dense samples.
    #[error("trajectory still collides after {iterations} iterations at {} samples; first at u = {:.4}, t = {:.3} s: {}", collisions.len(), collisions.first().map(|c| c.u).unwrap_or(f64::NAN), collisions.first().map(|c| c.time).unwrap_or(f64::NAN), collisions.first().map(|c| c.reason.as_str()).unwrap_or(""))]
    Collision {
        /// Iterations run.
        iterations: usize,
        /// Every colliding sample (in time order).
        collisions: Vec<CollisionReport>,
    },
    /// The final trajectory leaves a joint limit on the dense samples.
    #[error("trajectory violates {} joint limit(s); first: {}", violations.len(), violations.first().map(|v| format!("{} {} {:.4} > {:.4} at t = {:.3} s", v.joint, v.quantity, v.value, v.limit, v.time)).unwrap_or_default())]
    LimitViolation {
        /// Every violation found (at most one per joint and quantity).
        violations: Vec<LimitViolation>,
    },
    /// The plan fails the trajectory executor's own validation
    /// (`kerf_executor::check_executable` of [`crate::CutPlan::joint_trajectory`]): a planner
    /// bug, never published as a success.
    #[error("the planned trajectory would be refused by the trajectory executor: {reason}")]
    NotExecutable {
        /// The executor's reason.
        reason: String,
    },
    /// Planning stopped before its end: the request's time budget ran out (status TIMEOUT) or
    /// the planner was cancelled (the node is stopping; INTERNAL_ERROR).
    #[error("{0}")]
    Interrupted(#[from] kerf_budget::Interrupt),
}

/// Status codes of `kerf_msgs/msg/CutPlan` (kept equal to the constants in
/// `msgs/msg/CutPlan.msg`).
pub mod status {
    /// The plan succeeded.
    pub const SUCCESS: u8 = 0;
    /// Malformed request.
    pub const INVALID_REQUEST: u8 = 1;
    /// Mesh missing or unreadable.
    pub const MESH_ERROR: u8 = 2;
    /// A CL point is outside the machine's stroke.
    pub const UNREACHABLE: u8 = 3;
    /// A QP is infeasible (constraint family named in the message).
    pub const INFEASIBLE: u8 = 4;
    /// Collisions remain (or no feasible orientation exists).
    pub const COLLISION: u8 = 5;
    /// A joint limit is exceeded on the dense samples.
    pub const LIMIT_VIOLATION: u8 = 6;
    /// Solver failure or another internal error.
    pub const INTERNAL_ERROR: u8 = 7;
    /// The request's time budget ran out before the plan was finished.
    pub const TIMEOUT: u8 = 8;
    /// The request queue is full (answered by the node's harness).
    pub const QUEUE_FULL: u8 = 9;
    /// The plan would need more memory than its budget allows.
    pub const RESOURCE_LIMIT: u8 = 10;
    /// No collision-free approach or retract (answered by the node's harness, issue 27).
    pub const NO_APPROACH: u8 = 11;
}

impl PlanError {
    /// The `CutPlan` status code of this error.
    pub fn status(&self) -> u8 {
        match self {
            PlanError::InvalidRequest { .. } => status::INVALID_REQUEST,
            PlanError::Mesh { .. } => status::MESH_ERROR,
            PlanError::Unreachable { .. } => status::UNREACHABLE,
            PlanError::Infeasible { .. } => status::INFEASIBLE,
            PlanError::NoFeasibleOrientation { .. } | PlanError::Collision { .. } => {
                status::COLLISION
            }
            PlanError::LimitViolation { .. } => status::LIMIT_VIOLATION,
            PlanError::Solver { .. } | PlanError::NotExecutable { .. } => status::INTERNAL_ERROR,
            PlanError::Interrupted(i) if i.is_timeout() => status::TIMEOUT,
            PlanError::Interrupted(i) if i.is_over_memory() => status::RESOURCE_LIMIT,
            PlanError::Interrupted(_) => status::INTERNAL_ERROR,
        }
    }

    /// Shorthand for [`PlanError::InvalidRequest`].
    pub fn invalid(field: impl Into<String>, reason: impl Into<String>) -> Self {
        PlanError::InvalidRequest {
            field: field.into(),
            reason: reason.into(),
        }
    }
}
