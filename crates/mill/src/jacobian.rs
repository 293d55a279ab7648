//! The geometric Jacobian at the tool tip and the normalized condition
//! number of seed 004 eq. 14.
//!
//! # The characteristic length
//!
//! The translational rows of J carry metres, the rotational rows carry
//! nothing, so the condition number of J itself depends on the unit of
//! length. Seed 004 eq. 14 uses a "characteristic-length normalized
//! Jacobian" `J_N = diag(I₃ / L, I₃) J` without giving L. kerf follows
//! Angeles (*Fundamentals of Robotic Mechanical Systems*, 4th ed., §4.9;
//! Khan & Angeles, ASME J. Mech. Des. 128:199, 2006): **L is the length
//! that minimizes the condition number over the task**. Here the task is the
//! milling path: L minimizes the mean of K over the 100 segments of the
//! default path of seed 004 Table 1 and 9 redundancy angles
//! g ∈ {−π, −3π/4, …, π} (those that are reachable within the limits).
//! [`characteristic_length`] computes it (golden-section search); the value
//! stored in `urdf/irb6660_milling.yaml` (`condition.characteristic_length`)
//! is its result, and `tests/condition.rs` recomputes it and checks the
//! stored value: **L = 1.2799 m**, mean K = 2.188 over the 491 reachable
//! (segment, g) samples (K = 2.73 at L/2 and at 2L). It is of the order of
//! the arm's reach from the wrist to the tool (a2 ≈ 1.28 m, d4 ≈ 1.51 m),
//! as Angeles' length typically is. Any other value can be configured
//! (`condition.characteristic_length`).

use nalgebra::{Matrix6, Vector3};

use crate::error::{check_positive, MillError};
use crate::ik::Kinematics;

/// Iteration cap of the symmetric eigen-solver.
const EIGEN_MAX_ITER: usize = 1000;
/// Relative eigenvalue below which J_N J_Nᵀ is treated as singular.
const SINGULAR_REL: f64 = 1e-13;

impl Kinematics {
    /// The geometric Jacobian at the tool tip (TCP), linear rows first:
    /// column i is `[z_i × (p_tcp − o_i); z_i]` with `z_i`, `o_i` the axis and
    /// origin of MDH frame i in the base frame (Craig, *Introduction to
    /// Robotics*, 3rd ed., §5.8; Siciliano et al., *Robotics*, eq. 3.30).
    /// It maps joint rates to the tool tip's linear and angular velocity in
    /// the base frame.
    ///
    /// # Errors
    /// [`MillError::NonFinite`] for a NaN/infinite joint value.
    ///
    /// # Performance
    /// O(1), no allocation.
    pub fn jacobian(&self, q: &[f64; 6]) -> Result<Matrix6<f64>, MillError> {
        self.flange_pose(q)?;
        let frames = self.geometry().frames(q);
        let tip = (frames[5] * crate::mdh::frame6_to_tool0() * self.tcp())
            .translation
            .vector;
        let mut j = Matrix6::zeros();
        for (i, f) in frames.iter().enumerate() {
            let z = f.rotation * Vector3::z();
            let v = z.cross(&(tip - f.translation.vector));
            j.fixed_view_mut::<3, 1>(0, i).copy_from(&v);
            j.fixed_view_mut::<3, 1>(3, i).copy_from(&z);
        }
        Ok(j)
    }
}

