//! Merging nearly collinear micro-segments of a G01 polyline (issue 14, item
//! 2: "nearly collinear micro-segments merge within δ").
//!
//! From each kept point, the next kept point is the farthest j such that
//! every point between lies within the tolerance of the chord and their
//! projections onto the chord increase strictly inside it. Then the chord
//! and the polyline it replaces are within the tolerance of each other in
//! both directions (Hausdorff): each replaced point is near the chord by the
//! test, and each chord point lies between the projections of two
//! consecutive replaced points, whose segment passes within the larger of
//! their two distances. Smoothing the merged polyline's corners within δ_c
//! then keeps the path within δ_m + δ_c of the original (triangle
//! inequality).

use kerf_budget::Budget;

use crate::error::{check_positive, ToolpathError};
use crate::vec3::{dot, norm, scale, sub};

/// The most points one chord may replace: the check of a chord is linear in
/// the points it replaces, so merging costs O(n · window) (a straight run of
/// 10⁶ points: about 1.3 · 10⁸ distance checks).
pub const MERGE_WINDOW: usize = 256;

/// The polyline with its nearly collinear runs merged.
///
/// # Arguments
/// * `points` — at least two, finite.
/// * `tolerance` — δ_m \[m\], > 0.
///
/// # Returns
/// The kept points (the first and the last always), in order.
///
/// # Errors
/// [`ToolpathError::InvalidParameter`] for a bad tolerance or fewer than
/// two points; [`ToolpathError::BadPoint`] for a point that is not finite.
pub fn merge_collinear(
    points: &[[f64; 3]],
    tolerance: f64,
) -> Result<Vec<[f64; 3]>, ToolpathError> {
    Ok(merge_collinear_indices(points, tolerance)?
        .into_iter()
        .map(|k| points[k])
        .collect())
}

/// [`merge_collinear`] as the indices of the kept points (increasing, the
/// first and the last always), for a caller that carries data along with
/// the points.
///
/// # Errors
/// As [`merge_collinear`].
pub fn merge_collinear_indices(
    points: &[[f64; 3]],
    tolerance: f64,
) -> Result<Vec<usize>, ToolpathError> {
    merge_collinear_indices_within(points, tolerance, &Budget::unlimited())
}

/// [`merge_collinear_indices`] under a budget, checked at every kept point (each costs at most
/// [`MERGE_WINDOW`]² / 2 distance checks, about 30 µs).
///
/// # Errors
/// As [`merge_collinear`]; [`ToolpathError::Interrupted`] when the budget runs out.
pub fn merge_collinear_indices_within(
    points: &[[f64; 3]],
    tolerance: f64,
    budget: &Budget,
) -> Result<Vec<usize>, ToolpathError> {
    check_positive(&[("merge tolerance [m]", tolerance)])?;
    if points.len() < 2 {
        return Err(ToolpathError::InvalidParameter {
            name: "points".to_string(),
            value: points.len() as f64,
            reason: "a path needs at least two".to_string(),
        });
    }
    if let Some(index) = points.iter().position(|p| p.iter().any(|v| !v.is_finite())) {
        return Err(ToolpathError::BadPoint {
            index,
            reason: "not finite".to_string(),
        });
    }
    let n = points.len();
    let mut kept = vec![0];
    let mut i = 0;
    while i < n - 1 {
        budget.check("merging collinear segments")?;
        let mut best = i + 1;
        let last = (i + MERGE_WINDOW).min(n - 1);
        for j in i + 2..=last {
            if within(points, i, j, tolerance) {
                best = j;
            } else {
                break;
            }
        }
        kept.push(best);
        i = best;
    }
    Ok(kept)
}

/// Whether the points strictly between `i` and `j` are within `tolerance`
/// of the chord from `i` to `j` with strictly increasing projections inside
/// it.
fn within(points: &[[f64; 3]], i: usize, j: usize, tolerance: f64) -> bool {
    let chord = sub(points[j], points[i]);
    let length = norm(chord);
    if length == 0.0 {
        return false;
    }
    let t = scale(chord, 1.0 / length);
    let mut previous = 0.0;
    for p in &points[i + 1..j] {
        let d = sub(*p, points[i]);
        let along = dot(d, t);
        if !(along > previous && along < length) {
            return false;
        }
        let off = norm(sub(d, scale(t, along)));
        if off > tolerance {
            return false;
        }
        previous = along;
    }
    true
}
