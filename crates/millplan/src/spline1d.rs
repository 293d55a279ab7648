//! Smooth scalar functions of the arc length through given values: the
//! interpolating cubic spline and the piecewise quintic "smootherstep"
//! profile (issue 13, item 1: Ω, f and g vary smoothly along the path).
//!
//! # Cubic spline
//! [`CubicSpline`] interpolates (x_i, y_i) with a C² piecewise cubic whose
//! second derivatives M_i solve the tridiagonal system of de Boor, *A
//! Practical Guide to Splines* (2001), ch. IV, eq. (IV.10):
//! h_{i−1} M_{i−1} + 2 (h_{i−1} + h_i) M_i + h_i M_{i+1}
//! = 6 (δ_i − δ_{i−1}), δ_i = (y_{i+1} − y_i)/h_i, with either natural ends
//! (M_0 = M_n = 0) or clamped end slopes. Among all C² interpolants of the
//! data it minimizes ∫ y''² (Holladay's theorem, de Boor ch. V): the least
//! bending of g(s), i.e. the least wrist acceleration the redundancy angle
//! asks for.
//!
//! # Smootherstep profile
//! [`StepProfile`] joins consecutive values with the quintic
//! S(u) = 6u⁵ − 15u⁴ + 10u³ (u ∈ [0, 1] across the interval; S' = S'' = 0
//! at both ends): C², exact at the knots, monotone between them, never
//! outside the range of its two knots (no overshoot). Used for the feed and
//! the spindle speed, whose values must not leave the plan's range between
//! two segments.

use crate::error::MillPlanError;

/// Value and first three derivatives of a profile at one abscissa.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Derivatives {
    /// y(x).
    pub value: f64,
    /// y'(x).
    pub d1: f64,
    /// y''(x).
    pub d2: f64,
}

fn bad(name: &str, reason: String) -> MillPlanError {
    MillPlanError::InvalidConfig {
        name: name.to_string(),
        reason,
    }
}

/// Checks knots: ≥ 2, finite, strictly increasing; values finite, as many.
fn check_knots(name: &str, x: &[f64], y: &[f64]) -> Result<(), MillPlanError> {
    if x.len() < 2 || x.len() != y.len() {
        return Err(bad(
            name,
            format!(
                "{} abscissae and {} values (>= 2, as many)",
                x.len(),
                y.len()
            ),
        ));
    }
    if let Some(i) = x.iter().chain(y).position(|v| !v.is_finite()) {
        return Err(bad(name, format!("non-finite knot entry {i}")));
    }
    if let Some(i) = x.windows(2).position(|w| w[1] <= w[0]) {
        return Err(bad(
            name,
            format!(
                "abscissae not strictly increasing at {i} ({} then {})",
                x[i],
                x[i + 1]
            ),
        ));
    }
    Ok(())
}

/// The interval i with x_i ≤ t ≤ x_{i+1} (clamped to the first/last).
fn interval(x: &[f64], t: f64) -> usize {
    let n = x.len() - 1;
    match x.binary_search_by(|v| v.total_cmp(&t)) {
        Ok(i) => i.min(n - 1),
        Err(i) => i.saturating_sub(1).min(n - 1),
    }
}

/// An interpolating C² cubic spline (module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct CubicSpline {
    x: Vec<f64>,
    y: Vec<f64>,
    m: Vec<f64>,
}

