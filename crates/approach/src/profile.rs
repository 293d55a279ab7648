//! The minimum-jerk rest-to-rest profile and its analytic peaks.
//!
//! Source: T. Flash, N. Hogan, "The coordination of arm movements: an experimentally confirmed
//! mathematical model", Journal of Neuroscience 5(7), 1985, pp. 1688–1703, eq. 2: the motion
//! between two rests that minimises the integral of the squared jerk over a fixed duration `T`
//! is, per coordinate, `x(t) = x_a + (x_b − x_a) s(t/T)` with the quintic
//!
//! ```text
//! s(τ)    = 10τ³ − 15τ⁴ + 6τ⁵          s(0) = 0, s(1) = 1
//! s'(τ)   = 30τ²(1 − τ)²               s'(0) = s'(1) = 0     (rest at both ends)
//! s''(τ)  = 60τ(1 − τ)(1 − 2τ)         s''(0) = s''(1) = 0   (no acceleration step)
//! s'''(τ) = 60 − 360τ + 360τ²
//! ```
//!
//! # Peaks on τ ∈ [0, 1]
//! * `|s'|`: `s'' = 0` inside (0, 1) only at τ = ½, so the peak is `s'(½) = 30/16 = 15/8`.
//! * `|s''|`: `s''' = 0` at `τ = ½ ± √3/6`. There `τ(1 − τ) = ¼ − (√3/6)² = 1/6` and
//!   `|1 − 2τ| = √3/3`, so the peak is `60 · 1/6 · √3/3 = 10/√3 ≈ 5.7735`.
//! * `|s'''|`: a parabola with its vertex at τ = ½ (`s''' = −30`) and `s''' = 60` at both
//!   ends, so the peak is 60, at τ = 0 and τ = 1.
//!
//! `s` is monotone (`s' ≥ 0`) and stays in [0, 1]: a joint moved with it never overshoots its
//! end positions, so a move between two configurations inside the position limits stays
//! inside them.
//!
//! # Scaling to a joint
//! With `Δ = q_b − q_a` and `τ = t/T`: `q̇ = Δ s'/T`, `q̈ = Δ s''/T²`, `q⃛ = Δ s'''/T³`. The
//! joint meets its limits `v`, `a`, `j` exactly when
//!
//! ```text
//! T ≥ 15/8 · |Δ| / v,     T ≥ sqrt(10/√3 · |Δ| / a),     T ≥ cbrt(60 · |Δ| / j)
//! ```
//!
//! and all joints share one `T` (synchronised: every joint starts and stops together, the
//! joint-space path is the straight segment from `q_a` to `q_b`), the largest of these
//! bounds over the joints ([`min_duration`]).

/// Peak of `|s'(τ)|` on [0, 1]: 15/8, at τ = ½.
pub const PEAK_VELOCITY: f64 = 15.0 / 8.0;

/// Peak of `|s''(τ)|` on [0, 1]: 10/√3, at τ = ½ ∓ √3/6.
pub const PEAK_ACCELERATION: f64 = 5.773_502_691_896_258;

/// Peak of `|s'''(τ)|` on [0, 1]: 60, at τ = 0 and τ = 1.
pub const PEAK_JERK: f64 = 60.0;

/// `s(τ) = 10τ³ − 15τ⁴ + 6τ⁵` (Horner form).
pub fn position(tau: f64) -> f64 {
    tau * tau * tau * (10.0 + tau * (-15.0 + 6.0 * tau))
}

/// `s'(τ) = 30τ²(1 − τ)²`.
pub fn velocity(tau: f64) -> f64 {
    let u = tau * (1.0 - tau);
    30.0 * u * u
}

/// `s''(τ) = 60τ(1 − τ)(1 − 2τ)`.
pub fn acceleration(tau: f64) -> f64 {
    60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau)
}

