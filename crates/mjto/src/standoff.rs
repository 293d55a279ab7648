//! The M-path QP of the standoff axis (seed 001 eq. 46-54, 62-64,
//! Appendix A) as a second-order cone program in the q6 spline
//! coefficients.
//!
//! # Formulation
//!
//! With `M = C − q6·O` (eq. 2/3; eq. 46 prints the opposite sign) and the
//! standoff on its own spline, `w = N s` (`N_ij = N_j(u_i)`, the q6 values at
//! the CL points, eq. 50), the control points of each Cartesian axis `a`
//! are (eq. 49-52, per axis)
//!
//! ```text
//! P_a = N⁺ (C_a − diag(O_a) N s) = K1_a + K2_a s,
//! K1_a = N⁺ C_a,   K2_a = −N⁺ diag(O_a) N,
//! ```
//!
//! and the jerk of the M path is `J_M = Σ_a P_aᵀ H P_a` (eq. 48) with H of
//! eq. 18. Writing `H = D₃ᵀ G D₃` (D₃ maps coefficients to third-derivative
//! coefficients, eq. 12; G is the Gram matrix of the degree-(k−3) basis,
//! positive definite, `G = L Lᵀ`),
//!
//! ```text
//! J_M = Σ_a ‖R_a s + r_a‖²,   R_a = Lᵀ D₃ K2_a,   r_a = Lᵀ D₃ K1_a,
//! ```
//!
//! so D and f of eq. 53 / Appendix A are `D = 2 Σ_a R_aᵀ R_a = 2 Σ_a K2_aᵀ
//! H K2_a` and `f = 2 Σ_a R_aᵀ r_a = 2 Σ_a K2_aᵀ H K1_a` ([`dense_objective`]).
//! Minimising `‖·‖` instead of `‖·‖²` has the same minimiser, and a
//! second-order cone over `R` has the conditioning of R (~n³ for n + 1
//! coefficients on [0, 1]), not that of `RᵀR` (~n⁶, 10¹⁷ for the paper's
//! n + 1 = 628), which a QP solver cannot resolve. So Clarabel solves
//!
//! ```text
//! min t   s.t.  ‖[R s + r;  √τ (N s − w_ref)]‖ ≤ t,
//!               q6_min ≤ s_j ≤ q6_max          (eq. 54 on the coefficients: by the
//!                                              convex hull, the whole q6 curve)
//!               (N s)_i = q6(ũ_i)              (RTO equalities, eq. 62-64)
//!               lo_i ≤ (N s)_i ≤ hi_i          (kerf: RTO boxes, issue 16 item 3)
//! ```
//!
//! The interval rows are kerf's, not seed 001's: an RTO given as a box of
//! free, feasible GFD samples ([`crate::gfd::Gfd::free_box`]) leaves the
//! standoff there free within the box's q6 range.
//!
//! The small Tikhonov term `τ‖N s − w_ref‖²` (relative weight
//! [`TIKHONOV`]) makes the minimiser unique: D is only positive
//! semidefinite (a quadratic-in-u motion of M along a constant O costs no
//! jerk), although eq. 53 calls it definite.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use kerf_bspline::{collocation, KnotVector};
use nalgebra::{DMatrix, DVector, Vector3};

use crate::error::ConstraintFamily;
use crate::rotary::JerkFactor;
use crate::PlanError;

/// The M-path problem of seed 001 eq. 62.
#[derive(Debug, Clone, Copy)]
pub struct MPathProblem<'a> {
    /// Knot vector of the M-path and q6 splines (degree ≥ 3).
    pub knots: &'a KnotVector,
    /// The factored jerk Hessian of these knots.
    pub factor: &'a JerkFactor,
    /// Parameters u_i of the CL points, strictly increasing in [0, 1]; at
    /// least as many as coefficients.
    pub params: &'a [f64],
    /// CL points C_i in the machine frame (m).
    pub points: &'a [Vector3<f64>],
    /// Optimised unit tool axes O_i (from q4, q5 by eq. 2).
    pub axes: &'a [Vector3<f64>],
    /// Standoff stroke `(q6_min, q6_max)` (m, eq. 54).
    pub stroke: (f64, f64),
    /// RTO equalities `(CL index, q6)` (eq. 62-64).
    pub via: &'a [(usize, f64)],
    /// RTO intervals `(CL index, lo, hi)`: `lo ≤ q6 ≤ hi` there (kerf, issue
    /// 16 item 3, the q6 range of an RTO box).
    pub via_box: &'a [(usize, f64, f64)],
    /// Reference standoff w_ref of the Tikhonov term (m).
    pub reference: f64,
}

