//! The jerk a corner transition asks of the machine at constant speed, and
//! the corner shape that minimizes it.
//!
//! # The jerk norm
//! Along a curve run at constant speed v, the Cartesian jerk is v³ r‴(s),
//! and by the Frenet–Serret formulas (do Carmo, "Differential Geometry of
//! Curves and Surfaces", 1976, section 1-5: t′ = κ n, n′ = −κ t + τ b) a
//! plane curve has r‴(s) = κ′ n − κ² t, so
//!
//! |j| = v³ g, g = √(κ′² + κ⁴), κ′ = dκ/ds.
//!
//! Seed 003's normal jerk (its eq. 20–21) bounds v³ κ² only; the machine's
//! axes feel the whole of it, and κ′ dominates in a small corner (the
//! gantry's axis jerk in `kerf_gcodeplan` binds there). Both κ′ and κ²
//! scale as 1/s² with the corner's scale s, so g · δ² (tolerance binding)
//! and g · L² (length binding) depend on the shape and the turning angle
//! only, as κ_max · δ and κ_max · L do for the curvature-optimal shape
//! ([`crate::corner`]).
//!
//! # κ′ of a Bézier curve
//! In the corner's plane, with unit normal m, the signed curvature is
//! k = (b′ × b″)·m / |b′|³ (Farin, "Curves and Surfaces for CAGD", 5th ed.,
//! eq. 10.5, signed), so by the quotient rule (b″ × b″ = 0)
//!
//! dk/du = (b′ × b‴)·m / |b′|³ − 3 k (b′·b″) / |b′|², κ′ = (dk/du) / |b′|,
//!
//! with the third derivative 60 Σ Δ³bᵢ Bᵢ² (Farin eq. 5.3 applied three
//! times).

use crate::bezier::QuinticBezier;
use crate::corner::{unit_curve, Binding, CornerShape};
use crate::maximum::sampled_maximum;
use crate::vec3::{cross, dot, norm, scale, sub};

/// Samples of the half curve for its largest jerk norm (then refined).
pub const JERK_SAMPLES: usize = 64;

/// The third derivative in u of a quintic Bézier curve (60 Σ Δ³bᵢ Bᵢ²,
/// Farin eq. 5.3 three times), by de Casteljau on the three coefficients.
pub fn third_derivative(curve: &QuinticBezier, u: f64) -> [f64; 3] {
    let c = &curve.control;
    let d: [[f64; 3]; 3] = std::array::from_fn(|i| {
        // Δ³bᵢ = b_{i+3} − 3 b_{i+2} + 3 b_{i+1} − b_i.
        std::array::from_fn(|k| {
            60.0 * (c[i + 3][k] - 3.0 * c[i + 2][k] + 3.0 * c[i + 1][k] - c[i][k])
        })
    });
    let v = 1.0 - u;
    std::array::from_fn(|k| v * v * d[0][k] + 2.0 * u * v * d[1][k] + u * u * d[2][k])
}

/// The unit normal of a corner curve's plane: (P₂ − P₀) × (P₅ − P₃), along
/// t₁ × t₂ ([`crate::corner`]'s control points); `None` for a straight
/// curve.
fn plane_normal(curve: &QuinticBezier) -> Option<[f64; 3]> {
    let c = &curve.control;
    let m = cross(sub(c[2], c[0]), sub(c[5], c[3]));
    let l = norm(m);
    (l > 0.0).then(|| scale(m, 1.0 / l))
}

/// The curvature κ \[1/m\] and its arc-length rate κ′ = dκ/ds \[1/m²\] of a
/// plane quintic (module documentation) at u, κ signed about `normal`.
pub fn curvature_and_rate(curve: &QuinticBezier, normal: [f64; 3], u: f64) -> (f64, f64) {
    let d1 = curve.d1(u);
    let d2 = curve.d2(u);
    let d3 = third_derivative(curve, u);
    let speed2 = dot(d1, d1);
    let speed = speed2.sqrt();
    if speed == 0.0 {
        return (0.0, 0.0);
    }
    let speed3 = speed2 * speed;
    let k = dot(cross(d1, d2), normal) / speed3;
    let dk_du = dot(cross(d1, d3), normal) / speed3 - 3.0 * k * dot(d1, d2) / speed2;
    (k, dk_du / speed)
}

/// g = √(κ′² + κ⁴) at u \[1/m²\]: the jerk per v³ at constant speed
/// (module documentation).
pub fn jerk_norm(curve: &QuinticBezier, normal: [f64; 3], u: f64) -> f64 {
    let (k, rate) = curvature_and_rate(curve, normal, u);
    (rate * rate + k.powi(4)).sqrt()
}

/// A quintic in the power basis, b(u) = Σ aₖ uᵏ with
/// aₖ = C(5, k) Σᵢ (−1)^(k−i) C(k, i) Pᵢ (Farin section 5.7, the monomial
/// form): its first three derivatives by Horner's rule, about three times
/// cheaper than three de Casteljau runs.
pub(crate) struct PowerQuintic {
    a: [[f64; 3]; 6],
}

