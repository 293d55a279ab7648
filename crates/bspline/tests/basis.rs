//! Knot vectors, spans and basis functions (seed 001 eq. 5, 8-10; NURBS
//! Book A2.1, A2.3).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::{cox_de_boor, dense, greville, random_knots, Lcg};
use kerf_bspline::{basis_row, fit, BSpline, KnotVector};

fn knot_vectors() -> Vec<KnotVector> {
    let mut v = Vec::new();
    for k in 0..=5 {
        v.push(KnotVector::clamped_uniform(k, k + 1).unwrap());
        v.push(KnotVector::clamped_uniform(k, k + 4).unwrap());
        v.push(KnotVector::clamped_uniform(k, 20).unwrap());
        v.push(random_knots(k, 9, 17 + k as u64));
    }
    v
}

fn sample_params(rng: &mut Lcg, m: usize) -> Vec<f64> {
    let mut u = rng.vec(m, 0.0, 1.0);
    u.extend([0.0, 1.0, 0.5, 1e-15, 1.0 - 1e-15]);
    u
}

#[test]
fn clamped_uniform_knots_are_as_specified() {
    let kv = KnotVector::clamped_uniform(5, 10).unwrap();
    // n = 9, k = 5: 6 zeros, n - k = 4 interior knots j/5, 6 ones.
    let expected = [
        0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.2, 0.4, 0.6, 0.8, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0,
    ];
    assert_eq!(kv.knots().len(), expected.len());
    for (a, b) in kv.knots().iter().zip(expected) {
        assert!((a - b).abs() < 1e-15, "{:?}", kv.knots());
    }
    assert_eq!(kv.n_coeffs(), 10);
    assert_eq!(kv.degree(), 5);
    assert_eq!(kv.interior().len(), 4);

    let kv = KnotVector::clamped_with_interior(3, &[0.1, 0.7]).unwrap();
    assert_eq!(
        kv.knots(),
        &[0.0, 0.0, 0.0, 0.0, 0.1, 0.7, 1.0, 1.0, 1.0, 1.0]
    );
    assert_eq!(kv.n_coeffs(), 6);
}

#[test]
fn span_brackets_u() {
    let kv = random_knots(5, 12, 3);
    let t = kv.knots();
    let n = kv.n_coeffs() - 1;
    assert_eq!(kv.span(0.0), 5);
    assert_eq!(kv.span(1.0), n);
    assert_eq!(kv.span(1.5), n);
    assert_eq!(kv.span(-0.5), 5);
    for (i, &knot) in kv.interior().iter().enumerate() {
        // A knot belongs to the span that starts at it.
        assert_eq!(kv.span(knot), 6 + i);
    }
    let mut rng = Lcg(5);
    for _ in 0..500 {
        let u = rng.next_f64();
        let i = kv.span(u);
        assert!(t[i] <= u && u < t[i + 1], "u = {u}, span {i}");
    }
    assert!(kv.try_span(f64::NAN).is_err());
    assert!(kv.try_span(1.0 + 1e-9).is_err());
    assert_eq!(kv.try_span(1.0 + 1e-13).unwrap(), n);
}

#[test]
fn basis_matches_cox_de_boor_partition_of_unity_and_nonnegativity() {
    let mut rng = Lcg(11);
    for kv in knot_vectors() {
        let n1 = kv.n_coeffs();
        for u in sample_params(&mut rng, 200) {
            let (first, ders) = kv.basis_derivs(u, 0);
            assert_eq!(ders.len(), 1);
            assert_eq!(ders[0].len(), kv.degree() + 1);
            assert!(first + kv.degree() < n1);
            let sum: f64 = ders[0].iter().sum();
            assert!((sum - 1.0).abs() < 1e-13, "sum {sum} at u = {u}");
            for (r, &v) in ders[0].iter().enumerate() {
                assert!(v >= -1e-15, "N_{} = {v} < 0 at u = {u}", first + r);
                let reference = cox_de_boor(kv.knots(), first + r, kv.degree(), u);
                assert!(
                    (v - reference).abs() < 1e-13,
                    "degree {}: N_{}({u}) = {v}, Cox-de Boor {reference}",
                    kv.degree(),
                    first + r
                );
            }
            // Every basis function outside the returned window vanishes.
            for j in (0..n1).filter(|&j| j < first || j > first + kv.degree()) {
                assert_eq!(cox_de_boor(kv.knots(), j, kv.degree(), u), 0.0);
            }
        }
    }
}

