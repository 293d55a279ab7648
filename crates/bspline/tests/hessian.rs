//! The jerk Hessian of seed 001 eq. 17-19 against brute-force quadrature.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::{greville, random_knots, simpson_per_span, Lcg};
use kerf_bspline::{
    basis_row, derivative_gram, fit, gauss_legendre, jerk_hessian, BSpline, BsplineError,
    KnotVector,
};

fn quad_form(h: &kerf_bspline::BandedSym, x: &[f64]) -> f64 {
    h.mul_vec(x).iter().zip(x).map(|(a, b)| a * b).sum()
}

/// x^T H x against ∫ (q'''(u))^2 du by composite Simpson (2000 subintervals
/// per span: Simpson's h^4 error with 200 is ~1e-8 relative on a Bézier span), with q''' evaluated from the degree k - 3 derivative spline
/// (values only: an evaluation path independent of the basis derivatives
/// the Hessian uses).
fn check_against_simpson(kv: &KnotVector, seed: u64, trials: usize) {
    let h = jerk_hessian(kv).unwrap();
    assert_eq!(h.n(), kv.n_coeffs());
    assert_eq!(h.bandwidth(), kv.degree());
    let mut rng = Lcg(seed);
    for _ in 0..trials {
        let x = rng.vec(kv.n_coeffs(), -1.0, 1.0);
        let s = BSpline::new(kv.clone(), x.clone()).unwrap();
        let jerk = s.derivative(3).unwrap();
        let brute = simpson_per_span(kv, 2000, |u| jerk.eval(u)[0].powi(2));
        let exact = quad_form(&h, &x);
        assert!(
            (exact - brute).abs() <= 1e-9 * brute.abs(),
            "degree {}, n+1 = {}: x^T H x = {exact}, Simpson {brute}",
            kv.degree(),
            kv.n_coeffs()
        );
        assert!(exact > 0.0);
    }
}

#[test]
fn quadratic_form_equals_integral_of_squared_jerk_small() {
    check_against_simpson(&KnotVector::clamped_uniform(5, 8).unwrap(), 1, 5);
    check_against_simpson(&KnotVector::clamped_uniform(5, 6).unwrap(), 2, 5);
    check_against_simpson(&random_knots(5, 6, 3), 3, 5);
}

#[test]
fn quadratic_form_equals_integral_of_squared_jerk_628() {
    check_against_simpson(&KnotVector::clamped_uniform(5, 628).unwrap(), 4, 1);
}

#[test]
fn lower_degrees_and_non_uniform_knots() {
    check_against_simpson(&KnotVector::clamped_uniform(3, 12).unwrap(), 5, 3);
    check_against_simpson(&KnotVector::clamped_uniform(4, 12).unwrap(), 6, 3);
    check_against_simpson(&random_knots(4, 9, 7), 7, 3);
    check_against_simpson(&random_knots(6, 9, 8), 8, 3);
    assert_eq!(
        jerk_hessian(&KnotVector::clamped_uniform(2, 12).unwrap()),
        Err(BsplineError::DegreeTooLow {
            degree: 2,
            required: 3
        })
    );
}

#[test]
fn entries_match_brute_force_integrals_of_basis_products() {
    let kv = KnotVector::clamped_uniform(5, 8).unwrap();
    let h = jerk_hessian(&kv).unwrap();
    let n1 = kv.n_coeffs();
    let basis3 = |j: usize, u: f64| -> f64 { basis_row(&kv, u, 3).unwrap().get(j) };
    for i in 0..n1 {
        for j in 0..n1 {
            let brute = simpson_per_span(&kv, 2000, |u| basis3(i, u) * basis3(j, u));
            let got = h.get(i, j);
            assert!(
                (got - brute).abs() <= 1e-9 * h.max_abs(),
                "h[{i}][{j}] = {got}, Simpson {brute}"
            );
            assert_eq!(got, h.get(j, i));
        }
    }
}