impl PowerQuintic {
    pub(crate) fn new(curve: &QuinticBezier) -> Self {
        const C: [[f64; 6]; 6] = [
            [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            [1.0, 1.0, 0.0, 0.0, 0.0, 0.0],
            [1.0, 2.0, 1.0, 0.0, 0.0, 0.0],
            [1.0, 3.0, 3.0, 1.0, 0.0, 0.0],
            [1.0, 4.0, 6.0, 4.0, 1.0, 0.0],
            [1.0, 5.0, 10.0, 10.0, 5.0, 1.0],
        ];
        let p = &curve.control;
        let a = std::array::from_fn(|k| {
            std::array::from_fn(|d| {
                let sum: f64 = (0..=k)
                    .map(|i| {
                        let sign = if (k - i) % 2 == 0 { 1.0 } else { -1.0 };
                        sign * C[k][i] * p[i][d]
                    })
                    .sum();
                C[5][k] * sum
            })
        });
        Self { a }
    }

    /// (b′, b″, b‴) at u.
    fn derivatives(&self, u: f64) -> ([f64; 3], [f64; 3], [f64; 3]) {
        let a = &self.a;
        let d1 = std::array::from_fn(|d| {
            a[1][d]
                + u * (2.0 * a[2][d]
                    + u * (3.0 * a[3][d] + u * (4.0 * a[4][d] + u * 5.0 * a[5][d])))
        });
        let d2 = std::array::from_fn(|d| {
            2.0 * a[2][d] + u * (6.0 * a[3][d] + u * (12.0 * a[4][d] + u * 20.0 * a[5][d]))
        });
        let d3 = std::array::from_fn(|d| 6.0 * a[3][d] + u * (24.0 * a[4][d] + u * 60.0 * a[5][d]));
        (d1, d2, d3)
    }

    /// The curvature at u (Farin eq. 10.5); 0 where b′ = 0.
    pub(crate) fn curvature(&self, u: f64) -> f64 {
        let (d1, d2, _) = self.derivatives(u);
        let speed = norm(d1);
        if speed == 0.0 {
            return 0.0;
        }
        norm(cross(d1, d2)) / (speed * speed * speed)
    }

    /// g at u about `normal` (as [`jerk_norm`]).
    fn jerk_norm(&self, normal: [f64; 3], u: f64) -> f64 {
        let (d1, d2, d3) = self.derivatives(u);
        let speed2 = dot(d1, d1);
        if speed2 == 0.0 {
            return 0.0;
        }
        let speed = speed2.sqrt();
        let speed3 = speed2 * speed;
        let k = dot(cross(d1, d2), normal) / speed3;
        let rate = (dot(cross(d1, d3), normal) / speed3 - 3.0 * k * dot(d1, d2) / speed2) / speed;
        (rate * rate + k.powi(4)).sqrt()
    }
}

/// The largest jerk norm g of a symmetric corner curve \[1/m²\]: the first
/// half at [`JERK_SAMPLES`] + 1 parameters, the best refined by golden
/// section on its neighbouring interval; 0 for a straight curve.
///
/// # Performance
/// About 115 evaluations of the first three derivatives in the power basis.
pub fn max_jerk_norm(curve: &QuinticBezier) -> f64 {
    let Some(m) = plane_normal(curve) else {
        return 0.0;
    };
    let power = PowerQuintic::new(curve);
    sampled_maximum(|u| power.jerk_norm(m, u), 0.0, 0.5, JERK_SAMPLES)
}

/// The largest jerk norm per unit of the binding constraint of a shape at a
/// turning angle: g_max · δ² (tolerance) or g_max · L² (length).
pub fn normalized_jerk(turn: f64, shape: CornerShape, binding: Binding) -> f64 {
    max_jerk_norm(&unit_curve(turn, shape, binding))
}

/// The largest jerk norm g of any corner curve, sampled \[1/m²\]: κ at
/// `samples` + 1 equal parameter steps, κ′ by the central difference of |κ|
/// over the arc length between the neighbouring samples (the chord), for
/// comparing kerf's corner with a baseline's (whose κ′ jumps at its knots).
/// An estimate: it converges as the step falls, it is not a bound.
pub fn sampled_max_jerk_norm(curve: &crate::corner_curve::CornerCurve, samples: usize) -> f64 {
    let n = samples.max(2);
    let points: Vec<([f64; 3], f64)> = (0..=n)
        .map(|k| {
            let u = k as f64 / n as f64;
            (curve.point(u), curve.curvature(u))
        })
        .collect();
    points
        .windows(3)
        .map(|w| {
            let ds = norm(sub(w[2].0, w[0].0));
            let rate = if ds > 0.0 {
                (w[2].1 - w[0].1) / ds
            } else {
                0.0
            };
            (rate * rate + w[1].1.powi(4)).sqrt()
        })
        .fold(0.0, f64::max)
}