/// The optimal standoff and M path.
#[derive(Debug, Clone, PartialEq)]
pub struct MPathSolution {
    /// q6 at each CL point, `w = N s` (m).
    pub w: Vec<f64>,
    /// Control points of the M-path spline per axis x, y, z (m).
    pub control_points: [Vec<f64>; 3],
    /// The coefficients s of the q6(u) spline on the same knots (m).
    pub standoff_coeffs: Vec<f64>,
    /// Clarabel iterations.
    pub iterations: u32,
}

/// Relative weight of the Tikhonov term against the jerk term (against
/// ‖R‖²_F, which the stiffest, oscillating modes dominate: ~n⁶ above the
/// smooth ones). Small enough not to bias the smooth optimum (1e-8 moved w
/// by 0.2 mm on planner-sized problems), large enough to fix the exact null
/// space of D.
pub const TIKHONOV: f64 = 1e-14;

/// Tolerance of the post-check of the constraints (m).
const CHECK_TOL: f64 = 1e-7;

const PROBLEM: &str = "M path";

fn solver_error(detail: impl Into<String>) -> PlanError {
    PlanError::Solver {
        problem: PROBLEM.into(),
        detail: detail.into(),
    }
}

/// The dense pieces of the formulation.
struct Pieces {
    /// Collocation matrix N (m × (n+1)).
    n: DMatrix<f64>,
    /// K1_a per axis.
    k1: [DVector<f64>; 3],
    /// K2_a per axis.
    k2: [DMatrix<f64>; 3],
    /// Lᵀ D₃ (rows: third-derivative coefficients).
    ltd3: DMatrix<f64>,
    /// Lower Cholesky factor of NᵀN.
    ntn_l: DMatrix<f64>,
}

fn pieces(p: &MPathProblem) -> Result<Pieces, PlanError> {
    let m = p.params.len();
    if m != p.points.len() || m != p.axes.len() {
        return Err(PlanError::invalid(
            "M path",
            format!(
                "{} parameters, {} points, {} axes",
                m,
                p.points.len(),
                p.axes.len()
            ),
        ));
    }
    let err = |e: kerf_bspline::BsplineError| solver_error(e.to_string());
    let n = collocation(p.knots, p.params).map_err(err)?.to_dense();
    let ntn = n.transpose() * &n;
    let chol = ntn.cholesky().ok_or_else(|| {
        solver_error("NᵀN is singular: the CL parameters do not determine the spline coefficients")
    })?;
    let mut k1: [DVector<f64>; 3] = Default::default();
    let mut k2: [DMatrix<f64>; 3] = Default::default();
    for a in 0..3 {
        let c = DVector::from_iterator(m, p.points.iter().map(|x| x[a]));
        k1[a] = chol.solve(&(n.transpose() * c));
        let mut on = n.clone();
        for (i, o) in p.axes.iter().enumerate() {
            on.row_mut(i).scale_mut(o[a]);
        }
        k2[a] = -chol.solve(&(n.transpose() * on));
    }
    let nc = p.knots.n_coeffs();
    if p.factor.n_coeffs != nc {
        return Err(solver_error("jerk factor built for other knots"));
    }
    let rows = p.factor.lt_d3.len();
    let mut ltd3 = DMatrix::zeros(rows, nc);
    for (i, row) in p.factor.lt_d3.iter().enumerate() {
        for &(j, v) in row {
            ltd3[(i, j)] = v;
        }
    }
    let ntn_l = chol.l();
    Ok(Pieces {
        n,
        k1,
        k2,
        ltd3,
        ntn_l,
    })
}

/// D and f of eq. 53 / Appendix A (A4, A5), per axis: `J_M(s) = ½ sᵀ D s +
/// fᵀ s + c` in the q6 spline coefficients s (w = N s).
pub fn dense_objective(p: &MPathProblem) -> Result<(DMatrix<f64>, DVector<f64>), PlanError> {
    let pc = pieces(p)?;
    let nc = pc.n.ncols();
    let h = pc.ltd3.transpose() * &pc.ltd3;
    let mut d = DMatrix::zeros(nc, nc);
    let mut f = DVector::zeros(nc);
    for a in 0..3 {
        let hk2 = &h * &pc.k2[a];
        d += 2.0 * pc.k2[a].transpose() * &hk2;
        f += 2.0 * pc.k2[a].transpose() * (&h * &pc.k1[a]);
    }
    Ok((d, f))
}

