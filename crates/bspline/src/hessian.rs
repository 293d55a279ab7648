//! Exact Gram matrices of basis-function derivatives: the jerk Hessian of
//! seed 001 eq. 17-19.

use crate::banded_sym::BandedSym;
use crate::error::BsplineError;
use crate::knots::KnotVector;

/// Nodes and weights of the m-point Gauss-Legendre rule on [-1, 1]
/// (Newton iteration on the Legendre polynomial P_m with the three-term
/// recurrence; Abramowitz & Stegun 25.4.29). Exact for polynomials of
/// degree <= 2m - 1.
///
/// # Returns
/// `(nodes, weights)`, nodes in decreasing order, both of length m.
pub fn gauss_legendre(m: usize) -> (Vec<f64>, Vec<f64>) {
    let mut nodes = Vec::with_capacity(m);
    let mut weights = Vec::with_capacity(m);
    let mf = m as f64;
    for i in 0..m {
        // Initial guess (Tricomi), then Newton.
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (mf + 0.5)).cos();
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for j in 2..=m {
                let jf = j as f64;
                let p2 = ((2.0 * jf - 1.0) * x * p1 - (jf - 1.0) * p0) / jf;
                p0 = p1;
                p1 = p2;
            }
            // p1 = P_m(x), p0 = P_{m-1}(x) (for m = 1: P_1 = x, P_0 = 1).
            let dp = mf * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() <= 1e-16 {
                break;
            }
        }
        // Recompute the derivative at the converged node.
        let (mut p0, mut p1) = (1.0, x);
        for j in 2..=m {
            let jf = j as f64;
            let p2 = ((2.0 * jf - 1.0) * x * p1 - (jf - 1.0) * p0) / jf;
            p0 = p1;
            p1 = p2;
        }
        let dp = mf * (x * p1 - p0) / (x * x - 1.0);
        nodes.push(x);
        weights.push(2.0 / ((1.0 - x * x) * dp * dp));
    }
    (nodes, weights)
}

/// Gram matrix of the r-th derivatives of the basis:
/// `g_ij = ∫_0^1 N^{(r)}_{i,k}(u) N^{(r)}_{j,k}(u) du` (seed 001 eq. 18 for
/// r = 3).
///
/// On each knot span `N^{(r)}` is a polynomial of degree k - r, so the
/// product has degree 2(k - r) and the (k - r + 1)-point Gauss-Legendre
/// rule per span (exact to degree 2(k - r) + 1) integrates it exactly up
/// to rounding.
///
/// # Errors
/// [`BsplineError::DerivativeOrderTooHigh`] when `r > k`.
///
/// # Performance
/// O(n k^2) time for n + 1 coefficients (k - r + 1 basis evaluations of
/// cost O(k^2) per span plus (k + 1)^2 / 2 products per node); the result
/// stores (n + 1)(k + 1) values.
pub fn derivative_gram(kv: &KnotVector, r: usize) -> Result<BandedSym, BsplineError> {
    let k = kv.degree();
    if r > k {
        return Err(BsplineError::DerivativeOrderTooHigh {
            order: r,
            degree: k,
        });
    }
    let n1 = kv.n_coeffs();
    let mut h = BandedSym::zeros(n1, k);
    let (nodes, weights) = gauss_legendre(k - r + 1);
    let knots = kv.knots();
    for s in k..n1 {
        let (a, b) = match (knots.get(s), knots.get(s + 1)) {
            (Some(&a), Some(&b)) if b > a => (a, b),
            _ => continue,
        };
        let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
        for (x, w) in nodes.iter().zip(&weights) {
            let u = mid + half * x;
            let (first, ders) = kv.basis_derivs(u, r);
            let Some(d) = ders.get(r) else { continue };
            let wu = w * half;
            for (ia, da) in d.iter().enumerate() {
                for (ib, db) in d.iter().enumerate().take(ia + 1) {
                    h.add(first + ia, first + ib, wu * da * db);
                }
            }
        }
    }
    Ok(h)
}

/// Jerk Hessian H of seed 001 eq. 17-19:
/// `h_ij = ∫_0^1 N'''_{i,k}(u) N'''_{j,k}(u) du`, exact (see
/// [`derivative_gram`]), banded with bandwidth k (eq. 18: `h_ij = 0` for
/// `|i - j| > k`).
///
/// `Θ^T H Θ = ∫_0^1 (q'''(u))^2 du`; the jerk cost of eq. 17 is this times
/// `f^5 / σ^5` for feedrate f and path length σ (omitted, eq. 19). For a
/// quintic, 3 Gauss points per span.
///
/// # Conditioning
/// On uniform knots the entries grow like `(n - k + 1)^5`: max|H| is about
/// 5e5 for n + 1 = 8 and 2e17 for n + 1 = 628, and H has the quadratics as
/// its null space (eigenvalues 0, then a spread of ~1e-6 max|H| and
/// below). Scale it (e.g. [`BandedSym::scaled`] by `1 / max_abs()`) before
/// handing it to a QP solver; `Θ^T H Θ` of a smooth Θ on fine knots loses
/// about `ε max|H| |Θ|^2` to rounding.
///
/// # Errors
/// [`BsplineError::DegreeTooLow`] when k < 3.
///
/// # Performance
/// O(n k^2); about 2 ms for n + 1 = 628, k = 5 on a 2-core dev machine (the paper reports
/// 9.5 s in Python) - see `benches/hessian.rs`.
pub fn jerk_hessian(kv: &KnotVector) -> Result<BandedSym, BsplineError> {
    if kv.degree() < 3 {
        return Err(BsplineError::DegreeTooLow {
            degree: kv.degree(),
            required: 3,
        });
    }
    derivative_gram(kv, 3)
}
