//! `KnotVector::for_parameters`: knots placed by the fit parameters, de
//! Boor's averaging for interpolation (*The NURBS Book* eq. 9.8) and
//! Piegl-Tiller eq. 9.68-9.69 for least squares.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::Lcg;
use kerf_bspline::{
    collocation, fit, normal_matrix, normal_rhs, BSpline, BsplineError, KnotVector,
};

fn assert_close(got: &[f64], want: &[f64], tol: f64) {
    assert_eq!(got.len(), want.len(), "{got:?} vs {want:?}");
    for (g, w) in got.iter().zip(want) {
        assert!((g - w).abs() <= tol, "{got:?} vs {want:?}");
    }
}

/// The clamped knot vector of `degree` with these interior knots.
fn full(degree: usize, interior: &[f64]) -> Vec<f64> {
    let mut v = vec![0.0; degree + 1];
    v.extend_from_slice(interior);
    v.extend(std::iter::repeat_n(1.0, degree + 1));
    v
}

/// 2-norm condition number of the (dense) collocation matrix; infinite
/// when it is singular to machine precision.
fn collocation_cond(kv: &KnotVector, params: &[f64]) -> f64 {
    let s = collocation(kv, params)
        .unwrap()
        .to_dense()
        .singular_values();
    s.max() / s.min()
}

/// `n` parameters from 0 to 1, equally spaced except the last gap, which
/// is `short` times the others.
fn equal_with_short_last(n: usize, short: f64) -> Vec<f64> {
    let h = 1.0 / ((n - 2) as f64 + short);
    let mut p: Vec<f64> = (0..n - 1).map(|i| i as f64 * h).collect();
    p.push(1.0);
    p
}

fn max_error(spline: &BSpline, us: &[f64], f: impl Fn(f64) -> f64) -> f64 {
    us.iter()
        .map(|&u| (spline.eval(u)[0] - f(u)).abs())
        .fold(0.0, f64::max)
}

#[test]
fn de_boor_averaging_for_interpolation() {
    // k = 3, 6 parameters, 6 coefficients (n = 5): n - k = 2 interior
    // knots t_{j+3} = (u_j + u_{j+1} + u_{j+2}) / 3, j = 1, 2:
    // (0.1 + 0.3 + 0.6) / 3 = 1/3 and (0.3 + 0.6 + 0.8) / 3 = 0.5667.
    let params = [0.0, 0.1, 0.3, 0.6, 0.8, 1.0];
    let kv = KnotVector::for_parameters(3, 6, &params).unwrap();
    assert_eq!((kv.degree(), kv.n_coeffs()), (3, 6));
    assert_close(kv.interior(), &[1.0 / 3.0, 1.7 / 3.0], 1e-15);
    assert_close(kv.knots(), &full(3, &[1.0 / 3.0, 1.7 / 3.0]), 1e-15);

    // k = 2: t_{j+2} = (u_j + u_{j+1}) / 2: (0.2 + 0.5) / 2, (0.5 + 0.6) / 2.
    let kv = KnotVector::for_parameters(2, 5, &[0.0, 0.2, 0.5, 0.6, 1.0]).unwrap();
    assert_close(kv.knots(), &full(2, &[0.35, 0.55]), 1e-15);

    // Equally spaced u_i = i / 7, k = 3, 8 coefficients:
    // t_{j+3} = (3 j + 3) / 21 = (j + 1) / 7, j = 1..4, evenly spaced (but
    // not the clamped uniform j / 5).
    let params: Vec<f64> = (0..8).map(|i| i as f64 / 7.0).collect();
    let kv = KnotVector::for_parameters(3, 8, &params).unwrap();
    assert_close(
        kv.interior(),
        &[2.0 / 7.0, 3.0 / 7.0, 4.0 / 7.0, 5.0 / 7.0],
        1e-15,
    );
    let uniform = KnotVector::clamped_uniform(3, 8).unwrap();
    assert_close(uniform.interior(), &[0.2, 0.4, 0.6, 0.8], 1e-15);

    // n_coeffs = k + 1: no interior knot (a Bezier segment).
    let kv = KnotVector::for_parameters(3, 4, &[0.0, 0.2, 0.7, 1.0]).unwrap();
    assert_eq!(kv.knots(), &full(3, &[])[..]);
}