/// `s'''(τ) = 60 − 360τ + 360τ²`.
pub fn jerk(tau: f64) -> f64 {
    60.0 + tau * (-360.0 + 360.0 * tau)
}

/// The shortest duration `T` (s) of a minimum-jerk move of one joint by `|delta|` that keeps
/// its velocity, acceleration and jerk within `v`, `a`, `j`.
///
/// # Arguments
/// * `delta` – the joint's displacement (rad or m); its sign does not matter.
/// * `v`, `a`, `j` – the joint's limits (per s, s², s³), finite and > 0 (not checked here:
///   [`crate::JointLimit::check`] does).
///
/// # Returns
/// `max(15/8·|Δ|/v, sqrt(10/√3·|Δ|/a), cbrt(60·|Δ|/j))`; 0 for `Δ = 0`. At this `T` the
/// binding limit is met with equality at its peak.
///
/// # Performance
/// One square root and one cube root.
pub fn min_duration(delta: f64, v: f64, a: f64, j: f64) -> f64 {
    let d = delta.abs();
    let by_velocity = PEAK_VELOCITY * d / v;
    let by_acceleration = (PEAK_ACCELERATION * d / a).sqrt();
    let by_jerk = (PEAK_JERK * d / j).cbrt();
    by_velocity.max(by_acceleration).max(by_jerk)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boundary_values() {
        assert_eq!(position(0.0), 0.0);
        assert!((position(1.0) - 1.0).abs() < 1e-15);
        for f in [velocity, acceleration] {
            assert_eq!(f(0.0), 0.0);
            assert!(f(1.0).abs() < 1e-15);
        }
        assert_eq!(jerk(0.0), 60.0);
        assert!((jerk(1.0) - 60.0).abs() < 1e-12);
    }

    #[test]
    fn peaks_match_a_dense_scan() {
        assert!((PEAK_ACCELERATION - 10.0 / 3f64.sqrt()).abs() < 1e-15);
        let n = 200_000;
        let (mut v, mut a, mut j) = (0.0f64, 0.0f64, 0.0f64);
        for k in 0..=n {
            let tau = k as f64 / n as f64;
            v = v.max(velocity(tau).abs());
            a = a.max(acceleration(tau).abs());
            j = j.max(jerk(tau).abs());
        }
        assert!(v <= PEAK_VELOCITY && PEAK_VELOCITY - v < 1e-9, "{v}");
        assert!(
            a <= PEAK_ACCELERATION + 1e-12 && PEAK_ACCELERATION - a < 1e-6,
            "{a}"
        );
        assert!((j - PEAK_JERK).abs() < 1e-9, "{j}");
    }

    #[test]
    fn derivatives_are_consistent() {
        let h = 1e-6;
        for k in 1..100 {
            let tau = k as f64 / 100.0;
            let dv = (position(tau + h) - position(tau - h)) / (2.0 * h);
            let da = (velocity(tau + h) - velocity(tau - h)) / (2.0 * h);
            let dj = (acceleration(tau + h) - acceleration(tau - h)) / (2.0 * h);
            assert!((dv - velocity(tau)).abs() < 1e-6);
            assert!((da - acceleration(tau)).abs() < 1e-6);
            assert!((dj - jerk(tau)).abs() < 1e-5);
        }
    }

    #[test]
    fn min_duration_meets_the_binding_limit() {
        // velocity-bound, acceleration-bound, jerk-bound cases.
        let t = min_duration(1.0, 0.1, 100.0, 1e4);
        assert!((t - 18.75).abs() < 1e-12);
        let t = min_duration(-1.0, 1e3, 1.0, 1e6);
        assert!((t - PEAK_ACCELERATION.sqrt()).abs() < 1e-12);
        let t = min_duration(1.0, 1e3, 1e3, 1.0);
        assert!((t - 60f64.cbrt()).abs() < 1e-12);
        assert_eq!(min_duration(0.0, 1.0, 1.0, 1.0), 0.0);
    }
}
