//! Rounding of generated coordinates to short decimals (deterministic files), for every part.

use nalgebra::Vector3;

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
