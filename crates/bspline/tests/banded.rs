//! Band matrices: BandRows products and BandedSym Cholesky solves against
//! dense nalgebra.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::Lcg;
use kerf_bspline::{BandRow, BandRows, BandedSym, BsplineError};
use nalgebra::{DMatrix, DVector};

/// A random band matrix: `nrows` rows of `len` values starting at
/// increasing columns.
fn random_band_rows(rng: &mut Lcg, nrows: usize, ncols: usize, len: usize) -> BandRows {
    let rows = (0..nrows)
        .map(|i| BandRow {
            start: (i * (ncols - len)) / nrows.max(1),
            values: rng.vec(len, -1.0, 1.0),
        })
        .collect();
    BandRows::new(ncols, rows).unwrap()
}

/// A random SPD band matrix B = R^T R + I with R banded.
fn random_spd(rng: &mut Lcg, n: usize, bw: usize) -> BandedSym {
    let mut d = DMatrix::<f64>::zeros(n, n);
    for i in 0..n {
        for j in i..n.min(i + bw + 1) {
            d[(i, j)] = rng.uniform(-1.0, 1.0);
        }
    }
    // R upper with bandwidth bw: R^T R has bandwidth bw.
    let spd = d.transpose() * &d + DMatrix::identity(n, n);
    BandedSym::from_dense_lower(&spd, bw).unwrap()
}

#[test]
fn band_rows_products_match_dense() {
    let mut rng = Lcg(1);
    let a = random_band_rows(&mut rng, 17, 12, 4);
    let d = a.to_dense();
    let x = rng.vec(12, -1.0, 1.0);
    let y = rng.vec(17, -1.0, 1.0);
    let ax = a.mul_vec(&x);
    let ref_ax = &d * DVector::from_column_slice(&x);
    let aty = a.tr_mul_vec(&y);
    let ref_aty = d.transpose() * DVector::from_column_slice(&y);
    for (p, q) in ax.iter().zip(ref_ax.iter()) {
        assert!((p - q).abs() < 1e-14);
    }
    for (p, q) in aty.iter().zip(ref_aty.iter()) {
        assert!((p - q).abs() < 1e-14);
    }
    // Triplets rebuild the dense matrix; scaled scales it.
    let mut rebuilt = DMatrix::zeros(17, 12);
    for (i, j, v) in a.triplets() {
        assert!(v != 0.0);
        rebuilt[(i, j)] = v;
    }
    assert_eq!(rebuilt, d);
    assert_eq!(a.scaled(-2.5).to_dense(), d * -2.5);
    // Band product against the dense product.
    let b = random_band_rows(&mut rng, 12, 9, 3);
    let ab = a.mul(&b).unwrap().to_dense();
    assert!((ab - a.to_dense() * b.to_dense()).amax() < 1e-14);
    assert!(b.mul(&a).is_err());
}

#[test]
fn band_rows_reject_bad_dimensions() {
    let mut rng = Lcg(2);
    let a = random_band_rows(&mut rng, 5, 8, 3);
    assert!(a.mul_vec(&[1.0; 7]).iter().all(|v| v.is_nan()));
    assert_eq!(a.mul_vec(&[1.0; 7]).len(), 5);
    assert!(a.tr_mul_vec(&[1.0; 6]).iter().all(|v| v.is_nan()));
    assert!(matches!(
        a.try_mul_vec(&[1.0; 7]),
        Err(BsplineError::LengthMismatch {
            expected: 8,
            got: 7,
            ..
        })
    ));
    assert!(a.try_tr_mul_vec(&[1.0; 5]).is_ok());
    // A row past the last column is rejected by the constructor.
    let bad = vec![BandRow {
        start: 6,
        values: vec![1.0, 2.0, 3.0],
    }];
    assert!(matches!(
        BandRows::new(8, bad.clone()),
        Err(BsplineError::LengthMismatch { .. })
    ));
    // Built by hand anyway, it never panics and yields NaN products.
    let raw = BandRows {
        ncols: 8,
        rows: bad,
    };
    assert!(raw.mul_vec(&[1.0; 8])[0].is_nan());
    assert_eq!(raw.triplets().count(), 2);
    assert!(BandRows::new(
        3,
        vec![BandRow {
            start: 0,
            values: vec![f64::NAN]
        }]
    )
    .is_err());
}

