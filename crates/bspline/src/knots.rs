//! Clamped knot vectors on [0, 1], knot spans and basis functions.

use crate::error::{check_param, BsplineError};

/// A clamped (open) knot vector on the normalized parameter u in [0, 1].
///
/// The knots are `degree + 1` zeros, strictly increasing interior knots in
/// (0, 1), and `degree + 1` ones, so that a spline of degree k with
/// `n + 1 = n_coeffs` coefficients interpolates its first and last
/// coefficients (seed 001 eq. 5; *The NURBS Book*, eq. 2.13).
#[derive(Debug, Clone, PartialEq)]
pub struct KnotVector {
    degree: usize,
    knots: Vec<f64>,
}

impl KnotVector {
    /// Clamped uniform knot vector on [0, 1].
    ///
    /// `k + 1` zeros, the `n - k` uniform interior knots `j / (n - k + 1)`
    /// for `j = 1..=n-k`, and `k + 1` ones, where `n + 1 = n_coeffs` and
    /// `k = degree` (the "uniform method" of seed 001 section 2.1).
    ///
    /// # Arguments
    /// * `degree` - the degree k (the planner uses k = 5);
    /// * `n_coeffs` - the number of coefficients n + 1.
    ///
    /// # Errors
    /// [`BsplineError::TooFewCoefficients`] when `n_coeffs < degree + 1`.
    pub fn clamped_uniform(degree: usize, n_coeffs: usize) -> Result<Self, BsplineError> {
        if n_coeffs < degree + 1 {
            return Err(BsplineError::TooFewCoefficients { n_coeffs, degree });
        }
        let n_interior = n_coeffs - degree - 1;
        let denom = (n_interior + 1) as f64;
        let interior: Vec<f64> = (1..=n_interior).map(|j| j as f64 / denom).collect();
        Ok(Self::assemble(degree, &interior))
    }

    /// Clamped knot vector with the given interior knots.
    ///
    /// The knot vector has `degree + 1` zeros, `interior`, and `degree + 1`
    /// ones; the spline has `interior.len() + degree + 1` coefficients.
    ///
    /// # Errors
    /// [`BsplineError::NotFinite`] for a NaN/infinite knot and
    /// [`BsplineError::InvalidKnots`] when the interior knots are not
    /// strictly increasing inside the open interval (0, 1).
    pub fn clamped_with_interior(degree: usize, interior: &[f64]) -> Result<Self, BsplineError> {
        let mut prev = 0.0;
        for (i, &t) in interior.iter().enumerate() {
            if !t.is_finite() {
                return Err(BsplineError::NotFinite {
                    what: format!("interior knot {i} = {t}"),
                });
            }
            if t <= prev || t >= 1.0 {
                return Err(BsplineError::InvalidKnots {
                    detail: format!(
                        "interior knot {i} = {t} must lie in (0, 1) and exceed the previous knot {prev}"
                    ),
                });
            }
            prev = t;
        }
        Ok(Self::assemble(degree, interior))
    }

