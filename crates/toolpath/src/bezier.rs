//! Quintic Bézier curves: points, derivatives and curvature (Farin,
//! "Curves and Surfaces for CAGD", 5th ed., 2002: de Casteljau's algorithm,
//! section 4.2; the derivative as a Bézier curve of the forward differences,
//! eq. 5.3: d/du b(u) = n Σ Δb_i B_i^{n−1}(u); curvature κ = |b' × b''| /
//! |b'|³, eq. 10.5).

use crate::quadrature::gauss_legendre_8;
use crate::vec3::{cross, norm, sub};

/// A quintic Bézier curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuinticBezier {
    /// The six control points.
    pub control: [[f64; 3]; 6],
}

/// de Casteljau on `n + 1` points (n ≤ 5) at `u`.
fn casteljau<const N: usize>(mut p: [[f64; 3]; N], u: f64) -> [f64; 3] {
    for level in 1..N {
        for i in 0..N - level {
            let next = p[i + 1];
            for (x, y) in p[i].iter_mut().zip(next) {
                *x = (1.0 - u) * *x + u * y;
            }
        }
    }
    p[0]
}

impl QuinticBezier {
    /// The point at u ∈ [0, 1].
    pub fn point(&self, u: f64) -> [f64; 3] {
        casteljau(self.control, u)
    }

    /// The first derivative (Farin eq. 5.3: 5 Σ Δb_i B_i⁴).
    pub fn d1(&self, u: f64) -> [f64; 3] {
        let c = &self.control;
        let d: [[f64; 3]; 5] = std::array::from_fn(|i| {
            let v = sub(c[i + 1], c[i]);
            [5.0 * v[0], 5.0 * v[1], 5.0 * v[2]]
        });
        casteljau(d, u)
    }

    /// The second derivative (20 Σ Δ²b_i B_i³).
    pub fn d2(&self, u: f64) -> [f64; 3] {
        let c = &self.control;
        let d: [[f64; 3]; 4] = std::array::from_fn(|i| {
            let v = sub(sub(c[i + 2], c[i + 1]), sub(c[i + 1], c[i]));
            [20.0 * v[0], 20.0 * v[1], 20.0 * v[2]]
        });
        casteljau(d, u)
    }

    /// The curvature at u (Farin eq. 10.5); 0 where b' = 0.
    pub fn curvature(&self, u: f64) -> f64 {
        let d1 = self.d1(u);
        let speed = norm(d1);
        if speed == 0.0 {
            return 0.0;
        }
        norm(cross(d1, self.d2(u))) / (speed * speed * speed)
    }

    /// The arc length between the parameters `u0` and `u1` by 8-point
    /// Gauss–Legendre quadrature \[m\] (exact for polynomial speeds up to
    /// degree 15; the speed of a quintic is not polynomial, the error falls
    /// as (u1 − u0)^16). Nodes and weights: Abramowitz and Stegun, Handbook
    /// of Mathematical Functions, Table 25.4, n = 8.
    pub fn length_between(&self, u0: f64, u1: f64) -> f64 {
        gauss_legendre_8(u0, u1, |u| norm(self.d1(u)))
    }

    /// The arc length by 8-point Gauss–Legendre quadrature on each of
    /// `pieces` equal parameter intervals \[m\].
    pub fn length(&self, pieces: usize) -> f64 {
        let pieces = pieces.max(1);
        let h = 1.0 / pieces as f64;
        (0..pieces)
            .map(|k| self.length_between(k as f64 * h, (k + 1) as f64 * h))
            .sum()
    }
}
