//! The minimum-jerk QP of one rotary axis, q4 or q5 (seed 001 eq. 15,
//! 19-45, 57-61).
//!
//! ```text
//! min_Θ  Θᵀ H Θ                                      (eq. 19)
//! s.t.   q_min ≤ Θ_j ≤ q_max                         (eq. 15 row 1, 39)
//!        |(D₁Θ)_j| ≤ ω_max σ/f                       (eq. 15, 21, 40)
//!        |(D₂Θ)_j| ≤ α_max σ²/f²                     (eq. 15, 22, 41)
//!        |(D₃Θ)_j| ≤ J_max σ³/f³                     (eq. 15, 23, 42)
//!        q_u(0), q_u(1), q_uu(0), q_uu(1) given      (eq. 45)
//!        q(ũ_i) = q_i  for every RTO                 (eq. 57-60)
//! ```
//!
//! `D_r` is the exact derivative-coefficient operator of `kerf_bspline`
//! (eq. 12, with the clamped-end correction documented there). Position
//! bounds on the coefficients and kinematic bounds on the derivative
//! coefficients are sufficient by the convex hull property (section 2.1):
//! the spline of the r-th derivative lies between its smallest and largest
//! coefficient.
//!
//! # How it is solved
//!
//! For 628 coefficients `H` has entries ≈ 10¹⁷ while the optimal cost of a
//! 1 rad motion is ≈ 10⁴: smooth motions live 13 orders of magnitude below
//! the scale of `H`. The paper's form (eq. 61) handed directly to an
//! interior-point solver stops far from the optimum or reports false
//! infeasibility, depending on the scaling (measured with Clarabel: with
//! `H/max|H|` the cost found is 6·10⁸ instead of 2.2·10⁴; unscaled, a
//! feasible problem is declared infeasible). So the problem is solved in
//! three steps, each exact up to rounding:
//!
//! 1. **Equality-only optimum.** Minimise eq. 19 under the boundary and RTO
//!    equalities alone (a banded KKT solve, `qp::kkt`). If it satisfies
//!    every bound it is the optimum of eq. 61 (a relaxation's optimum that
//!    is feasible is optimal) and no interior-point solve is needed.
//! 2. **Interior point (Clarabel) on a lifted form.** Variables
//!    `(Θ, y₁, y₂, y₃)` with `y_r = E_r y_{r−1}` (`E_r` one step of the
//!    recursion eq. 12, so `y_r = D_r Θ`), the objective `y₃ᵀ G y₃` with
//!    `G` the Gram matrix of the degree k − 3 basis of the jerk spline
//!    (`H = D₃ᵀ G D₃`, so the cost is the same, eq. 17-19), and the bounds
//!    of eq. 15 as plain bounds on Θ and y_r. `G` is well conditioned
//!    (entries ≈ 1/n), so the solver converges reliably and its status
//!    (optimal / infeasible) can be trusted. Bounds far from the
//!    equality-only optimum are left out and added only if the answer
//!    reaches them (exact, see `RotaryModel::lazy_solve`). The answer
//!    identifies the active bounds.
//! 3. **Polish.** The optimum of eq. 61 is the equality-constrained optimum
//!    with the active bounds held; it is solved exactly (banded KKT with
//!    iterative refinement), and the KKT conditions of eq. 61 are checked
//!    (all bounds hold, all active multipliers have the right sign), with
//!    the active set corrected if needed (`qp::active_set`).
//!
//! The reported cost is evaluated as `(D₃Θ)ᵀ G (D₃Θ)` rather than `ΘᵀHΘ`:
//! the same number, without the cancellation of summing terms of 10¹⁷.

use kerf_bspline::KnotVector;
use kerf_bspline::{basis_row, derivative_operator, BandRow, BandRows, BandedSym, BsplineError};

use super::active_set::{polish, LinRow, PolishQp, Side};
use super::constraints::{Bound, ConstraintSet};
use super::diagnose::{culprit, max_feasible_feedrate};
use super::lifting::JerkChain;
use super::solve::{solve, Objective, Verdict};
use crate::error::ConstraintFamily;
use crate::machine::AxisLimits;
use crate::PlanError;