    /// Clamped knot vector for `n_coeffs` coefficients fitted to the
    /// parameters `params` (strictly increasing, from 0 to 1).
    ///
    /// * `n_coeffs == params.len()` (interpolation): de Boor's averaging,
    ///   t_{j+k} = (u_j + ... + u_{j+k-1}) / k for j = 1..n-k (Piegl &
    ///   Tiller, *The NURBS Book*, eq. 9.8).
    /// * `n_coeffs < params.len()` (least squares): Piegl & Tiller eq.
    ///   9.68-9.69, d = m/(n-k+1), i = ⌊jd⌋, α = jd - i,
    ///   t_{k+j} = (1-α) u_{i-1} + α u_i (m + 1 = params.len()).
    ///
    /// Seed 001 uses a uniform knot vector (section 2.1). With as many
    /// coefficients as parameters that is already numerically singular for
    /// a few hundred *equally spaced* parameters (they drift half a knot span
    /// against uniform knots, where odd-degree interpolation breaks down;
    /// condition number ∞ for 241 points against about 15 with averaged
    /// knots), and uneven parameters (a short last segment) make it worse.
    /// Both rules here place every parameter inside its basis function's
    /// support (Schoenberg–Whitney), so the collocation and fit of eq. 49-52
    /// stay well conditioned (`tests/knots_for_parameters.rs`).
    ///
    /// # Errors
    /// [`BsplineError::TooFewCoefficients`], [`BsplineError::TooFewPoints`]
    /// (more coefficients than parameters), [`BsplineError::NotFinite`],
    /// [`BsplineError::InvalidKnots`] (parameters not strictly increasing
    /// from 0 to 1).
    pub fn for_parameters(
        degree: usize,
        n_coeffs: usize,
        params: &[f64],
    ) -> Result<Self, BsplineError> {
        if n_coeffs < degree + 1 {
            return Err(BsplineError::TooFewCoefficients { n_coeffs, degree });
        }
        if params.len() < n_coeffs {
            return Err(BsplineError::TooFewPoints {
                n_points: params.len(),
                n_coeffs,
            });
        }
        if params.iter().any(|u| !u.is_finite()) {
            return Err(BsplineError::NotFinite {
                what: "parameters".into(),
            });
        }
        let m = params.len() - 1;
        if params[0] != 0.0 || params[m] != 1.0 || params.windows(2).any(|w| w[1] <= w[0]) {
            return Err(BsplineError::InvalidKnots {
                detail: "parameters must increase strictly from 0 to 1".into(),
            });
        }
        let n = n_coeffs - 1;
        let interior: Vec<f64> = if n_coeffs == params.len() {
            (1..=n - degree)
                .map(|j| params[j..j + degree].iter().sum::<f64>() / degree as f64)
                .collect()
        } else {
            let d = (m + 1) as f64 / (n - degree + 1) as f64;
            (1..=n - degree)
                .map(|j| {
                    let jd = j as f64 * d;
                    let i = (jd.floor() as usize).clamp(1, m);
                    let alpha = jd - i as f64;
                    (1.0 - alpha) * params[i - 1] + alpha * params[i]
                })
                .collect()
        };
        Self::clamped_with_interior(degree, &interior)
    }

    fn assemble(degree: usize, interior: &[f64]) -> Self {
        let mut knots = Vec::with_capacity(interior.len() + 2 * degree + 2);
        knots.extend(std::iter::repeat_n(0.0, degree + 1));
        knots.extend_from_slice(interior);
        knots.extend(std::iter::repeat_n(1.0, degree + 1));
        Self { degree, knots }
    }

    /// The degree k.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// All knots u_0 .. u_{n+k+1} (length `n_coeffs + degree + 1`).
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// The interior knots u_{k+1} .. u_n (strictly inside (0, 1)).
    pub fn interior(&self) -> &[f64] {
        let k = self.degree;
        let end = self.knots.len().saturating_sub(k + 1);
        self.knots.get(k + 1..end).unwrap_or(&[])
    }

    /// The number of coefficients n + 1 = `knots().len() - degree - 1`.
    pub fn n_coeffs(&self) -> usize {
        self.knots.len() - self.degree - 1
    }

    /// Knot span index i with `knots[i] <= u < knots[i + 1]`
    /// (*The NURBS Book*, algorithm A2.1).
    ///
    /// `u = 1` (and anything above) maps to the last non-empty span n,
    /// anything below 0 to the first span k. A NaN maps to span k; the basis
    /// functions evaluated there are then NaN, so a NaN never passes
    /// silently. Use [`KnotVector::try_span`] to reject such inputs.
    ///
    /// # Performance
    /// O(log n) (binary search over the interior knots).
    pub fn span(&self, u: f64) -> usize {
        // For a clamped vector with strictly increasing interior knots the
        // span is k + #(interior knots <= u).
        self.degree + self.interior().partition_point(|&t| t <= u)
    }

    /// [`KnotVector::span`] after validating `u`.
    ///
    /// # Errors
    /// [`BsplineError::NotFinite`] or [`BsplineError::ParameterOutOfRange`]
    /// (beyond 1e-12 outside [0, 1]).
    pub fn try_span(&self, u: f64) -> Result<usize, BsplineError> {
        Ok(self.span(check_param(u)?))
    }

    /// The k + 1 nonzero basis functions and their derivatives at u
    /// (*The NURBS Book*, algorithm A2.3; seed 001 eq. 5, 8-10).
    ///
    /// # Arguments
    /// * `u` - the parameter; values outside [0, 1] are clamped, NaN gives
    ///   NaN values (see [`KnotVector::try_basis_derivs`] for a checked
    ///   version);
    /// * `nderiv` - highest derivative order; orders above the degree are
    ///   returned as zero rows (they vanish identically).
    ///
    /// # Returns
    /// `(first, ders)` where `ders[d][r]` is the d-th derivative of
    /// `N_{first + r, k}(u)` for `d = 0..=nderiv`, `r = 0..=k`.
    ///
    /// # Performance
    /// O(k^2 + nderiv k) plus the allocation of the result
    /// (`BSpline::eval` uses the allocation-free form).
    pub fn basis_derivs(&self, u: f64, nderiv: usize) -> (usize, Vec<Vec<f64>>) {
        let p = self.degree;
        let w = p + 1;
        let mut ders = vec![0.0; (nderiv + 1) * w];
        let mut ndu = vec![0.0; w * w];
        let mut scratch = vec![0.0; 4 * w];
        let first = self.basis_derivs_into(u, nderiv, &mut ders, &mut ndu, &mut scratch);
        (first, ders.chunks(w).map(<[f64]>::to_vec).collect())
    }

