//! The M-path QP of the standoff axis q6 (seed 001 eq. 46-54, 62-64,
//! Appendix A).
//!
//! # The model
//!
//! The M point is the centre of the rotary axes. Seed 001 eq. 46 writes
//! `M = C + q6·O`, but the forward kinematics eq. 2 (and eq. 3, and the URDF
//! chain `Trans(q1,q2,q3)·Rz(q4)·Ry(q5)·Trans(0,0,q6)`) give `C = M + q6·O`,
//! so here, with that sign, **`M = C − q6·O`**.
//!
//! The decision variable is `w`, one standoff value per CL point
//! (`w_i = q6(u_i)`, eq. 50). Per Cartesian axis `a ∈ {x, y, z}`:
//!
//! ```text
//! M_a = C_a − diag(O_a) w                 (M = C − q6 O at the CL points)
//! P_a = N⁺ M_a                            (eq. 49-52; N_ij = N_j(u_i))
//! J_M = Σ_a P_aᵀ H P_a                    (eq. 48)
//! ```
//!
//! with `N⁺ = N⁻¹` when there are as many CL points as coefficients and
//! the least-squares `(NᵀN)⁻¹Nᵀ` when there are more. The paper's compact
//! `P = K₁ + K₂ w` (eq. 50-52) hides that this is one relation per axis:
//!
//! ```text
//! K1_a = N⁺ C_a,     K2_a = −N⁺ diag(O_a),     P_a = K1_a + K2_a w
//! J_M = Σ_a (K1_a + K2_a w)ᵀ H (K1_a + K2_a w) = ½ wᵀ D w + fᵀ w + c
//! D = 2 Σ_a K2_aᵀ H K2_a,   f = 2 Σ_a K2_aᵀ H K1_a,   c = Σ_a K1_aᵀ H K1_a
//! ```
//!
//! (Appendix A eq. A1-A6, per axis; [`mpath_dense_objective`] computes D
//! and f explicitly.) D is dense (`N⁻¹` is) and only positive
//! semidefinite: `J_M` does not change when M moves by a quadratic
//! polynomial in u along a constant O. A Tikhonov term
//! `τ Σ_i (w_i − w_ref)²` ([`mpath_tikhonov_weight`]) makes the minimiser
//! unique; it selects, among the jerk-optimal standoffs, the one closest
//! to the reference standoff.
//!
//! # Standoff values on the spline
//!
//! The standoff values are taken on the q6 spline itself: `w = N s`, with
//! `s` the coefficients of `q6(u)` on the same knots ([`MPathSolution`]'s
//! `standoff_coeffs`). With as many CL points as coefficients N is
//! invertible and this is no restriction. With more points, a free `w`
//! would have `m − (n + 1)` directions that the least-squares fit `N⁺`
//! filters out of every `P_a` (for a constant tool axis exactly): they do
//! not change `J_M` at all, are decided by the Tikhonov term alone and are
//! numerically undetermined (their curvature is `τ`, 10²⁰ times below
//! that of `H`). The machine runs the q6 spline anyway. The optimum is then
//! the minimiser over `s` of `½ sᵀ(NᵀDN)s + (Nᵀf)ᵀs + τ‖Ns − w_ref‖²`.
//!
//! # How it is solved
//!
//! Never through the dense D. The problem is posed in the sparse lifted
//! variables `(s, P_x, P_y, P_z)` with the objective `Σ_a P_aᵀ H P_a +
//! τ‖Ns − w_ref‖²` and, per axis, the equalities `N P_a + diag(O_a) N s =
//! C_a` (square N), or their normal equations `NᵀN P_a + Nᵀ diag(O_a) N s =
//! NᵀC_a` (more CL points than coefficients), plus the stroke `q6_min ≤
//! (Ns)_i ≤ q6_max` (eq. 54) and the RTO equalities `(Ns)_index = value`
//! (eq. 62-64). Its KKT system is banded once the variables are ordered by
//! their Greville abscissae, and it is solved exactly with an active-set
//! loop over the stroke rows (`qp::active_set`, banded LU with iterative
//! refinement). Only if that loop does not settle is Clarabel run, on the
//! same lifted form with each axis's jerk lifted to `y₃ᵀ G y₃`
//! (`qp::lifting`), to find the active rows for a final polish.
//!
//! The paper (eq. 53) calls D positive definite; it is only semidefinite,
//! hence the Tikhonov term.

