//! CL paths: a curve on a part's surface sampled at constant arc length `f Δt`, as a
//! controller samples a cut (open paths end after a whole number of steps; closed contours
//! are split into equal steps no longer than `f Δt` and end on their first point).

use nalgebra::Vector3;

use crate::rounding::{round_axis, round_point};
use crate::TestPartError;

/// Chords of the arc-length table of a curve.
const TABLE_CHORDS: usize = 1 << 15;

/// A CL path: points on the head-side surface and unit nominal tool axes (the surface
/// normals).
#[derive(Debug, Clone, PartialEq)]
pub struct ClPath {
    /// CL points in the workpiece frame (m), rounded to 1 nm.
    pub points: Vec<[f64; 3]>,
    /// Unit nominal tool axes, rounded to 1e-12 per component.
    pub axes: Vec<[f64; 3]>,
    /// The requested spacing `f Δt` (m); a closed contour uses its length over the smallest
    /// whole number of steps not longer than this.
    pub spacing: f64,
    /// True for a closed contour: the last point is the first.
    pub closed: bool,
}

/// Samples `curve` (parameter t in [0, 1]; returns point and unit normal) at constant arc
/// length.
///
/// # Arguments
/// * `curve` - the curve on the surface; for `closed`, `curve(1)` must equal `curve(0)`.
/// * `closed` - closed contour (start = end) or open path.
/// * `spacing` - `f Δt` (m).
///
/// # Returns
/// The path; arc lengths come from a table of 32768 chords with linear inversion.
///
/// # Errors
/// [`TestPartError::Invalid`] for a non-positive spacing, a curve shorter than two steps, a
/// closed curve whose ends differ by more than 1 nm, or more than 100 000 points.
pub fn sample_curve(
    curve: &dyn Fn(f64) -> (Vector3<f64>, Vector3<f64>),
    closed: bool,
    spacing: f64,
) -> Result<ClPath, TestPartError> {
    if !(spacing.is_finite() && spacing > 0.0) {
        return Err(TestPartError::invalid(
            "path spacing",
            format!("{spacing} must be finite and > 0"),
        ));
    }
    let mut cum = Vec::with_capacity(TABLE_CHORDS + 1);
    cum.push(0.0);
    let mut previous = curve(0.0).0;
    for m in 1..=TABLE_CHORDS {
        let p = curve(m as f64 / TABLE_CHORDS as f64).0;
        let last = cum.last().copied().unwrap_or(0.0);
        cum.push(last + (p - previous).norm());
        previous = p;
    }
    let total = cum[TABLE_CHORDS];
    if closed && (curve(1.0).0 - curve(0.0).0).norm() > 1e-9 {
        return Err(TestPartError::invalid("closed path", "its ends differ"));
    }
    let steps = if closed {
        (total / spacing).ceil()
    } else {
        (total / spacing + 1e-9).floor()
    };
    if !(2.0..=1e5).contains(&steps) {
        return Err(TestPartError::invalid(
            "path",
            format!("{total} m at {spacing} m gives {steps} steps"),
        ));
    }
    let steps = steps as usize;
    let step = if closed {
        total / steps as f64
    } else {
        spacing
    };
    let at = |s: f64| {
        let m = cum.partition_point(|&c| c <= s).clamp(1, TABLE_CHORDS) - 1;
        let span = cum[m + 1] - cum[m];
        let frac = if span > 0.0 { (s - cum[m]) / span } else { 0.0 };
        curve((m as f64 + frac.clamp(0.0, 1.0)) / TABLE_CHORDS as f64)
    };
    let mut points = Vec::with_capacity(steps + 1);
    let mut axes = Vec::with_capacity(steps + 1);
    let last = if closed { steps - 1 } else { steps };
    for k in 0..=last {
        let (p, n) = at(step * k as f64);
        points.push(round_point(&p));
        axes.push(round_axis(&n.normalize()));
    }
    if closed {
        points.push(points[0]);
        axes.push(axes[0]);
    }
    Ok(ClPath {
        points,
        axes,
        spacing,
        closed,
    })
}