#[test]
fn piegl_tiller_for_least_squares() {
    // k = 2, 8 parameters (m = 7), 5 coefficients (n = 4):
    // d = (m + 1) / (n - k + 1) = 8 / 3.
    // j = 1: jd = 2.667, i = 2, a = 2/3: u_1 / 3 + 2 u_2 / 3 = 0.13333.
    // j = 2: jd = 5.333, i = 5, a = 1/3: 2 u_4 / 3 + u_5 / 3 = 0.56667.
    let params = [0.0, 0.1, 0.15, 0.3, 0.5, 0.7, 0.9, 1.0];
    let kv = KnotVector::for_parameters(2, 5, &params).unwrap();
    assert_eq!(kv.n_coeffs(), 5);
    assert_close(
        kv.knots(),
        &full(2, &[0.1 / 3.0 + 0.3 / 3.0, 1.0 / 3.0 + 0.7 / 3.0]),
        1e-15,
    );

    // Integer jd (a = 0) picks u_{i-1}: 6 parameters, k = 2, 5 coefficients:
    // d = 6 / 3 = 2; j = 1: i = 2 -> u_1; j = 2: i = 4 -> u_3.
    let params = [0.0, 0.1, 0.25, 0.5, 0.8, 1.0];
    let kv = KnotVector::for_parameters(2, 5, &params).unwrap();
    assert_eq!(kv.interior(), &[0.1, 0.5]);

    // k = 3, 7 parameters, 5 coefficients: d = 7 / 2, one interior knot at
    // i = 3, a = 1/2: (u_2 + u_3) / 2.
    let params = [0.0, 0.05, 0.2, 0.4, 0.45, 0.9, 1.0];
    let kv = KnotVector::for_parameters(3, 5, &params).unwrap();
    assert_close(kv.interior(), &[0.3], 1e-15);

    // n_coeffs = k + 1 with more parameters: no interior knot either.
    let params: Vec<f64> = (0..10).map(|i| (i as f64 / 9.0).powi(2)).collect();
    let kv = KnotVector::for_parameters(3, 4, &params).unwrap();
    assert_eq!(kv.knots(), &full(3, &[])[..]);
}

