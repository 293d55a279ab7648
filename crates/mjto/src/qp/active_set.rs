//! Active-set polish of a convex QP with equality and two-sided inequality
//! rows (OSQP-style solution polishing: Stellato et al., "OSQP: an
//! operator splitting solver for quadratic programs", *Math. Prog.
//! Comp.* 12, 2020, §5.2; active-set optimality conditions: Nocedal &
//! Wright, *Numerical Optimization*, 2nd ed., Theorem 16.4).
//!
//! Starting from a guess of the active inequalities (from an interior-point
//! solve, or empty), it solves the equality-constrained QP with those
//! inequalities held at their bounds ([`solve_eq_qp`]), then checks the
//! KKT conditions of the full problem: every inequality satisfied, and
//! every active multiplier of the right sign. Violated rows are added,
//! wrong-sign rows released, and the solve repeated. When it returns, the
//! point is the optimum of the full QP to the checking tolerance,
//! whatever the accuracy of the initial guess.

use super::kkt::{solve_eq_qp, EqQp, MatVec};

/// Relative tolerance of the primal checks of the polish.
pub(crate) const PRIMAL_TOL: f64 = 1e-9;

/// Relative tolerance (to the largest multiplier) of the sign checks.
const DUAL_TOL: f64 = 1e-9;

/// Most polish rounds.
const MAX_ROUNDS: usize = 30;

/// Absolute floor of the checks (SI).
const ABS_FLOOR: f64 = 1e-12;

/// One row `lo ≤ aᵀx ≤ hi` or `aᵀx = lo = hi`.
#[derive(Debug, Clone)]
pub(crate) struct LinRow {
    /// `(column, coefficient)` pairs.
    pub entries: Vec<(usize, f64)>,
    /// Lower side (may be −∞).
    pub lo: f64,
    /// Upper side (may be +∞).
    pub hi: f64,
    /// Reference magnitude of the check besides the bound itself.
    pub scale: f64,
}

impl LinRow {
    /// `aᵀx`.
    pub fn value(&self, x: &[f64]) -> f64 {
        self.entries
            .iter()
            .map(|&(c, a)| a * x.get(c).copied().unwrap_or(f64::NAN))
            .sum()
    }

    /// `Σ |a_j x_j|`, the magnitude of the terms of `aᵀx`.
    fn magnitude(&self, x: &[f64]) -> f64 {
        self.entries
            .iter()
            .map(|&(c, a)| (a * x.get(c).copied().unwrap_or(f64::NAN)).abs())
            .sum()
    }

    /// Tolerance at bound `b`: [`PRIMAL_TOL`] relative to `max(|b|,
    /// scale)`, plus the rounding error of evaluating `aᵀx` (64 ε Σ|a_j x_j|)
    /// and an absolute floor.
    fn tol(&self, b: f64, x: &[f64]) -> f64 {
        PRIMAL_TOL * b.abs().max(self.scale) + 64.0 * f64::EPSILON * self.magnitude(x) + ABS_FLOOR
    }

    /// By how much `x` exceeds the given side (positive when violated).
    fn excess(&self, x: &[f64], side: Side) -> f64 {
        match side {
            Side::Upper => self.value(x) - self.hi,
            Side::Lower => self.lo - self.value(x),
        }
    }

    /// Whether the equality `aᵀx = lo` holds (to [`LinRow::tol`]).
    pub fn holds_as_equality(&self, x: &[f64]) -> bool {
        (self.value(x) - self.lo).abs() <= self.tol(self.lo, x)
    }

    /// Which side `x` violates, if any (NaN counts as the upper side).
    pub fn violated(&self, x: &[f64]) -> Option<Side> {
        let v = self.value(x);
        if v.is_nan() || (self.hi.is_finite() && v - self.hi > self.tol(self.hi, x)) {
            Some(Side::Upper)
        } else if self.lo.is_finite() && self.lo - v > self.tol(self.lo, x) {
            Some(Side::Lower)
        } else {
            None
        }
    }
}

/// Which side of an inequality is held.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Side {
    /// `aᵀx = lo`.
    Lower,
    /// `aᵀx = hi`.
    Upper,
}

/// The objective and variable layout of a QP to polish.
pub(crate) struct PolishQp<'a> {
    /// Number of variables.
    pub n: usize,
    /// Upper triangle of P (objective `½xᵀPx + qᵀx`).
    pub p_upper: &'a [(usize, usize, f64)],
    /// Accurate `x ↦ P x` (see [`EqQp::apply_p`]).
    pub apply_p: Option<MatVec<'a>>,
    /// Linear term.
    pub q: &'a [f64],
    /// Location keys of the variables (see [`EqQp::keys`]).
    pub keys: &'a [f64],
}

