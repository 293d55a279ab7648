//! Exact solve of an equality-constrained QP through its KKT system:
//!
//! ```text
//! min ½ xᵀPx + qᵀx  s.t.  C x = d      ⇔      [P  Cᵀ] [x]   [−q]
//!                                             [C −δI] [λ] = [ d]
//! ```
//!
//! (Nocedal & Wright, *Numerical Optimization*, 2nd ed., eq. 16.4; the
//! small `−δI` block is a quasi-definite regularisation that keeps the
//! factorisation defined when equality rows are dependent, removed again
//! by iterative refinement against the unregularised system, N&W §16.2 and
//! Higham, *Accuracy and Stability of Numerical Algorithms*, §12.1).
//!
//! The variables carry a location key (e.g. the parameter u of the basis
//! function or CL point they belong to); ordering variables by key and
//! placing each constraint row right after the last variable it touches
//! makes the KKT matrix banded for the B-spline problems here, so it is
//! factorised by [`BandLu`] in O(N b²) for bandwidth b.
//!
//! This is the "polish" of the QPs: once the interior-point solve has
//! identified which inequalities are active, the optimum is the solution of
//! this linear system, which a direct solve gives to near machine
//! precision, where an interior-point iterate is only accurate to its
//! stopping tolerance.

use super::band_lu::{BandLu, BandLuError};

/// Relative quasi-definite regularisation δ of the constraint block.
const REGULARISATION: f64 = 1e-12;

/// Most iterative-refinement steps.
const MAX_REFINEMENT: usize = 12;

/// An accurate matrix-vector product `x ↦ P x`.
pub(crate) type MatVec<'a> = &'a dyn Fn(&[f64]) -> Vec<f64>;

/// An equality-constrained QP.
pub(crate) struct EqQp<'a> {
    /// Number of variables.
    pub n: usize,
    /// Upper triangle of P (row ≤ col), entries of a symmetric banded P.
    pub p_upper: &'a [(usize, usize, f64)],
    /// An accurate product `x ↦ P x` for the refinement residuals (the
    /// assembled P may be evaluated with cancellation; e.g. `D₃ᵀ G D₃ x`
    /// for the jerk Hessian). `None`: use `p_upper`.
    pub apply_p: Option<MatVec<'a>>,
    /// Linear term.
    pub q: &'a [f64],
    /// Rows of `C x = d`: sparse `(column, value)` lists and `d`.
    pub rows: &'a [(Vec<(usize, f64)>, f64)],
    /// Location key of each variable (ordering for bandedness).
    pub keys: &'a [f64],
}

/// Solution of an [`EqQp`].
#[derive(Debug, Clone)]
pub(crate) struct EqQpSolution {
    /// The minimiser x.
    pub x: Vec<f64>,
    /// Multipliers λ of the rows (`P x + q + Cᵀ λ = 0`).
    pub lambda: Vec<f64>,
}

/// Why the KKT solve failed.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum KktError {
    /// Inconsistent sizes or a bad index / non-finite entry.
    Malformed(String),
    /// The KKT matrix is numerically singular (e.g. P is not positive
    /// definite on the null space of C).
    Singular(String),
}

impl std::fmt::Display for KktError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            KktError::Malformed(s) => write!(f, "malformed KKT system: {s}"),
            KktError::Singular(s) => write!(f, "singular KKT system: {s}"),
        }
    }
}

/// `y = P x` from the upper triangle.
fn sym_mul(n: usize, p_upper: &[(usize, usize, f64)], x: &[f64]) -> Vec<f64> {
    let mut y = vec![0.0; n];
    for &(i, j, v) in p_upper {
        if let (Some(&xi), Some(&xj)) = (x.get(i), x.get(j)) {
            if let Some(yi) = y.get_mut(i) {
                *yi += v * xj;
            }
            if i != j {
                if let Some(yj) = y.get_mut(j) {
                    *yj += v * xi;
                }
            }
        }
    }
    y
}