use kerf_bspline::{collocation, fit, normal_matrix, BandedSym, KnotVector};
use nalgebra::{DMatrix, DVector, Vector3};

use super::active_set::{polish, LinRow, PolishQp, Side};
use super::constraints::{Bound, ConstraintSet};
use super::diagnose::culprit;
use super::lifting::JerkChain;
use super::solve::{solve, Objective, Verdict};
use crate::error::ConstraintFamily;
use crate::request::AXIS_NORM_TOLERANCE;
use crate::PlanError;

/// Name of this QP in errors.
const PROBLEM: &str = "M path";

/// Relative Tikhonov weight (see [`mpath_tikhonov_weight`]).
pub const MPATH_TIKHONOV: f64 = 1e-6;

/// A stroke bound counts as active in the interior-point answer when its
/// slack is below this fraction of the stroke length.
const ACTIVE_REL: f64 = 1e-5;

/// The M-path QP of seed 001 eq. 62.
#[derive(Debug, Clone, Copy)]
pub struct MPathProblem<'a> {
    /// Knot vector of the M-path spline (degree ≥ 3).
    pub knots: &'a KnotVector,
    /// Jerk Hessian of these knots (`kerf_bspline::jerk_hessian`, eq. 18).
    pub hessian: &'a BandedSym,
    /// Parameters u_i of the CL points, in [0, 1], non-decreasing; at least
    /// as many as coefficients.
    pub params: &'a [f64],
    /// CL points C_i in the machine frame (m).
    pub points: &'a [Vector3<f64>],
    /// Optimised unit tool axes O_i (from q4, q5 by eq. 2).
    pub axes: &'a [Vector3<f64>],
    /// Standoff stroke `(q6_min, q6_max)` (m, eq. 54).
    pub stroke: (f64, f64),
    /// RTO equalities `(CL index, q6)` (eq. 62-64).
    pub via: &'a [(usize, f64)],
    /// Reference standoff w_ref of the Tikhonov term (m).
    pub reference: f64,
}

/// The optimal standoff and M path.
#[derive(Debug, Clone, PartialEq)]
pub struct MPathSolution {
    /// q6 at each CL point (m).
    pub w: Vec<f64>,
    /// Control points of the M-path spline, per axis x, y, z (m).
    pub control_points: [Vec<f64>; 3],
    /// `N⁺ w`: the coefficients of the q6(u) spline on the same knots (m).
    pub standoff_coeffs: Vec<f64>,
    /// Clarabel iterations (0 when the active-set solve settled alone).
    pub iterations: u32,
}

/// The Tikhonov weight τ of the solved objective
/// `J_M(w) + τ Σ_i (w_i − w_ref)²` for `n_points` CL points.
///
/// `τ = MPATH_TIKHONOV · 36 / n_points`: a standoff change shaped like the
/// cubic `u³` (the smoothest shape with jerk: `∫(d³u³/du³)² du = 36`) of
/// amplitude A costs `36 A²` of jerk and about `τ·n_points·A²/7` of
/// Tikhonov, a relative bias of `MPATH_TIKHONOV/7 ≈ 1.4·10⁻⁷`; jerk-free
/// directions (quadratic M shifts along a constant axis) are decided by the
/// Tikhonov term alone.
pub fn mpath_tikhonov_weight(n_points: usize) -> f64 {
    MPATH_TIKHONOV * 36.0 / n_points.max(1) as f64
}

