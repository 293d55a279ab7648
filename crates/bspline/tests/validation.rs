//! Input validation: every bad input is an error, never a panic or a
//! silent NaN.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_bspline::{
    basis_row, collocation, derivative_operator, BSpline, BandedSym, BsplineError, KnotVector,
};

#[test]
fn knot_vector_constructors_validate() {
    assert_eq!(
        KnotVector::clamped_uniform(5, 5),
        Err(BsplineError::TooFewCoefficients {
            n_coeffs: 5,
            degree: 5
        })
    );
    let kv = KnotVector::clamped_uniform(5, 6).unwrap();
    assert_eq!(
        kv.knots(),
        &[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0]
    );
    assert!(kv.interior().is_empty());
    for bad in [
        vec![0.5, 0.5],
        vec![0.6, 0.4],
        vec![0.0, 0.5],
        vec![0.5, 1.0],
        vec![-0.1],
        vec![1.2],
    ] {
        assert!(
            matches!(
                KnotVector::clamped_with_interior(3, &bad),
                Err(BsplineError::InvalidKnots { .. })
            ),
            "{bad:?}"
        );
    }
    assert!(matches!(
        KnotVector::clamped_with_interior(3, &[0.2, f64::NAN]),
        Err(BsplineError::NotFinite { .. })
    ));
    // Degree 0 (piecewise constant) is a valid space.
    let k0 = KnotVector::clamped_with_interior(0, &[0.25, 0.5]).unwrap();
    assert_eq!(k0.n_coeffs(), 3);
    assert_eq!(basis_row(&k0, 0.3, 0).unwrap().start, 1);
}

#[test]
fn parameters_are_checked_with_a_tiny_tolerance() {
    let kv = KnotVector::clamped_uniform(5, 10).unwrap();
    assert!(basis_row(&kv, -1e-13, 1).is_ok());
    assert!(basis_row(&kv, 1.0 + 1e-13, 2).is_ok());
    assert_eq!(
        basis_row(&kv, 1.0 + 1e-9, 0),
        Err(BsplineError::ParameterOutOfRange { u: 1.0 + 1e-9 })
    );
    assert_eq!(
        basis_row(&kv, -0.5, 0),
        Err(BsplineError::ParameterOutOfRange { u: -0.5 })
    );
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert!(matches!(
            basis_row(&kv, bad, 0),
            Err(BsplineError::NotFinite { .. })
        ));
        assert!(kv.try_basis_derivs(bad, 1).is_err());
    }
    assert!(collocation(&kv, &[0.1, 0.2, f64::NAN]).is_err());
    // The end rows at u = 0 and u = 1 (eq. 45): the first derivative at 0
    // involves only the first two coefficients, with values ∓k/u_{k+1}.
    let r = basis_row(&kv, 0.0, 1).unwrap();
    let h = kv.knots()[6];
    assert_eq!(r.start, 0);
    assert!((r.values[0] + 5.0 / h).abs() < 1e-9 && (r.values[1] - 5.0 / h).abs() < 1e-9);
    assert!(r.values[2..].iter().all(|v| v.abs() < 1e-9));
    let r = basis_row(&kv, 1.0, 1).unwrap();
    assert_eq!(r.start, 4);
    assert!((r.values[5] - 5.0 / h).abs() < 1e-9 && (r.values[4] + 5.0 / h).abs() < 1e-9);
}

#[test]
fn spline_and_matrix_constructors_validate() {
    let kv = KnotVector::clamped_uniform(5, 8).unwrap();
    assert!(matches!(
        BSpline::new(kv.clone(), vec![0.0; 7]),
        Err(BsplineError::LengthMismatch {
            expected: 8,
            got: 7,
            ..
        })
    ));
    let mut c = vec![0.0; 8];
    c[4] = f64::INFINITY;
    assert!(matches!(
        BSpline::new(kv.clone(), c),
        Err(BsplineError::NotFinite { .. })
    ));
    assert!(derivative_operator(&kv, 9).is_err());
    assert!(BandedSym::from_dense_lower(&nalgebra::DMatrix::zeros(3, 4), 1).is_err());
    let mut m = nalgebra::DMatrix::identity(3, 3);
    m[(2, 1)] = f64::NAN;
    assert!(BandedSym::from_dense_lower(&m, 1).is_err());
}

#[test]
fn error_messages_name_the_problem() {
    let e = KnotVector::clamped_uniform(5, 3).unwrap_err();
    assert_eq!(
        e.to_string(),
        "3 coefficients are too few for a B-spline of degree 5 (at least degree + 1 = 6 are needed)"
    );
    let e = basis_row(&KnotVector::clamped_uniform(5, 6).unwrap(), 2.0, 0).unwrap_err();
    assert_eq!(e.to_string(), "parameter u = 2 is outside [0, 1]");
}
