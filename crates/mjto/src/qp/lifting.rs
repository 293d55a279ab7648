//! The lifted, well-conditioned form of a jerk objective `ΘᵀHΘ` handed to
//! the interior-point solver.
//!
//! With `y_r` the coefficients of the r-th derivative spline (seed 001
//! eq. 11-12), one level of the recursion eq. 12 is `y_r = E_r y_{r−1}`
//! (`y₀ = Θ`, `E_r` bidiagonal: row j is `c_j (y_{j+1} − y_j)`), and
//! `ΘᵀHΘ = ∫ q'''² du = y₃ᵀ G y₃` with `G` the Gram matrix of the
//! degree k − 3 B-spline basis of the jerk spline (eq. 17-18 after the
//! change of variables). `H` spans ≈ 17 orders of magnitude for 628
//! quintic coefficients; `G` has entries ≈ 1/n and a condition number
//! bounded independently of n (a B-spline Gram matrix), so the lifted QP —
//! variables `(Θ, y₁, y₂, y₃)`, structural equalities `E_r y_{r−1} − y_r =
//! 0`, objective `y₃ᵀ G y₃` — has the same minimiser and is well scaled.
//! The kinematic bounds of eq. 15 become plain bounds on `y₁, y₂, y₃`.

use kerf_bspline::{derivative_gram, derivative_knots, derivative_operator, BandRows, BandedSym};
use kerf_bspline::{BsplineError, KnotVector};

use super::constraints::{Bound, ConstraintSet};
use crate::PlanError;

/// The chain `Θ → y₁ → y₂ → y₃` of one spline and its jerk Gram matrix.
#[derive(Debug, Clone)]
pub(crate) struct JerkChain {
    /// Number of coefficients n + 1.
    n1: usize,
    /// E₁, E₂, E₃.
    steps: [BandRows; 3],
    /// Gram matrix of the degree k − 3 basis on the jerk knots.
    gram: BandedSym,
    /// Knot vectors of the first and second derivative splines.
    derivative_knots: [KnotVector; 2],
}

impl JerkChain {
    /// The chain of the splines on `kv`.
    ///
    /// # Errors
    /// [`BsplineError`] if the degree is below 3.
    pub fn new(kv: &KnotVector) -> Result<Self, BsplineError> {
        let k1 = derivative_knots(kv, 1)?;
        let k2 = derivative_knots(kv, 2)?;
        let k3 = derivative_knots(kv, 3)?;
        let steps = [
            derivative_operator(kv, 1)?,
            derivative_operator(&k1, 1)?,
            derivative_operator(&k2, 1)?,
        ];
        let gram = derivative_gram(&k3, 0)?;
        Ok(Self {
            n1: kv.n_coeffs(),
            steps,
            gram,
            derivative_knots: [k1, k2],
        })
    }

    /// Number of auxiliary variables `y₁, y₂, y₃`: `3(n + 1) − 6`.
    pub fn n_aux(&self) -> usize {
        3 * self.n1 - 6
    }

    /// Columns of `y₁, y₂, y₃` when the auxiliaries start at `aux`.
    pub fn y_offsets(&self, aux: usize) -> [usize; 3] {
        [aux, aux + self.n1 - 1, aux + 2 * self.n1 - 3]
    }

    /// Knot vector of the r-th derivative spline, r = 1 or 2.
    pub fn derivative_knots(&self, r: usize) -> Option<&KnotVector> {
        self.derivative_knots.get(r.checked_sub(1)?)
    }

    /// Adds the structural rows `E_r y_{r−1} − y_r = 0` for Θ at column
    /// `theta` and auxiliaries at `aux`; `scales[r−1]` is the post-check
    /// magnitude of level r (e.g. its kinematic bound).
    ///
    /// # Errors
    /// Internal [`PlanError::Solver`] if a column is out of range.
    pub fn push_structural(
        &self,
        set: &mut ConstraintSet,
        theta: usize,
        aux: usize,
        scales: [f64; 3],
    ) -> Result<(), PlanError> {
        let y = self.y_offsets(aux);
        for (r, step) in self.steps.iter().enumerate() {
            let from = if r == 0 { theta } else { y[r - 1] };
            for (j, row) in step.rows.iter().enumerate() {
                let mut entries: Vec<(usize, f64)> = row
                    .values
                    .iter()
                    .enumerate()
                    .map(|(i, &v)| (from + row.start + i, v))
                    .collect();
                entries.push((y[r] + j, -1.0));
                set.push(None, entries, Bound::Eq(0.0), scales[r])?;
            }
        }
        Ok(())
    }

