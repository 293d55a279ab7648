//! Helpers shared by the integration tests: a deterministic random
//! generator, an independent Cox-de Boor reference and knot vectors.

#![allow(dead_code)]

use kerf_bspline::{BandRow, KnotVector};

/// Deterministic 64-bit LCG (Knuth's MMIX constants), uniform in [lo, hi).
pub struct Lcg(pub u64);

impl Lcg {
    pub fn next_f64(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next_f64()
    }

    pub fn vec(&mut self, n: usize, lo: f64, hi: f64) -> Vec<f64> {
        (0..n).map(|_| self.uniform(lo, hi)).collect()
    }
}

/// Cox-de Boor recursion (de Boor 1972, *The NURBS Book* eq. 2.5), written
/// independently of the crate: N_{j,p}(u) on `knots`, with the convention
/// that the last non-empty span is closed at its right end.
pub fn cox_de_boor(knots: &[f64], j: usize, p: usize, u: f64) -> f64 {
    if p == 0 {
        let (a, b) = (knots[j], knots[j + 1]);
        let last = knots[knots.len() - 1];
        if (a <= u && u < b) || (u == last && b == last && a < b) {
            return 1.0;
        }
        return 0.0;
    }
    let mut v = 0.0;
    let d1 = knots[j + p] - knots[j];
    if d1 > 0.0 {
        v += (u - knots[j]) / d1 * cox_de_boor(knots, j, p - 1, u);
    }
    let d2 = knots[j + p + 1] - knots[j + 1];
    if d2 > 0.0 {
        v += (knots[j + p + 1] - u) / d2 * cox_de_boor(knots, j + 1, p - 1, u);
    }
    v
}

/// A dense row of length `n` from a band row.
pub fn dense(row: &BandRow, n: usize) -> Vec<f64> {
    (0..n).map(|j| row.get(j)).collect()
}

/// A non-uniform clamped knot vector with `n_interior` random interior
/// knots (spacing ratio up to ~10).
pub fn random_knots(degree: usize, n_interior: usize, seed: u64) -> KnotVector {
    let mut rng = Lcg(seed);
    let gaps: Vec<f64> = (0..=n_interior).map(|_| rng.uniform(0.1, 1.0)).collect();
    let total: f64 = gaps.iter().sum();
    let mut acc = 0.0;
    let interior: Vec<f64> = gaps[..n_interior]
        .iter()
        .map(|g| {
            acc += g;
            acc / total
        })
        .collect();
    KnotVector::clamped_with_interior(degree, &interior).unwrap()
}

/// Greville abscissae (knot averages) of a knot vector: a parameter set
/// that satisfies the Schoenberg-Whitney condition.
pub fn greville(kv: &KnotVector) -> Vec<f64> {
    let k = kv.degree();
    let t = kv.knots();
    (0..kv.n_coeffs())
        .map(|j| {
            if k == 0 {
                0.5 * (t[j] + t[j + 1])
            } else {
                t[j + 1..=j + k].iter().sum::<f64>() / k as f64
            }
        })
        .collect()
}

/// Evenly spaced parameters 0, 1/(m-1), ..., 1.
pub fn linspace(m: usize) -> Vec<f64> {
    (0..m).map(|i| i as f64 / (m - 1) as f64).collect()
}

/// Composite Simpson rule with `per_span` (even) subintervals on each
/// non-empty knot span of `kv`.
pub fn simpson_per_span(kv: &KnotVector, per_span: usize, f: impl Fn(f64) -> f64) -> f64 {
    let t = kv.knots();
    let mut total = 0.0;
    for w in t.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b <= a {
            continue;
        }
        let h = (b - a) / per_span as f64;
        // End points just inside the span, so that a piecewise polynomial
        // is taken from this span's piece (it may jump at the knots).
        let eps = 1e-13 * (b - a);
        let mut s = f(a + eps) + f(b - eps);
        for i in 1..per_span {
            let x = a + h * i as f64;
            s += if i % 2 == 1 { 4.0 } else { 2.0 } * f(x);
        }
        total += s * h / 3.0;
    }
    total
}
