//! The two QPs of the MJTO planner (seed 001 sections 2.2-2.4), solved
//! with Clarabel:
//!
//! * [`rotary`]: the minimum-jerk spline of one rotary axis, q4 or q5, under
//!   position, velocity, acceleration and jerk bounds, boundary and RTO
//!   equalities (eq. 15, 19-45, 57-61);
//! * [`mpath`]: the standoff axis q6 chosen to minimise the jerk of the
//!   M path `M = C − q6·O` (eq. 46-54, 62, Appendix A).
//!
//! Both build sparse constraint matrices directly from the banded B-spline
//! structures of `kerf_bspline`, so a problem of 628 coefficients solves in
//! milliseconds. An infeasible problem is diagnosed: the error names the
//! constraint family at fault and, when it is a kinematic bound, the largest
//! feasible feedrate.

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
