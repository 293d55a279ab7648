//! kerf's corner transition and the smoothed polyline, checked on the densely sampled curves:
//! the exact deviation bound, G2 joins, the shape table against its search, bad input.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

#[allow(dead_code)] // shared test data; this file uses some of it
mod support;
use support::{corner_points, sampled_deviation};

use kerf_toolpath::corner::{
    corner_transition, normalized_curvature, search_shape, table_shape, Binding,
};
use kerf_toolpath::vec3::{cross, dot, norm, sub};
use kerf_toolpath::{smooth_polyline, Piece, ToolpathError};

#[test]
fn the_deviation_is_exact_and_within_the_tolerance_at_every_angle() {
    let delta = 1e-4;
    for deg in [0.5, 5.0, 30.0, 60.0, 90.0, 120.0, 150.0, 170.0, 179.0] {
        let [a, v, b] = corner_points(deg);
        let c = corner_transition(a, v, b, delta, 0.010).unwrap().unwrap();
        assert!(
            c.deviation <= delta * (1.0 + 1e-12),
            "{deg}: {}",
            c.deviation
        );
        // Dense sampling: the largest distance to the two segments is the stated one.
        let worst = sampled_deviation(&c.curve, a, v, b);
        assert!(
            worst <= c.deviation * (1.0 + 1e-9),
            "{deg}: sampled {worst} > {}",
            c.deviation
        );
        assert!(
            worst >= c.deviation * (1.0 - 1e-6),
            "{deg}: sampled {worst} < {}",
            c.deviation
        );
        // G2 joins: tangent along the lines, zero curvature at both ends.
        let t_in = sub(v, a);
        let t_out = sub(b, v);
        assert!(norm(cross(c.curve.d1(0.0), t_in)) <= 1e-9 * norm(c.curve.d1(0.0)) * norm(t_in));
        assert!(dot(c.curve.d1(0.0), t_in) > 0.0);
        assert!(norm(cross(c.curve.d1(1.0), t_out)) <= 1e-9 * norm(c.curve.d1(1.0)) * norm(t_out));
        assert!(c.curve.curvature(0.0) < 1e-9 * c.max_curvature);
        assert!(c.curve.curvature(1.0) < 1e-9 * c.max_curvature);
        // The stated largest curvature against a dense sampling.
        let sampled = (0..=4000)
            .map(|k| c.curve.curvature(k as f64 / 4000.0))
            .fold(0.0, f64::max);
        assert!(
            sampled <= c.max_curvature * (1.0 + 1e-6),
            "{deg}: {sampled} > {}",
            c.max_curvature
        );
        assert!(sampled >= c.max_curvature * (1.0 - 1e-3));
    }
}

#[test]
fn short_segments_bind_the_length_not_the_tolerance() {
    let [a, v, b] = corner_points(90.0);
    let loose = corner_transition(a, v, b, 1e-3, 0.001).unwrap().unwrap();
    assert_eq!(loose.binding, Binding::Length);
    assert!(loose.tangent_length <= 0.001 * (1.0 + 1e-12));
    assert!(loose.deviation < 1e-3);
    let tight = corner_transition(a, v, b, 1e-5, 0.010).unwrap().unwrap();
    assert_eq!(tight.binding, Binding::Tolerance);
    assert!((tight.deviation - 1e-5).abs() < 1e-17);
}

#[test]
fn the_shape_table_is_the_search_on_its_grid() {
    for deg in [15.0, 90.0, 150.0] {
        let turn = f64::to_radians(deg);
        for binding in [Binding::Tolerance, Binding::Length] {
            let searched = normalized_curvature(turn, search_shape(turn, binding, 40), binding);
            let table = normalized_curvature(turn, table_shape(turn, binding), binding);
            assert!(
                table <= searched * (1.0 + 1e-9),
                "{deg} {binding:?}: {table} > {searched}"
            );
            // Not vacuous: a poor shape is clearly worse.
            let poor = kerf_toolpath::CornerShape { b: 3.5, c: 0.05 };
            assert!(normalized_curvature(turn, poor, binding) > 1.01 * table);
        }
    }
}

#[test]
fn a_smoothed_polyline_stays_within_the_tolerance_and_joins_smoothly() {
    // A zig-zag with short and long segments and a near-straight vertex.
    let poly = vec![
        [0.0, 0.0, 0.0],
        [0.010, 0.0, 0.0],
        [0.012, 0.004, 0.0],
        [0.020, 0.004, 0.001],
        [0.030, 0.0041, 0.001],
        [0.031, 0.010, 0.0],
        [0.020, 0.015, 0.0],
    ];
    let delta = 5e-5;
    let path = smooth_polyline(&poly, delta).unwrap();
    assert_eq!(path.corners().count(), 5);
    let samples = path.sample(400);
    let worst = path.distance_from_polyline(&samples);
    assert!(worst <= delta * (1.0 + 1e-9), "{worst}");
    assert!(path.max_deviation() <= delta * (1.0 + 1e-12));
    // Pieces join end to start with matching tangents.
    let ends = |p: &Piece| match p {
        Piece::Line { start, end } => (*start, *end, sub(*end, *start), sub(*end, *start)),
        Piece::Corner(c) => (
            c.curve.point(0.0),
            c.curve.point(1.0),
            c.curve.d1(0.0),
            c.curve.d1(1.0),
        ),
    };
    for w in path.pieces.windows(2) {
        let (_, end, _, t_end) = ends(&w[0]);
        let (start, _, t_start, _) = ends(&w[1]);
        assert!(norm(sub(end, start)) < 1e-15, "{w:?}");
        // (A line of a few nanometres between two corners has no useful direction.)
        if norm(t_end) > 1e-6 && norm(t_start) > 1e-6 {
            let angle = norm(cross(t_end, t_start)).atan2(dot(t_end, t_start));
            assert!(angle < 1e-9, "{angle}");
        }
    }
    // Transitions never overlap: each corner stays within its share of the segments.
    assert_eq!(path.pieces.first().map(|p| ends(p).0), Some(poly[0]));
    assert_eq!(path.pieces.last().map(|p| ends(p).1), Some(poly[6]));
}

#[test]
fn bad_input_is_refused_by_name() {
    let [a, v, b] = corner_points(90.0);
    for delta in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            corner_transition(a, v, b, delta, 0.01),
            Err(ToolpathError::InvalidParameter { .. })
        ));
        assert!(smooth_polyline(&[a, v, b], delta).is_err());
    }
    assert!(corner_transition(a, v, v, 1e-4, 0.01).is_err());
    // A reversal cannot be smoothed within a tolerance.
    let e = corner_transition([0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0], 1e-4, 0.5).unwrap_err();
    assert!(e.to_string().contains("reversal"), "{e}");
    let e = smooth_polyline(&[a, v, v, b], 1e-4).unwrap_err();
    assert!(matches!(e, ToolpathError::BadPoint { index: 2, .. }), "{e}");
    let e = smooth_polyline(&[a, [f64::NAN, 0.0, 0.0]], 1e-4).unwrap_err();
    assert!(matches!(e, ToolpathError::BadPoint { index: 1, .. }), "{e}");
    assert!(smooth_polyline(&[a], 1e-4).is_err());
    // Straight: no corner.
    assert!(
        corner_transition([0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], 1e-4, 0.5)
            .unwrap()
            .is_none()
    );
}
