//! Scalar B-spline curves q(u) = Σ Θ_j N_{j,k}(u) (seed 001 eq. 5, 8-10).

use crate::derivative::{derivative_knots, derivative_operator};
use crate::error::{check_finite, check_param, BsplineError};
use crate::knots::KnotVector;

/// Largest degree + 1 that [`BSpline::eval`] evaluates on the stack.
const FAST_WIDTH: usize = 8;

/// A scalar clamped B-spline `q(u) = Σ_{j=0}^{n} Θ_j N_{j,k}(u)` on
/// u in [0, 1] (seed 001 eq. 5).
#[derive(Debug, Clone, PartialEq)]
pub struct BSpline {
    kv: KnotVector,
    coeffs: Vec<f64>,
}

impl BSpline {
    /// A spline from its knot vector and coefficients Θ_0 .. Θ_n.
    ///
    /// # Errors
    /// [`BsplineError::LengthMismatch`] when `coeffs.len() != kv.n_coeffs()`,
    /// [`BsplineError::NotFinite`] for a NaN/infinite coefficient.
    pub fn new(kv: KnotVector, coeffs: Vec<f64>) -> Result<Self, BsplineError> {
        if coeffs.len() != kv.n_coeffs() {
            return Err(BsplineError::LengthMismatch {
                what: "B-spline coefficients".into(),
                expected: kv.n_coeffs(),
                got: coeffs.len(),
            });
        }
        check_finite("B-spline coefficient", &coeffs)?;
        Ok(Self { kv, coeffs })
    }

    /// The knot vector.
    pub fn knots(&self) -> &KnotVector {
        &self.kv
    }

    /// The coefficients Θ_0 .. Θ_n.
    pub fn coeffs(&self) -> &[f64] {
        &self.coeffs
    }

    /// Value and derivatives `[q, q_u, q_uu, q_uuu]` at u (seed 001 eq. 5,
    /// 8-10); derivatives above the degree are 0.
    ///
    /// u outside [0, 1] is clamped; a NaN u gives NaN values (use
    /// [`BSpline::try_eval`] to reject it).
    ///
    /// # Performance
    /// O(k^2).
    pub fn eval(&self, u: f64) -> [f64; 4] {
        let [out] = self.eval_coefficients([&self.coeffs], u);
        out
    }

    /// `[q, q_u, q_uu, q_uuu]` at u of the splines with this knot vector and the coefficient
    /// lists `coeffs` (each of `n_coeffs` entries; a shorter list contributes zeros), from one
    /// basis evaluation (on the stack for degree < 8; the arithmetic of
    /// [`KnotVector::basis_derivs`]).
    fn eval_coefficients<const N: usize>(&self, coeffs: [&[f64]; N], u: f64) -> [[f64; 4]; N] {
        let w = self.kv.degree() + 1;
        let mut out = [[0.0; 4]; N];
        let mut combine = |first: usize, ders: &[f64]| {
            for (o, c) in out.iter_mut().zip(coeffs) {
                for (v, row) in o.iter_mut().zip(ders.chunks(w)) {
                    *v = c
                        .get(first..)
                        .unwrap_or(&[])
                        .iter()
                        .zip(row)
                        .map(|(c, n)| c * n)
                        .sum();
                }
            }
        };
        if w <= FAST_WIDTH {
            let mut ders = [0.0; 4 * FAST_WIDTH];
            let mut ndu = [0.0; FAST_WIDTH * FAST_WIDTH];
            let mut scratch = [0.0; 4 * FAST_WIDTH];
            let first = self
                .kv
                .basis_derivs_into(u, 3, &mut ders, &mut ndu, &mut scratch);
            combine(first, &ders[..4 * w]);
        } else {
            let (first, ders) = self.kv.basis_derivs(u, 3);
            combine(first, &ders.concat());
        }
        out
    }

    /// [`BSpline::eval`] of several splines that share this spline's knot vector, with one
    /// basis evaluation for all: `out[i]` is `[q, q_u, q_uu, q_uuu]` of the spline with this
    /// knot vector and the coefficients `coeffs[i]` (a curve's coordinates, fitted on one
    /// knot vector).
    ///
    /// # Errors
    /// [`BsplineError::NotFinite`] / [`BsplineError::ParameterOutOfRange`] for u;
    /// [`BsplineError::LengthMismatch`] for a coefficient list of another length.
    ///
    /// # Performance
    /// One basis evaluation (O(k²), on the stack for degree < 8) and N dot products.
    pub fn eval_shared<const N: usize>(
        &self,
        coeffs: [&[f64]; N],
        u: f64,
    ) -> Result<[[f64; 4]; N], BsplineError> {
        let u = check_param(u)?;
        let n = self.kv.n_coeffs();
        if let Some(c) = coeffs.iter().find(|c| c.len() != n) {
            return Err(BsplineError::LengthMismatch {
                what: "B-spline coefficients".into(),
                expected: n,
                got: c.len(),
            });
        }
        Ok(self.eval_coefficients(coeffs, u))
    }

    /// [`BSpline::eval`] after validating u.
    ///
    /// # Errors
    /// [`BsplineError::NotFinite`] / [`BsplineError::ParameterOutOfRange`].
    pub fn try_eval(&self, u: f64) -> Result<[f64; 4], BsplineError> {
        Ok(self.eval(check_param(u)?))
    }

    /// The r-th derivative `d^r q / du^r` at u, for any r (0 above the
    /// degree).
    ///
    /// # Errors
    /// [`BsplineError::NotFinite`] / [`BsplineError::ParameterOutOfRange`].
    pub fn eval_deriv(&self, u: f64, r: usize) -> Result<f64, BsplineError> {
        let (first, ders) = self.kv.basis_derivs(check_param(u)?, r);
        Ok(ders
            .get(r)
            .map(|row| {
                self.coeffs
                    .get(first..)
                    .unwrap_or(&[])
                    .iter()
                    .zip(row)
                    .map(|(c, n)| c * n)
                    .sum()
            })
            .unwrap_or(0.0))
    }

    /// The r-th derivative as a spline of degree k - r, with coefficients
    /// Θ^{r} = D_r Θ (seed 001 eq. 11-12, exact recursion, see
    /// [`derivative_operator`]).
    ///
    /// # Errors
    /// [`BsplineError::DerivativeOrderTooHigh`] when r > k.
    pub fn derivative(&self, r: usize) -> Result<BSpline, BsplineError> {
        let d = derivative_operator(&self.kv, r)?;
        let kv = derivative_knots(&self.kv, r)?;
        BSpline::new(kv, d.try_mul_vec(&self.coeffs)?)
    }
}