/// Order in which constraint families are dropped to find the cause of an
/// infeasible rotary QP: the kinematic bounds first (they are the ones a
/// feedrate change can fix), then position, RTO and boundary equalities.
/// Each family is tried alone; after the three kinematic families, the
/// three are also tried together (a feedrate too high for the velocity,
/// acceleration and jerk limits at once is fixed by none of them alone);
/// if no single family explains it, they are dropped cumulatively in this
/// order.
pub const ROTARY_DIAGNOSIS_ORDER: [ConstraintFamily; 6] = [
    ConstraintFamily::Jerk,
    ConstraintFamily::Acceleration,
    ConstraintFamily::Velocity,
    ConstraintFamily::Position,
    ConstraintFamily::Rto,
    ConstraintFamily::Boundary,
];

/// A bound counts as active in the interior-point answer when its slack is
/// below this fraction of the bound.
const ACTIVE_REL: f64 = 1e-5;

/// Most rounds of lazily added bounds before all are added at once.
const MAX_LAZY_ROUNDS: usize = 8;

/// The minimum-jerk QP of one rotary axis (seed 001 eq. 61).
#[derive(Debug, Clone, Copy)]
pub struct RotaryProblem<'a> {
    /// Axis name ("q4" / "q5"), used in errors.
    pub axis_name: &'a str,
    /// Knot vector of the joint spline (degree ≥ 3).
    pub knots: &'a KnotVector,
    /// Jerk Hessian of these knots (`kerf_bspline::jerk_hessian`, eq. 18).
    pub hessian: &'a BandedSym,
    /// The axis limits (Table 2 row; rad, rad/s, rad/s², rad/s³).
    pub limits: AxisLimits,
    /// Path length σ (m).
    pub sigma: f64,
    /// Constant feedrate f (m/s).
    pub feedrate: f64,
    /// `[q_u(0), q_u(1), q_uu(0), q_uu(1)]` in u-units (rad, rad; eq. 45).
    pub boundary: [f64; 4],
    /// RTO equalities `(ũ_i, q_i)`: `q(ũ_i) = q_i` (eq. 57-60).
    pub via: &'a [(f64, f64)],
}

/// The optimal spline of a rotary axis.
#[derive(Debug, Clone, PartialEq)]
pub struct RotarySolution {
    /// The coefficients Θ (rad), one per basis function.
    pub coeffs: Vec<f64>,
    /// Clarabel's interior-point iterations (0 when the equality-only
    /// optimum already satisfied every bound).
    pub iterations: u32,
    /// `Θᵀ H Θ = ∫₀¹ q'''(u)² du` (rad², eq. 19; the time-domain jerk cost
    /// of eq. 17 is this times f⁵/σ⁵), evaluated as `(D₃Θ)ᵀ G (D₃Θ)`.
    pub objective: f64,
}

