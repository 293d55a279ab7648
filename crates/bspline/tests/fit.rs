//! Collocation matrices and least-squares / interpolating fits (seed 001
//! eq. 35, 49-52).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::{cox_de_boor, greville, linspace, random_knots, Lcg};
use kerf_bspline::{collocation, fit, normal_matrix, BSpline, BsplineError, KnotVector};
use nalgebra::{DMatrix, DVector};

#[test]
fn collocation_rows_are_basis_values() {
    let kv = random_knots(5, 8, 2);
    let mut rng = Lcg(3);
    let params = rng.vec(30, 0.0, 1.0);
    let n = collocation(&kv, &params).unwrap();
    assert_eq!(n.nrows(), 30);
    assert_eq!(n.ncols, kv.n_coeffs());
    let d = n.to_dense();
    for (i, &u) in params.iter().enumerate() {
        assert!((d.row(i).sum() - 1.0).abs() < 1e-13);
        for j in 0..kv.n_coeffs() {
            assert!((d[(i, j)] - cox_de_boor(kv.knots(), j, 5, u)).abs() < 1e-13);
        }
        // Band structure: at most k + 1 consecutive nonzeros (eq. 35).
        assert_eq!(n.rows[i].values.len(), 6);
    }
}

#[test]
fn square_interpolation_reproduces_the_data() {
    let mut rng = Lcg(9);
    for kv in [
        KnotVector::clamped_uniform(5, 8).unwrap(),
        KnotVector::clamped_uniform(5, 40).unwrap(),
        KnotVector::clamped_uniform(3, 25).unwrap(),
        random_knots(5, 12, 4),
    ] {
        let params = greville(&kv);
        let values = rng.vec(params.len(), -2.0, 2.0);
        let c = fit(&kv, &params, &values).unwrap();
        let s = BSpline::new(kv.clone(), c.clone()).unwrap();
        for (&u, &v) in params.iter().zip(&values) {
            assert!((s.eval(u)[0] - v).abs() < 1e-10, "u = {u}");
        }
        // The same through the collocation matrix: N c = values.
        let nc = collocation(&kv, &params).unwrap().mul_vec(&c);
        for (a, b) in nc.iter().zip(&values) {
            assert!((a - b).abs() < 1e-10);
        }
    }
}

#[test]
fn cubic_is_reproduced_exactly_by_a_quintic_fit() {
    // Least squares from noiseless samples of a cubic: the cubic is in the
    // spline space, so the residual is zero and every derivative matches.
    let kv = random_knots(5, 9, 5);
    let params = linspace(57);
    let q = |u: f64| {
        [
            0.3 - 1.5 * u + 2.0 * u * u - 4.0 * u.powi(3),
            -1.5 + 4.0 * u - 12.0 * u * u,
            4.0 - 24.0 * u,
            -24.0,
        ]
    };
    let values: Vec<f64> = params.iter().map(|&u| q(u)[0]).collect();
    let s = BSpline::new(kv.clone(), fit(&kv, &params, &values).unwrap()).unwrap();
    let mut rng = Lcg(6);
    for u in rng.vec(200, 0.0, 1.0).into_iter().chain([0.0, 1.0]) {
        let (got, want) = (s.eval(u), q(u));
        for r in 0..4 {
            assert!(
                (got[r] - want[r]).abs() < 1e-8 * want[r].abs().max(1.0),
                "r = {r}, u = {u}: {} vs {}",
                got[r],
                want[r]
            );
        }
    }
}

#[test]
fn tall_least_squares_matches_dense_pseudo_inverse() {
    let kv = random_knots(5, 4, 7);
    let mut rng = Lcg(8);
    let mut params = rng.vec(25, 0.0, 1.0);
    params.extend([0.0, 1.0]);
    let values = rng.vec(params.len(), -1.0, 1.0);
    let c = fit(&kv, &params, &values).unwrap();
    let n = collocation(&kv, &params).unwrap().to_dense();
    let pinv = n.clone().pseudo_inverse(1e-14).unwrap();
    let reference = pinv * DVector::from_column_slice(&values);
    for (a, b) in c.iter().zip(reference.iter()) {
        assert!((a - b).abs() < 1e-9 * b.abs().max(1.0), "{a} vs {b}");
    }
    // Optimality: the residual is orthogonal to the columns of N.
    let resid = &n * DVector::from_column_slice(&c) - DVector::from_column_slice(&values);
    let grad = n.transpose() * resid;
    assert!(grad.amax() < 1e-10, "N^T r = {grad}");
    // The fit is not an interpolation here: the residual is not zero.
    assert!(
        (&n * DVector::from_column_slice(&c) - DVector::from_column_slice(&values)).norm() > 1e-3
    );
}

#[test]
fn normal_matrix_equals_dense_product_and_widens_its_band() {
    let kv = KnotVector::clamped_uniform(5, 15).unwrap();
    let params = linspace(40);
    let n = collocation(&kv, &params).unwrap();
    // Too small a requested bandwidth is raised to k.
    let a = normal_matrix(&n, 1);
    assert_eq!(a.bandwidth(), 5);
    let dense = n.to_dense();
    let reference: DMatrix<f64> = dense.transpose() * &dense;
    assert!((a.to_dense() - reference).amax() < 1e-14);
}

#[test]
fn singular_fits_are_reported() {
    let kv = KnotVector::clamped_uniform(5, 12).unwrap();
    // Enough points, but all in the first span: the last basis functions
    // have no data (Schoenberg-Whitney violated).
    let params: Vec<f64> = (0..30).map(|i| 0.1 * i as f64 / 29.0).collect();
    let values = vec![1.0; 30];
    match fit(&kv, &params, &values) {
        Err(BsplineError::Singular { detail }) => {
            assert!(detail.contains("Schoenberg-Whitney"), "{detail}");
        }
        other => panic!("expected a singular fit, got {other:?}"),
    }
    // Enough distinct points per span, but interlacing fails: twelve
    // parameters crowded into the middle of the domain.
    let params: Vec<f64> = (0..12).map(|i| 0.45 + 0.1 * i as f64 / 11.0).collect();
    assert!(matches!(
        fit(&kv, &params, &[0.0; 12]),
        Err(BsplineError::Singular { .. })
    ));
    // Repeated parameters: rank-deficient square system.
    let mut params = greville(&kv);
    params[5] = params[4];
    assert!(matches!(
        fit(&kv, &params, &[0.0; 12]),
        Err(BsplineError::Singular { .. })
    ));
}

#[test]
fn fit_validates_its_inputs() {
    let kv = KnotVector::clamped_uniform(5, 8).unwrap();
    let params = linspace(10);
    assert_eq!(
        fit(&kv, &params, &[0.0; 9]),
        Err(BsplineError::LengthMismatch {
            what: "values of a fit (one per parameter)".into(),
            expected: 10,
            got: 9
        })
    );
    assert_eq!(
        fit(&kv, &linspace(7), &[0.0; 7]),
        Err(BsplineError::TooFewPoints {
            n_points: 7,
            n_coeffs: 8
        })
    );
    let mut bad = vec![0.0; 10];
    bad[3] = f64::NAN;
    assert!(matches!(
        fit(&kv, &params, &bad),
        Err(BsplineError::NotFinite { .. })
    ));
    let mut p = params.clone();
    p[2] = 1.5;
    assert_eq!(
        fit(&kv, &p, &[0.0; 10]),
        Err(BsplineError::ParameterOutOfRange { u: 1.5 })
    );
    p[2] = f64::INFINITY;
    assert!(matches!(
        collocation(&kv, &p),
        Err(BsplineError::NotFinite { .. })
    ));
}