/// Polishes: returns the optimum of `min ½xᵀPx + qᵀx` subject to the
/// equality rows `eq` (`lo = hi`) and the inequality rows `ineq`,
/// starting from the active guess `active` (indices into `ineq`).
///
/// # Errors
/// A description when the KKT system is singular, the rounds do not settle
/// within their limit, or an equality row cannot be met (inconsistent
/// equalities).
pub(crate) fn polish(
    qp: &PolishQp,
    eq: &[LinRow],
    ineq: &[LinRow],
    mut active: Vec<(usize, Side)>,
) -> Result<Vec<f64>, String> {
    active.sort_by_key(|&(i, _)| i);
    active.dedup_by_key(|&mut (i, _)| i);
    active.retain(|&(i, _)| i < ineq.len());
    for round in 0..MAX_ROUNDS {
        let mut rows: Vec<(Vec<(usize, f64)>, f64)> =
            eq.iter().map(|r| (r.entries.clone(), r.lo)).collect();
        for &(i, side) in &active {
            let r = &ineq[i];
            let b = match side {
                Side::Lower => r.lo,
                Side::Upper => r.hi,
            };
            rows.push((r.entries.clone(), b));
        }
        let sol = solve_eq_qp(&EqQp {
            n: qp.n,
            p_upper: qp.p_upper,
            apply_p: qp.apply_p,
            q: qp.q,
            rows: &rows,
            keys: qp.keys,
        })
        .map_err(|e| format!("round {round}: {e}"))?;
        let x = sol.x;
        if let Some((i, r)) = eq
            .iter()
            .enumerate()
            .find(|(_, r)| !r.holds_as_equality(&x))
        {
            return Err(format!(
                "equality row {i} is {:.9e} against {:.9e}: the equalities are inconsistent",
                r.value(&x),
                r.lo
            ));
        }
        // Multipliers of the active rows follow the equalities.
        let lam = sol.lambda.get(eq.len()..).unwrap_or(&[]);
        let lam_max = sol.lambda.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        // P x + q + Cᵀλ = 0: an upper-held row needs λ ≥ 0, a lower-held
        // one λ ≤ 0 (the multiplier of −aᵀx ≤ −lo is −λ ≥ 0).
        let wrong: Vec<usize> = active
            .iter()
            .zip(lam)
            .filter(|&(&(_, side), &l)| match side {
                Side::Upper => l < -DUAL_TOL * lam_max,
                Side::Lower => l > DUAL_TOL * lam_max,
            })
            .map(|(&(i, _), _)| i)
            .collect();
        let mut violated: Vec<(usize, Side, f64)> = ineq
            .iter()
            .enumerate()
            .filter(|(i, _)| !active.iter().any(|&(a, _)| a == *i))
            .filter_map(|(i, r)| r.violated(&x).map(|s| (i, s, r.excess(&x, s))))
            .collect();
        if wrong.is_empty() && violated.is_empty() {
            return Ok(x);
        }
        // Add one violated row per cluster: the most violated of each group
        // of violated rows chained by shared variables. Bounds on a densely
        // sampled smooth function (a spline at many parameters) are touched
        // at isolated points; holding a whole violated run at once makes the
        // multipliers of neighbouring rows alternate in sign and the active
        // set oscillate.
        active.retain(|(i, _)| !wrong.contains(i));
        let span = |i: usize| {
            let cols = ineq[i].entries.iter().map(|&(c, _)| c);
            (cols.clone().min().unwrap_or(0), cols.max().unwrap_or(0))
        };
        violated.sort_by_key(|&(i, _, _)| (span(i), i));
        let mut best: Option<(usize, Side, f64)> = None;
        let mut reach = 0usize;
        for (i, side, excess) in violated {
            let (lo, hi) = span(i);
            match best {
                Some(b) if lo <= reach => {
                    if excess > b.2 {
                        best = Some((i, side, excess));
                    }
                    reach = reach.max(hi);
                }
                _ => {
                    if let Some((bi, bs, _)) = best {
                        active.push((bi, bs));
                    }
                    best = Some((i, side, excess));
                    reach = hi;
                }
            }
        }
        if let Some((bi, bs, _)) = best {
            active.push((bi, bs));
        }
        active.sort_by_key(|&(i, _)| i);
    }
    Err(format!(
        "active set did not settle in {MAX_ROUNDS} rounds ({} rows held)",
        active.len()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// min Σ (x_i − t_i)² with 0.2 ≤ x_i ≤ 0.6 and x_0 + x_1 = 1: the
    /// solution is the clipped target, with the equality shared.
    #[test]
    fn finds_the_clipped_optimum_from_an_empty_guess() {
        let n = 6;
        let t = [0.9, 0.5, -0.3, 0.4, 0.8, 0.1];
        let p_upper: Vec<_> = (0..n).map(|i| (i, i, 2.0)).collect();
        let q: Vec<f64> = t.iter().map(|v| -2.0 * v).collect();
        let keys: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let qp = PolishQp {
            n,
            p_upper: &p_upper,
            apply_p: None,
            q: &q,
            keys: &keys,
        };
        let eq = [LinRow {
            entries: vec![(0, 1.0), (1, 1.0)],
            lo: 1.0,
            hi: 1.0,
            scale: 1.0,
        }];
        let ineq: Vec<LinRow> = (0..n)
            .map(|i| LinRow {
                entries: vec![(i, 1.0)],
                lo: 0.2,
                hi: 0.6,
                scale: 1.0,
            })
            .collect();
        // A wrong initial guess (x_2 held at its upper side) is released.
        let x = polish(&qp, &eq, &ineq, vec![(2, Side::Upper)]).unwrap();
        let expect = [0.6, 0.4, 0.2, 0.4, 0.6, 0.2];
        for (a, e) in x.iter().zip(expect) {
            assert!((a - e).abs() < 1e-12, "{x:?}");
        }
        // Inconsistent equalities are reported.
        let bad = [
            eq[0].clone(),
            LinRow {
                entries: vec![(0, 1.0), (1, 1.0)],
                lo: 2.0,
                hi: 2.0,
                scale: 1.0,
            },
        ];
        assert!(polish(&qp, &bad, &ineq, vec![]).is_err());
    }
}