    /// [`KnotVector::basis_derivs`] into caller storage (no allocation):
    /// `ders[d * (k + 1) + r]` receives the d-th derivative of
    /// `N_{first + r, k}(u)`; `ndu` ((k + 1)² entries) and `scratch`
    /// (4 (k + 1)) are work space. Returns `first`.
    ///
    /// # Panics
    /// When a slice is shorter than stated (a caller bug; internal use).
    pub(crate) fn basis_derivs_into(
        &self,
        u: f64,
        nderiv: usize,
        ders: &mut [f64],
        ndu: &mut [f64],
        scratch: &mut [f64],
    ) -> usize {
        let p = self.degree;
        let w = p + 1;
        let u = if u.is_nan() { u } else { u.clamp(0.0, 1.0) };
        let i = self.span(u);
        let kn = &self.knots;
        ders[..(nderiv + 1) * w].fill(0.0);
        ndu[..w * w].fill(0.0);
        scratch[..4 * w].fill(0.0);
        let (left, rest) = scratch.split_at_mut(w);
        let (right, a) = rest.split_at_mut(w);
        // ndu: upper triangle = basis functions, lower triangle = knot
        // differences (A2.3); ndu[j][r] is ndu[j * w + r].
        ndu[0] = 1.0;
        for j in 1..=p {
            left[j] = u - kn[i + 1 - j];
            right[j] = kn[i + j] - u;
            let mut saved = 0.0;
            for r in 0..j {
                ndu[j * w + r] = right[r + 1] + left[j - r];
                let temp = ndu[r * w + j - 1] / ndu[j * w + r];
                ndu[r * w + j] = saved + right[r + 1] * temp;
                saved = left[j - r] * temp;
            }
            ndu[j * w + j] = saved;
        }
        for j in 0..=p {
            ders[j] = ndu[j * w + p];
        }
        let n = nderiv.min(p);
        // a[s][j] is a[s * w + j] (two rows).
        for r in 0..=p {
            let (mut s1, mut s2) = (0usize, 1usize);
            a[0] = 1.0;
            for k in 1..=n {
                let mut d = 0.0;
                let rk = r as isize - k as isize;
                let pk = p - k;
                if r >= k {
                    let rku = r - k;
                    a[s2 * w] = a[s1 * w] / ndu[(pk + 1) * w + rku];
                    d = a[s2 * w] * ndu[rku * w + pk];
                }
                let j1: usize = if rk >= -1 { 1 } else { (-rk) as usize };
                let j2: usize = if r as isize - 1 <= pk as isize {
                    k - 1
                } else {
                    p - r
                };
                for j in j1..=j2 {
                    let idx = (rk + j as isize) as usize;
                    a[s2 * w + j] = (a[s1 * w + j] - a[s1 * w + j - 1]) / ndu[(pk + 1) * w + idx];
                    d += a[s2 * w + j] * ndu[idx * w + pk];
                }
                if r <= pk {
                    a[s2 * w + k] = -a[s1 * w + k - 1] / ndu[(pk + 1) * w + r];
                    d += a[s2 * w + k] * ndu[r * w + pk];
                }
                ders[k * w + r] = d;
                std::mem::swap(&mut s1, &mut s2);
            }
        }
        let mut fac = p as f64;
        for k in 1..=n {
            for v in &mut ders[k * w..(k + 1) * w] {
                *v *= fac;
            }
            fac *= (p - k) as f64;
        }
        i - p
    }

    /// [`KnotVector::basis_derivs`] after validating `u`.
    ///
    /// # Errors
    /// [`BsplineError::NotFinite`] or [`BsplineError::ParameterOutOfRange`].
    pub fn try_basis_derivs(
        &self,
        u: f64,
        nderiv: usize,
    ) -> Result<(usize, Vec<Vec<f64>>), BsplineError> {
        Ok(self.basis_derivs(check_param(u)?, nderiv))
    }
}