/// The dense quadratic form of Appendix A: `(D, f)` with
/// `J_M(w) = ½ wᵀ D w + fᵀ w + c` (see the module documentation for the
/// per-axis `K1_a`, `K2_a`). The Tikhonov term is not included.
///
/// # Errors
/// [`PlanError::InvalidRequest`] for malformed inputs (as
/// [`solve_mpath`]) or a singular `NᵀN`.
///
/// # Performance
/// Dense: O(m² (n + 1) + m (n + 1)²) time and O(m²) memory for m CL points.
/// Meant for tests and small problems; [`solve_mpath`] never forms D.
pub fn mpath_dense_objective(p: &MPathProblem) -> Result<(DMatrix<f64>, DVector<f64>), PlanError> {
    validate(p)?;
    let m = p.points.len();
    let nmat = collocation(p.knots, p.params)
        .map_err(|e| PlanError::invalid("M path params", e.to_string()))?
        .to_dense();
    let ntn = nmat.transpose() * &nmat;
    let chol = ntn.cholesky().ok_or_else(|| {
        PlanError::invalid(
            "M path params",
            "NᵀN is singular: the CL parameters violate the Schoenberg-Whitney condition",
        )
    })?;
    let npinv = chol.solve(&nmat.transpose());
    let h = p.hessian.to_dense();
    let mut d = DMatrix::zeros(m, m);
    let mut f = DVector::zeros(m);
    for a in 0..3 {
        let c = DVector::from_iterator(m, p.points.iter().map(|c| c[a]));
        let k1 = &npinv * c;
        let mut k2 = -npinv.clone();
        for (i, mut col) in k2.column_iter_mut().enumerate() {
            col *= p.axes[i][a];
        }
        let hk2 = &h * &k2;
        d += 2.0 * k2.transpose() * &hk2;
        f += 2.0 * hk2.transpose() * k1;
    }
    Ok((d, f))
}

/// Solves the M-path QP of seed 001 eq. 62 (method in the module
/// documentation).
///
/// # Errors
/// * [`PlanError::InvalidRequest`]: lengths of `params`, `points`, `axes`
///   differ or are fewer than the coefficients; a non-finite value; a
///   parameter outside [0, 1] or decreasing; a non-unit axis; an empty or
///   non-finite stroke; a via index out of range; a Hessian that is not the
///   jerk Hessian of the knots; parameters for which `NᵀN` is numerically
///   singular
///   (Schoenberg-Whitney). Note: uniform parameters with a clamped uniform
///   knot vector of as many coefficients are singular beyond ≈ 100
///   coefficients (condition number ≈ 10⁸ at 40, infinite at 100); use
///   the Greville abscissae, knots placed by averaging the parameters, or
///   fewer coefficients;
/// * [`PlanError::Infeasible`] (problem "M path"): family
///   [`ConstraintFamily::Stroke`] when an RTO asks a standoff outside the
///   stroke, [`ConstraintFamily::Rto`] when two RTOs ask different
///   standoffs at the same CL point (the only ways the problem can be
///   infeasible once the inputs are valid: the box is non-empty and the
///   M-path equalities always have a solution);
/// * [`PlanError::Solver`] if neither the active-set solve nor Clarabel
///   with a polish can certify the optimum.
///
/// # Performance
/// One banded KKT factorisation per active-set round, O(n b²) with
/// bandwidth b ≈ 8(k + 1) ≈ 50 for quintics. Measured in release builds on
/// the loaded 2-core test machine for 628 CL points: 7-18 ms with the
/// stroke inactive (one round; 300 or 628 coefficients), 130-230 ms when
/// the stroke cuts the free standoff at several places (≈ 14 rounds).
pub fn solve_mpath(p: &MPathProblem) -> Result<MPathSolution, PlanError> {
    let model = MPathModel::new(p)?;
    let first = match model.polish(Vec::new()) {
        Ok(x) => return model.solution(x, 0),
        Err(e) => e,
    };
    // The active-set loop alone did not settle: Clarabel finds the active
    // stroke bounds, then the polish certifies.
    let lifted = model.lifted_constraints()?;
    let (x, iterations, status) = match solve(PROBLEM, &model.lifted_objective, &lifted, &|_| true)?
    {
        Verdict::Optimal { x, iterations } => (x, iterations, "solved".to_string()),
        Verdict::Failed {
            detail,
            last: Some((x, iterations)),
        } => (x, iterations, detail),
        Verdict::Failed { detail, last: None } => {
            return Err(PlanError::Solver {
                problem: PROBLEM.into(),
                detail: format!("active-set solve: {first}; Clarabel: {detail}"),
            })
        }
        Verdict::Infeasible { status } => {
            let found = culprit(
                &[&[ConstraintFamily::Stroke], &[ConstraintFamily::Rto]],
                &[ConstraintFamily::Stroke, ConstraintFamily::Rto],
                &mut |dropped| {
                    let keep = |f: ConstraintFamily| !dropped.contains(&f);
                    let v = solve(PROBLEM, &model.lifted_objective, &lifted, &keep)?;
                    Ok(v.is_feasible())
                },
            )?;
            return Err(PlanError::Infeasible {
                problem: PROBLEM.into(),
                family: found.map_or(ConstraintFamily::Stroke, |c| c.family),
                detail: format!("Clarabel reports {status:?}"),
                max_feasible_feedrate: None,
            });
        }
    };
    let active = model.active_set(&x);
    let x = model.polish(active).map_err(|e| PlanError::Solver {
        problem: PROBLEM.into(),
        detail: format!(
            "active-set solve: {first}; Clarabel: {status} ({iterations} iterations); \
             the polish failed: {e}"
        ),
    })?;
    model.solution(x, iterations)
}