#[test]
fn banded_sym_matches_dense() {
    let mut rng = Lcg(3);
    let a = random_spd(&mut rng, 30, 5);
    let d = a.to_dense();
    assert_eq!(d, d.transpose());
    let x = rng.vec(30, -1.0, 1.0);
    let ax = a.mul_vec(&x);
    let reference = &d * DVector::from_column_slice(&x);
    for (p, q) in ax.iter().zip(reference.iter()) {
        assert!((p - q).abs() < 1e-12);
    }
    assert!(a.mul_vec(&x[1..]).iter().all(|v| v.is_nan()));
    assert_eq!(a.get(3, 20), 0.0);
    assert_eq!(a.get(40, 0), 0.0);
    assert_eq!(a.get(3, 8), d[(3, 8)]);
    assert!((a.max_abs() - d.amax()).abs() < 1e-15);
    assert_eq!(a.scaled(3.0).to_dense(), &d * 3.0);
    let mut rebuilt = DMatrix::zeros(30, 30);
    for (i, j, v) in a.upper_triplets() {
        assert!(i <= j && j - i <= 5);
        rebuilt[(i, j)] = v;
        rebuilt[(j, i)] = v;
    }
    assert_eq!(rebuilt, d);
    let mut m = BandedSym::zeros(4, 1);
    assert!(m.add(1, 0, 2.0));
    assert!(!m.add(3, 0, 1.0));
    assert_eq!(m.get(0, 1), 2.0);
}

#[test]
fn solve_spd_matches_dense_cholesky() {
    let mut rng = Lcg(4);
    for (n, bw) in [(1, 0), (6, 2), (40, 5), (628, 5), (50, 12)] {
        let a = random_spd(&mut rng, n, bw);
        let b = rng.vec(n, -1.0, 1.0);
        let x = a.solve_spd(&b).unwrap();
        let chol = a.to_dense().cholesky().unwrap();
        let reference = chol.solve(&DVector::from_column_slice(&b));
        for (p, q) in x.iter().zip(reference.iter()) {
            assert!(
                (p - q).abs() < 1e-10 * q.abs().max(1.0),
                "n = {n}: {p} vs {q}"
            );
        }
        // Residual.
        let r = a.mul_vec(&x);
        for (p, q) in r.iter().zip(&b) {
            assert!((p - q).abs() < 1e-10);
        }
    }
}

#[test]
fn solve_spd_rejects_indefinite_singular_and_bad_inputs() {
    // Indefinite: [[1, 2], [2, 1]].
    let mut a = BandedSym::zeros(2, 1);
    a.add(0, 0, 1.0);
    a.add(1, 1, 1.0);
    a.add(1, 0, 2.0);
    assert!(matches!(
        a.solve_spd(&[1.0, 1.0]),
        Err(BsplineError::Singular { .. })
    ));
    // Singular: [[1, 1], [1, 1]].
    let mut s = BandedSym::zeros(2, 1);
    s.add(0, 0, 1.0);
    s.add(1, 1, 1.0);
    s.add(1, 0, 1.0);
    assert!(matches!(
        s.solve_spd(&[1.0, 1.0]),
        Err(BsplineError::Singular { .. })
    ));
    // Nearly singular (cond ~ 4e12) is rejected, well-conditioned (cond ~ 4e8) is not.
    let mut near = BandedSym::zeros(2, 1);
    near.add(0, 0, 1.0);
    near.add(1, 1, 1.0);
    near.add(1, 0, 1.0 - 5e-13);
    assert!(near.solve_spd(&[1.0, 0.0]).is_err());
    let mut ok = BandedSym::zeros(2, 1);
    ok.add(0, 0, 1.0);
    ok.add(1, 1, 1.0);
    ok.add(1, 0, 1.0 - 5e-9);
    assert!(ok.solve_spd(&[1.0, 0.0]).is_ok());
    // Dimension and NaN.
    let mut rng = Lcg(5);
    let good = random_spd(&mut rng, 5, 2);
    assert!(matches!(
        good.solve_spd(&[1.0; 4]),
        Err(BsplineError::LengthMismatch { .. })
    ));
    assert!(matches!(
        good.solve_spd(&[1.0, f64::NAN, 1.0, 1.0, 1.0]),
        Err(BsplineError::NotFinite { .. })
    ));
    let mut nan = random_spd(&mut rng, 3, 1);
    nan.add(1, 1, f64::NAN);
    assert!(nan.solve_spd(&[1.0; 3]).is_err());
    assert!(nan.max_abs().is_nan());
}