    /// Upper-triangle entries of `2·weight·G` on the `y₃` block (Clarabel's
    /// `½ xᵀPx` form of `weight · y₃ᵀ G y₃`).
    pub fn objective_upper(&self, aux: usize, weight: f64) -> Vec<(usize, usize, f64)> {
        let y3 = self.y_offsets(aux)[2];
        self.gram
            .upper_triplets()
            .into_iter()
            .map(|(i, j, v)| (y3 + i, y3 + j, 2.0 * weight * v))
            .collect()
    }

    /// `∫ q'''² du = (D₃Θ)ᵀ G (D₃Θ)` evaluated through the chain, without
    /// the cancellation of the assembled H.
    pub fn jerk_cost(&self, theta: &[f64]) -> f64 {
        let y3 = self.apply_d3(theta);
        self.gram
            .mul_vec(&y3)
            .iter()
            .zip(&y3)
            .map(|(a, b)| a * b)
            .sum()
    }

    /// `D₃ Θ = E₃ E₂ E₁ Θ`.
    pub fn apply_d3(&self, theta: &[f64]) -> Vec<f64> {
        let mut y = theta.to_vec();
        for step in &self.steps {
            y = step.mul_vec(&y);
        }
        y
    }

    /// Checks that `h` is the jerk Hessian of these knots (eq. 18): `h x`
    /// must equal `D₃ᵀ G D₃ x` for two probe vectors (a smooth and an
    /// oscillating one) to 1e-6 relative.
    ///
    /// # Errors
    /// A description of the mismatch.
    pub fn check_hessian(&self, h: &BandedSym) -> Result<(), String> {
        if h.n() != self.n1 {
            return Err(format!("size {} for {} coefficients", h.n(), self.n1));
        }
        let n = self.n1 as f64;
        let probes = [
            (0..self.n1)
                .map(|j| (j as f64 / n).powi(4))
                .collect::<Vec<_>>(),
            (0..self.n1)
                .map(|j| (0.9 * j as f64).sin() + (j % 3) as f64)
                .collect(),
        ];
        for x in probes {
            let (a, b) = (h.mul_vec(&x), self.apply_h(&x));
            let scale = b.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let diff = a
                .iter()
                .zip(&b)
                .fold(0.0_f64, |m, (p, q)| m.max((p - q).abs()));
            if diff.is_nan() || diff > 1e-6 * scale {
                return Err(format!(
                    "it is not the jerk Hessian of these knots (H x differs by {diff:.3e} \
                     from ∫N'''N''' x, scale {scale:.3e})"
                ));
            }
        }
        Ok(())
    }

    /// `H x = D₃ᵀ G D₃ x` through the chain.
    pub fn apply_h(&self, x: &[f64]) -> Vec<f64> {
        let mut z = self.gram.mul_vec(&self.apply_d3(x));
        for step in self.steps.iter().rev() {
            z = step.tr_mul_vec(&z);
        }
        z
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kerf_bspline::jerk_hessian;

    /// The chain reproduces H: `xᵀ(D₃ᵀGD₃)x = xᵀHx` and `apply_h = H x`.
    #[test]
    fn chain_reproduces_the_jerk_hessian() {
        let kv = KnotVector::clamped_uniform(5, 15).unwrap();
        let h = jerk_hessian(&kv).unwrap();
        let chain = JerkChain::new(&kv).unwrap();
        let x: Vec<f64> = (0..15)
            .map(|i| (0.7 * i as f64).sin() + 0.01 * (i * i) as f64)
            .collect();
        let hx = h.mul_vec(&x);
        let xhx: f64 = hx.iter().zip(&x).map(|(a, b)| a * b).sum();
        assert!((chain.jerk_cost(&x) - xhx).abs() < 1e-9 * xhx.abs());
        for (a, b) in chain.apply_h(&x).iter().zip(&hx) {
            assert!((a - b).abs() < 1e-9 * hx.iter().fold(0.0_f64, |m, v| m.max(v.abs())));
        }
        assert_eq!(chain.n_aux(), 14 + 13 + 12);
        assert!(chain.check_hessian(&h).is_ok());
        assert!(chain.check_hessian(&h.scaled(1.01)).is_err());
        let other = jerk_hessian(&KnotVector::clamped_uniform(4, 15).unwrap()).unwrap();
        assert!(chain.check_hessian(&other).is_err());
        assert_eq!(chain.y_offsets(15), [15, 29, 42]);
    }
}