/// A validated M-path problem in the lifted variables `(s, P_x, P_y, P_z)`
/// (`w = N s`, see [`solve_mpath`]).
struct MPathModel<'p, 'a> {
    p: &'p MPathProblem<'a>,
    /// Number of coefficients n + 1.
    nc: usize,
    /// The collocation matrix N (m × (n + 1)).
    nmat: kerf_bspline::BandRows,
    /// The jerk chain of the knots (accurate `H x`, lifted objective).
    chain: JerkChain,
    /// `NᵀN` (the Tikhonov Hessian up to 2τ).
    ntn: BandedSym,
    /// The link equalities (per axis), then the RTO rows.
    equalities: Vec<LinRow>,
    /// Number of link equalities (the RTO rows follow).
    n_links: usize,
    /// The stroke rows `lo ≤ N_i s ≤ hi`, one per CL point.
    stroke_rows: Vec<LinRow>,
    /// Ordering keys of the variables (Greville abscissae).
    keys: Vec<f64>,
    /// Polish objective: upper triangle of `2H/σ_H` per axis and
    /// `2τNᵀN/σ_H` on s.
    polish_p: Vec<(usize, usize, f64)>,
    /// Polish linear term: `−2τ w_ref Nᵀ1 / σ_H` on s.
    polish_q: Vec<f64>,
    /// `σ_H = max|H|`.
    h_scale: f64,
    /// Tikhonov weight τ.
    tau: f64,
    /// Clarabel form of the lifted problem (jerk of each axis lifted).
    lifted_objective: Objective,
}