/// Solves the M-path problem (see the module documentation).
///
/// # Errors
/// [`PlanError::Infeasible`] (family `Rto` when the RTO values alone
/// conflict with the stroke, else `Stroke`), [`PlanError::Solver`] for a
/// solver failure, [`PlanError::InvalidRequest`] for inconsistent inputs.
///
/// # Performance
/// Dense in the n + 1 coefficients: O(m (n+1)²) to build, one Clarabel
/// SOCP of n + 2 variables.
pub fn solve_standoff(p: &MPathProblem) -> Result<MPathSolution, PlanError> {
    let (lo, hi) = p.stroke;
    if !(lo.is_finite() && hi.is_finite() && lo < hi && p.reference.is_finite()) {
        return Err(PlanError::invalid(
            "M path",
            "stroke or reference not finite",
        ));
    }
    for &(i, v) in p.via {
        if i >= p.params.len() || !v.is_finite() {
            return Err(PlanError::invalid(
                "M path",
                format!("RTO ({i}, {v}) invalid"),
            ));
        }
        if v < lo - CHECK_TOL || v > hi + CHECK_TOL {
            return Err(PlanError::Infeasible {
                problem: PROBLEM.into(),
                family: ConstraintFamily::Rto,
                detail: format!(
                    "RTO at CL point {i} asks q6 = {v} m outside the stroke [{lo}, {hi}] m"
                ),
                max_feasible_feedrate: None,
            });
        }
    }
    for &(i, a, b) in p.via_box {
        if i >= p.params.len() || !(a.is_finite() && b.is_finite() && a <= b) {
            return Err(PlanError::invalid(
                "M path",
                format!("RTO interval ({i}, [{a}, {b}]) invalid"),
            ));
        }
        if b < lo - CHECK_TOL || a > hi + CHECK_TOL {
            return Err(PlanError::Infeasible {
                problem: PROBLEM.into(),
                family: ConstraintFamily::Rto,
                detail: format!(
                    "RTO at CL point {i} asks q6 in [{a}, {b}] m, outside the stroke [{lo}, {hi}] m"
                ),
                max_feasible_feedrate: None,
            });
        }
    }
    let pc = pieces(p)?;
    let (m, nc) = pc.n.shape();
    // R = [R_x; R_y; R_z], r likewise, scaled to unit largest entry.
    let rows = pc.ltd3.nrows();
    let mut r_mat = DMatrix::zeros(3 * rows, nc);
    let mut r_vec = DVector::zeros(3 * rows);
    for a in 0..3 {
        r_mat
            .rows_mut(a * rows, rows)
            .copy_from(&(&pc.ltd3 * &pc.k2[a]));
        r_vec
            .rows_mut(a * rows, rows)
            .copy_from(&(&pc.ltd3 * &pc.k1[a]));
    }
    let scale = r_mat.amax().max(f64::MIN_POSITIVE);
    r_mat /= scale;
    r_vec /= scale;
    let sqrt_tau =
        (TIKHONOV * r_mat.norm_squared() / pc.n.norm_squared().max(f64::MIN_POSITIVE)).sqrt();
    let nt_w = pc.n.transpose() * DVector::from_element(m, p.reference);
    let tik_c = pc
        .ntn_l
        .solve_lower_triangular(&nt_w)
        .ok_or_else(|| solver_error("NᵀN factor is singular"))?;

    // The cone rows ‖R s + r‖² + τ‖Lᵀ s − c‖² = ‖M s − y‖², compressed by a
    // QR factorisation M = Q R̃ to ‖R̃ s − Q₁ᵀ y‖ (+ a constant, which does
    // not move the minimiser): n + 1 rows, and R̃ keeps the conditioning
    // of M (no normal equations).
    let mut stacked = DMatrix::zeros(3 * rows + nc, nc);
    let mut target = DVector::zeros(3 * rows + nc);
    stacked.rows_mut(0, 3 * rows).copy_from(&r_mat);
    target.rows_mut(0, 3 * rows).copy_from(&(-&r_vec));
    stacked
        .rows_mut(3 * rows, nc)
        .copy_from(&(pc.ntn_l.transpose() * sqrt_tau));
    target
        .rows_mut(3 * rows, nc)
        .copy_from(&(&tik_c * sqrt_tau));
    let qr = stacked.qr();
    let r_tilde = qr.r();
    let y_tilde = qr.q().transpose() * &target;
    let try_solve = |with_stroke: bool| -> Result<Option<(DVector<f64>, u32)>, PlanError> {
        let nx = nc + 1;
        let (mut ii, mut jj, mut vv) = (Vec::new(), Vec::new(), Vec::new());
        let mut b = Vec::new();
        let mut cones = Vec::new();
        let mut row = 0;
        let push_row = |ii: &mut Vec<usize>,
                        jj: &mut Vec<usize>,
                        vv: &mut Vec<f64>,
                        r: usize,
                        coeffs: &[(usize, f64)]| {
            for &(j, v) in coeffs {
                if v != 0.0 {
                    ii.push(r);
                    jj.push(j);
                    vv.push(v);
                }
            }
        };
        for &(i, v) in p.via {
            let c: Vec<(usize, f64)> = (0..nc).map(|j| (j, pc.n[(i, j)])).collect();
            push_row(&mut ii, &mut jj, &mut vv, row, &c);
            b.push(v);
            row += 1;
        }
        cones.push(SupportedConeT::ZeroConeT(p.via.len()));
        for &(i, a, bh) in p.via_box {
            let c: Vec<(usize, f64)> = (0..nc).map(|j| (j, pc.n[(i, j)])).collect();
            let neg: Vec<(usize, f64)> = c.iter().map(|&(j, v)| (j, -v)).collect();
            push_row(&mut ii, &mut jj, &mut vv, row, &c);
            b.push(bh);
            row += 1;
            push_row(&mut ii, &mut jj, &mut vv, row, &neg);
            b.push(-a);
            row += 1;
        }
        if !p.via_box.is_empty() {
            cones.push(SupportedConeT::NonnegativeConeT(2 * p.via_box.len()));
        }
        if with_stroke {
            // Convex hull (as eq. 15 for the rotary axes): bounds on the
            // coefficients of q6(u) keep the whole curve, not only the CL
            // points of eq. 54, inside the stroke.
            for j in 0..nc {
                push_row(&mut ii, &mut jj, &mut vv, row, &[(j, 1.0)]);
                b.push(hi);
                row += 1;
                push_row(&mut ii, &mut jj, &mut vv, row, &[(j, -1.0)]);
                b.push(-lo);
                row += 1;
            }
            cones.push(SupportedConeT::NonnegativeConeT(2 * nc));
        }
        // SOC: (t, R̃ s − ỹ).
        push_row(&mut ii, &mut jj, &mut vv, row, &[(nc, -1.0)]);
        b.push(0.0);
        row += 1;
        for k in 0..nc {
            let c: Vec<(usize, f64)> = (k..nc).map(|j| (j, -r_tilde[(k, j)])).collect();
            push_row(&mut ii, &mut jj, &mut vv, row, &c);
            b.push(-y_tilde[k]);
            row += 1;
        }
        cones.push(SupportedConeT::SecondOrderConeT(1 + nc));
        let a = CscMatrix::new_from_triplets(row, nx, ii, jj, vv);
        let pm = CscMatrix::zeros((nx, nx));
        let mut q = vec![0.0; nx];
        q[nc] = 1.0;
        let settings = DefaultSettingsBuilder::default()
            .verbose(false)
            .max_iter(200)
            .build()
            .map_err(|e| solver_error(format!("settings: {e}")))?;
        let mut solver = DefaultSolver::new(&pm, &q, &a, &b, &cones, settings)
            .map_err(|e| solver_error(format!("setup: {e}")))?;
        solver.solve();
        let x = DVector::from_iterator(nc, solver.solution.x.iter().take(nc).copied());
        match solver.solution.status {
            SolverStatus::Solved | SolverStatus::AlmostSolved => {
                let w = &pc.n * &x;
                let ok_via = p
                    .via
                    .iter()
                    .all(|&(i, v)| (w[i] - v).abs() <= CHECK_TOL.max(1e-6 * v.abs()))
                    && p.via_box
                        .iter()
                        .all(|&(i, a, bh)| w[i] >= a - CHECK_TOL && w[i] <= bh + CHECK_TOL);
                let ok_stroke = !with_stroke
                    || w.iter()
                        .all(|&v| v >= lo - CHECK_TOL && v <= hi + CHECK_TOL);
                if x.iter().all(|v| v.is_finite()) && ok_via && ok_stroke {
                    Ok(Some((x, solver.solution.iterations)))
                } else {
                    Err(solver_error(format!(
                        "{:?} after {} iterations, but the answer violates its constraints",
                        solver.solution.status, solver.solution.iterations
                    )))
                }
            }
            SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => Ok(None),
            s => Err(solver_error(format!(
                "{s:?} after {} iterations",
                solver.solution.iterations
            ))),
        }
    };

    let (s, iterations) = match try_solve(true)? {
        Some(found) => found,
        None => {
            let family = match try_solve(false)? {
                Some(_) => ConstraintFamily::Stroke,
                None => ConstraintFamily::Rto,
            };
            return Err(PlanError::Infeasible {
                problem: PROBLEM.into(),
                family,
                detail: format!(
                    "no standoff within [{lo}, {hi}] m meets the {} RTO values and {} RTO intervals",
                    p.via.len(),
                    p.via_box.len()
                ),
                max_feasible_feedrate: None,
            });
        }
    };
    // Interior-point answers sit within CHECK_TOL of an active stroke end;
    // that rounding is removed so the values are exactly inside the stroke.
    let w: Vec<f64> = (&pc.n * &s).iter().map(|v| v.clamp(lo, hi)).collect();
    let control_points = [0, 1, 2].map(|a| {
        (&pc.k1[a] + &pc.k2[a] * &s)
            .iter()
            .copied()
            .collect::<Vec<f64>>()
    });
    Ok(MPathSolution {
        w,
        control_points,
        standoff_coeffs: s.iter().copied().collect(),
        iterations,
    })
}