/// The normalized condition number of seed 004 eq. 14,
/// `K = (1/n) √(tr(J_N J_Nᵀ) · tr((J_N J_Nᵀ)⁻¹))`, n = 6,
/// `J_N = diag(I₃/L, I₃) J`.
///
/// With λ_i the eigenvalues of `A = J_N J_Nᵀ`, `tr A = Σ λ_i` and
/// `tr A⁻¹ = Σ 1/λ_i`, so K ≥ 1 (Cauchy–Schwarz), K = 1 for an isotropic
/// J_N. (This is the Frobenius-norm condition number divided by n.)
///
/// # Arguments
/// * `j` - the Jacobian, linear rows first ([`Kinematics::jacobian`]);
/// * `length` - the characteristic length L \[m\] (module documentation).
///
/// # Returns
/// K ≥ 1, or `f64::INFINITY` when J is singular (smallest eigenvalue of A
/// ≤ 1e-13 × the largest: e.g. q5 = 0 or the arm stretched): never NaN.
///
/// # Errors
/// [`MillError::InvalidParameter`] for a bad L, [`MillError::NonFinite`] for
/// a non-finite J, [`MillError::NotConverged`] if the eigen-solver hits its
/// cap.
///
/// # Performance
/// One 6×6 symmetric eigen-decomposition, a few µs.
pub fn condition_number(j: &Matrix6<f64>, length: f64) -> Result<f64, MillError> {
    let length = check_positive("characteristic length L [m]", length)?;
    if j.iter().any(|v| !v.is_finite()) {
        return Err(MillError::NonFinite {
            what: "Jacobian".to_string(),
        });
    }
    let mut jn = *j;
    for r in 0..3 {
        for c in 0..6 {
            jn[(r, c)] /= length;
        }
    }
    let a = jn * jn.transpose();
    let eig = a
        .try_symmetric_eigen(f64::EPSILON, EIGEN_MAX_ITER)
        .ok_or_else(|| MillError::NotConverged {
            what: "eigenvalues of J_N J_N^T (seed 004 eq. 14)".to_string(),
            iterations: EIGEN_MAX_ITER,
            residual: f64::NAN,
        })?;
    let max = eig.eigenvalues.max();
    let min = eig.eigenvalues.min();
    if max.is_nan() || max <= 0.0 || min <= SINGULAR_REL * max {
        return Ok(f64::INFINITY);
    }
    let tr: f64 = eig.eigenvalues.sum();
    let tr_inv: f64 = eig.eigenvalues.iter().map(|l| 1.0 / l).sum();
    Ok((tr * tr_inv).sqrt() / 6.0)
}

/// The singularity indicator reported by seed 004 (section 4, "minimum
/// singularity indicator 0.48"): `1/K` ∈ [0, 1], 0 at a singularity, 1 for
/// an isotropic Jacobian.
///
/// # Errors
/// As [`condition_number`].
pub fn condition_indicator(j: &Matrix6<f64>, length: f64) -> Result<f64, MillError> {
    Ok(1.0 / condition_number(j, length)?)
}

/// The characteristic length minimizing the mean condition number over a
/// set of Jacobians (module documentation).
///
/// Golden-section search on log L over `[lo, hi]`, to a relative
/// tolerance of 1e-6; singular Jacobians (K = ∞) are skipped.
///
/// # Returns
/// `(L, mean K at L)`.
///
/// # Errors
/// [`MillError::InvalidParameter`] for an empty set or a bad interval,
/// [`MillError::Singular`] if every Jacobian is singular,
/// [`MillError::NotConverged`] after 200 iterations.
pub fn characteristic_length(
    jacobians: &[Matrix6<f64>],
    lo: f64,
    hi: f64,
) -> Result<(f64, f64), MillError> {
    check_positive("characteristic length search lower bound [m]", lo)?;
    check_positive("characteristic length search upper bound [m]", hi)?;
    if jacobians.is_empty() || hi <= lo {
        return Err(MillError::InvalidParameter {
            name: "characteristic length search".to_string(),
            value: jacobians.len() as f64,
            reason: "needs at least one Jacobian and lo < hi".to_string(),
        });
    }
    let mean_k = |l: f64| -> Result<f64, MillError> {
        let mut sum = 0.0;
        let mut n = 0usize;
        for j in jacobians {
            let k = condition_number(j, l)?;
            if k.is_finite() {
                sum += k;
                n += 1;
            }
        }
        if n == 0 {
            return Err(MillError::Singular {
                what: "every Jacobian of the characteristic-length search".to_string(),
            });
        }
        Ok(sum / n as f64)
    };
    let invphi = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (lo.ln(), hi.ln());
    let mut c = b - invphi * (b - a);
    let mut d = a + invphi * (b - a);
    let (mut fc, mut fd) = (mean_k(c.exp())?, mean_k(d.exp())?);
    for _ in 0..200 {
        if (b - a).abs() < 1e-6 {
            let l = (0.5 * (a + b)).exp();
            return Ok((l, mean_k(l)?));
        }
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - invphi * (b - a);
            fc = mean_k(c.exp())?;
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + invphi * (b - a);
            fd = mean_k(d.exp())?;
        }
    }
    Err(MillError::NotConverged {
        what: "characteristic length golden-section search".to_string(),
        iterations: 200,
        residual: b - a,
    })
}
