//! The two QPs of the MJTO planner (seed 001 sections 2.2-2.4), solved
//! with Clarabel:
//!
//! * [`rotary`]: the minimum-jerk spline of one rotary axis, q4 or q5, under
//!   position, velocity, acceleration and jerk bounds, boundary and RTO
//!   equalities (eq. 15, 19-45, 57-61);
//! * [`mpath`]: the standoff axis q6 chosen to minimise the jerk of the
//!   M path `M = C − q6·O` (eq. 46-54, 62, Appendix A).
//!
//! Both are built directly from the banded B-spline structures of
//! `kerf_bspline` (no dense n × n matrix). The jerk Hessian of 628 quintic
//! coefficients spans 17 orders of magnitude, more than an interior-point
//! solver resolves, so the optimum is computed exactly by an active-set
//! polish on banded KKT systems (`qp::kkt`, `qp::active_set`), and Clarabel is
//! run on a well-conditioned lifted form (`qp::lifting`) to decide
//! feasibility and find the active bounds. Every returned solution is
//! certified: all constraints hold to 1e-9 relative and every active bound
//! has a multiplier of the right sign. An infeasible problem is diagnosed:
//! the error names the constraint family at fault and, when it is a
//! kinematic bound, the largest feasible feedrate.

mod active_set;
mod band_lu;
mod constraints;
mod diagnose;
mod kkt;
mod lifting;
pub mod mpath;
pub mod rotary;
mod solve;

pub use mpath::{
    mpath_dense_objective, mpath_tikhonov_weight, solve_mpath, MPathProblem, MPathSolution,
    MPATH_TIKHONOV,
};
pub use rotary::{solve_rotary, RotaryProblem, RotarySolution, ROTARY_DIAGNOSIS_ORDER};