impl<'p, 'a> MPathModel<'p, 'a> {
    fn new(p: &'p MPathProblem<'a>) -> Result<Self, PlanError> {
        validate(p)?;
        precheck_vias(p)?;
        let bad = |field: &str, e: kerf_bspline::BsplineError| {
            PlanError::invalid(format!("M path {field}"), e.to_string())
        };
        let kv = p.knots;
        let (m, nc, k) = (p.points.len(), kv.n_coeffs(), kv.degree());
        // Schoenberg-Whitney: NᵀN must be (numerically) positive definite.
        fit(kv, p.params, &vec![0.0; m]).map_err(|e| bad("params", e))?;
        let nmat = collocation(kv, p.params).map_err(|e| bad("params", e))?;
        let ntn = normal_matrix(&nmat, k);
        let chain = JerkChain::new(kv).map_err(|e| bad("knots", e))?;
        chain
            .check_hessian(p.hessian)
            .map_err(|why| PlanError::invalid("M path hessian", why))?;
        let h_scale = p.hessian.max_abs();
        if !(h_scale.is_finite() && h_scale > 0.0) {
            return Err(PlanError::invalid(
                "M path hessian",
                format!("largest entry {h_scale} (must be finite and positive)"),
            ));
        }
        let tau = mpath_tikhonov_weight(m);
        // Columns: s at 0..nc, P_a at (1 + a)·nc.
        let pcol = |a: usize, j: usize| (1 + a) * nc + j;
        let length = p
            .points
            .iter()
            .fold(0.0_f64, |acc, c| acc.max(c.amax()))
            .max(1.0);
        let mut equalities = Vec::with_capacity(3 * m + p.via.len());
        if m == nc {
            // N P_a + diag(O_a) N s = C_a, one row per CL point.
            for a in 0..3 {
                for (i, row) in nmat.rows.iter().enumerate() {
                    let o = p.axes[i][a];
                    let mut entries: Vec<(usize, f64)> = row
                        .values
                        .iter()
                        .enumerate()
                        .map(|(t, &v)| (pcol(a, row.start + t), v))
                        .collect();
                    entries.extend(
                        row.values
                            .iter()
                            .enumerate()
                            .map(|(t, &v)| (row.start + t, o * v)),
                    );
                    let c = p.points[i][a];
                    equalities.push(LinRow {
                        entries,
                        lo: c,
                        hi: c,
                        scale: length,
                    });
                }
            }
        } else {
            // NᵀN P_a + Nᵀ diag(O_a) N s = Nᵀ C_a, one row per coefficient.
            let bw = ntn.bandwidth();
            for a in 0..3 {
                let mut g = BandedSym::zeros(nc, bw);
                let mut rhs = vec![0.0; nc];
                for (i, row) in nmat.rows.iter().enumerate() {
                    let o = p.axes[i][a];
                    for (t1, &v1) in row.values.iter().enumerate() {
                        if let Some(b) = rhs.get_mut(row.start + t1) {
                            *b += v1 * p.points[i][a];
                        }
                        for (t2, &v2) in row.values.iter().enumerate().take(t1 + 1) {
                            g.add(row.start + t1, row.start + t2, v1 * o * v2);
                        }
                    }
                }
                for (j, b) in rhs.into_iter().enumerate() {
                    let cols = j.saturating_sub(bw)..=(j + bw).min(nc - 1);
                    let mut entries: Vec<(usize, f64)> = cols
                        .clone()
                        .map(|l| (pcol(a, l), ntn.get(j, l)))
                        .filter(|&(_, v)| v != 0.0)
                        .collect();
                    entries.extend(cols.map(|l| (l, g.get(j, l))).filter(|&(_, v)| v != 0.0));
                    equalities.push(LinRow {
                        entries,
                        lo: b,
                        hi: b,
                        scale: length,
                    });
                }
            }
        }
        let n_links = equalities.len();
        let (lo, hi) = p.stroke;
        let stroke_scale = lo.abs().max(hi.abs());
        let n_row = |i: usize| {
            nmat.rows.get(i).map_or_else(Vec::new, |row| {
                row.values
                    .iter()
                    .enumerate()
                    .map(|(t, &v)| (row.start + t, v))
                    .collect::<Vec<_>>()
            })
        };
        for &(i, v) in p.via {
            equalities.push(LinRow {
                entries: n_row(i),
                lo: v,
                hi: v,
                scale: stroke_scale,
            });
        }
        let stroke_rows = (0..m)
            .map(|i| LinRow {
                entries: n_row(i),
                lo,
                hi,
                scale: stroke_scale,
            })
            .collect();
        let knots = kv.knots();
        let greville: Vec<f64> = (0..nc)
            .map(|j| {
                knots
                    .get(j + 1..=j + k)
                    .map_or(0.0, |s| s.iter().sum::<f64>() / k as f64)
            })
            .collect();
        let keys = greville.repeat(4);
        // Tikhonov τ‖N s − w_ref‖²: Hessian 2τNᵀN, linear −2τ w_ref Nᵀ1.
        let ntn_upper = ntn.upper_triplets();
        let nt1 = nmat.tr_mul_vec(&vec![1.0; m]);
        let mut polish_p: Vec<(usize, usize, f64)> = ntn_upper
            .iter()
            .map(|&(i, j, v)| (i, j, 2.0 * tau * v / h_scale))
            .collect();
        let h_upper = p.hessian.upper_triplets();
        for a in 0..3 {
            polish_p.extend(
                h_upper
                    .iter()
                    .map(|&(i, j, v)| (pcol(a, i), pcol(a, j), 2.0 * v / h_scale)),
            );
        }
        let mut polish_q = vec![0.0; 4 * nc];
        for (q, v) in polish_q.iter_mut().zip(&nt1) {
            *q = -2.0 * tau * p.reference * v / h_scale;
        }
        // Lifted Clarabel objective: s, then per axis P_a and its chain.
        let per_axis = nc + chain.n_aux();
        let nvars = nc + 3 * per_axis;
        let mut lifted_p: Vec<(usize, usize, f64)> = ntn_upper
            .iter()
            .map(|&(i, j, v)| (i, j, 2.0 * tau * v))
            .collect();
        for a in 0..3 {
            lifted_p.extend(chain.objective_upper(nc + a * per_axis + nc, 1.0));
        }
        let mut lifted_q = vec![0.0; nvars];
        for (q, v) in lifted_q.iter_mut().zip(&nt1) {
            *q = -2.0 * tau * p.reference * v;
        }
        let lifted_objective = Objective {
            n: nvars,
            p_upper: lifted_p,
            q: lifted_q,
        };
        Ok(Self {
            p,
            nc,
            nmat,
            chain,
            ntn,
            equalities,
            n_links,
            stroke_rows,
            keys,
            polish_p,
            polish_q,
            h_scale,
            tau,
            lifted_objective,
        })
    }

