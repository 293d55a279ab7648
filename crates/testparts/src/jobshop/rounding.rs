//! Rounding of generated coordinates to short decimals (deterministic files).

use nalgebra::Vector3;

use super::{AXIS_SCALE, COORD_SCALE};

/// `x` rounded to a multiple of `1 / scale`; negative zero becomes zero.
pub(super) fn round_to(x: f64, scale: f64) -> f64 {
    let y = (x * scale).round() / scale;
    if y == 0.0 {
        0.0
    } else {
        y
    }
}

/// A point rounded to 1 nm.
pub(super) fn round_point(v: &Vector3<f64>) -> [f64; 3] {
    [
        round_to(v.x, COORD_SCALE),
        round_to(v.y, COORD_SCALE),
        round_to(v.z, COORD_SCALE),
    ]
}

/// A unit axis rounded to 1e-12 per component.
pub(super) fn round_axis(v: &Vector3<f64>) -> [f64; 3] {
    [
        round_to(v.x, AXIS_SCALE),
        round_to(v.y, AXIS_SCALE),
        round_to(v.z, AXIS_SCALE),
    ]
}