/// Solves the equality-constrained QP `qp` (see the module doc).
///
/// # Errors
/// [`KktError::Malformed`] for inconsistent inputs,
/// [`KktError::Singular`] when the factorisation meets a zero pivot.
///
/// # Performance
/// O((n + m) b²) for bandwidth b of the reordered KKT matrix, plus a few
/// O((n + m) b) refinement steps.
pub(crate) fn solve_eq_qp(qp: &EqQp) -> Result<EqQpSolution, KktError> {
    let n = qp.n;
    let m = qp.rows.len();
    if qp.q.len() != n || qp.keys.len() != n {
        return Err(KktError::Malformed(format!(
            "{n} variables, {} linear terms, {} keys",
            qp.q.len(),
            qp.keys.len()
        )));
    }
    if qp.keys.iter().any(|k| k.is_nan()) || qp.q.iter().any(|v| !v.is_finite()) {
        return Err(KktError::Malformed("NaN key or linear term".into()));
    }
    for &(i, j, v) in qp.p_upper {
        if i > j || j >= n || !v.is_finite() {
            return Err(KktError::Malformed(format!("P entry ({i}, {j}) = {v}")));
        }
    }
    for (r, (entries, d)) in qp.rows.iter().enumerate() {
        if !d.is_finite() || entries.iter().any(|&(c, v)| c >= n || !v.is_finite()) {
            return Err(KktError::Malformed(format!("constraint row {r}")));
        }
    }
    // Rows scaled to unit largest coefficient (an equivalent system; the
    // multipliers are scaled back at the end).
    let row_scale: Vec<f64> = qp
        .rows
        .iter()
        .map(|(e, _)| {
            let s = e.iter().fold(0.0_f64, |a, &(_, v)| a.max(v.abs()));
            if s > 0.0 {
                s
            } else {
                1.0
            }
        })
        .collect();
    let scaled_rows: Vec<(Vec<(usize, f64)>, f64)> = qp
        .rows
        .iter()
        .zip(&row_scale)
        .map(|((e, d), s)| (e.iter().map(|&(c, v)| (c, v / s)).collect(), d / s))
        .collect();
    let rows = &scaled_rows;
    // Variable order by key; each row after its last variable.
    let mut var_order: Vec<usize> = (0..n).collect();
    var_order.sort_by(|&a, &b| qp.keys[a].total_cmp(&qp.keys[b]).then(a.cmp(&b)));
    let mut var_rank = vec![0usize; n];
    for (rank, &v) in var_order.iter().enumerate() {
        var_rank[v] = rank;
    }
    let last_rank =
        |entries: &[(usize, f64)]| entries.iter().map(|&(c, _)| var_rank[c]).max().unwrap_or(0);
    let mut row_order: Vec<usize> = (0..m).collect();
    row_order.sort_by_key(|&r| (last_rank(&rows[r].0), r));
    // Merge into one position list: pos_var[v], pos_row[r].
    let mut pos_var = vec![0usize; n];
    let mut pos_row = vec![0usize; m];
    let mut next = 0usize;
    let mut ri = 0usize;
    for (rank, &v) in var_order.iter().enumerate() {
        pos_var[v] = next;
        next += 1;
        while let Some(&r) = row_order.get(ri) {
            if last_rank(&rows[r].0) != rank {
                break;
            }
            pos_row[r] = next;
            next += 1;
            ri += 1;
        }
    }
    while let Some(&r) = row_order.get(ri) {
        pos_row[r] = next;
        next += 1;
        ri += 1;
    }
    let dim = n + m;
    // Entries of the regularised KKT matrix in the permuted numbering.
    let pmax = qp.p_upper.iter().fold(0.0_f64, |a, e| a.max(e.2.abs()));
    let cmax = qp
        .rows
        .iter()
        .flat_map(|(e, _)| e.iter())
        .fold(0.0_f64, |a, e| a.max(e.1.abs()));
    let delta = REGULARISATION * pmax.max(cmax).max(f64::MIN_POSITIVE);
    let mut entries = Vec::with_capacity(2 * qp.p_upper.len() + 2 * m * 8 + m);
    for &(i, j, v) in qp.p_upper {
        entries.push((pos_var[i], pos_var[j], v));
        if i != j {
            entries.push((pos_var[j], pos_var[i], v));
        }
    }
    for (r, (row, _)) in rows.iter().enumerate() {
        for &(c, v) in row {
            entries.push((pos_row[r], pos_var[c], v));
            entries.push((pos_var[c], pos_row[r], v));
        }
        entries.push((pos_row[r], pos_row[r], -delta));
    }
    let bw = entries
        .iter()
        .map(|&(a, b, _)| a.abs_diff(b))
        .max()
        .unwrap_or(0);
    let scale = pmax.max(cmax).max(delta);
    let lu = BandLu::factor(dim, bw, bw, entries, 1e-300 * scale).map_err(|e| match e {
        BandLuError::Singular { column } => {
            KktError::Singular(format!("zero pivot at KKT position {column} of {dim}"))
        }
        other => KktError::Malformed(format!("{other:?}")),
    })?;
    // Right-hand side in permuted numbering.
    let mut rhs = vec![0.0; dim];
    for v in 0..n {
        rhs[pos_var[v]] = -qp.q[v];
    }
    for (r, (_, d)) in rows.iter().enumerate() {
        rhs[pos_row[r]] = *d;
    }
    // True (unregularised) KKT product, in natural numbering.
    let kkt_residual = |x: &[f64], lam: &[f64]| -> Vec<f64> {
        let px = match qp.apply_p {
            Some(f) => f(x),
            None => sym_mul(n, qp.p_upper, x),
        };
        let mut res = vec![0.0; dim];
        for v in 0..n {
            res[pos_var[v]] = -qp.q[v] - px.get(v).copied().unwrap_or(f64::NAN);
        }
        for (r, (row, d)) in rows.iter().enumerate() {
            let mut cx = 0.0;
            for &(c, a) in row {
                cx += a * x[c];
                res[pos_var[c]] -= a * lam[r];
            }
            res[pos_row[r]] = d - cx;
        }
        res
    };
    let mut sol = rhs.clone();
    lu.solve(&mut sol);
    let mut x: Vec<f64> = (0..n).map(|v| sol[pos_var[v]]).collect();
    let mut lam: Vec<f64> = (0..m).map(|r| sol[pos_row[r]]).collect();
    let mut prev = f64::INFINITY;
    for _ in 0..MAX_REFINEMENT {
        let mut res = kkt_residual(&x, &lam);
        let norm = res.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        if !norm.is_finite() || norm >= 0.5 * prev {
            break;
        }
        prev = norm;
        lu.solve(&mut res);
        for v in 0..n {
            x[v] += res[pos_var[v]];
        }
        for r in 0..m {
            lam[r] += res[pos_row[r]];
        }
    }
    if x.iter().chain(&lam).any(|v| !v.is_finite()) {
        return Err(KktError::Singular("non-finite solution".into()));
    }
    let lambda = lam.iter().zip(&row_scale).map(|(l, s)| l / s).collect();
    Ok(EqQpSolution { x, lambda })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    /// A small banded QP with scattered keys against a dense KKT solve.
    #[test]
    fn matches_dense_kkt() {
        let n = 12;
        let mut p_upper = Vec::new();
        for i in 0..n {
            p_upper.push((i, i, 4.0 + i as f64 * 0.1));
            if i + 1 < n {
                p_upper.push((i, i + 1, -1.0));
            }
        }
        let q: Vec<f64> = (0..n).map(|i| (i as f64).cos()).collect();
        let rows = vec![
            (vec![(0, 1.0), (1, 1.0)], 1.0),
            (vec![(5, 2.0), (6, -1.0), (7, 0.5)], -0.3),
            (vec![(11, 1.0)], 0.25),
        ];
        // Keys: reverse order, to exercise the permutation.
        let keys: Vec<f64> = (0..n).map(|i| (n - i) as f64).collect();
        let qp = EqQp {
            n,
            p_upper: &p_upper,
            apply_p: None,
            q: &q,
            rows: &rows,
            keys: &keys,
        };
        let sol = solve_eq_qp(&qp).unwrap();
        let m = rows.len();
        let mut k = DMatrix::zeros(n + m, n + m);
        for &(i, j, v) in &p_upper {
            k[(i, j)] = v;
            k[(j, i)] = v;
        }
        let mut rhs = DVector::zeros(n + m);
        for i in 0..n {
            rhs[i] = -q[i];
        }
        for (r, (e, d)) in rows.iter().enumerate() {
            for &(c, v) in e {
                k[(n + r, c)] = v;
                k[(c, n + r)] = v;
            }
            rhs[n + r] = *d;
        }
        let dense = k.lu().solve(&rhs).unwrap();
        for i in 0..n {
            assert!((sol.x[i] - dense[i]).abs() < 1e-12, "x[{i}]");
        }
        for r in 0..m {
            assert!((sol.lambda[r] - dense[n + r]).abs() < 1e-10, "lambda[{r}]");
        }
    }

    /// Duplicate (dependent) rows are handled by the regularisation.
    #[test]
    fn dependent_rows_are_tolerated() {
        let p_upper = [(0, 0, 2.0), (1, 1, 2.0)];
        let rows = vec![
            (vec![(0, 1.0), (1, 1.0)], 1.0),
            (vec![(0, 1.0), (1, 1.0)], 1.0),
        ];
        let qp = EqQp {
            n: 2,
            p_upper: &p_upper,
            apply_p: None,
            q: &[0.0, 0.0],
            rows: &rows,
            keys: &[0.0, 1.0],
        };
        let sol = solve_eq_qp(&qp).unwrap();
        assert!((sol.x[0] - 0.5).abs() < 1e-9 && (sol.x[1] - 0.5).abs() < 1e-9);
    }
}
