//! Derivative operators D_r and derivative knot vectors (seed 001 eq. 11-12,
//! 21-26), against direct evaluation and against the paper's closed forms.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::{random_knots, Lcg};
use kerf_bspline::{derivative_knots, derivative_operator, BSpline, BsplineError, KnotVector};

/// Check that Σ_j (D_r Θ)_j N_{j,k-r}(u) = q^{(r)}(u) at many u.
fn check_operator_against_eval(kv: &KnotVector, seed: u64) {
    let mut rng = Lcg(seed);
    let coeffs = rng.vec(kv.n_coeffs(), -2.0, 2.0);
    let s = BSpline::new(kv.clone(), coeffs.clone()).unwrap();
    for r in 0..=kv.degree() {
        let d = derivative_operator(kv, r).unwrap();
        assert_eq!(d.nrows(), kv.n_coeffs() - r);
        assert_eq!(d.ncols, kv.n_coeffs());
        for (j, row) in d.rows.iter().enumerate() {
            assert_eq!(row.start, j);
            assert_eq!(row.values.len(), r + 1);
        }
        let dk = derivative_knots(kv, r).unwrap();
        assert_eq!(dk.degree(), kv.degree() - r);
        assert_eq!(dk.knots(), &kv.knots()[r..kv.knots().len() - r]);
        let ds = BSpline::new(dk, d.mul_vec(&coeffs)).unwrap();
        let mut us = rng.vec(150, 0.0, 1.0);
        us.extend([0.0, 1.0]);
        us.extend(kv.interior());
        for u in us {
            let want = s.eval_deriv(u, r).unwrap();
            let got = ds.eval(u)[0];
            assert!(
                (got - want).abs() < 1e-9 * want.abs().max(1.0),
                "degree {}, r = {r}, u = {u}: operator {got}, direct {want}",
                kv.degree()
            );
        }
    }
}

#[test]
fn operator_matches_direct_derivatives_uniform_knots() {
    for (k, n1) in [(5, 6), (5, 8), (5, 20), (5, 64), (3, 10), (4, 9), (1, 5)] {
        check_operator_against_eval(&KnotVector::clamped_uniform(k, n1).unwrap(), 3 + n1 as u64);
    }
}

#[test]
fn operator_matches_direct_derivatives_non_uniform_knots() {
    for (k, ni, seed) in [(5, 3, 1), (5, 15, 2), (3, 8, 3), (4, 6, 4)] {
        check_operator_against_eval(&random_knots(k, ni, seed), seed);
    }
}

/// The paper's closed-form row of D_r (eq. 21-26): c_j^r (1, -1), (1, -2, 1)
/// or (1, -3, 3, -1) with c_j^1 = -k / (u_{j+k+1} - u_{j+1}),
/// c_j^2 = (k^2 - k) / ((u_{j+k+1} - u_{j+2})(u_{j+k+1} - u_{j+1})),
/// c_j^3 = (-k^3 + 3k^2 - 2k) / ((u_{j+k+1} - u_{j+3})(u_{j+k+1} - u_{j+2})(u_{j+k+1} - u_{j+1})).
fn paper_row(kv: &KnotVector, r: usize, j: usize) -> Vec<f64> {
    let k = kv.degree() as f64;
    let u = kv.knots();
    let kk = kv.degree();
    let d = |a: usize| u[j + kk + 1] - u[j + a];
    match r {
        1 => {
            let c = -k / d(1);
            vec![c, -c]
        }
        2 => {
            let c = (k * k - k) / (d(2) * d(1));
            vec![c, -2.0 * c, c]
        }
        3 => {
            let c = (-k * k * k + 3.0 * k * k - 2.0 * k) / (d(3) * d(2) * d(1));
            vec![c, -3.0 * c, 3.0 * c, -c]
        }
        _ => unreachable!(),
    }
}

#[test]
fn operator_reduces_to_paper_closed_forms_on_uniform_rows() {
    let kv = KnotVector::clamped_uniform(5, 30).unwrap();
    let k = 5;
    let n = 29;
    for r in 1..=3 {
        let d = derivative_operator(&kv, r).unwrap();
        // Rows whose knots u_{j+1} .. u_{j+k+r} are uniformly spaced.
        let uniform_rows = (k - 1)..=(n + 1 - k - r);
        assert!(uniform_rows.clone().count() > 10);
        for j in uniform_rows {
            let paper = paper_row(&kv, r, j);
            for (a, b) in d.rows[j].values.iter().zip(&paper) {
                assert!(
                    (a - b).abs() < 1e-10 * b.abs(),
                    "r = {r}, row {j}: exact {a}, paper {b}"
                );
            }
        }
    }
}