#[test]
fn basis_derivatives_match_central_differences() {
    let mut rng = Lcg(23);
    let h = 1e-5;
    for kv in knot_vectors() {
        let k = kv.degree();
        let n1 = kv.n_coeffs();
        for _ in 0..60 {
            let u = rng.uniform(2.0 * h, 1.0 - 2.0 * h);
            for d in 1..=k.min(3) {
                let exact = dense(&basis_row(&kv, u, d).unwrap(), n1);
                let plus = dense(&basis_row(&kv, u + h, d - 1).unwrap(), n1);
                let minus = dense(&basis_row(&kv, u - h, d - 1).unwrap(), n1);
                // Derivatives of order d - 1 < k - 1 are C^1 across simple
                // knots; for d - 1 = k - 1 they are only C^0, so skip
                // stencils straddling a knot there.
                let straddles = kv.interior().iter().any(|&t| (t - u).abs() <= h);
                if d == k && straddles {
                    continue;
                }
                let scale = exact.iter().fold(1.0f64, |m, v| m.max(v.abs()));
                for j in 0..n1 {
                    let fd = (plus[j] - minus[j]) / (2.0 * h);
                    assert!(
                        (fd - exact[j]).abs() < 1e-5 * scale,
                        "degree {k}, d = {d}, j = {j}, u = {u}: exact {}, fd {fd}",
                        exact[j]
                    );
                }
            }
            // The derivatives of a partition of unity sum to zero.
            let (_, ders) = kv.basis_derivs(u, 3);
            for row in ders.iter().skip(1) {
                let s: f64 = row.iter().sum();
                let scale = row.iter().fold(1.0f64, |m, v| m.max(v.abs()));
                assert!(s.abs() < 1e-10 * scale, "sum of derivatives {s}");
            }
        }
    }
}

#[test]
fn derivatives_above_the_degree_vanish() {
    let kv = KnotVector::clamped_uniform(2, 7).unwrap();
    let (_, ders) = kv.basis_derivs(0.37, 4);
    assert_eq!(ders.len(), 5);
    assert!(ders[2].iter().any(|v| v.abs() > 1.0));
    assert!(ders[3].iter().chain(&ders[4]).all(|&v| v == 0.0));
    let row = basis_row(&kv, 0.37, 3).unwrap();
    assert!(row.values.iter().all(|&v| v == 0.0));
}

#[test]
fn clamped_ends_interpolate_the_end_coefficients() {
    let mut rng = Lcg(31);
    for kv in knot_vectors() {
        let c = rng.vec(kv.n_coeffs(), -3.0, 3.0);
        let s = BSpline::new(kv.clone(), c.clone()).unwrap();
        assert!((s.eval(0.0)[0] - c[0]).abs() < 1e-14);
        assert!((s.eval(1.0)[0] - c[c.len() - 1]).abs() < 1e-14);
        // The end tangents are k/(u_{k+1}) (Θ_1 - Θ_0) and
        // k/(1 - u_n) (Θ_n - Θ_{n-1}) (NURBS Book eq. 3.7 at the ends).
        let k = kv.degree();
        if k >= 1 && c.len() >= 2 {
            let t = kv.knots();
            let n = c.len() - 1;
            let d0 = k as f64 / t[k + 1] * (c[1] - c[0]);
            let d1 = k as f64 / (1.0 - t[n]) * (c[n] - c[n - 1]);
            assert!((s.eval(0.0)[1] - d0).abs() < 1e-10 * d0.abs().max(1.0));
            assert!((s.eval(1.0)[1] - d1).abs() < 1e-10 * d1.abs().max(1.0));
        }
    }
}

#[test]
fn quintic_reproduces_a_quintic_polynomial_with_its_derivatives() {
    // Interpolation at the Greville abscissae of a quintic spline space
    // reproduces every polynomial of degree <= 5 exactly.
    let p = |u: f64| -> [f64; 4] {
        [
            1.0 - 2.0 * u + 3.0 * u.powi(3) - 4.0 * u.powi(4) + 2.5 * u.powi(5),
            -2.0 + 9.0 * u * u - 16.0 * u.powi(3) + 12.5 * u.powi(4),
            18.0 * u - 48.0 * u * u + 50.0 * u.powi(3),
            18.0 - 96.0 * u + 150.0 * u * u,
        ]
    };
    for kv in [
        KnotVector::clamped_uniform(5, 14).unwrap(),
        random_knots(5, 7, 99),
    ] {
        let params = greville(&kv);
        let values: Vec<f64> = params.iter().map(|&u| p(u)[0]).collect();
        let s = BSpline::new(kv.clone(), fit(&kv, &params, &values).unwrap()).unwrap();
        let mut rng = Lcg(7);
        for u in sample_params(&mut rng, 100) {
            let got = s.eval(u);
            let want = p(u);
            for r in 0..4 {
                assert!(
                    (got[r] - want[r]).abs() < 1e-8 * want[r].abs().max(1.0),
                    "r = {r}, u = {u}: {} vs {}",
                    got[r],
                    want[r]
                );
            }
            // Fourth and fifth derivatives too, through eval_deriv.
            let d4 = -96.0 + 300.0 * u;
            assert!((s.eval_deriv(u, 4).unwrap() - d4).abs() < 1e-6 * d4.abs().max(1.0));
            assert!((s.eval_deriv(u, 5).unwrap() - 300.0).abs() < 1e-5);
            assert_eq!(s.eval_deriv(u, 6).unwrap(), 0.0);
        }
    }
}

#[test]
fn nan_propagates_through_the_infallible_evaluators() {
    let kv = KnotVector::clamped_uniform(5, 9).unwrap();
    let (_, ders) = kv.basis_derivs(f64::NAN, 2);
    assert!(ders[0].iter().all(|v| v.is_nan()));
    let s = BSpline::new(kv.clone(), vec![1.0; 9]).unwrap();
    assert!(s.eval(f64::NAN)[0].is_nan());
    assert!(s.try_eval(f64::NAN).is_err());
    assert!(s.try_eval(-1e-6).is_err());
    // Clamping outside [0, 1] for the infallible evaluator.
    assert_eq!(s.eval(2.0), s.eval(1.0));
}
