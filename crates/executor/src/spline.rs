//! Segment polynomials between two waypoints, as JTC's `interpolation_method: splines`.
//!
//! Source: ros2_controllers `joint_trajectory_controller/src/trajectory.cpp`,
//! `Trajectory::interpolate_between_points` (Jazzy): linear when either end lacks
//! velocities, cubic Hermite when both ends have velocities, quintic Hermite when both ends
//! also have accelerations. The coefficients below are the same closed forms.

/// Which polynomial a segment uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interpolation {
    /// Degree 1 through both positions; velocity constant, acceleration 0.
    Linear,
    /// Degree 3 matching positions and velocities at both ends (cubic Hermite).
    Cubic,
    /// Degree 5 matching positions, velocities and accelerations at both ends (quintic Hermite).
    Quintic,
}

impl Interpolation {
    /// The JTC rule: quintic if both ends have velocities and accelerations, cubic if both
    /// have velocities, else linear.
    pub fn between(from_vel: bool, from_acc: bool, to_vel: bool, to_acc: bool) -> Interpolation {
        let vel = from_vel && to_vel;
        let acc = from_acc && to_acc;
        match (vel, acc) {
            (true, true) => Interpolation::Quintic,
            (true, false) => Interpolation::Cubic,
            _ => Interpolation::Linear,
        }
    }

    /// Lower-case name for messages.
    pub fn name(self) -> &'static str {
        match self {
            Interpolation::Linear => "linear",
            Interpolation::Cubic => "cubic",
            Interpolation::Quintic => "quintic",
        }
    }
}

/// One end of a segment for one joint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Knot {
    /// Position.
    pub p: f64,
    /// Velocity (ignored by linear segments).
    pub v: f64,
    /// Acceleration (used by quintic segments only).
    pub a: f64,
}

/// Coefficients `c` (ascending powers of the local time τ ∈ [0, T]) of one joint's segment.
///
/// # Arguments
/// * `kind` — the interpolation.
/// * `k0`, `k1` — the states at τ = 0 and τ = T.
/// * `t` — segment duration T > 0 (s).
///
/// # Returns
/// Six coefficients; unused higher ones are 0. Formulas: linear `p0 + (p1−p0)/T τ`; cubic and
/// quintic Hermite as in JTC `interpolate_between_points` (ros2_controllers, Jazzy).
pub fn coefficients(kind: Interpolation, k0: Knot, k1: Knot, t: f64) -> [f64; 6] {
    let (p0, v0, a0, p1, v1, a1) = (k0.p, k0.v, k0.a, k1.p, k1.v, k1.a);
    let t2 = t * t;
    let t3 = t2 * t;
    match kind {
        Interpolation::Linear => [p0, (p1 - p0) / t, 0.0, 0.0, 0.0, 0.0],
        Interpolation::Cubic => [
            p0,
            v0,
            (-3.0 * p0 + 3.0 * p1 - 2.0 * v0 * t - v1 * t) / t2,
            (2.0 * p0 - 2.0 * p1 + v0 * t + v1 * t) / t3,
            0.0,
            0.0,
        ],
        Interpolation::Quintic => {
            let t4 = t3 * t;
            let t5 = t4 * t;
            [
                p0,
                v0,
                0.5 * a0,
                (-20.0 * p0 + 20.0 * p1 - 3.0 * a0 * t2 + a1 * t2 - 12.0 * v0 * t - 8.0 * v1 * t)
                    / (2.0 * t3),
                (30.0 * p0 - 30.0 * p1 + 3.0 * a0 * t2 - 2.0 * a1 * t2
                    + 16.0 * v0 * t
                    + 14.0 * v1 * t)
                    / (2.0 * t4),
                (-12.0 * p0 + 12.0 * p1 - a0 * t2 + a1 * t2 - 6.0 * v0 * t - 6.0 * v1 * t)
                    / (2.0 * t5),
            ]
        }
    }
}

/// Position, velocity and acceleration of the quintic (or lower) polynomial `c` at τ.
///
/// # Performance
/// Three Horner evaluations, 12 multiply-adds, no allocation.
#[inline]
pub fn evaluate(c: &[f64; 6], tau: f64) -> (f64, f64, f64) {
    let p = c[0] + tau * (c[1] + tau * (c[2] + tau * (c[3] + tau * (c[4] + tau * c[5]))));
    let v = c[1] + tau * (2.0 * c[2] + tau * (3.0 * c[3] + tau * (4.0 * c[4] + tau * 5.0 * c[5])));
    let a = 2.0 * c[2] + tau * (6.0 * c[3] + tau * (12.0 * c[4] + tau * 20.0 * c[5]));
    (p, v, a)
}

/// Coefficients of the velocity polynomial (degree ≤ 4) of `c`.
pub fn velocity_coefficients(c: &[f64; 6]) -> [f64; 5] {
    [c[1], 2.0 * c[2], 3.0 * c[3], 4.0 * c[4], 5.0 * c[5]]
}

/// Coefficients of the acceleration polynomial (degree ≤ 3) of `c`.
pub fn acceleration_coefficients(c: &[f64; 6]) -> [f64; 4] {
    [2.0 * c[2], 6.0 * c[3], 12.0 * c[4], 20.0 * c[5]]
}