#[test]
fn interpolation_with_a_short_last_segment_is_well_conditioned() {
    // 241 equally spaced parameters whose last gap is 1e-4 of the others
    // (a CL path whose last segment is tiny), quintic, interpolation.
    let params = equal_with_short_last(241, 1e-4);
    let gaps = (params[240] - params[239]) / (params[239] - params[238]);
    assert!((gaps - 1e-4).abs() < 1e-9);
    let f = |u: f64| (3.0 * u).sin() + u * u;
    let values: Vec<f64> = params.iter().map(|&u| f(u)).collect();

    let kv = KnotVector::for_parameters(5, 241, &params).unwrap();
    // Schoenberg-Whitney, strictly: t_j < u_j < t_{j+k+1} for j = 1..n-1.
    let t = kv.knots();
    for j in 1..240 {
        assert!(t[j] < params[j] && params[j] < t[j + 6], "j = {j}");
    }
    // The square collocation matrix: its conditioning is set by the two
    // nearly equal rows at u_239 and u_240 (~1e4 for the 1e-4 gap), far from
    // singular.
    let cond = collocation_cond(&kv, &params);
    assert!(cond < 1e5, "cond {cond:e}");
    // The banded Cholesky of N^T N (cond ~1e8, under its 1e10 pivot test)
    // and fit() succeed and interpolate.
    let n = collocation(&kv, &params).unwrap();
    let coeffs = normal_matrix(&n, 5)
        .solve_spd(&normal_rhs(&n, &values).unwrap())
        .unwrap();
    let spline = BSpline::new(kv.clone(), coeffs.clone()).unwrap();
    assert!(max_error(&spline, &params, f) < 1e-9);
    let fitted = fit(&kv, &params, &values).unwrap();
    assert_eq!(fitted, coeffs);
    // Between the data the interpolant follows f too.
    let mid: Vec<f64> = params.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect();
    assert!(max_error(&spline, &mid, f) < 1e-8);

    // The clamped uniform knot vector on the same parameters: numerically
    // singular collocation, and fit() reports it.
    let uniform = KnotVector::clamped_uniform(5, 241).unwrap();
    let cond_u = collocation_cond(&uniform, &params);
    assert!(cond_u >= 1e12, "cond {cond_u:e}");
    assert!(matches!(
        fit(&uniform, &params, &values),
        Err(BsplineError::Singular { .. })
    ));
    // At this size uniform knots fail on equally spaced parameters already
    // (1/236 knot spacing against 1/240 parameter spacing: the parameters
    // drift half a span against the knots, where odd-degree interpolation
    // degenerates); the averaged knots are at cond ~15 there.
    let equal = equal_with_short_last(241, 1.0);
    let cond_e = collocation_cond(&KnotVector::for_parameters(5, 241, &equal).unwrap(), &equal);
    assert!(cond_e < 100.0, "cond {cond_e:e}");
    assert!(collocation_cond(&uniform, &equal) >= 1e12);
    // On a small case uniform knots still work, and the short last segment
    // is what degrades them (by more than 10x).
    let small_equal = equal_with_short_last(21, 1.0);
    let small_short = equal_with_short_last(21, 1e-4);
    let u21 = KnotVector::clamped_uniform(5, 21).unwrap();
    let (ce, cs) = (
        collocation_cond(&u21, &small_equal),
        collocation_cond(&u21, &small_short),
    );
    assert!(ce < 1e4 && cs > 10.0 * ce, "{ce:e} {cs:e}");
}

#[test]
fn least_squares_on_uneven_parameters() {
    // 628 parameters clustered at 0 (u_i = (i / 627)^2: gaps from 2.5e-6
    // to 3.2e-3), 64 quintic coefficients.
    let params: Vec<f64> = (0..628)
        .map(|i| {
            let s = i as f64 / 627.0;
            if i == 627 {
                1.0
            } else {
                s * s
            }
        })
        .collect();
    let kv = KnotVector::for_parameters(5, 64, &params).unwrap();
    assert_eq!(kv.n_coeffs(), 64);
    // d = 628 / 59 = 10.64: knot t_{k+j} sits at the fractional index
    // j d - 1, so every knot span holds 10 or 11 parameters (the uniform
    // knots put 82 in the first span, u < 1/59, i.e. i <= 81, and 6 in the
    // last, u >= 58/59, i.e. i >= 622).
    let count = |kv: &KnotVector| -> Vec<usize> {
        let t = kv.knots();
        (5..64)
            .map(|s| {
                params
                    .iter()
                    .filter(|&&u| t[s] <= u && (u < t[s + 1] || (s == 63 && u <= 1.0)))
                    .count()
            })
            .collect()
    };
    let per_span = count(&kv);
    assert_eq!(per_span.iter().sum::<usize>(), 628);
    assert!(per_span.iter().all(|&c| c == 10 || c == 11), "{per_span:?}");
    let per_uniform = count(&KnotVector::clamped_uniform(5, 64).unwrap());
    assert_eq!((per_uniform[0], per_uniform[58]), (82, 6));

    // A smooth function: small error over all of [0, 1], not just at the
    // data.
    let f = |u: f64| (2.0 * std::f64::consts::PI * u).sin() + 0.3 * (5.0 * u).cos() + u.powi(3);
    let values: Vec<f64> = params.iter().map(|&u| f(u)).collect();
    let spline = BSpline::new(kv.clone(), fit(&kv, &params, &values).unwrap()).unwrap();
    let dense: Vec<f64> = (0..=10_000).map(|i| i as f64 / 10_000.0).collect();
    let err = max_error(&spline, &dense, f);
    assert!(err < 1e-7, "{err:e}");
    assert!(max_error(&spline, &params, f) < 1e-7);

    // A quintic is in the spline space: reproduced to rounding.
    let poly = |u: f64| 1.0 - 2.0 * u + 3.0 * u.powi(3) - u.powi(5);
    let values: Vec<f64> = params.iter().map(|&u| poly(u)).collect();
    let spline = BSpline::new(kv.clone(), fit(&kv, &params, &values).unwrap()).unwrap();
    assert!(max_error(&spline, &dense, poly) < 1e-11);

    // Random gaps (ratio up to 10) and a last gap 1e-4 of a mean one.
    let mut rng = Lcg(7);
    let mut gaps: Vec<f64> = (0..627).map(|_| rng.uniform(0.1, 1.0)).collect();
    gaps[626] = 0.55e-4;
    let total: f64 = gaps.iter().sum();
    let mut params = vec![0.0];
    let mut acc = 0.0;
    for g in &gaps[..626] {
        acc += g;
        params.push(acc / total);
    }
    params.push(1.0);
    let kv = KnotVector::for_parameters(5, 64, &params).unwrap();
    let cond = collocation_cond(&kv, &params);
    assert!(cond < 100.0, "cond {cond:e}");
    let values: Vec<f64> = params.iter().map(|&u| f(u)).collect();
    let spline = BSpline::new(kv.clone(), fit(&kv, &params, &values).unwrap()).unwrap();
    let err = max_error(&spline, &dense, f);
    assert!(err < 1e-8, "{err:e}");
}

