//! The real-root finder and extremum search on intervals.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::Rng;
use kerf_executor::roots::{derivative, eval, extrema, real_roots_in};

/// Coefficients (ascending) of `scale · Π (x − r)`.
fn from_roots(roots: &[f64], scale: f64) -> Vec<f64> {
    let mut c = vec![scale];
    for &r in roots {
        let mut next = vec![0.0; c.len() + 1];
        for (i, &ci) in c.iter().enumerate() {
            next[i + 1] += ci;
            next[i] -= r * ci;
        }
        c = next;
    }
    c
}

fn assert_roots(found: &[f64], expected: &[f64], tol: f64) {
    assert_eq!(
        found.len(),
        expected.len(),
        "found {found:?}, expected {expected:?}"
    );
    for (f, e) in found.iter().zip(expected) {
        assert!(
            (f - e).abs() <= tol,
            "found {found:?}, expected {expected:?}"
        );
    }
}

#[test]
fn linear_and_constant() {
    assert_roots(&real_roots_in(&[-1.0, 2.0], 0.0, 1.0), &[0.5], 0.0);
    assert!(real_roots_in(&[-1.0, 2.0], 0.6, 1.0).is_empty());
    assert!(real_roots_in(&[3.0], -1.0, 1.0).is_empty());
    assert!(real_roots_in(&[0.0, 0.0, 0.0], -1.0, 1.0).is_empty());
    assert!(real_roots_in(&[], -1.0, 1.0).is_empty());
}

#[test]
fn cubic_with_three_roots_and_subintervals() {
    let c = from_roots(&[1.0, 2.0, 3.0], 1.0);
    assert_roots(&real_roots_in(&c, 0.0, 4.0), &[1.0, 2.0, 3.0], 1e-12);
    assert_roots(&real_roots_in(&c, 1.5, 4.0), &[2.0, 3.0], 1e-12);
    // Roots exactly at the interval ends are included once.
    assert_roots(&real_roots_in(&c, 1.0, 3.0), &[1.0, 2.0, 3.0], 1e-12);
    assert!(real_roots_in(&c, 3.5, 10.0).is_empty());
}

#[test]
fn quartic_with_irrational_roots() {
    // (x² − 2)(x² − 3) = 6 − 5x² + x⁴
    let c = [6.0, 0.0, -5.0, 0.0, 1.0];
    let s2 = 2f64.sqrt();
    let s3 = 3f64.sqrt();
    assert_roots(&real_roots_in(&c, -2.0, 2.0), &[-s3, -s2, s2, s3], 1e-14);
    assert_roots(&real_roots_in(&c, 0.0, 1.5), &[s2], 1e-14);
}

#[test]
fn no_real_roots_and_double_roots() {
    assert!(real_roots_in(&[1.0, 0.0, 1.0], -5.0, 5.0).is_empty());
    // (x − 1)² touches zero exactly at a critical point.
    assert_roots(&real_roots_in(&[1.0, -2.0, 1.0], -5.0, 5.0), &[1.0], 0.0);
    // Triple root (x − 0.5)³ changes sign.
    let c = from_roots(&[0.5, 0.5, 0.5], 1.0);
    assert_roots(&real_roots_in(&c, 0.0, 1.0), &[0.5], 1e-5);
}

#[test]
fn invalid_interval_gives_nothing() {
    let c = [-1.0, 2.0];
    assert!(real_roots_in(&c, 1.0, 0.0).is_empty());
    assert!(real_roots_in(&c, f64::NAN, 1.0).is_empty());
    assert!(real_roots_in(&c, 0.0, f64::INFINITY).is_empty());
}

#[test]
fn tiny_leading_coefficient() {
    // 1e-20 x³ + x − 0.5: the cubic term is negligible on [0, 1].
    assert_roots(
        &real_roots_in(&[-0.5, 1.0, 0.0, 1e-20], 0.0, 1.0),
        &[0.5],
        1e-15,
    );
}

#[test]
fn random_polynomials_degree_1_to_5() {
    let mut rng = Rng(7);
    for _ in 0..2000 {
        let degree = 1 + (rng.next_u64() % 5) as usize;
        let mut roots: Vec<f64> = (0..degree).map(|_| rng.range(-3.0, 3.0)).collect();
        roots.sort_by(f64::total_cmp);
        // Keep the roots separated, so each is well conditioned.
        if roots.windows(2).any(|w| w[1] - w[0] < 0.05) {
            continue;
        }
        let scale = rng.range(0.1, 10.0) * if rng.unit() < 0.5 { -1.0 } else { 1.0 };
        let c = from_roots(&roots, scale);
        let (lo, hi) = (rng.range(-4.0, 0.0), rng.range(0.0, 4.0));
        let inside: Vec<f64> = roots
            .iter()
            .copied()
            .filter(|r| lo <= *r && *r <= hi)
            .collect();
        let found = real_roots_in(&c, lo, hi);
        assert_roots(&found, &inside, 1e-9);
        for r in found {
            assert!(eval(&c, r).abs() < 1e-9, "p({r}) = {}", eval(&c, r));
        }
    }
}

#[test]
fn derivative_and_eval() {
    // p = 1 + 2x + 3x² → p' = 2 + 6x
    assert_eq!(derivative(&[1.0, 2.0, 3.0]), vec![2.0, 6.0]);
    assert!(derivative(&[5.0]).is_empty());
    assert_eq!(eval(&[1.0, 2.0, 3.0], 2.0), 17.0);
}

#[test]
fn extrema_of_a_parabola_and_a_cubic() {
    // x (1 − x) on [0, 1]: min 0 at the ends, max 1/4 at 1/2.
    let ((_, min), (x_max, max)) = extrema(&[0.0, 1.0, -1.0], 0.0, 1.0);
    assert_eq!(min, 0.0);
    assert!((x_max - 0.5).abs() < 1e-15 && (max - 0.25).abs() < 1e-15);
    // x³ − 3x on [−3, 3]: ends dominate (±18); on [−1.5, 1.5] the critical points (∓1 → ±2).
    let c = [0.0, -3.0, 0.0, 1.0];
    let ((x_min, min), (x_max, max)) = extrema(&c, -3.0, 3.0);
    assert_eq!((x_min, min, x_max, max), (-3.0, -18.0, 3.0, 18.0));
    let ((x_min, min), (x_max, max)) = extrema(&c, -1.5, 1.5);
    assert!((x_min - 1.0).abs() < 1e-12 && (min + 2.0).abs() < 1e-15);
    assert!((x_max + 1.0).abs() < 1e-12 && (max - 2.0).abs() < 1e-15);
}
