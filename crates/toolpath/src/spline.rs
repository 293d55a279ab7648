//! Clamped rational cubic B-splines (NURBS of degree 3) with at most
//! [`MAX_CONTROL`] control points: the curves of the corner baselines
//! ([`crate::baseline`]).
//!
//! Formulas (seed 003's equation numbers; the same in Piegl and Tiller,
//! "The NURBS Book", 2nd ed., 1997, sections 2.2–2.3 and 4.2–4.3):
//! * the curve C(u) = Σ Nᵢ,₃(u) wᵢ Pᵢ / Σ Nᵢ,₃(u) wᵢ (eq. 1);
//! * the basis by the Cox–de Boor recursion with 0/0 = 0 (eq. 2);
//! * its first and second derivatives (eqs. 3–4);
//! * the curve's derivatives from those of A(u) = Σ Nᵢ wᵢ Pᵢ and
//!   W(u) = Σ Nᵢ wᵢ: C′ = (A′ − W′ C) / W and C″ = (A″ − 2 W′ C′ − W″ C) /
//!   W (eq. 5 and the unnumbered one after it);
//! * the curvature κ = |C′ × C″| / |C′|³ (the inverse of seed 003 eq. 6,
//!   which gives the radius).

use crate::error::ToolpathError;
use crate::quadrature::gauss_legendre_8;
use crate::vec3::{add, cross, norm, scale, sub};

/// The most control points of a [`CubicSpline`].
pub const MAX_CONTROL: usize = 9;

/// Below this sine of the angle between C′ and C″ the curvature is
/// rounding, reported as 0 (a genuine corner with θ ≥
/// [`crate::corner::MIN_TURN`] stays far above it except within ~1e-10 of
/// its ends).
pub const ROUNDING_SINE: f64 = 1e-10;

/// The degree.
const P: usize = 3;

/// A clamped rational cubic B-spline on u ∈ [0, 1].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CubicSpline {
    control: [[f64; 3]; MAX_CONTROL],
    weights: [f64; MAX_CONTROL],
    knots: [f64; MAX_CONTROL + P + 1],
    count: usize,
}

impl CubicSpline {
    /// A spline from its control points, weights and knot vector.
    ///
    /// # Arguments
    /// * `control` — 4 to [`MAX_CONTROL`] points, finite.
    /// * `weights` — one per point, finite and > 0.
    /// * `knots` — `control.len()` + 4 values, non-decreasing, clamped:
    ///   the first four 0, the last four 1, no inner knot of multiplicity
    ///   above 3.
    ///
    /// # Errors
    /// [`ToolpathError::InvalidParameter`] naming the first rule broken.
    pub fn new(
        control: &[[f64; 3]],
        weights: &[f64],
        knots: &[f64],
    ) -> Result<Self, ToolpathError> {
        let bad = |name: &str, value: f64, reason: &str| ToolpathError::InvalidParameter {
            name: name.to_string(),
            value,
            reason: reason.to_string(),
        };
        let n = control.len();
        if !(P + 1..=MAX_CONTROL).contains(&n) {
            return Err(bad(
                "control points",
                n as f64,
                "a cubic spline needs 4 to 9",
            ));
        }
        if weights.len() != n || knots.len() != n + P + 1 {
            return Err(bad(
                "weights and knots",
                (weights.len() + knots.len()) as f64,
                "one weight per control point and control points + 4 knots",
            ));
        }
        if let Some(w) = weights.iter().find(|w| !(w.is_finite() && **w > 0.0)) {
            return Err(bad("weight", *w, "must be finite and > 0"));
        }
        if let Some(c) = control.iter().flatten().find(|c| !c.is_finite()) {
            return Err(bad("control point coordinate", *c, "must be finite"));
        }
        let clamped = knots[..=P].iter().all(|k| *k == 0.0) && knots[n..].iter().all(|k| *k == 1.0);
        let increasing = knots.windows(2).all(|w| w[0] <= w[1]);
        let inner = &knots[P + 1..n];
        let inner_ok =
            inner.iter().all(|k| *k > 0.0 && *k < 1.0) && inner.windows(P + 1).all(|w| w[0] < w[P]);
        if !(clamped && increasing && inner_ok) {
            return Err(bad(
                "knot vector",
                knots.len() as f64,
                "must be non-decreasing from four 0s to four 1s, inner multiplicity ≤ 3",
            ));
        }
        let mut s = CubicSpline {
            control: [[0.0; 3]; MAX_CONTROL],
            weights: [0.0; MAX_CONTROL],
            knots: [0.0; MAX_CONTROL + P + 1],
            count: n,
        };
        s.control[..n].copy_from_slice(control);
        s.weights[..n].copy_from_slice(weights);
        s.knots[..n + P + 1].copy_from_slice(knots);
        Ok(s)
    }

    /// The control points.
    pub fn control(&self) -> &[[f64; 3]] {
        &self.control[..self.count]
    }

    /// The weights.
    pub fn weights(&self) -> &[f64] {
        &self.weights[..self.count]
    }

    /// The knot vector.
    pub fn knots(&self) -> &[f64] {
        &self.knots[..self.count + P + 1]
    }

    /// The index k of the knot span [u_k, u_k+1) holding u (the last
    /// non-empty span for u = 1).
    fn span(&self, u: f64) -> usize {
        let n = self.count;
        let u = u.clamp(0.0, 1.0);
        if u >= self.knots[n] {
            return n - 1;
        }
        // The largest k in [P, n − 1] with u_k ≤ u.
        let mut k = P;
        while k + 1 < n && self.knots[k + 1] <= u {
            k += 1;
        }
        k
    }

