//! Rounding of generated coordinates to short decimals (deterministic files), for every part.

use nalgebra::Vector3;

/// Mesh and CL coordinates are rounded to 1 / COORD_SCALE m (1 nm).
pub(crate) const COORD_SCALE: f64 = 1e9;

/// Tool-axis components (and workpiece quaternions) are rounded to 1 / AXIS_SCALE.
pub(crate) const AXIS_SCALE: f64 = 1e12;

/// `x` rounded to a multiple of `1 / scale` (`scale` a power of ten, so
/// the result prints as a short decimal); negative zero becomes zero.
pub(crate) fn round_to(x: f64, scale: f64) -> f64 {
    let y = (x * scale).round() / scale;
    if y == 0.0 {
        0.0
    } else {
        y
    }
}

/// `v` rounded componentwise with [`round_to`].
pub(crate) fn round_vec(v: &Vector3<f64>, scale: f64) -> [f64; 3] {
    [
        round_to(v.x, scale),
        round_to(v.y, scale),
        round_to(v.z, scale),
    ]
}

/// A point rounded to 1 nm ([`COORD_SCALE`]).
pub(crate) fn round_point(v: &Vector3<f64>) -> [f64; 3] {
    round_vec(v, COORD_SCALE)
}

/// A unit axis rounded to 1e-12 per component ([`AXIS_SCALE`]).
pub(crate) fn round_axis(v: &Vector3<f64>) -> [f64; 3] {
    round_vec(v, AXIS_SCALE)
}