/// Solves the rotary-axis QP of seed 001 eq. 61 (method in the module
/// documentation).
///
/// # Errors
/// * [`PlanError::InvalidRequest`] for malformed inputs: non-finite or
///   non-positive σ or f, NaN limits or `min > max`, non-positive
///   velocity/acceleration/jerk limits, non-finite boundary values, a via
///   with a non-finite value or ũ outside [0, 1], a Hessian that is not the
///   jerk Hessian of the knots (size or values), degree below 3;
/// * [`PlanError::Infeasible`] when Clarabel certifies infeasibility: the
///   family is the first of [`ROTARY_DIAGNOSIS_ORDER`] whose removal makes
///   the problem feasible; when only dropping the three kinematic families
///   together does, the one closest to its bound at the largest feasible
///   feedrate; if nothing but a cumulative drop works, the last family
///   dropped. For the velocity, acceleration and jerk families,
///   `max_feasible_feedrate` is the largest feasible f found by bisection
///   to 0.1 % (feasibility is monotone in f because those bounds scale with
///   `1/f^r`, see `qp::diagnose`);
/// * [`PlanError::Solver`] when no certified optimum is found: Clarabel
///   stops with another status (`MaxIterations`, `NumericalError`, ...,
///   named in the message) without a finite iterate, or its answer
///   (`Solved`, or `AlmostSolved`/stopped with an iterate that failed the
///   1e-6 post-check) cannot be polished into a point that meets every
///   constraint to 1e-9 relative with correctly signed multipliers. Every
///   returned solution passed that check, which is stricter than the
///   post-check of an `AlmostSolved` answer.
///
/// # Performance
/// Step 1 is O(n k²): ≈ 2-4 ms for n + 1 = 628 in release builds on the
/// 2-core test machine. Step 2, only when a bound is active, is one or a
/// few sparse interior-point solves of ≈ 4(n + 1) variables: ≈ 20-60 ms
/// for n + 1 = 628 on that machine. The diagnosis of an infeasible problem
/// costs up to seven more solves, plus ≈ 12 for the feedrate bisection.
pub fn solve_rotary(p: &RotaryProblem) -> Result<RotarySolution, PlanError> {
    let model = RotaryModel::new(p)?;
    let ineq = model.direct_bounds(p.feedrate);
    // Step 1: the equality-only optimum, optimal if it satisfies every bound.
    let reference = model.equality_optimum().ok();
    if let Some(theta) = &reference {
        if ineq.iter().all(|b| b.row.violated(theta).is_none()) {
            return Ok(model.solution(theta.clone(), 0));
        }
    }
    let reference = reference.unwrap_or_else(|| vec![0.0; model.n1]);
    // Step 2: interior point on the lifted form, with lazily added bounds.
    let (verdict, included) = model.lazy_solve(p.feedrate, &[], &reference)?;
    let (x, iterations, status) = match verdict {
        Verdict::Optimal { x, iterations } => (x, iterations, "solved".to_string()),
        Verdict::Infeasible { status } => {
            return Err(model.diagnose(&reference, &format!("{status:?}"))?)
        }
        // An uncertified answer may still show the active bounds; the
        // polish below certifies or rejects the result.
        Verdict::Failed {
            detail,
            last: Some((x, iterations)),
        } => (x, iterations, detail),
        Verdict::Failed { detail, last: None } => {
            return Err(PlanError::Solver {
                problem: p.axis_name.to_string(),
                detail,
            })
        }
    };
    // Step 3: polish from the active bounds of the interior point.
    let active = model.active_set(&x, &ineq, &included);
    let theta = model
        .polish(&ineq, active)
        .map_err(|detail| PlanError::Solver {
            problem: p.axis_name.to_string(),
            detail: format!(
                "Clarabel: {status} ({iterations} iterations); the polish failed: {detail}"
            ),
        })?;
    Ok(model.solution(theta, iterations))
}

/// A bound of eq. 15 in the direct form (a row on Θ), with its family and
/// the lifted variable it bounds.
struct DirectBound {
    family: ConstraintFamily,
    row: LinRow,
    /// Column of the matching variable in the lifted vector.
    lifted_col: usize,
}

impl DirectBound {
    /// Whether `v` lies in the outer `1 − θ` fraction of the half-width of
    /// the bound interval (or outside it): `|v − mid| ≥ θ · half`. A
    /// one-sided bound is always "near".
    fn near(&self, v: f64, theta: f64) -> bool {
        let (lo, hi) = (self.row.lo, self.row.hi);
        if !(lo.is_finite() && hi.is_finite()) {
            return true;
        }
        let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
        v.is_nan() || (v - mid).abs() >= theta * half
    }
}