impl CubicSpline {
    /// The spline through (x_i, y_i).
    ///
    /// # Arguments
    /// * `x` — strictly increasing, finite abscissae (≥ 2).
    /// * `y` — finite values, one per abscissa.
    /// * `end_slopes` — `Some((y'(x_0), y'(x_n)))` clamps both end slopes;
    ///   `None` gives natural ends (y'' = 0).
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] for bad knots or a non-finite slope.
    ///
    /// # Performance
    /// O(n): one tridiagonal solve (Thomas algorithm; the matrix is strictly
    /// diagonally dominant, so no pivoting is needed).
    pub fn new(
        name: &str,
        x: &[f64],
        y: &[f64],
        end_slopes: Option<(f64, f64)>,
    ) -> Result<Self, MillPlanError> {
        check_knots(name, x, y)?;
        let n = x.len() - 1;
        let h: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
        let delta: Vec<f64> = (0..n).map(|i| (y[i + 1] - y[i]) / h[i]).collect();
        // Rows: sub a, diagonal b, super c, right-hand side d (de Boor IV.10).
        let mut a = vec![0.0; n + 1];
        let mut b = vec![1.0; n + 1];
        let mut c = vec![0.0; n + 1];
        let mut d = vec![0.0; n + 1];
        for i in 1..n {
            a[i] = h[i - 1];
            b[i] = 2.0 * (h[i - 1] + h[i]);
            c[i] = h[i];
            d[i] = 6.0 * (delta[i] - delta[i - 1]);
        }
        if let Some((s0, sn)) = end_slopes {
            if !(s0.is_finite() && sn.is_finite()) {
                return Err(bad(name, format!("end slopes {s0}, {sn} not finite")));
            }
            b[0] = 2.0 * h[0];
            c[0] = h[0];
            d[0] = 6.0 * (delta[0] - s0);
            a[n] = h[n - 1];
            b[n] = 2.0 * h[n - 1];
            d[n] = 6.0 * (sn - delta[n - 1]);
        }
        // Thomas algorithm.
        for i in 1..=n {
            let w = a[i] / b[i - 1];
            b[i] -= w * c[i - 1];
            d[i] -= w * d[i - 1];
        }
        let mut m = vec![0.0; n + 1];
        m[n] = d[n] / b[n];
        for i in (0..n).rev() {
            m[i] = (d[i] - c[i] * m[i + 1]) / b[i];
        }
        if m.iter().any(|v| !v.is_finite()) {
            return Err(bad(name, "non-finite spline curvature".to_string()));
        }
        Ok(Self {
            x: x.to_vec(),
            y: y.to_vec(),
            m,
        })
    }

    /// y, y', y'' at `t` (the end cubic continued outside [x_0, x_n]).
    pub fn eval(&self, t: f64) -> Derivatives {
        let i = interval(&self.x, t);
        let h = self.x[i + 1] - self.x[i];
        let (m0, m1) = (self.m[i], self.m[i + 1]);
        let u = t - self.x[i];
        let b = (self.y[i + 1] - self.y[i]) / h - h * (2.0 * m0 + m1) / 6.0;
        let k3 = (m1 - m0) / (6.0 * h);
        Derivatives {
            value: self.y[i] + u * (b + u * (0.5 * m0 + u * k3)),
            d1: b + u * (m0 + 3.0 * u * k3),
            d2: m0 + 6.0 * u * k3,
        }
    }

    /// The smallest and largest value of the spline on [x_0, x_n]: each
    /// cubic piece's ends and the real roots of its derivative.
    pub fn range(&self) -> (f64, f64) {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for i in 0..self.x.len() - 1 {
            let h = self.x[i + 1] - self.x[i];
            let (m0, m1) = (self.m[i], self.m[i + 1]);
            let b = (self.y[i + 1] - self.y[i]) / h - h * (2.0 * m0 + m1) / 6.0;
            let k3 = (m1 - m0) / (6.0 * h);
            let mut candidates = vec![0.0, h];
            // y' = b + m0 u + 3 k3 u².
            let (qa, qb, qc) = (3.0 * k3, m0, b);
            if qa.abs() > 1e-300 {
                let disc = qb * qb - 4.0 * qa * qc;
                if disc >= 0.0 {
                    let r = disc.sqrt();
                    candidates.push((-qb + r) / (2.0 * qa));
                    candidates.push((-qb - r) / (2.0 * qa));
                }
            } else if qb.abs() > 1e-300 {
                candidates.push(-qc / qb);
            }
            for u in candidates {
                if (0.0..=h).contains(&u) {
                    let v = self.eval(self.x[i] + u).value;
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
            }
        }
        (lo, hi)
    }
}

/// S(u) = 6u⁵ − 15u⁴ + 10u³ and its first two derivatives, u clamped to
/// [0, 1] (smootherstep; Perlin, "Improving noise", SIGGRAPH 2002, eq. 2).
pub fn smootherstep(u: f64) -> (f64, f64, f64) {
    if u <= 0.0 {
        return (0.0, 0.0, 0.0);
    }
    if u >= 1.0 {
        return (1.0, 0.0, 0.0);
    }
    let u2 = u * u;
    (
        u2 * u * (10.0 + u * (-15.0 + 6.0 * u)),
        30.0 * u2 * (1.0 - u) * (1.0 - u),
        60.0 * u * (1.0 - u) * (1.0 - 2.0 * u),
    )
}

/// Consecutive values joined by [`smootherstep`] (module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct StepProfile {
    x: Vec<f64>,
    y: Vec<f64>,
}

