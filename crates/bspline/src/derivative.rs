//! Derivative control coefficients as linear operators (seed 001 eq. 11-12,
//! 21-26, 36-38).

use crate::band::{BandRow, BandRows};
use crate::error::BsplineError;
use crate::knots::KnotVector;

/// Linear operator D_r mapping the coefficients Θ to the control
/// coefficients Θ^{r} of the r-th derivative (seed 001 eq. 11-12, 21-23).
///
/// The r-th derivative of `q(u) = Σ_j Θ_j N_{j,k}(u)` is
/// `q^{(r)}(u) = Σ_{j=0}^{n-r} Θ^{r}_j N_{j,k-r}(u)` on the knot vector
/// returned by [`derivative_knots`] (seed 001 eq. 11), with the recursion
///
/// `Θ^{l}_j = (k - l + 1) / (u_{j+k+1} - u_{j+l}) · (Θ^{l-1}_{j+1} - Θ^{l-1}_j)`
///
/// for `l = 1..=r` (*The NURBS Book*, eq. 3.8 and algorithm A3.3).
///
/// **Deviation from the paper.** Seed 001 eq. 12 writes the denominator
/// `u_{j+k+1} - u_{j+1}` for every l, and the closed forms eq. 22-26 (with
/// one factor `c_j^r` per row) assume that all the denominators met in the
/// recursion are equal, i.e. uniformly spaced knots. On the first and last
/// k spans of a clamped knot vector the knots repeat, so those formulas are
/// wrong there (the r-th derivative they give is not that of the spline).
/// This function implements the exact recursion for any clamped knot
/// vector; on rows whose knots `u_{j+1} .. u_{j+k+r}` are uniformly spaced
/// it reduces to eq. 21-26 (tested in `tests/derivatives.rs`).
///
/// # Arguments
/// * `kv` - the knot vector (degree k, n + 1 coefficients);
/// * `r` - the derivative order, `0 <= r <= k` (r = 0 gives the identity).
///
/// # Returns
/// A `(n + 1 - r) × (n + 1)` band matrix; row j holds the r + 1 values of
/// columns `j ..= j + r` (the rows of eq. 36-38, without the paper's
/// restriction to the uniform rows).
///
/// # Errors
/// [`BsplineError::DerivativeOrderTooHigh`] when `r > k`;
/// [`BsplineError::Singular`] if a knot difference vanishes (impossible for
/// the knot vectors this crate builds).
///
/// # Performance
/// O(n r^2).
pub fn derivative_operator(kv: &KnotVector, r: usize) -> Result<BandRows, BsplineError> {
    let k = kv.degree();
    if r > k {
        return Err(BsplineError::DerivativeOrderTooHigh {
            order: r,
            degree: k,
        });
    }
    let n1 = kv.n_coeffs();
    let u = kv.knots();
    // Level 0: identity rows.
    let mut rows: Vec<BandRow> = (0..n1)
        .map(|j| BandRow {
            start: j,
            values: vec![1.0],
        })
        .collect();
    for l in 1..=r {
        let mut next = Vec::with_capacity(rows.len().saturating_sub(1));
        for (j, pair) in rows.windows(2).enumerate() {
            let (lo, hi) = match pair {
                [a, b] => (a, b),
                _ => continue,
            };
            let (ua, ub) = match (u.get(j + k + 1), u.get(j + l)) {
                (Some(&a), Some(&b)) => (a, b),
                _ => {
                    return Err(BsplineError::InvalidKnots {
                        detail: format!("knot index {} out of range", j + k + 1),
                    })
                }
            };
            let den = ua - ub;
            if den <= 0.0 {
                return Err(BsplineError::Singular {
                    detail: format!(
                        "derivative level {l}, row {j}: knot difference u[{}] - u[{}] = {den}",
                        j + k + 1,
                        j + l
                    ),
                });
            }
            let c = (k - l + 1) as f64 / den;
            // Row j of level l spans columns j ..= j + l: c * (hi - lo),
            // where lo spans j ..= j + l - 1 and hi spans j + 1 ..= j + l.
            let mut values = vec![0.0; l + 1];
            for (t, v) in lo.values.iter().enumerate() {
                if let Some(d) = values.get_mut(t) {
                    *d -= c * v;
                }
            }
            for (t, v) in hi.values.iter().enumerate() {
                if let Some(d) = values.get_mut(t + 1) {
                    *d += c * v;
                }
            }
            next.push(BandRow { start: j, values });
        }
        rows = next;
    }
    Ok(BandRows { ncols: n1, rows })
}

/// Knot vector of the r-th derivative curve: degree k - r, the knots of
/// `kv` without the first and last r (same interior knots; seed 001
/// eq. 11, *The NURBS Book* eq. 3.9).
///
/// Evaluate `Σ_j Θ^{r}_j N_{j,k-r}(u)` with it, Θ^{r} from
/// [`derivative_operator`].
///
/// # Errors
/// [`BsplineError::DerivativeOrderTooHigh`] when `r > k`.
pub fn derivative_knots(kv: &KnotVector, r: usize) -> Result<KnotVector, BsplineError> {
    let k = kv.degree();
    if r > k {
        return Err(BsplineError::DerivativeOrderTooHigh {
            order: r,
            degree: k,
        });
    }
    KnotVector::clamped_with_interior(k - r, kv.interior())
}