#[test]
fn paper_eq24_is_exact_everywhere_for_first_derivative() {
    // For l = 1 the paper's denominator u_{j+k+1} - u_{j+1} is the exact one.
    for kv in [
        KnotVector::clamped_uniform(5, 12).unwrap(),
        random_knots(5, 8, 8),
    ] {
        let d = derivative_operator(&kv, 1).unwrap();
        for j in 0..d.nrows() {
            let paper = paper_row(&kv, 1, j);
            for (a, b) in d.rows[j].values.iter().zip(&paper) {
                assert!((a - b).abs() < 1e-12 * b.abs());
            }
        }
    }
}

#[test]
fn paper_closed_forms_are_wrong_near_clamped_ends() {
    let kv = KnotVector::clamped_uniform(5, 30).unwrap();
    let n1 = kv.n_coeffs();
    let mut rng = Lcg(77);
    let coeffs = rng.vec(n1, -1.0, 1.0);
    let s = BSpline::new(kv.clone(), coeffs.clone()).unwrap();
    for r in 2..=3 {
        let d = derivative_operator(&kv, r).unwrap();
        // Row 0 and the last row: the coefficients themselves differ.
        for j in [0, d.nrows() - 1] {
            let paper = paper_row(&kv, r, j);
            let rel = d.rows[j]
                .values
                .iter()
                .zip(&paper)
                .map(|(a, b)| (a - b).abs() / a.abs())
                .fold(0.0f64, f64::max);
            assert!(
                rel > 0.1,
                "r = {r}, row {j}: relative difference only {rel}"
            );
        }
        // And the derivative they give at u = 0 is not q^{(r)}(0): the
        // clamped derivative curve interpolates its first coefficient.
        let paper_theta0: f64 = paper_row(&kv, r, 0)
            .iter()
            .zip(&coeffs)
            .map(|(c, t)| c * t)
            .sum();
        let exact_theta0: f64 = d.rows[0]
            .values
            .iter()
            .zip(&coeffs)
            .map(|(c, t)| c * t)
            .sum();
        let qr0 = s.eval(0.0)[r];
        assert!((exact_theta0 - qr0).abs() < 1e-9 * qr0.abs().max(1.0));
        assert!(
            (paper_theta0 - qr0).abs() > 1e-3 * qr0.abs(),
            "r = {r}: paper Θ^r_0 = {paper_theta0}, q^(r)(0) = {qr0}"
        );
    }
}

#[test]
fn operator_on_a_polynomial_gives_its_derivative_coefficients() {
    // Coefficients all equal to 1 represent q = 1: every derivative
    // coefficient vanishes. Greville abscissae as coefficients represent
    // q(u) = u: Θ^1 = 1, Θ^2 = 0 (NURBS Book, linear precision).
    let kv = random_knots(5, 10, 12);
    let ones = vec![1.0; kv.n_coeffs()];
    let greville = common::greville(&kv);
    for r in 1..=3 {
        let d = derivative_operator(&kv, r).unwrap();
        assert!(d.mul_vec(&ones).iter().all(|v| v.abs() < 1e-9));
    }
    let d1 = derivative_operator(&kv, 1).unwrap().mul_vec(&greville);
    assert!(d1.iter().all(|v| (v - 1.0).abs() < 1e-12), "{d1:?}");
    let d2 = derivative_operator(&kv, 2).unwrap().mul_vec(&greville);
    assert!(d2.iter().all(|v| v.abs() < 1e-9), "{d2:?}");
}

#[test]
fn identity_for_order_zero_and_errors_above_the_degree() {
    let kv = KnotVector::clamped_uniform(5, 9).unwrap();
    let d0 = derivative_operator(&kv, 0).unwrap();
    assert_eq!(d0.to_dense(), nalgebra::DMatrix::identity(9, 9));
    assert_eq!(
        derivative_operator(&kv, 6),
        Err(BsplineError::DerivativeOrderTooHigh {
            order: 6,
            degree: 5
        })
    );
    assert!(derivative_knots(&kv, 6).is_err());
    // The derivative spline helper agrees with the operator.
    let s = BSpline::new(kv.clone(), (0..9).map(|i| (i * i) as f64).collect()).unwrap();
    let d3 = s.derivative(3).unwrap();
    assert_eq!(d3.knots().degree(), 2);
    assert!((d3.eval(0.4)[0] - s.eval(0.4)[3]).abs() < 1e-9 * s.eval(0.4)[3].abs().max(1.0));
    assert!(s.derivative(6).is_err());
}
