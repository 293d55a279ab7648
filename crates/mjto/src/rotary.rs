//! The rotary-axis jerk QP (seed 001 eq. 15, 19-45, 57-61) solved as a
//! sparse second-order cone program.
//!
//! # Formulation
//!
//! The objective of eq. 19 is `Θᵀ H Θ` with `H = D₃ᵀ G D₃` (eq. 17-18: D₃
//! maps Θ to the third-derivative coefficients Θ⁽³⁾ of eq. 12, G is the
//! Gram matrix of the degree-(k−3) basis they multiply, `G = L Lᵀ`). So
//! `Θᵀ H Θ = ‖Lᵀ D₃ Θ‖²`, and Clarabel solves
//!
//! ```text
//! min t   s.t.  ‖Lᵀ D₃ Θ‖ ≤ t
//!               q_min ≤ Θ_j ≤ q_max                        (eq. 15, 39)
//!               |D₁Θ| ≤ ω_max σ/f, |D₂Θ| ≤ α_max σ²/f², |D₃Θ| ≤ J_max σ³/f³   (eq. 15, 40-42)
//!               q_u(0), q_u(1), q_uu(0), q_uu(1) given      (eq. 45; q_u free: kerf option)
//!               q(ũ_i) = q_i                                (eq. 57-60)
//!               lo_i ≤ q(ũ_i) ≤ hi_i                        (kerf, RTO boxes)
//!               a_i ≤ q(u_i) ≤ b_i                          (kerf, allowance corridor)
//! ```
//!
//! which has the minimiser of eq. 61. The interval rows are kerf's
//! (issue 16 item 3), not seed 001's: an RTO given as a box of free,
//! lead/tilt-feasible GFD samples ([`crate::gfd::Gfd::free_box`]) lets the
//! QP choose the orientation of least jerk inside it instead of one grid
//! pick; with `lo_i = hi_i` the row is the equality of eq. 57-60. The corridor rows (kerf, issue
//! 16 item 3, [`RotaryQp::corridor`]) bound q at CL points between the RTOs to the lead/tilt
//! allowance, so the jerk is minimized inside the feasible orientations along the whole cut,
//! not only at the RTOs (seed 001 has no such rows: its spline is free between RTOs). A cone over `Lᵀ D₃` carries the
//! conditioning of that matrix (~n³ on [0, 1]) instead of H's (~n⁶,
//! 10¹⁷ for the paper's 628 coefficients), every row is banded (the whole
//! problem is sparse), and each constraint row is scaled to unit largest
//! coefficient. D_r is the exact recursion of eq. 12 on the clamped knots
//! (`kerf_bspline::derivative_operator`; eq. 21-26 hold on uniform spans
//! only); all n + 1 − r rows are bounded, so by the convex-hull property
//! the bounds hold on the whole curve at constant feedrate (eq. 13).
//!
//! # Infeasibility
//!
//! An infeasible problem is solved again with one constraint family
//! dropped at a time (jerk, acceleration, velocity together and alone,
//! then position, RTO, boundary); the first family whose removal restores
//! feasibility is reported. When it is kinematic, the feedrate is bisected:
//! the kinematic bounds scale as 1/f, 1/f², 1/f³, so the feasible set only
//! grows as f decreases and feasibility is monotone in f.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use kerf_bspline::{
    basis_row, derivative_gram, derivative_knots, derivative_operator, BandRows, KnotVector,
};

use crate::error::ConstraintFamily;
use crate::machine::AxisLimits;
use crate::PlanError;

/// Relative margin of the kinematic bounds given to the solver.
pub const BOUND_MARGIN: f64 = 1e-4;

/// Tolerance of the post-check, relative to each bound (or to the size
/// of the terms of the row, whichever is larger).
const CHECK_REL: f64 = 1e-6;