/// A validated rotary problem with its feedrate-independent parts.
struct RotaryModel<'p, 'a> {
    p: &'p RotaryProblem<'a>,
    /// Number of coefficients n + 1.
    n1: usize,
    /// D₁, D₂, D₃ (eq. 12, 21-23).
    derivative_ops: [BandRows; 3],
    /// The lifting `Θ → y₁ → y₂ → y₃` and the jerk Gram matrix.
    chain: JerkChain,
    /// Column offsets of y₁, y₂, y₃ in the lifted vector.
    offsets: [usize; 3],
    /// Lifted objective `y₃ᵀ G y₃` (Clarabel form, P = 2G).
    lifted_objective: Objective,
    /// Equality rows on Θ: eq. 45 (boundary) then eq. 59-60 (RTO).
    equalities: Vec<(ConstraintFamily, LinRow)>,
    /// Eq. 45 rows on the lifted y₁ (first two) and y₂ (last two).
    lifted_boundary: [BandRow; 4],
    /// Greville abscissae of the coefficients (ordering keys).
    keys: Vec<f64>,
    /// `2H / max|H|`, upper triangle (polish objective).
    polish_p: Vec<(usize, usize, f64)>,
    /// `max|H|`.
    h_scale: f64,
}

impl<'p, 'a> RotaryModel<'p, 'a> {
    fn new(p: &'p RotaryProblem<'a>) -> Result<Self, PlanError> {
        validate(p)?;
        let name = p.axis_name;
        let bs = move |field: &'static str| {
            move |e: BsplineError| PlanError::invalid(format!("{name} {field}"), e.to_string())
        };
        let kv = p.knots;
        let k = kv.degree();
        let n1 = kv.n_coeffs();
        let op = |r| derivative_operator(kv, r).map_err(bs("knots"));
        let derivative_ops = [op(1)?, op(2)?, op(3)?];
        let chain = JerkChain::new(kv).map_err(bs("knots"))?;
        chain
            .check_hessian(p.hessian)
            .map_err(|why| PlanError::invalid(format!("{name} hessian"), why))?;
        let offsets = chain.y_offsets(n1);
        let nvars = n1 + chain.n_aux();
        let lifted_objective = Objective {
            n: nvars,
            p_upper: chain.objective_upper(n1, 1.0),
            q: vec![0.0; nvars],
        };
        let h_scale = p.hessian.max_abs();
        if !(h_scale.is_finite() && h_scale > 0.0) {
            return Err(PlanError::invalid(
                format!("{name} hessian"),
                format!("largest entry {h_scale} (must be finite and positive)"),
            ));
        }
        let polish_p = p
            .hessian
            .upper_triplets()
            .into_iter()
            .map(|(i, j, v)| (i, j, 2.0 * v / h_scale))
            .collect();
        // Boundary rows: on Θ (direct form, basis derivatives) and on y₁/y₂
        // (lifted form, basis of the derivative knots).
        let mut equalities = Vec::with_capacity(4 + p.via.len());
        let derivs = [(0.0, 1), (1.0, 1), (0.0, 2), (1.0, 2)];
        let mut lifted_boundary = Vec::with_capacity(4);
        for ((u, d), &v) in derivs.into_iter().zip(&p.boundary) {
            let row = basis_row(kv, u, d).map_err(bs("boundary"))?;
            // Checked relative to the kinematic bound of that derivative.
            let b = kinematic_bound(&p.limits, p.sigma, d, p.feedrate);
            let scale = if b.is_finite() { b } else { 1.0 };
            equalities.push((ConstraintFamily::Boundary, lin_eq(&row, 0, v, scale)));
            let kd = chain.derivative_knots(d).ok_or_else(|| {
                PlanError::invalid(format!("{name} boundary"), "no derivative knots")
            })?;
            lifted_boundary.push(basis_row(kd, u, 0).map_err(bs("boundary"))?);
        }
        let l = &p.limits;
        let range = l.min.abs().max(l.max.abs());
        let via_scale = if range.is_finite() { range } else { 1.0 };
        for &(u, q) in p.via {
            let row = basis_row(kv, u, 0).map_err(bs("via"))?;
            equalities.push((ConstraintFamily::Rto, lin_eq(&row, 0, q, via_scale)));
        }
        let knots = kv.knots();
        let keys = (0..n1)
            .map(|j| {
                knots
                    .get(j + 1..=j + k)
                    .map_or(0.0, |s| s.iter().sum::<f64>() / k as f64)
            })
            .collect();
        let lifted_boundary: [BandRow; 4] = lifted_boundary
            .try_into()
            .map_err(|_| PlanError::invalid(format!("{name} boundary"), "four rows expected"))?;
        Ok(Self {
            p,
            n1,
            derivative_ops,
            chain,
            offsets,
            lifted_objective,
            equalities,
            lifted_boundary,
            keys,
            polish_p,
            h_scale,
        })
    }

    /// The kinematic bound on |Θ^{r}| at feedrate f: `L_r σ^r / f^r`
    /// (eq. 15, 40-42), r = 1, 2, 3.
    fn kinematic_bound(&self, r: usize, f: f64) -> f64 {
        kinematic_bound(&self.p.limits, self.p.sigma, r, f)
    }

    /// The bounds of eq. 15 in the direct form (rows on Θ), at feedrate f.
    fn direct_bounds(&self, f: f64) -> Vec<DirectBound> {
        let l = &self.p.limits;
        let mut out = Vec::with_capacity(4 * self.n1);
        if l.min.is_finite() || l.max.is_finite() {
            for j in 0..self.n1 {
                out.push(DirectBound {
                    family: ConstraintFamily::Position,
                    row: LinRow {
                        entries: vec![(j, 1.0)],
                        lo: l.min,
                        hi: l.max,
                        scale: 0.0,
                    },
                    lifted_col: j,
                });
            }
        }
        let families = [
            ConstraintFamily::Velocity,
            ConstraintFamily::Acceleration,
            ConstraintFamily::Jerk,
        ];
        for (r, (op, family)) in self.derivative_ops.iter().zip(families).enumerate() {
            let b = self.kinematic_bound(r + 1, f);
            if !b.is_finite() {
                continue;
            }
            for (j, row) in op.rows.iter().enumerate() {
                let mut lr = lin_eq(row, 0, 0.0, 0.0);
                lr.lo = -b;
                lr.hi = b;
                out.push(DirectBound {
                    family,
                    row: lr,
                    lifted_col: self.offsets[r] + j,
                });
            }
        }
        out
    }

    /// The constraints of eq. 61 on the lifted variables at feedrate `f`,
    /// with the structural rows `E_r y_{r−1} − y_r = 0` (family `None`):
    /// every equality, and the bounds `ineq[i]` with `include[i]`.
    fn lifted_constraints(
        &self,
        f: f64,
        ineq: &[DirectBound],
        include: &[bool],
    ) -> Result<ConstraintSet, PlanError> {
        let p = self.p;
        let mut set = ConstraintSet::new(self.lifted_objective.n);
        let bounds = [1, 2, 3].map(|r| self.kinematic_bound(r, f));
        let scales = bounds.map(|b| if b.is_finite() { b } else { 1.0 });
        self.chain.push_structural(&mut set, 0, self.n1, scales)?;
        for (b, _) in ineq.iter().zip(include).filter(|(_, &inc)| inc) {
            let bound = Bound::Range {
                lo: b.row.lo,
                hi: b.row.hi,
            };
            set.push(Some(b.family), vec![(b.lifted_col, 1.0)], bound, 0.0)?;
        }
        for (i, (row, &v)) in self.lifted_boundary.iter().zip(&p.boundary).enumerate() {
            let r = if i < 2 { 0 } else { 1 };
            let scale = if bounds[r].is_finite() {
                bounds[r]
            } else {
                1.0
            };
            let family = Some(ConstraintFamily::Boundary);
            set.push_band(family, self.offsets[r], row, Bound::Eq(v), scale)?;
        }
        for (family, row) in &self.equalities {
            if *family == ConstraintFamily::Rto {
                let bound = Bound::Eq(row.lo);
                set.push(Some(*family), row.entries.clone(), bound, row.scale)?;
            }
        }
        Ok(set)
    }

    /// The included bounds active (slack below [`ACTIVE_REL`]) in a lifted
    /// interior-point solution.
    fn active_set(&self, x: &[f64], ineq: &[DirectBound], include: &[bool]) -> Vec<(usize, Side)> {
        ineq.iter()
            .zip(include)
            .enumerate()
            .filter(|(_, (_, &inc))| inc)
            .filter_map(|(i, (b, _))| {
                let v = x.get(b.lifted_col).copied()?;
                let near = |bound: f64| (v - bound).abs() <= ACTIVE_REL * bound.abs().max(1e-9);
                if b.row.hi.is_finite() && near(b.row.hi) {
                    Some((i, Side::Upper))
                } else if b.row.lo.is_finite() && near(b.row.lo) {
                    Some((i, Side::Lower))
                } else {
                    None
                }
            })
            .collect()
    }

    /// `x ↦ 2 D₃ᵀ G D₃ x / max|H|`: the polish Hessian product without the
    /// cancellation of the assembled H.
    fn apply_h(&self, x: &[f64]) -> Vec<f64> {
        self.chain
            .apply_h(x)
            .into_iter()
            .map(|v| 2.0 * v / self.h_scale)
            .collect()
    }

    /// The polish problem: objective `Θᵀ(2H/max|H|)Θ/2` with the accurate
    /// product, and the equality rows.
    fn polish_parts(&self) -> (Vec<f64>, Vec<LinRow>) {
        let eq = self.equalities.iter().map(|(_, r)| r.clone()).collect();
        (vec![0.0; self.n1], eq)
    }

    /// The optimum of eq. 19 under the equalities of eq. 45 and 58 alone.
    fn equality_optimum(&self) -> Result<Vec<f64>, String> {
        let (q, eq) = self.polish_parts();
        let apply = |x: &[f64]| self.apply_h(x);
        let qp = PolishQp {
            n: self.n1,
            p_upper: &self.polish_p,
            apply_p: Some(&apply),
            q: &q,
            keys: &self.keys,
        };
        polish(&qp, &eq, &[], Vec::new())
    }

    /// The optimum of eq. 61 from an active-set guess (see
    /// `qp::active_set`).
    fn polish(&self, ineq: &[DirectBound], active: Vec<(usize, Side)>) -> Result<Vec<f64>, String> {
        let (q, eq) = self.polish_parts();
        let apply = |x: &[f64]| self.apply_h(x);
        let qp = PolishQp {
            n: self.n1,
            p_upper: &self.polish_p,
            apply_p: Some(&apply),
            q: &q,
            keys: &self.keys,
        };
        let rows: Vec<LinRow> = ineq.iter().map(|b| b.row.clone()).collect();
        polish(&qp, &eq, &rows, active)
    }

    /// Clarabel on the lifted form at feedrate `f` without the families
    /// `dropped`, adding bounds lazily: first those whose value at
    /// `reference` (coefficients Θ) is in the outer half of their interval,
    /// then, round after round, every bound the answer violates or comes
    /// within 10 % of. Far-away bounds never enter, which keeps the problem
    /// small and well scaled (a loose bound of 10⁸ next to values of 10²
    /// would otherwise dominate the solver's residual norms). The answer is
    /// exact: an optimum of a subset of the bounds that satisfies all of
    /// them is optimal for all; infeasibility of a subset implies
    /// infeasibility of all.
    ///
    /// # Returns
    /// The verdict of the last round (iterations summed) and the bounds
    /// included.
    fn lazy_solve(
        &self,
        f: f64,
        dropped: &[ConstraintFamily],
        reference: &[f64],
    ) -> Result<(Verdict, Vec<bool>), PlanError> {
        let ineq = self.direct_bounds(f);
        let allowed = |b: &DirectBound| !dropped.contains(&b.family);
        let mut include: Vec<bool> = ineq
            .iter()
            .map(|b| allowed(b) && b.near(b.row.value(reference), 0.5))
            .collect();
        let keep = |fam: ConstraintFamily| !dropped.contains(&fam);
        let mut total = 0;
        for _ in 0..MAX_LAZY_ROUNDS {
            let set = self.lifted_constraints(f, &ineq, &include)?;
            let verdict = solve(self.p.axis_name, &self.lifted_objective, &set, &keep)?;
            let Verdict::Optimal { x, iterations } = verdict else {
                return Ok((verdict, include));
            };
            total += iterations;
            let mut added = false;
            for (b, inc) in ineq.iter().zip(include.iter_mut()) {
                if !*inc && allowed(b) {
                    let v = x.get(b.lifted_col).copied().unwrap_or(f64::NAN);
                    if b.near(v, 0.9) {
                        *inc = true;
                        added = true;
                    }
                }
            }
            if !added {
                return Ok((
                    Verdict::Optimal {
                        x,
                        iterations: total,
                    },
                    include,
                ));
            }
        }
        // Still adding after the round limit: solve with every bound.
        let include: Vec<bool> = ineq.iter().map(allowed).collect();
        let set = self.lifted_constraints(f, &ineq, &include)?;
        let verdict = solve(self.p.axis_name, &self.lifted_objective, &set, &keep)?;
        Ok((verdict, include))
    }

    /// The solution record of coefficients Θ.
    fn solution(&self, coeffs: Vec<f64>, iterations: u32) -> RotarySolution {
        let objective = self.chain.jerk_cost(&coeffs);
        RotarySolution {
            coeffs,
            iterations,
            objective,
        }
    }

    /// Whether the problem at feedrate `f` without the families in
    /// `dropped` has an (accepted) optimum.
    fn feasible(
        &self,
        f: f64,
        dropped: &[ConstraintFamily],
        reference: &[f64],
    ) -> Result<bool, PlanError> {
        Ok(self.lazy_solve(f, dropped, reference)?.0.is_feasible())
    }

    /// The kinematic family whose bound is the most used (largest
    /// `max |y_r| / b_r`) by the optimum at feedrate `f`, ties to the
    /// higher derivative.
    fn tightest_kinematic(
        &self,
        f: f64,
        reference: &[f64],
    ) -> Result<Option<ConstraintFamily>, PlanError> {
        let (Verdict::Optimal { x, .. }, _) = self.lazy_solve(f, &[], reference)? else {
            return Ok(None);
        };
        let families = [
            ConstraintFamily::Velocity,
            ConstraintFamily::Acceleration,
            ConstraintFamily::Jerk,
        ];
        let mut best: Option<(f64, ConstraintFamily)> = None;
        for (r, family) in families.into_iter().enumerate() {
            let b = self.kinematic_bound(r + 1, f);
            let len = self.n1 - (r + 1);
            let start = self.offsets[r];
            let peak = x
                .get(start..start + len)
                .unwrap_or(&[])
                .iter()
                .fold(0.0_f64, |m, v| m.max(v.abs()));
            let ratio = peak / b;
            if best.is_none_or(|(q, _)| ratio >= q * (1.0 - 1e-6)) {
                best = Some((ratio, family));
            }
        }
        Ok(best.map(|(_, f)| f))
    }

    /// The [`PlanError::Infeasible`] of an infeasible problem.
    fn diagnose(&self, reference: &[f64], status: &str) -> Result<PlanError, PlanError> {
        let p = self.p;
        use ConstraintFamily::{Acceleration, Boundary, Jerk, Position, Rto, Velocity};
        let candidates: [&[ConstraintFamily]; 7] = [
            &[Jerk],
            &[Acceleration],
            &[Velocity],
            &[Jerk, Acceleration, Velocity],
            &[Position],
            &[Rto],
            &[Boundary],
        ];
        let found = culprit(&candidates, &ROTARY_DIAGNOSIS_ORDER, &mut |dropped| {
            self.feasible(p.feedrate, dropped, reference)
        })?;
        let Some(c) = found else {
            return Ok(PlanError::Solver {
                problem: p.axis_name.to_string(),
                detail: format!(
                    "Clarabel reports {status}, yet the problem stays infeasible with every \
                     constraint family dropped"
                ),
            });
        };
        let names: Vec<String> = c.dropped.iter().map(|f| f.to_string()).collect();
        let mut detail = format!(
            "Clarabel reports {status} at f = {:.6} m/s over σ = {:.6} m; feasible without the {}",
            p.feedrate,
            p.sigma,
            names.join(" and ")
        );
        let kinematic = c.dropped.iter().all(|f| {
            matches!(
                f,
                ConstraintFamily::Velocity
                    | ConstraintFamily::Acceleration
                    | ConstraintFamily::Jerk
            )
        });
        let mut max_feasible = None;
        let mut family = c.family;
        if kinematic {
            for (r, name) in [(1, "|Θ'|"), (2, "|Θ''|"), (3, "|Θ'''|")] {
                detail += &format!("; {name} ≤ {:.6e}", self.kinematic_bound(r, p.feedrate));
            }
            max_feasible =
                max_feasible_feedrate(p.feedrate, &mut |f| self.feasible(f, &[], reference))?;
            if let (Some(fmax), true) = (max_feasible, c.dropped.len() > 1) {
                // Several kinematic families bind together: report the one
                // closest to its bound at the largest feasible feedrate.
                if let Some(tightest) = self.tightest_kinematic(fmax, reference)? {
                    family = tightest;
                }
            }
        } else {
            let l = &p.limits;
            for (i, &(u, q)) in p.via.iter().enumerate() {
                if q < l.min || q > l.max {
                    detail += &format!(
                        "; RTO {i} (u = {u:.6}) asks {} = {q:.6} outside [{:.6}, {:.6}]",
                        p.axis_name, l.min, l.max
                    );
                }
            }
        }
        Ok(PlanError::Infeasible {
            problem: p.axis_name.to_string(),
            family,
            detail,
            max_feasible_feedrate: max_feasible,
        })
    }
}

