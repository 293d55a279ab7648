//! The job-shop parts' rounding of points and axes ([`crate::rounding`]).

use nalgebra::Vector3;

use super::{AXIS_SCALE, COORD_SCALE};
use crate::rounding::round_vec;

/// A point rounded to 1 nm.
pub(super) fn round_point(v: &Vector3<f64>) -> [f64; 3] {
    round_vec(v, COORD_SCALE)
}

/// A unit axis rounded to 1e-12 per component.
pub(super) fn round_axis(v: &Vector3<f64>) -> [f64; 3] {
    round_vec(v, AXIS_SCALE)
}