    /// `x ↦ P x` of the polish objective, the jerk blocks through the chain.
    fn apply_p(&self, x: &[f64]) -> Vec<f64> {
        let nc = self.nc;
        let block = |b: usize| x.get(b * nc..(b + 1) * nc).unwrap_or(&[]);
        let mut y: Vec<f64> = self
            .ntn
            .mul_vec(block(0))
            .into_iter()
            .map(|v| 2.0 * self.tau * v / self.h_scale)
            .collect();
        for a in 0..3 {
            y.extend(
                self.chain
                    .apply_h(block(1 + a))
                    .into_iter()
                    .map(|v| 2.0 * v / self.h_scale),
            );
        }
        y
    }

    /// The optimum of the lifted QP from an active-set guess over the
    /// stroke rows (see `qp::active_set`).
    fn polish(&self, active: Vec<(usize, Side)>) -> Result<Vec<f64>, String> {
        let apply = |x: &[f64]| self.apply_p(x);
        let qp = PolishQp {
            n: 4 * self.nc,
            p_upper: &self.polish_p,
            apply_p: Some(&apply),
            q: &self.polish_q,
            keys: &self.keys,
        };
        polish(&qp, &self.equalities, &self.stroke_rows, active)
    }

    /// The Clarabel form: s, then per axis `(P_a, y₁, y₂, y₃)`; structural
    /// rows (chains and link equalities) have no family; RTO rows are
    /// [`ConstraintFamily::Rto`], stroke rows [`ConstraintFamily::Stroke`].
    fn lifted_constraints(&self) -> Result<ConstraintSet, PlanError> {
        let nc = self.nc;
        let per_axis = nc + self.chain.n_aux();
        let mut set = ConstraintSet::new(self.lifted_objective.n);
        for a in 0..3 {
            let base = nc + a * per_axis;
            self.chain
                .push_structural(&mut set, base, base + nc, [1.0; 3])?;
        }
        // Polish column c (P_a at (1 + a)·nc) to lifted column.
        let lift = |c: usize| {
            if c < nc {
                c
            } else {
                let (a, j) = ((c - nc) / nc, (c - nc) % nc);
                nc + a * per_axis + j
            }
        };
        for (r, row) in self.equalities.iter().enumerate() {
            let entries = row.entries.iter().map(|&(c, v)| (lift(c), v)).collect();
            let family = (r >= self.n_links).then_some(ConstraintFamily::Rto);
            set.push(family, entries, Bound::Eq(row.lo), row.scale)?;
        }
        for row in &self.stroke_rows {
            let bound = Bound::Range {
                lo: row.lo,
                hi: row.hi,
            };
            set.push(
                Some(ConstraintFamily::Stroke),
                row.entries.clone(),
                bound,
                row.scale,
            )?;
        }
        Ok(set)
    }

    /// Stroke rows active (slack below [`ACTIVE_REL`] of the stroke) in a
    /// lifted interior-point answer.
    fn active_set(&self, x: &[f64]) -> Vec<(usize, Side)> {
        let (lo, hi) = self.p.stroke;
        let tol = ACTIVE_REL * (hi - lo).max(f64::MIN_POSITIVE);
        let w = self.nmat.mul_vec(x.get(..self.nc).unwrap_or(&[]));
        w.iter()
            .enumerate()
            .filter_map(|(i, &w)| {
                if hi - w <= tol {
                    Some((i, Side::Upper))
                } else if w - lo <= tol {
                    Some((i, Side::Lower))
                } else {
                    None
                }
            })
            .collect()
    }

