//! Per-corner figures (seed 003 Table 2's kind) on the shipped W-shaped program: one entry per
//! corner with its vertex and turning angle; the approximation error is the largest distance from
//! the polyline found by dense sampling and within the tolerance; the curvature is the sampled
//! maximum.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_gcode::{read_program, Motion, ReaderSettings};
use kerf_toolpath::{corner_metrics, smooth_polyline};

/// The W-shape's polyline \[m\] from `crates/gcode/data/programs/w_shape.ngc`.
fn w_shape() -> Vec<[f64; 3]> {
    let file =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../gcode/data/programs/w_shape.ngc");
    let text = std::fs::read_to_string(file).unwrap();
    let mut out = Vec::new();
    for m in read_program(&text, ReaderSettings::default()).unwrap() {
        if let Motion::Line { start, end, .. } = m {
            if out.is_empty() {
                out.push(start);
            }
            out.push(end);
        }
    }
    out
}

#[test]
fn the_w_shapes_three_corners() {
    let poly = w_shape();
    assert_eq!(poly.len(), 5);
    let tolerance = 1e-4;
    let path = smooth_polyline(&poly, tolerance).unwrap();
    let corners = corner_metrics(&path);
    assert_eq!(corners.len(), 3);
    let curves: Vec<_> = path.corners().collect();
    for (k, c) in corners.iter().enumerate() {
        assert_eq!(c.index, Some(k + 1));
        assert_eq!(c.vertex, poly[k + 1]);
        // The turning angle from the segments.
        let d = |a: [f64; 3], b: [f64; 3]| [b[0] - a[0], b[1] - a[1]];
        let (u, v) = (d(poly[k], poly[k + 1]), d(poly[k + 1], poly[k + 2]));
        let turn = (u[0] * v[1] - u[1] * v[0])
            .abs()
            .atan2(u[0] * v[0] + u[1] * v[1]);
        assert!(
            (c.turn - turn).abs() < 1e-12,
            "corner {k}: {} vs {turn}",
            c.turn
        );
        // The approximation error against dense sampling of the transition (u = 1/2 included).
        let n = 2000;
        let points: Vec<[f64; 3]> = (0..=n)
            .map(|i| curves[k].curve.point(i as f64 / n as f64))
            .collect();
        let sampled = path.distance_from_polyline(&points);
        assert!(
            (c.approximation_error - sampled).abs() <= 1e-9 * tolerance,
            "corner {k}: {} vs sampled {sampled}",
            c.approximation_error
        );
        assert!(c.approximation_error <= tolerance * (1.0 + 1e-12));
        let kappa = (0..=n)
            .map(|i| curves[k].curve.curvature(i as f64 / n as f64))
            .fold(0.0, f64::max);
        assert!(
            c.max_curvature >= kappa * (1.0 - 1e-9) && c.max_curvature <= kappa * 1.001,
            "corner {k}: {} vs sampled {kappa}",
            c.max_curvature
        );
        println!(
            "corner {k}: θ {:.2}°, error {:.4} mm, κ_max {:.3} 1/mm, {:?}",
            c.turn.to_degrees(),
            c.approximation_error * 1e3,
            c.max_curvature * 1e-3,
            c.binding
        );
    }
    // The sharpest corner (b, the middle one) has the largest curvature.
    assert!(corners[1].max_curvature > corners[0].max_curvature.max(corners[2].max_curvature));
}
