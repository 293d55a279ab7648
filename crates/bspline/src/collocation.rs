//! Collocation matrices and single basis rows (seed 001 eq. 35, 45, 49, 59).

use crate::band::{BandRow, BandRows};
use crate::error::{check_param, BsplineError};
use crate::knots::KnotVector;

/// Row of basis-function derivatives at u: `N^{(r)}_{j,k}(u)` for all j,
/// stored as the k + 1 possibly nonzero entries (seed 001 eq. 45 rows for
/// r = 1, 2 at u = 0 and 1; eq. 59 rows for r = 0 at the RTO via points).
///
/// # Arguments
/// * `kv` - the knot vector;
/// * `u` - the parameter in [0, 1] (1e-12 tolerance, then clamped);
/// * `deriv` - the derivative order r; above the degree the row is zero.
///
/// # Errors
/// [`BsplineError::NotFinite`] / [`BsplineError::ParameterOutOfRange`] for a
/// bad `u`.
///
/// # Performance
/// O(k^2).
pub fn basis_row(kv: &KnotVector, u: f64, deriv: usize) -> Result<BandRow, BsplineError> {
    let u = check_param(u)?;
    let (first, mut ders) = kv.basis_derivs(u, deriv);
    let values = ders.pop().unwrap_or_default();
    Ok(BandRow {
        start: first,
        values,
    })
}

/// Collocation matrix N with `n_ij = N_{j,k}(u_i)` (seed 001 eq. 35, 49,
/// 59): one row per parameter, one column per coefficient.
///
/// Works for any number of parameters: square when
/// `params.len() == kv.n_coeffs()` (interpolation, eq. 35), tall for least
/// squares (eq. 49-52), or a few rows for via-point equalities (eq. 59).
///
/// # Errors
/// [`BsplineError::NotFinite`] / [`BsplineError::ParameterOutOfRange`] for
/// the first bad parameter.
///
/// # Performance
/// O(m k^2) for m parameters; the result stores m (k + 1) values.
pub fn collocation(kv: &KnotVector, params: &[f64]) -> Result<BandRows, BsplineError> {
    let rows = params
        .iter()
        .map(|&u| basis_row(kv, u, 0))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(BandRows {
        ncols: kv.n_coeffs(),
        rows,
    })
}