/// The problem of one rotary axis (see the module documentation).
#[derive(Debug, Clone, Copy)]
pub struct RotaryQp<'a> {
    /// "q4" or "q5", used in errors.
    pub axis_name: &'a str,
    /// Knot vector of the joint spline.
    pub knots: &'a KnotVector,
    /// The factored jerk Hessian of these knots.
    pub factor: &'a JerkFactor,
    /// Axis limits (Table 2).
    pub limits: AxisLimits,
    /// Path length σ (m).
    pub sigma: f64,
    /// Constant feedrate f (m/s) of eq. 13.
    pub feedrate: f64,
    /// `[q_u(0), q_u(1), q_uu(0), q_uu(1)]` (eq. 45).
    pub boundary: [f64; 4],
    /// Leave `q_u(0)` and `q_u(1)` free (kerf, issue 16 item 3): only the `q_uu` rows of
    /// eq. 45 are kept. A cut that starts where the tool axis tilts fastest (a closed saddle
    /// starting at the vertical) cannot follow its allowance with zero end slopes; a trajectory
    /// from rest has zero joint velocity whatever `q_u` is, and the time-optimal feed limits
    /// the start and stop ramps by the joint jerk `q_u s⃛ / σ` (eq. 7). `false` is seed 001.
    pub free_end_slopes: bool,
    /// RTO equalities `(ũ_i, q_i)` (eq. 57-60).
    pub via: &'a [(f64, f64)],
    /// RTO intervals `(ũ_i, lo_i, hi_i)`, `lo_i ≤ q(ũ_i) ≤ hi_i` (kerf, issue
    /// 16 item 3: the box of an RTO, see the module documentation); in the
    /// constraint family `Rto` with the equalities.
    pub via_box: &'a [(f64, f64, f64)],
    /// Corridor intervals `(u_i, a_i, b_i)`, `a_i ≤ q(u_i) ≤ b_i` at CL points between the
    /// RTOs (kerf, issue 16 item 3: the q values whose tool axis is inside the lead/tilt
    /// allowance there; `options.orientation_corridor`); empty in seed 001's problem. Their
    /// own constraint family, [`ConstraintFamily::Allowance`].
    pub corridor: &'a [(f64, f64, f64)],
}

/// One sparse row: `(column, coefficient)` pairs.
type SparseRow = Vec<(usize, f64)>;

/// The `deriv`-th derivative of the basis at `u` as a sparse row over the coefficients (eq. 12).
fn sparse_basis(
    knots: &KnotVector,
    u: f64,
    deriv: usize,
) -> Result<SparseRow, kerf_bspline::BsplineError> {
    let row = basis_row(knots, u, deriv)?;
    Ok(row
        .values
        .iter()
        .enumerate()
        .map(|(i, &v)| (row.start + i, v))
        .collect())
}

/// Which families a solve keeps.
type Keep<'a> = &'a dyn Fn(ConstraintFamily) -> bool;

/// Sparse rows of one family: `(row coefficients, lower, upper)`.
struct Family {
    family: ConstraintFamily,
    rows: Vec<(SparseRow, f64, f64)>,
}

fn band_rows(b: &BandRows) -> Vec<Vec<(usize, f64)>> {
    b.rows
        .iter()
        .map(|r| {
            r.values
                .iter()
                .enumerate()
                .map(|(i, &v)| (r.start + i, v))
                .collect()
        })
        .collect()
}

fn solver_error(axis: &str, detail: impl Into<String>) -> PlanError {
    PlanError::Solver {
        problem: axis.into(),
        detail: detail.into(),
    }
}

/// Banded Cholesky `G = L Lᵀ` of a symmetric banded matrix given densely
/// by `get(i, j)` with bandwidth `bw`; returns the rows of `Lᵀ`
/// (upper-banded), i.e. row i holds `L[j][i]` for j = i..i+bw.
fn cholesky_lt(
    n: usize,
    bw: usize,
    get: impl Fn(usize, usize) -> f64,
) -> Option<Vec<Vec<(usize, f64)>>> {
    // l[i][d] = L[i][i-d] for d = 0..=bw.
    let mut l = vec![vec![0.0; bw + 1]; n];
    for i in 0..n {
        for d in (0..=bw.min(i)).rev() {
            let j = i - d;
            let mut sum = get(i, j);
            for e in 1..=bw {
                // L[i][j-e] * L[j][j-e]
                if e + d <= bw && j >= e {
                    sum -= l[i][d + e] * l[j][e];
                }
            }
            if d == 0 {
                if sum <= 0.0 || !sum.is_finite() {
                    return None;
                }
                l[i][0] = sum.sqrt();
            } else {
                l[i][d] = sum / l[j][0];
            }
        }
    }
    // Row i of Lᵀ: entries (j, L[j][i]) for j = i..=i+bw.
    Some(
        (0..n)
            .map(|i| {
                (i..(i + bw + 1).min(n))
                    .map(|j| (j, l[j][j - i]))
                    .filter(|&(_, v)| v != 0.0)
                    .collect()
            })
            .collect(),
    )
}