    /// The solution record from the polished vector `(s, P_x, P_y, P_z)`.
    fn solution(&self, x: Vec<f64>, iterations: u32) -> Result<MPathSolution, PlanError> {
        let nc = self.nc;
        let block = |b: usize| {
            x.get(b * nc..(b + 1) * nc)
                .map(<[f64]>::to_vec)
                .unwrap_or_default()
        };
        let standoff_coeffs = block(0);
        let w = self.nmat.mul_vec(&standoff_coeffs);
        if w.iter().any(|v| !v.is_finite()) {
            return Err(PlanError::Solver {
                problem: PROBLEM.into(),
                detail: "non-finite standoff".into(),
            });
        }
        Ok(MPathSolution {
            w,
            control_points: [block(1), block(2), block(3)],
            standoff_coeffs,
            iterations,
        })
    }
}

/// The analytic infeasibility diagnosis: an RTO outside the stroke, or two
/// RTOs asking different standoffs at one CL point.
fn precheck_vias(p: &MPathProblem) -> Result<(), PlanError> {
    let (lo, hi) = p.stroke;
    for (k, &(i, v)) in p.via.iter().enumerate() {
        if v < lo || v > hi {
            return Err(PlanError::Infeasible {
                problem: PROBLEM.into(),
                family: ConstraintFamily::Stroke,
                detail: format!(
                    "RTO {k} asks q6 = {v:.6} m at CL point {i}, outside the stroke \
                     [{lo:.6}, {hi:.6}] m"
                ),
                max_feasible_feedrate: None,
            });
        }
    }
    let mut sorted: Vec<(usize, f64)> = p.via.to_vec();
    sorted.sort_by_key(|&(i, _)| i);
    for pair in sorted.windows(2) {
        if let [(i, a), (j, b)] = pair {
            if i == j && (a - b).abs() > 1e-12 * a.abs().max(b.abs()).max(1.0) {
                return Err(PlanError::Infeasible {
                    problem: PROBLEM.into(),
                    family: ConstraintFamily::Rto,
                    detail: format!("two RTOs at CL point {i} ask q6 = {a:.6} m and q6 = {b:.6} m"),
                    max_feasible_feedrate: None,
                });
            }
        }
    }
    Ok(())
}

/// Checks every input (see [`solve_mpath`] errors).
fn validate(p: &MPathProblem) -> Result<(), PlanError> {
    let bad = |field: &str, why: String| Err(PlanError::invalid(format!("M path {field}"), why));
    let m = p.points.len();
    let nc = p.knots.n_coeffs();
    if p.params.len() != m || p.axes.len() != m {
        return bad(
            "points",
            format!(
                "{} params, {m} points, {} axes: one of each per CL point",
                p.params.len(),
                p.axes.len()
            ),
        );
    }
    if m < nc {
        return bad(
            "points",
            format!("{m} CL points for {nc} coefficients: need at least as many points"),
        );
    }
    if p.knots.degree() < 3 {
        return bad(
            "knots",
            format!("degree {} < 3: no jerk to minimise", p.knots.degree()),
        );
    }
    if p.hessian.n() != nc {
        return bad(
            "hessian",
            format!("size {} differs from the {nc} coefficients", p.hessian.n()),
        );
    }
    let mut prev = 0.0;
    for (i, &u) in p.params.iter().enumerate() {
        if !(u.is_finite() && (0.0..=1.0).contains(&u) && u >= prev) {
            return bad(
                &format!("params[{i}]"),
                format!("u = {u} is not in [0, 1] or decreases (previous {prev})"),
            );
        }
        prev = u;
    }
    for (i, (c, o)) in p.points.iter().zip(p.axes).enumerate() {
        if c.iter().any(|v| !v.is_finite()) {
            return bad(&format!("points[{i}]"), "not finite".into());
        }
        let norm = o.norm();
        if !(norm.is_finite() && (norm - 1.0).abs() <= AXIS_NORM_TOLERANCE) {
            return bad(&format!("axes[{i}]"), format!("norm {norm} is not 1"));
        }
    }
    let (lo, hi) = p.stroke;
    if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
        return bad("stroke", format!("[{lo}, {hi}] is not a finite interval"));
    }
    if !p.reference.is_finite() {
        return bad("reference", format!("{} is not finite", p.reference));
    }
    for (k, &(i, v)) in p.via.iter().enumerate() {
        if i >= m || !v.is_finite() {
            return bad(
                &format!("via[{k}]"),
                format!("CL index {i} (of {m}) or value {v} is invalid"),
            );
        }
    }
    Ok(())
}
