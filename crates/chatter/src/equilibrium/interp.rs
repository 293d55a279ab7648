//! Locating a time on the node grid and cubic Hermite interpolation
//! between nodes.

use nalgebra::Vector2;

/// `x.rem_euclid(y)` (y > 0) without the software `fmod` when x already
/// lies in [0, y), where `x % y` is x exactly: bit-identical.
pub(crate) fn wrap(x: f64, y: f64) -> f64 {
    if x >= 0.0 && x < y {
        x
    } else {
        x.rem_euclid(y)
    }
}

/// Step of node `k` of a trajectory and the local parameter, for `t` in [0, T).
pub(super) fn locate(times: &[f64], t: f64) -> usize {
    let n = times.len().saturating_sub(1).max(1);
    match times.binary_search_by(|x| x.total_cmp(&t)) {
        Ok(k) => k.min(n - 1),
        Err(k) => k.saturating_sub(1).min(n - 1),
    }
}

/// [`locate`] for a grid close to uniform: starts at the proportional
/// index and walks (the same index as the binary search for a finite t
/// and strictly increasing times).
pub(super) fn locate_guess(times: &[f64], t: f64) -> usize {
    let len = times.len();
    if len < 3 || !t.is_finite() {
        return locate(times, t);
    }
    let n = len - 1;
    let (first, last) = (times[0], times[n]);
    let x = (t - first) / (last - first) * n as f64;
    let mut k = if x > 0.0 { (x as usize).min(n) } else { 0 };
    while k > 0 && times[k] > t {
        k -= 1;
    }
    while k < n && times[k + 1] <= t {
        k += 1;
    }
    k.min(n - 1)
}

pub(super) fn hermite(
    s: f64,
    h: f64,
    p0: Vector2<f64>,
    v0: Vector2<f64>,
    p1: Vector2<f64>,
    v1: Vector2<f64>,
) -> Vector2<f64> {
    let s2 = s * s;
    let s3 = s2 * s;
    p0 * (2.0 * s3 - 3.0 * s2 + 1.0)
        + v0 * (h * (s3 - 2.0 * s2 + s))
        + p1 * (-2.0 * s3 + 3.0 * s2)
        + v1 * (h * (s3 - s2))
}

pub(super) fn hermite1(s: f64, h: f64, p0: f64, v0: f64, p1: f64, v1: f64) -> f64 {
    let s2 = s * s;
    let s3 = s2 * s;
    p0 * (2.0 * s3 - 3.0 * s2 + 1.0)
        + v0 * (h * (s3 - 2.0 * s2 + s))
        + p1 * (-2.0 * s3 + 3.0 * s2)
        + v1 * (h * (s3 - s2))
}