/// Multiplies two row-sparse matrices (`a` rows over `b` rows).
fn mul_rows(a: &[Vec<(usize, f64)>], b: &[Vec<(usize, f64)>]) -> Vec<Vec<(usize, f64)>> {
    a.iter()
        .map(|row| {
            let mut acc: std::collections::BTreeMap<usize, f64> = Default::default();
            for &(k, v) in row {
                for &(j, w) in &b[k] {
                    *acc.entry(j).or_insert(0.0) += v * w;
                }
            }
            acc.into_iter().collect()
        })
        .collect()
}

/// The jerk Hessian of eq. 17-18 in factored form, `H = D₃ᵀ G D₃ =
/// (Lᵀ D₃)ᵀ (Lᵀ D₃)`, with the derivative operators D₁..D₃ of eq. 12; built
/// once per knot vector and shared by both QPs of every iteration.
#[derive(Debug, Clone)]
pub struct JerkFactor {
    /// Rows of D₁, D₂, D₃ (index r − 1).
    pub d: Vec<Vec<Vec<(usize, f64)>>>,
    /// Rows of `Lᵀ D₃` (banded).
    pub lt_d3: Vec<Vec<(usize, f64)>>,
    /// Number of coefficients n + 1.
    pub n_coeffs: usize,
}

impl JerkFactor {
    /// Builds the factor for `knots` (degree ≥ 3).
    ///
    /// # Errors
    /// [`PlanError::Solver`] if the knots are unusable (degree < 3) or the
    /// Gram matrix is not positive definite.
    ///
    /// # Performance
    /// O(n k²); 628 coefficients take about a millisecond.
    pub fn new(knots: &KnotVector) -> Result<Self, PlanError> {
        let err = |e: kerf_bspline::BsplineError| solver_error("jerk Hessian", e.to_string());
        let d: Vec<Vec<Vec<(usize, f64)>>> = (1..=3)
            .map(|r| derivative_operator(knots, r).map(|b| band_rows(&b)))
            .collect::<Result<_, _>>()
            .map_err(err)?;
        let g = derivative_gram(&derivative_knots(knots, 3).map_err(err)?, 0).map_err(err)?;
        let lt = cholesky_lt(g.n(), g.bandwidth(), |i, j| g.get(i, j)).ok_or_else(|| {
            solver_error(
                "jerk Hessian",
                "the Gram matrix of the jerk basis is not positive definite",
            )
        })?;
        let lt_d3 = mul_rows(&lt, &d[2]);
        Ok(Self {
            d,
            lt_d3,
            n_coeffs: knots.n_coeffs(),
        })
    }

    /// `Θᵀ H Θ` (eq. 17-19 without the constant f⁵/σ⁵), computed as
    /// `‖Lᵀ D₃ Θ‖²` (no cancellation of terms of 10¹⁷).
    pub fn jerk_cost(&self, theta: &[f64]) -> f64 {
        self.lt_d3
            .iter()
            .map(|row| {
                row.iter()
                    .map(|&(j, v)| v * theta.get(j).copied().unwrap_or(f64::NAN))
                    .sum::<f64>()
                    .powi(2)
            })
            .sum()
    }
}