impl StepProfile {
    /// The profile through (x_i, y_i).
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] for bad knots.
    pub fn new(name: &str, x: &[f64], y: &[f64]) -> Result<Self, MillPlanError> {
        check_knots(name, x, y)?;
        Ok(Self {
            x: x.to_vec(),
            y: y.to_vec(),
        })
    }

    /// y, y', y'' at `t` (constant outside [x_0, x_n]).
    pub fn eval(&self, t: f64) -> Derivatives {
        self.eval_in(interval(&self.x, t), t)
    }

    /// [`StepProfile::eval`] for abscissae that move little from call to
    /// call (an integration along the path): the interval of the previous
    /// call (`hint`) is tried first, and `hint` is set to this call's. The
    /// same interval as [`StepProfile::eval`]'s binary search (both order by
    /// `f64::total_cmp`), so the same value, bit for bit.
    pub fn eval_near(&self, t: f64, hint: &mut usize) -> Derivatives {
        let n = self.x.len() - 1;
        let i = *hint;
        let inside = i < n
            && self.x[i].total_cmp(&t) != std::cmp::Ordering::Greater
            && t.total_cmp(&self.x[i + 1]) == std::cmp::Ordering::Less;
        let i = if inside { i } else { interval(&self.x, t) };
        *hint = i;
        self.eval_in(i, t)
    }

    /// The profile on interval `i` at `t`.
    fn eval_in(&self, i: usize, t: f64) -> Derivatives {
        let h = self.x[i + 1] - self.x[i];
        let dy = self.y[i + 1] - self.y[i];
        let (s, s1, s2) = smootherstep((t - self.x[i]) / h);
        Derivatives {
            value: self.y[i] + dy * s,
            d1: dy * s1 / h,
            d2: dy * s2 / (h * h),
        }
    }

    /// The larger of the two knot values around `t` (the profile's bound
    /// there).
    pub fn local_max(&self, t: f64) -> f64 {
        let i = interval(&self.x, t);
        self.y[i].max(self.y[i + 1])
    }
}

/// A profile of either kind (the redundancy angle's: the cubic spline where it stays in range,
/// else the smootherstep profile, which cannot leave the range of its values).
#[derive(Debug, Clone, PartialEq)]
pub enum Profile {
    /// [`CubicSpline`].
    Cubic(CubicSpline),
    /// [`StepProfile`].
    Step(StepProfile),
}

impl Profile {
    /// y, y', y'' at `t`.
    pub fn eval(&self, t: f64) -> Derivatives {
        match self {
            Profile::Cubic(c) => c.eval(t),
            Profile::Step(p) => p.eval(t),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cubic_reproduces_a_cubic_with_clamped_slopes() {
        let f = |x: f64| 1.0 + 2.0 * x - 0.5 * x * x + 0.25 * x * x * x;
        let df = |x: f64| 2.0 - x + 0.75 * x * x;
        let x = [0.0, 0.3, 1.1, 1.5, 2.0];
        let y: Vec<f64> = x.iter().map(|v| f(*v)).collect();
        let s = CubicSpline::new("t", &x, &y, Some((df(0.0), df(2.0)))).unwrap();
        for k in 0..=40 {
            let t = 2.0 * k as f64 / 40.0;
            let e = s.eval(t);
            assert!((e.value - f(t)).abs() < 1e-12, "{t}");
            assert!((e.d1 - df(t)).abs() < 1e-11, "{t}");
            assert!((e.d2 - (-1.0 + 1.5 * t)).abs() < 1e-10, "{t}");
        }
    }

    #[test]
    fn natural_spline_is_c2_and_interpolates() {
        let x = [0.0, 1.0, 2.5, 3.0, 4.0];
        let y = [0.0, 1.0, -1.0, 0.5, 0.0];
        let s = CubicSpline::new("t", &x, &y, None).unwrap();
        for (xi, yi) in x.iter().zip(&y) {
            assert!((s.eval(*xi).value - yi).abs() < 1e-14);
        }
        assert!(s.eval(0.0).d2.abs() < 1e-12 && s.eval(4.0).d2.abs() < 1e-12);
        for xi in &x[1..4] {
            let (l, r) = (s.eval(xi - 1e-9), s.eval(xi + 1e-9));
            assert!((l.d1 - r.d1).abs() < 1e-7 && (l.d2 - r.d2).abs() < 1e-6);
        }
        let (lo, hi) = s.range();
        assert!(
            lo < -1.0 && hi > 1.0,
            "a spline through a zigzag overshoots"
        );
    }

    #[test]
    fn step_profile_stays_between_its_knots() {
        let p = StepProfile::new("t", &[0.0, 1.0, 3.0], &[1.0, 2.0, 0.5]).unwrap();
        for k in 0..=300 {
            let t = 3.0 * k as f64 / 300.0;
            let e = p.eval(t);
            assert!(e.value >= 0.5 - 1e-15 && e.value <= 2.0 + 1e-15);
            assert!(e.value <= p.local_max(t) + 1e-15);
        }
        assert_eq!(p.eval(1.0).d1, 0.0);
        assert!(CubicSpline::new("t", &[0.0, 0.0], &[1.0, 2.0], None).is_err());
    }
}