    /// The basis functions Nᵢ,₃ (i = k − 3 ..= k) at u with their first and
    /// second derivatives, k being the span.
    pub fn basis(&self, u: f64) -> (usize, [[f64; P + 1]; 3]) {
        let k = self.span(u);
        let t = &self.knots;
        // table[q][j] = N_{k−q+j, q}(u), j = 0..=q.
        let mut table = [[0.0; P + 1]; P + 1];
        table[0][0] = 1.0;
        let ratio = |num: f64, den: f64| if den > 0.0 { num / den } else { 0.0 };
        for q in 1..=P {
            for j in 0..=q {
                let i = k + j - q;
                let left = if j >= 1 { table[q - 1][j - 1] } else { 0.0 };
                let right = if j < q { table[q - 1][j] } else { 0.0 };
                table[q][j] = ratio(u - t[i], t[i + q] - t[i]) * left
                    + ratio(t[i + q + 1] - u, t[i + q + 1] - t[i + 1]) * right;
            }
        }
        // N′_{i,q} = q/(u_{i+q} − u_i) N_{i,q−1} − q/(u_{i+q+1} − u_{i+1}) N_{i+1,q−1}
        // (seed 003 eq. 3), for q = 2 (needed by the second derivative) and 3.
        let d_lower = |q: usize, lower: &[f64; P + 1], j: usize| {
            let i = k + j - q;
            let left = if j >= 1 { lower[j - 1] } else { 0.0 };
            let right = if j < q { lower[j] } else { 0.0 };
            let qf = q as f64;
            ratio(qf, t[i + q] - t[i]) * left - ratio(qf, t[i + q + 1] - t[i + 1]) * right
        };
        let mut d1_q2 = [0.0; P + 1];
        for (j, d) in d1_q2.iter_mut().enumerate().take(3) {
            *d = d_lower(2, &table[1], j);
        }
        let first: [f64; P + 1] = std::array::from_fn(|j| d_lower(P, &table[P - 1], j));
        // N″_{i,3} from N′_{·,2} (seed 003 eq. 4).
        let second: [f64; P + 1] = std::array::from_fn(|j| d_lower(P, &d1_q2, j));
        (k - P, [table[P], first, second])
    }

    /// C, C′ and C″ at u.
    fn derivatives(&self, u: f64) -> [[f64; 3]; 3] {
        let (first, b) = self.basis(u);
        // Relative to the span's first control point: smaller coordinates,
        // less rounding in the derivatives.
        let origin = self.control[first];
        let mut a = [[0.0; 3]; 3];
        let mut w = [0.0; 3];
        for (j, (p, wi)) in self.control[first..=first + P]
            .iter()
            .zip(&self.weights[first..=first + P])
            .enumerate()
        {
            let p = sub(*p, origin);
            for ((ad, wd), bd) in a.iter_mut().zip(w.iter_mut()).zip(&b) {
                *wd += bd[j] * wi;
                for (ax, px) in ad.iter_mut().zip(p) {
                    *ax += bd[j] * wi * px;
                }
            }
        }
        let c = scale(a[0], 1.0 / w[0]);
        let c1: [f64; 3] = std::array::from_fn(|x| (a[1][x] - w[1] * c[x]) / w[0]);
        let c2: [f64; 3] =
            std::array::from_fn(|x| (a[2][x] - 2.0 * w[1] * c1[x] - w[2] * c[x]) / w[0]);
        [add(c, origin), c1, c2]
    }

    /// The point at u ∈ [0, 1].
    pub fn point(&self, u: f64) -> [f64; 3] {
        self.derivatives(u)[0]
    }

    /// The first derivative in u.
    pub fn d1(&self, u: f64) -> [f64; 3] {
        self.derivatives(u)[1]
    }

    /// The second derivative in u.
    pub fn d2(&self, u: f64) -> [f64; 3] {
        self.derivatives(u)[2]
    }

    /// The curvature at u; 0 where C′ = 0, and 0 where |C′ × C″| is below
    /// [`ROUNDING_SINE`] |C′| |C″| (at a G2 end, where three control points
    /// lie on the line, rounding leaves ~1e-14 1/m instead of 0).
    pub fn curvature(&self, u: f64) -> f64 {
        let [_, d1, d2] = self.derivatives(u);
        let speed = norm(d1);
        let area = norm(cross(d1, d2));
        if speed == 0.0 || area <= ROUNDING_SINE * speed * norm(d2) {
            return 0.0;
        }
        area / (speed * speed * speed)
    }

    /// The arc length between `u0` and `u1` \[m\]: 8-point Gauss–Legendre
    /// quadrature on each knot span inside the interval (the speed is
    /// smooth within a span).
    pub fn length_between(&self, u0: f64, u1: f64) -> f64 {
        let mut total = 0.0;
        let mut a = u0;
        for &k in self.knots() {
            if k > a && k < u1 {
                total += gauss_legendre_8(a, k, |u| norm(self.d1(u)));
                a = k;
            }
        }
        total + gauss_legendre_8(a, u1, |u| norm(self.d1(u)))
    }

    /// The first control point (the curve's start).
    pub fn start(&self) -> [f64; 3] {
        self.control[0]
    }

    /// The last control point (the curve's end).
    pub fn end(&self) -> [f64; 3] {
        self.control[self.count - 1]
    }
}
