//! Merging nearly collinear micro-segments: the merged polyline and the original are within the
//! tolerance of each other in both directions (checked by dense sampling of both), and the
//! merged one, smoothed within δ_c, stays within δ_m + δ_c of the original.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_toolpath::vec3::distance_to_segment;
use kerf_toolpath::{merge_collinear, smooth_polyline, ToolpathError};

/// The largest distance from points sampled along `a` (every segment at 50 points) to the polyline `b`.
fn one_way(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    let mut worst: f64 = 0.0;
    for w in a.windows(2) {
        for k in 0..=50 {
            let u = k as f64 / 50.0;
            let p = std::array::from_fn(|d| w[0][d] + u * (w[1][d] - w[0][d]));
            let d = b
                .windows(2)
                .map(|s| distance_to_segment(p, s[0], s[1]))
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(d);
        }
    }
    worst
}

/// A CAM-like program: a 40 mm square whose sides are cut into 0.1 mm steps with ±2 µm of
/// noise across them (a fixed-seed generator).
fn dense_square() -> Vec<[f64; 3]> {
    let mut state: u64 = 12345;
    let mut noise = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        ((state % 2001) as f64 / 1000.0 - 1.0) * 2e-6
    };
    let corners = [
        [0.0, 0.0],
        [0.04, 0.0],
        [0.04, 0.04],
        [0.0, 0.04],
        [0.0, 0.0],
    ];
    let mut out = Vec::new();
    for w in corners.windows(2) {
        for k in 0..400 {
            let u = k as f64 / 400.0;
            let (dx, dy) = (w[1][0] - w[0][0], w[1][1] - w[0][1]);
            let n = noise();
            // Noise across the side (its normal).
            out.push([
                w[0][0] + u * dx - n * dy / 0.04,
                w[0][1] + u * dy + n * dx / 0.04,
                0.0,
            ]);
        }
    }
    out.push([0.0, 0.0, 0.0]);
    out
}

#[test]
fn micro_segments_merge_within_the_tolerance_both_ways() {
    let original = dense_square();
    let tol = 1e-5;
    let merged = merge_collinear(&original, tol).unwrap();
    assert!(
        merged.len() < original.len() / 20,
        "{} of {}",
        merged.len(),
        original.len()
    );
    assert_eq!(merged[0], original[0]);
    assert_eq!(merged.last(), original.last());
    assert!(one_way(&merged, &original) <= tol * (1.0 + 1e-9));
    assert!(one_way(&original, &merged) <= tol * (1.0 + 1e-9));
    // Smoothed within δ_c, the path stays within δ_m + δ_c of the original.
    let smoothed = smooth_polyline(&merged, 4e-5).unwrap();
    let samples = smoothed.sample(200);
    let worst = samples
        .iter()
        .map(|p| {
            original
                .windows(2)
                .map(|s| distance_to_segment(*p, s[0], s[1]))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max);
    assert!(worst <= 5e-5 * (1.0 + 1e-9), "{worst}");
}

#[test]
fn a_backtracking_run_is_not_merged() {
    // The middle point lies on the chord but behind its start: merging would drop a reversal.
    let pts = [
        [0.0, 0.0, 0.0],
        [0.01, 0.0, 0.0],
        [-0.005, 0.0, 0.0],
        [0.02, 0.0, 0.0],
    ];
    let merged = merge_collinear(&pts, 1e-3).unwrap();
    assert_eq!(merged.len(), 4);
}

#[test]
fn bad_input_is_refused() {
    assert!(matches!(
        merge_collinear(&[[0.0; 3], [1.0, 0.0, 0.0]], 0.0),
        Err(ToolpathError::InvalidParameter { .. })
    ));
    assert!(merge_collinear(&[[0.0; 3]], 1e-4).is_err());
    assert!(matches!(
        merge_collinear(&[[0.0; 3], [f64::NAN, 0.0, 0.0]], 1e-4),
        Err(ToolpathError::BadPoint { index: 1, .. })
    ));
}
