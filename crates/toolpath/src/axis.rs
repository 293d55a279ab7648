//! Per-axis limits of a Cartesian machine (issue 14, item 3): the speed,
//! acceleration and jerk of each of the three slides X, Y, Z (the laser
//! cutter's q1..q3: 2 m/s, 12 m/s², 120 m/s³).
//!
//! Along a path p(s) run at speed v = ṡ, acceleration a = s̈ and jerk
//! j = s⃛, axis i moves as x_i(s(t)); by the chain rule
//!
//! * velocity     ẋ_i = x_i′ v,
//! * acceleration ẍ_i = x_i″ v² + x_i′ a,
//! * jerk         x⃛_i = x_i‴ v³ + 3 x_i″ v a + x_i′ j,
//!
//! with ′ the derivatives in arc length: x′ is the unit tangent t, x″ = κ n
//! and x‴ = d(κ n)/ds (κ′ n − κ² t + κ τ b).
//!
//! **Sufficient tangential budget** ([`AxisLimits::tangential`],
//! [`AxisLimits::speed`]). The planner runs every tangential acceleration
//! and jerk within A = min(A_t, min_i A_i / 2) and J = min(J_t, min_i J_i / 2),
//! and keeps the speed at most the largest v with, on every axis,
//!
//! * |x_i′| v ≤ V_i,
//! * |x_i″| v² ≤ A_i − |x_i′| A,
//! * |x_i‴| v³ + 3 |x_i″| A v ≤ J_i − |x_i′| J.
//!
//! The right-hand sides are at least A_i / 2 and J_i / 2 (|x_i′| ≤ 1), and
//! with |a| ≤ A, |j| ≤ J the triangle inequality on the chain rule gives
//! |ẋ_i| ≤ V_i, |ẍ_i| ≤ A_i, |x⃛_i| ≤ J_i. The bounds |x_i′|, |x_i″|, |x_i‴|
//! over each interval between samples come from [`crate::limit_curve`](mod@crate::limit_curve).

use crate::error::{check_positive, ToolpathError};

/// Speed, acceleration and jerk limits of the X, Y and Z axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisLimits {
    /// Largest axis speed \[m/s\].
    pub velocity: [f64; 3],
    /// Largest axis acceleration \[m/s²\].
    pub acceleration: [f64; 3],
    /// Largest axis jerk \[m/s³\].
    pub jerk: [f64; 3],
}

impl AxisLimits {
    /// The laser cutter's X/Y/Z slides (q1..q3): 2 m/s, 12 m/s², 120 m/s³.
    pub fn laser_cutter() -> Self {
        Self {
            velocity: [2.0; 3],
            acceleration: [12.0; 3],
            jerk: [120.0; 3],
        }
    }

    /// Checks that every limit is finite and > 0.
    ///
    /// # Errors
    /// [`ToolpathError::InvalidParameter`] naming the limit.
    pub fn validate(&self) -> Result<(), ToolpathError> {
        const AXES: [&str; 3] = ["X", "Y", "Z"];
        let mut names = Vec::with_capacity(9);
        for (i, axis) in AXES.iter().enumerate() {
            names.push((format!("axis {axis} velocity [m/s]"), self.velocity[i]));
            names.push((
                format!("axis {axis} acceleration [m/s^2]"),
                self.acceleration[i],
            ));
            names.push((format!("axis {axis} jerk [m/s^3]"), self.jerk[i]));
        }
        let checks: Vec<(&str, f64)> = names.iter().map(|(n, v)| (n.as_str(), *v)).collect();
        check_positive(&checks)
    }

    /// The tangential acceleration and jerk the planner may use under these
    /// axes and the tangential limits `a_t`, `j_t`: (min(A_t, min_i A_i/2),
    /// min(J_t, min_i J_i/2)) (module documentation).
    pub fn tangential(&self, a_t: f64, j_t: f64) -> (f64, f64) {
        let half_min = |v: &[f64; 3]| 0.5 * v.iter().copied().fold(f64::INFINITY, f64::min);
        (
            a_t.min(half_min(&self.acceleration)),
            j_t.min(half_min(&self.jerk)),
        )
    }

    /// The largest speed on a stretch of path where, for every axis i,
    /// |x_i′| ≤ `d1[i]`, |x_i″| ≤ `d2[i]` and |x_i‴| ≤ `d3[i]`, with the
    /// tangential budget (`a`, `j`) of [`AxisLimits::tangential`] (module
    /// documentation). Infinite where nothing limits it.
    pub fn speed(&self, d1: [f64; 3], d2: [f64; 3], d3: [f64; 3], a: f64, j: f64) -> f64 {
        let mut v = f64::INFINITY;
        for i in 0..3 {
            if d1[i] > 0.0 {
                v = v.min(self.velocity[i] / d1[i]);
            }
            let acc = self.acceleration[i] - d1[i] * a;
            if d2[i] > 0.0 {
                v = v.min((acc.max(0.0) / d2[i]).sqrt());
            }
            let jerk = (self.jerk[i] - d1[i] * j).max(0.0);
            v = v.min(cubic_root_bound(d3[i], 3.0 * d2[i] * a, jerk));
        }
        v
    }
}

/// The largest v ≥ 0 with g v³ + p v ≤ q (g, p, q ≥ 0). The cubic is
/// convex and increasing on v ≥ 0, so Newton's method from the upper bound
/// min(q/p, ∛(q/g)) (each term alone within q) decreases monotonically to
/// the root; the last iterate is stepped down until the inequality holds.
fn cubic_root_bound(g: f64, p: f64, q: f64) -> f64 {
    if g <= 0.0 {
        return if p > 0.0 { q / p } else { f64::INFINITY };
    }
    let mut v = (q / g).cbrt();
    if p > 0.0 {
        v = v.min(q / p);
    }
    for _ in 0..60 {
        let f = g * v * v * v + p * v - q;
        let df = 3.0 * g * v * v + p;
        if f <= 0.0 || df <= 0.0 {
            break;
        }
        let next = v - f / df;
        if next >= v {
            break;
        }
        v = next;
    }
    while v > 0.0 && g * v * v * v + p * v > q {
        v *= 1.0 - 1e-12;
    }
    v.max(0.0)
}

#[cfg(test)]
mod tests {
    use super::cubic_root_bound;

    #[test]
    fn the_cubic_bound_is_the_root() {
        for (g, p, q) in [
            (1.0, 0.0, 8.0),
            (2.0, 3.0, 7.0),
            (1e-6, 1.0, 0.5),
            (5.0, 1e3, 1e-3),
        ] {
            let v = cubic_root_bound(g, p, q);
            assert!(g * v * v * v + p * v <= q, "{g} {p} {q}: {v}");
            let w = v * (1.0 + 1e-8);
            assert!(
                g * w * w * w + p * w > q,
                "{g} {p} {q}: {v} not the largest"
            );
        }
        assert_eq!(cubic_root_bound(0.0, 0.0, 1.0), f64::INFINITY);
        assert!((cubic_root_bound(0.0, 2.0, 1.0) - 0.5).abs() < 1e-15);
    }
}