#[test]
fn symmetric_banded_and_positive_semidefinite() {
    let kv = KnotVector::clamped_uniform(5, 628).unwrap();
    let h = jerk_hessian(&kv).unwrap();
    let d = h.to_dense();
    assert_eq!(d, d.transpose());
    for i in 0..628usize {
        for j in 0..628usize {
            if i.abs_diff(j) > 5 {
                assert_eq!(h.get(i, j), 0.0);
            }
        }
    }
    // The band is full: the outermost diagonal is nonzero in the interior.
    assert!(h.get(300, 305).abs() > 0.0);
    // The upper triplets rebuild the matrix.
    let mut rebuilt = nalgebra::DMatrix::zeros(628, 628);
    for (i, j, v) in h.upper_triplets() {
        assert!(i <= j);
        rebuilt[(i, j)] = v;
        rebuilt[(j, i)] = v;
    }
    assert_eq!(rebuilt, d);
    // Eigenvalues: three (numerically) zero, the rest positive.
    let small = KnotVector::clamped_uniform(5, 20).unwrap();
    let hs = jerk_hessian(&small).unwrap().to_dense();
    let mut eig: Vec<f64> = hs.symmetric_eigenvalues().iter().copied().collect();
    eig.sort_by(f64::total_cmp);
    let top = eig[eig.len() - 1];
    assert!(eig[..3].iter().all(|e| e.abs() < 1e-9 * top), "{eig:?}");
    assert!(eig[3] > 1e-7 * top, "{eig:?}");
}

#[test]
fn null_space_holds_every_quadratic() {
    for kv in [
        KnotVector::clamped_uniform(5, 8).unwrap(),
        KnotVector::clamped_uniform(5, 628).unwrap(),
        random_knots(5, 11, 21),
    ] {
        let h = jerk_hessian(&kv).unwrap();
        let params = greville(&kv);
        for quad in [
            |u: f64| 1.0 + 0.0 * u,
            |u: f64| u,
            |u: f64| 3.0 * u * u - 2.0 * u + 0.25,
        ] {
            let values: Vec<f64> = params.iter().map(|&u| quad(u)).collect();
            let c = fit(&kv, &params, &values).unwrap();
            let hc = h.mul_vec(&c);
            let norm_c = c.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let worst = hc.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(
                worst < 1e-9 * h.max_abs() * norm_c,
                "|H c| = {worst}, max|H| = {}",
                h.max_abs()
            );
        }
        // A cubic is not in the null space: its jerk is 6 a.
        let values: Vec<f64> = params.iter().map(|&u| 2.0 * u.powi(3)).collect();
        let c = fit(&kv, &params, &values).unwrap();
        // (Only on coarse knots: for n + 1 = 628, max|H| ~ 2e17 and the
        // rounding of c alone moves c^T H c by ~eps max|H| |c|^2 ~ 10.)
        if kv.n_coeffs() <= 64 {
            let got = quad_form(&h, &c);
            assert!((got - 144.0).abs() < 1e-6 * 144.0, "cubic jerk cost {got}");
        }
    }
}

#[test]
fn gauss_legendre_rules_are_exact_to_degree_2m_minus_1() {
    let (x, w) = gauss_legendre(3);
    let s = (0.6f64).sqrt();
    assert!((x[0] - s).abs() < 1e-15 && x[1].abs() < 1e-15 && (x[2] + s).abs() < 1e-15);
    assert!((w[0] - 5.0 / 9.0).abs() < 1e-15 && (w[1] - 8.0 / 9.0).abs() < 1e-15);
    for m in 1..=10 {
        let (x, w) = gauss_legendre(m);
        for p in 0..=(2 * m - 1) {
            let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(p as i32)).sum();
            let exact = if p % 2 == 1 {
                0.0
            } else {
                2.0 / (p as f64 + 1.0)
            };
            assert!((q - exact).abs() < 1e-14, "m = {m}, x^{p}: {q} vs {exact}");
        }
        // Degree 2m is not integrated exactly.
        let p = 2 * m;
        let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(p as i32)).sum();
        assert!((q - 2.0 / (p as f64 + 1.0)).abs() > 1e-6);
    }
}

#[test]
fn velocity_gram_matches_quadrature() {
    // The general Gram matrix for r = 1 (∫ q'^2 du) and r = 0 (∫ q^2 du).
    let kv = random_knots(5, 7, 40);
    let mut rng = Lcg(41);
    let x = rng.vec(kv.n_coeffs(), -1.0, 1.0);
    let s = BSpline::new(kv.clone(), x.clone()).unwrap();
    for r in 0..=2 {
        let g = derivative_gram(&kv, r).unwrap();
        let brute = simpson_per_span(&kv, 2000, |u| s.eval(u)[r].powi(2));
        let got = quad_form(&g, &x);
        assert!(
            (got - brute).abs() < 1e-9 * brute,
            "r = {r}: {got} vs {brute}"
        );
    }
    assert!(derivative_gram(&kv, 6).is_err());
}
