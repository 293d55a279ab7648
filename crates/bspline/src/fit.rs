//! Least-squares and interpolating fits (seed 001 eq. 49-52).

use crate::band::BandRows;
use crate::banded_sym::BandedSym;
use crate::collocation::collocation;
use crate::error::{check_finite, BsplineError};
use crate::knots::KnotVector;

/// The normal matrix N^T N of a band matrix N (banded, symmetric positive
/// semidefinite; positive definite when N has full column rank).
///
/// # Arguments
/// * `n` - the matrix N (e.g. from [`collocation`]);
/// * `bandwidth` - the bandwidth of the result; it is raised to what the
///   rows of N actually need (the longest row minus one, k for a
///   collocation matrix), so no product is ever dropped.
///
/// # Performance
/// O(m k^2) for m rows of k + 1 values.
pub fn normal_matrix(n: &BandRows, bandwidth: usize) -> BandedSym {
    let needed = n
        .rows
        .iter()
        .map(|r| r.values.len().saturating_sub(1))
        .max()
        .unwrap_or(0);
    let mut a = BandedSym::zeros(n.ncols, bandwidth.max(needed));
    for r in &n.rows {
        for (ia, va) in r.values.iter().enumerate() {
            for (ib, vb) in r.values.iter().enumerate().take(ia + 1) {
                a.add(r.start + ia, r.start + ib, va * vb);
            }
        }
    }
    a
}

/// The right-hand side N^T y of the normal equations.
///
/// # Errors
/// [`BsplineError::LengthMismatch`] when `y.len() != n.nrows()`.
pub fn normal_rhs(n: &BandRows, y: &[f64]) -> Result<Vec<f64>, BsplineError> {
    n.try_tr_mul_vec(y)
}

/// Least-squares or interpolating fit: the coefficients P minimizing
/// `||N P - values||_2` with `N = collocation(kv, params)`, i.e.
/// `P = N^+ values = (N^T N)^{-1} N^T values` (seed 001 eq. 51-52). With as
/// many parameters as coefficients N is square and P interpolates.
///
/// # Arguments
/// * `kv` - the knot vector;
/// * `params` - the parameters u_i in [0, 1];
/// * `values` - the data q_i at u_i (same length as `params`).
///
/// # Errors
/// [`BsplineError::LengthMismatch`] when the lengths differ,
/// [`BsplineError::TooFewPoints`] with fewer points than coefficients,
/// [`BsplineError::NotFinite`] / [`BsplineError::ParameterOutOfRange`] for
/// bad inputs, and [`BsplineError::Singular`] when N^T N is singular: the
/// parameters then violate the Schoenberg-Whitney condition (some basis
/// function has too few parameters in its support).
///
/// # Performance
/// O(m k^2 + n k^2) for m points and n + 1 coefficients.
pub fn fit(kv: &KnotVector, params: &[f64], values: &[f64]) -> Result<Vec<f64>, BsplineError> {
    if params.len() != values.len() {
        return Err(BsplineError::LengthMismatch {
            what: "values of a fit (one per parameter)".into(),
            expected: params.len(),
            got: values.len(),
        });
    }
    if params.len() < kv.n_coeffs() {
        return Err(BsplineError::TooFewPoints {
            n_points: params.len(),
            n_coeffs: kv.n_coeffs(),
        });
    }
    check_finite("fit values", values)?;
    let n = collocation(kv, params)?;
    let a = normal_matrix(&n, kv.degree());
    let rhs = normal_rhs(&n, values)?;
    a.solve_spd(&rhs).map_err(|e| match e {
        BsplineError::Singular { detail } => BsplineError::Singular {
            detail: format!(
                "N^T N of the fit is singular ({detail}); the parameters violate the \
                 Schoenberg-Whitney condition: every basis function needs its own \
                 parameter inside its support"
            ),
        },
        other => other,
    })
}