#[test]
fn invalid_inputs_are_errors() {
    let ok = [0.0, 0.2, 0.4, 0.6, 0.8, 1.0];
    assert!(KnotVector::for_parameters(2, 5, &ok).is_ok());
    // Fewer coefficients than degree + 1.
    assert_eq!(
        KnotVector::for_parameters(5, 4, &ok),
        Err(BsplineError::TooFewCoefficients {
            n_coeffs: 4,
            degree: 5
        })
    );
    // Fewer points than coefficients.
    assert_eq!(
        KnotVector::for_parameters(3, 7, &ok),
        Err(BsplineError::TooFewPoints {
            n_points: 6,
            n_coeffs: 7
        })
    );
    assert_eq!(
        KnotVector::for_parameters(3, 4, &[]),
        Err(BsplineError::TooFewPoints {
            n_points: 0,
            n_coeffs: 4
        })
    );
    // Not finite.
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let p = [0.0, 0.2, bad, 0.6, 0.8, 1.0];
        assert!(
            matches!(
                KnotVector::for_parameters(2, 5, &p),
                Err(BsplineError::NotFinite { .. })
            ),
            "{bad}"
        );
        assert!(matches!(
            KnotVector::for_parameters(2, 6, &p),
            Err(BsplineError::NotFinite { .. })
        ));
    }
    // Not strictly increasing, not from 0, not to 1.
    for p in [
        [0.0, 0.2, 0.2, 0.6, 0.8, 1.0],
        [0.0, 0.4, 0.3, 0.6, 0.8, 1.0],
        [0.0, 0.2, 0.4, 0.6, 1.0, 1.0],
        [0.1, 0.2, 0.4, 0.6, 0.8, 1.0],
        [-0.1, 0.2, 0.4, 0.6, 0.8, 1.0],
        [0.0, 0.2, 0.4, 0.6, 0.8, 0.9],
        [0.0, 0.2, 0.4, 0.6, 0.8, 1.1],
        [1.0, 0.8, 0.6, 0.4, 0.2, 0.0],
    ] {
        for n_coeffs in [5, 6] {
            assert!(
                matches!(
                    KnotVector::for_parameters(2, n_coeffs, &p),
                    Err(BsplineError::InvalidKnots { .. })
                ),
                "{p:?} {n_coeffs}"
            );
        }
    }
}