/// The kinematic bound on |Θ^{r}| at feedrate f: `L_r σ^r / f^r`
/// (eq. 15, 40-42), r = 1, 2, 3.
fn kinematic_bound(l: &AxisLimits, sigma: f64, r: usize, f: f64) -> f64 {
    let limit = match r {
        1 => l.vel,
        2 => l.acc,
        _ => l.jerk,
    };
    limit * (sigma / f).powi(r as i32)
}

/// A [`LinRow`] equality `row·x = v` with columns shifted by `offset`.
fn lin_eq(row: &BandRow, offset: usize, v: f64, scale: f64) -> LinRow {
    LinRow {
        entries: row
            .values
            .iter()
            .enumerate()
            .map(|(i, &a)| (offset + row.start + i, a))
            .collect(),
        lo: v,
        hi: v,
        scale,
    }
}

/// Checks every input of a rotary problem (see [`solve_rotary`] errors).
fn validate(p: &RotaryProblem) -> Result<(), PlanError> {
    let field = |f: &str| format!("{} {f}", p.axis_name);
    let bad = |f: &str, why: String| Err(PlanError::invalid(field(f), why));
    if !(p.sigma.is_finite() && p.sigma > 0.0) {
        return bad(
            "path length",
            format!("σ = {} m must be finite and positive", p.sigma),
        );
    }
    if !(p.feedrate.is_finite() && p.feedrate > 0.0) {
        return bad(
            "feedrate",
            format!("f = {} m/s must be finite and positive", p.feedrate),
        );
    }
    let l = &p.limits;
    if l.min.is_nan() || l.max.is_nan() || l.min > l.max {
        return bad("limits", format!("position range [{}, {}]", l.min, l.max));
    }
    for (name, v) in [
        ("velocity", l.vel),
        ("acceleration", l.acc),
        ("jerk", l.jerk),
    ] {
        if v.is_nan() || v <= 0.0 {
            return bad("limits", format!("{name} limit {v} must be positive"));
        }
    }
    if let Some((i, v)) = p.boundary.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return bad(&format!("boundary[{i}]"), format!("{v} is not finite"));
    }
    for (i, &(u, q)) in p.via.iter().enumerate() {
        if !(u.is_finite() && (0.0..=1.0).contains(&u)) {
            return bad(&format!("via[{i}]"), format!("u = {u} is not in [0, 1]"));
        }
        if !q.is_finite() {
            return bad(&format!("via[{i}]"), format!("value {q} is not finite"));
        }
    }
    let k = p.knots.degree();
    if k < 3 {
        return bad("knots", format!("degree {k} < 3: no jerk to minimise"));
    }
    let n = p.knots.n_coeffs();
    if p.hessian.n() != n {
        return bad(
            "hessian",
            format!(
                "size {} differs from the {n} spline coefficients",
                p.hessian.n()
            ),
        );
    }
    Ok(())
}
