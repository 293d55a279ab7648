//! One Clarabel solve of a QP and the mapping of its status to a verdict.
//!
//! Clarabel (0.11) minimises `½ xᵀPx + qᵀx` subject to `A x + s = b`,
//! `s ∈ K`, with `P` given by its upper triangle in CSC form.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus};

use super::constraints::{ConstraintSet, Violation};
use crate::error::ConstraintFamily;
use crate::PlanError;

/// Relative tolerance of the post-check of an `AlmostSolved` answer.
pub(crate) const POST_CHECK_TOL: f64 = 1e-6;

/// Iteration cap of one solve (Clarabel's default is 200; the QPs here
/// converge in 10–30).
const MAX_ITER: u32 = 200;

/// A quadratic objective `½ xᵀPx + qᵀx` over `n` variables.
#[derive(Debug, Clone)]
pub(crate) struct Objective {
    /// Number of variables.
    pub n: usize,
    /// Upper triangle of `P` as `(row, col, value)` with `row ≤ col`.
    pub p_upper: Vec<(usize, usize, f64)>,
    /// Linear term.
    pub q: Vec<f64>,
}

/// What a solve produced.
#[derive(Debug, Clone)]
pub(crate) enum Verdict {
    /// An optimal point that passed the checks.
    Optimal {
        /// The primal solution.
        x: Vec<f64>,
        /// Interior-point iterations.
        iterations: u32,
    },
    /// Clarabel certified (possibly with reduced accuracy) infeasibility.
    Infeasible {
        /// `PrimalInfeasible` or `AlmostPrimalInfeasible`.
        status: SolverStatus,
    },
    /// Anything else: no certified answer.
    Failed {
        /// Status name, iteration count and what went wrong.
        detail: String,
        /// The last finite iterate and the iteration count, if any: an
        /// `AlmostSolved` answer that failed the post-check, or where the
        /// solver stopped. Not an optimum, but a starting guess of the
        /// active bounds for a polish that certifies its own result.
        last: Option<(Vec<f64>, u32)>,
    },
}

impl Verdict {
    /// True for [`Verdict::Optimal`].
    pub fn is_feasible(&self) -> bool {
        matches!(self, Verdict::Optimal { .. })
    }
}

/// Solves `objective` under the rows of `constraints` whose family passes
/// `keep`, and classifies the result:
///
/// * `Solved` → [`Verdict::Optimal`] if `x` is finite;
/// * `AlmostSolved` → [`Verdict::Optimal`] only if every kept constraint
///   holds to [`POST_CHECK_TOL`] (see [`ConstraintSet::first_violation`]);
/// * `PrimalInfeasible`, `AlmostPrimalInfeasible` → [`Verdict::Infeasible`];
/// * any other status → [`Verdict::Failed`] with the status name.
///
/// # Errors
/// [`PlanError::Solver`] if Clarabel rejects the data or the settings
/// (a dimension bug, not a property of the request).
pub(crate) fn solve(
    problem: &str,
    objective: &Objective,
    constraints: &ConstraintSet,
    keep: &dyn Fn(ConstraintFamily) -> bool,
) -> Result<Verdict, PlanError> {
    let failed = |detail: String| PlanError::Solver {
        problem: problem.to_string(),
        detail,
    };
    let n = objective.n;
    if constraints.ncols() != n || objective.q.len() != n {
        return Err(failed(format!(
            "dimension mismatch: {n} variables, {} constraint columns, {} linear terms",
            constraints.ncols(),
            objective.q.len()
        )));
    }
    if let Some(&(i, j, v)) = objective
        .p_upper
        .iter()
        .find(|&&(i, j, v)| i > j || j >= n || !v.is_finite())
    {
        return Err(failed(format!("bad Hessian entry ({i}, {j}) = {v}")));
    }
    if objective.q.iter().any(|v| !v.is_finite()) {
        return Err(failed("non-finite linear term".into()));
    }
    let (pi, (pj, pv)): (Vec<usize>, (Vec<usize>, Vec<f64>)) = objective
        .p_upper
        .iter()
        .map(|&(i, j, v)| (i, (j, v)))
        .unzip();
    let p = CscMatrix::new_from_triplets(n, n, pi, pj, pv);
    let asm = constraints.assemble(keep);
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(MAX_ITER)
        .build()
        .map_err(|e| failed(format!("settings: {e}")))?;
    let mut solver = DefaultSolver::new(&p, &objective.q, &asm.a, &asm.b, &asm.cones, settings)
        .map_err(|e| failed(format!("setup: {e}")))?;
    solver.solve();
    let sol = &solver.solution;
    let iterations = sol.iterations;
    let finite = sol.x.iter().all(|v| v.is_finite());
    Ok(match sol.status {
        SolverStatus::Solved if finite => Verdict::Optimal {
            x: sol.x.clone(),
            iterations,
        },
        SolverStatus::AlmostSolved if finite => {
            match constraints.first_violation(&sol.x, POST_CHECK_TOL, keep) {
                None => Verdict::Optimal {
                    x: sol.x.clone(),
                    iterations,
                },
                Some(v) => Verdict::Failed {
                    detail: format!(
                        "AlmostSolved after {iterations} iterations, but {}",
                        describe(&v)
                    ),
                    last: Some((sol.x.clone(), iterations)),
                },
            }
        }
        s @ (SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible) => {
            Verdict::Infeasible { status: s }
        }
        s => Verdict::Failed {
            detail: format!(
                "{s:?} after {iterations} iterations{}",
                if finite { "" } else { " (non-finite solution)" }
            ),
            last: finite.then(|| (sol.x.clone(), iterations)),
        },
    })
}

/// A violation in words.
pub(crate) fn describe(v: &Violation) -> String {
    let family = v
        .family
        .map_or_else(|| "structural".to_string(), |f| f.to_string());
    format!(
        "{family} row {} is {:.9e} against {:.9e} (tolerance {:.1e})",
        v.index, v.value, v.bound, v.tolerance
    )
}