impl RotaryQp<'_> {
    fn families(&self, feed: f64) -> Result<Vec<Family>, PlanError> {
        let err = |e: kerf_bspline::BsplineError| solver_error(self.axis_name, e.to_string());
        let n = self.knots.n_coeffs();
        if self.factor.n_coeffs != n {
            return Err(solver_error(
                self.axis_name,
                "jerk factor built for other knots",
            ));
        }
        let d = &self.factor.d;
        // The bounds are given to the solver BOUND_MARGIN inside the limits
        // (relative; the position range shrinks by that fraction), so its
        // tolerance (~1e-6 relative) never shows as a violation of Table 2
        // on the dense samples.
        let half_margin = 0.5 * BOUND_MARGIN * (self.limits.max - self.limits.min);
        let l = AxisLimits {
            min: self.limits.min + half_margin,
            max: self.limits.max - half_margin,
            vel: self.limits.vel * (1.0 - BOUND_MARGIN),
            acc: self.limits.acc * (1.0 - BOUND_MARGIN),
            jerk: self.limits.jerk * (1.0 - BOUND_MARGIN),
        };
        let s = self.sigma / feed;
        let mut fams = vec![Family {
            family: ConstraintFamily::Position,
            rows: (0..n).map(|j| (vec![(j, 1.0)], l.min, l.max)).collect(),
        }];
        for (r, (family, bound)) in [
            (ConstraintFamily::Velocity, l.vel * s),
            (ConstraintFamily::Acceleration, l.acc * s * s),
            (ConstraintFamily::Jerk, l.jerk * s * s * s),
        ]
        .into_iter()
        .enumerate()
        {
            fams.push(Family {
                family,
                rows: d[r]
                    .iter()
                    .map(|row| (row.clone(), -bound, bound))
                    .collect(),
            });
        }
        let mut boundary = Vec::new();
        for (k, (u, deriv)) in [(0.0, 1), (1.0, 1), (0.0, 2), (1.0, 2)]
            .into_iter()
            .enumerate()
        {
            if deriv == 1 && self.free_end_slopes {
                continue;
            }
            let coeffs = sparse_basis(self.knots, u, deriv).map_err(err)?;
            boundary.push((coeffs, self.boundary[k], self.boundary[k]));
        }
        fams.push(Family {
            family: ConstraintFamily::Boundary,
            rows: boundary,
        });
        let mut rto = Vec::new();
        for &(u, q) in self.via {
            let coeffs = sparse_basis(self.knots, u, 0).map_err(err)?;
            rto.push((coeffs, q, q));
        }
        for &(u, lo, hi) in self.via_box {
            if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                return Err(PlanError::invalid(
                    self.axis_name,
                    format!("RTO interval [{lo}, {hi}] at u = {u} is empty or not finite"),
                ));
            }
            let coeffs = sparse_basis(self.knots, u, 0).map_err(err)?;
            rto.push((coeffs, lo, hi));
        }
        fams.push(Family {
            family: ConstraintFamily::Rto,
            rows: rto,
        });
        let mut corridor = Vec::with_capacity(self.corridor.len());
        for &(u, lo, hi) in self.corridor {
            if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                return Err(PlanError::invalid(
                    self.axis_name,
                    format!("corridor interval [{lo}, {hi}] at u = {u} is empty or not finite"),
                ));
            }
            let coeffs = sparse_basis(self.knots, u, 0).map_err(err)?;
            corridor.push((coeffs, lo, hi));
        }
        fams.push(Family {
            family: ConstraintFamily::Allowance,
            rows: corridor,
        });
        Ok(fams)
    }

    /// One Clarabel solve at feedrate `feed` with the families that pass
    /// `keep`: `Ok(Some(Θ))`, `Ok(None)` when infeasible.
    fn attempt(
        &self,
        feed: f64,
        keep: &dyn Fn(ConstraintFamily) -> bool,
    ) -> Result<Option<(Vec<f64>, u32)>, PlanError> {
        let axis = self.axis_name;
        let fams = self.families(feed)?;
        let cone = &self.factor.lt_d3;
        let n = self.knots.n_coeffs();
        let nx = n + 1;
        let (mut ii, mut jj, mut vv, mut b) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut row = 0;
        let mut push = |coeffs: &[(usize, f64)],
                        rhs: f64,
                        scale: f64,
                        ii: &mut Vec<usize>,
                        jj: &mut Vec<usize>,
                        vv: &mut Vec<f64>,
                        b: &mut Vec<f64>| {
            for &(j, v) in coeffs {
                if v != 0.0 {
                    ii.push(row);
                    jj.push(j);
                    vv.push(v * scale);
                }
            }
            b.push(rhs * scale);
            row += 1;
        };
        let kept: Vec<&Family> = fams.iter().filter(|f| keep(f.family)).collect();
        let mut n_eq = 0;
        for f in &kept {
            for (c, lo, hi) in &f.rows {
                if lo == hi {
                    let s = 1.0
                        / c.iter()
                            .fold(0.0f64, |m, &(_, v)| m.max(v.abs()))
                            .max(f64::MIN_POSITIVE);
                    push(c, *lo, s, &mut ii, &mut jj, &mut vv, &mut b);
                    n_eq += 1;
                }
            }
        }
        let mut n_ineq = 0;
        for f in &kept {
            for (c, lo, hi) in &f.rows {
                if lo != hi {
                    let s = 1.0
                        / c.iter()
                            .fold(0.0f64, |m, &(_, v)| m.max(v.abs()))
                            .max(f64::MIN_POSITIVE);
                    push(c, *hi, s, &mut ii, &mut jj, &mut vv, &mut b);
                    let neg: Vec<(usize, f64)> = c.iter().map(|&(j, v)| (j, -v)).collect();
                    push(&neg, -*lo, s, &mut ii, &mut jj, &mut vv, &mut b);
                    n_ineq += 2;
                }
            }
        }
        let cone_scale = 1.0
            / cone
                .iter()
                .flatten()
                .fold(0.0f64, |m, &(_, v)| m.max(v.abs()))
                .max(f64::MIN_POSITIVE);
        push(&[(n, -1.0)], 0.0, 1.0, &mut ii, &mut jj, &mut vv, &mut b);
        for c in cone {
            let neg: Vec<(usize, f64)> = c.iter().map(|&(j, v)| (j, -v)).collect();
            push(&neg, 0.0, cone_scale, &mut ii, &mut jj, &mut vv, &mut b);
        }
        let cones = vec![
            SupportedConeT::ZeroConeT(n_eq),
            SupportedConeT::NonnegativeConeT(n_ineq),
            SupportedConeT::SecondOrderConeT(1 + cone.len()),
        ];
        let a = CscMatrix::new_from_triplets(row, nx, ii, jj, vv);
        let p = CscMatrix::zeros((nx, nx));
        let mut q = vec![0.0; nx];
        q[n] = 1.0;
        let settings = DefaultSettingsBuilder::default()
            .verbose(false)
            .max_iter(200)
            .build()
            .map_err(|e| solver_error(axis, format!("settings: {e}")))?;
        let mut solver = DefaultSolver::new(&p, &q, &a, &b, &cones, settings)
            .map_err(|e| solver_error(axis, format!("setup: {e}")))?;
        solver.solve();
        let x: Vec<f64> = solver.solution.x.iter().take(n).copied().collect();
        let iterations = solver.solution.iterations;
        match solver.solution.status {
            SolverStatus::Solved | SolverStatus::AlmostSolved => {
                if let Some(msg) = violation(&kept, &x) {
                    // At the edge of feasibility Clarabel can stop with a
                    // point just outside a bound: that is not a solution.
                    // The caller treats it as infeasible and diagnoses it.
                    log::debug!(
                        "{axis}: {:?} after {iterations} iterations, but {msg}",
                        solver.solution.status
                    );
                    return Ok(None);
                }
                Ok(Some((x, iterations)))
            }
            SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => Ok(None),
            s => Err(solver_error(
                axis,
                format!("{s:?} after {iterations} iterations"),
            )),
        }
    }

    /// Whether a solve at `feed` with the families `keep` finds a verified
    /// solution. A solver failure (no certificate either way) counts as
    /// not feasible: the diagnosis and the feedrate bisection then stay
    /// conservative.
    fn feasible(&self, feed: f64, keep: Keep) -> bool {
        matches!(self.attempt(feed, keep), Ok(Some(_)))
    }

    /// Solves the QP.
    ///
    /// # Returns
    /// The coefficients Θ and Clarabel's iteration count.
    ///
    /// # Errors
    /// [`PlanError::Infeasible`] naming the constraint family at fault (and
    /// the largest feasible feedrate when it is kinematic);
    /// [`PlanError::Solver`] when Clarabel fails.
    pub fn solve(&self) -> Result<(Vec<f64>, u32), PlanError> {
        if !(self.sigma > 0.0
            && self.feedrate > 0.0
            && self.sigma.is_finite()
            && self.feedrate.is_finite())
        {
            return Err(PlanError::invalid(
                self.axis_name,
                "path length and feedrate must be positive",
            ));
        }
        if let Some(sol) = self.attempt(self.feedrate, &|_| true)? {
            return Ok(sol);
        }
        use ConstraintFamily::*;
        let kinematic = |f: ConstraintFamily| matches!(f, Velocity | Acceleration | Jerk);
        let drops: [(&str, Keep, Option<ConstraintFamily>); 8] = [
            ("jerk", &|f| f != Jerk, Some(Jerk)),
            ("acceleration", &|f| f != Acceleration, Some(Acceleration)),
            ("velocity", &|f| f != Velocity, Some(Velocity)),
            ("kinematic", &|f| !kinematic(f), None),
            ("position", &|f| f != Position, Some(Position)),
            ("RTO", &|f| f != Rto, Some(Rto)),
            ("allowance corridor", &|f| f != Allowance, Some(Allowance)),
            ("boundary", &|f| f != Boundary, Some(Boundary)),
        ];
        for (name, keep, family) in drops {
            if self.feasible(self.feedrate, keep) {
                let family = family.unwrap_or(Jerk);
                let max_feed = if kinematic(family) {
                    self.max_feasible_feedrate()?
                } else {
                    None
                };
                return Err(PlanError::Infeasible {
                    problem: self.axis_name.into(),
                    family,
                    detail: format!(
                        "no spline meets every constraint at f = {:.6} m/s over σ = {:.6} m; it becomes feasible without the {name} bounds{}",
                        self.feedrate,
                        self.sigma,
                        if max_feed.is_some() {
                            " (the largest feasible feedrate below is that of the constant-feed bounds of eq. 15 with these RTOs; the feed ramps of eq. 7 and inserted RTOs can need a lower one)"
                        } else {
                            ""
                        }
                    ),
                    max_feasible_feedrate: max_feed,
                });
            }
        }
        Err(PlanError::Infeasible {
            problem: self.axis_name.into(),
            family: Rto,
            detail: "infeasible even with any single constraint family removed".into(),
            max_feasible_feedrate: None,
        })
    }

    /// One solve at the requested feedrate with every constraint: `Ok(Some(Θ))`, or
    /// `Ok(None)` when it is infeasible (without the diagnosis and the feedrate bisection of
    /// [`Self::solve`]).
    ///
    /// # Errors
    /// [`PlanError::Solver`] when Clarabel fails, [`PlanError::InvalidRequest`] for an empty
    /// or non-finite interval.
    pub fn try_solve(&self) -> Result<Option<Vec<f64>>, PlanError> {
        Ok(self.attempt(self.feedrate, &|_| true)?.map(|(x, _)| x))
    }

    /// Largest feasible feedrate below the requested one, to 0.1 %, by
    /// bisection (feasibility is monotone in f, module documentation);
    /// `None` when even a 1000 times lower feedrate is infeasible.
    pub fn max_feasible_feedrate(&self) -> Result<Option<f64>, PlanError> {
        let mut hi = self.feedrate;
        let mut lo = self.feedrate * 1e-3;
        if !self.feasible(lo, &|_| true) {
            return Ok(None);
        }
        while hi - lo > 1e-3 * lo {
            let mid = 0.5 * (lo + hi);
            if self.feasible(mid, &|_| true) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Ok(Some(lo))
    }
}

/// The first kept constraint violated beyond [`CHECK_REL`], in words.
fn violation(kept: &[&Family], x: &[f64]) -> Option<String> {
    let x_scale = x.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    for f in kept {
        for (c, lo, hi) in &f.rows {
            let v: f64 = c.iter().map(|&(j, a)| a * x[j]).sum();
            // Relative to the bound and to the size the row can take for
            // coefficients of the solution's magnitude (boundary rows of
            // eq. 45 sum terms of order n·|Θ|).
            let tol = if lo == hi {
                let size: f64 = c.iter().map(|&(_, a)| a.abs()).sum::<f64>() * x_scale;
                CHECK_REL * lo.abs().max(size)
            } else {
                // Inequalities carry BOUND_MARGIN: an answer past the
                // solver's bound but inside the true limit is accepted.
                BOUND_MARGIN * lo.abs().max(hi.abs())
            };
            if !v.is_finite() || v < lo - tol || v > hi + tol {
                return Some(format!(
                    "a {} row is {v:e} outside [{lo:e}, {hi:e}]",
                    f.family
                ));
            }
        }
    }
    None
}
