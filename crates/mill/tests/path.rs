//! The planar milling path: interpolation, equal arc lengths (checked by an
//! independent adaptive Simpson quadrature and a fine polyline), tool axis,
//! cutting frames and input validation.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_mill::{MillError, MillingPath, PathSpec};
use nalgebra::Vector3;

/// Adaptive Simpson quadrature of f on [a, b] (an independent method).
fn simpson(f: &dyn Fn(f64) -> f64, a: f64, b: f64, tol: f64) -> f64 {
    #[allow(clippy::too_many_arguments)]
    fn rec(
        f: &dyn Fn(f64) -> f64,
        a: f64,
        b: f64,
        fa: f64,
        fm: f64,
        fb: f64,
        whole: f64,
        tol: f64,
        depth: u32,
    ) -> f64 {
        let m = 0.5 * (a + b);
        let (lm, rm) = (0.5 * (a + m), 0.5 * (m + b));
        let (flm, frm) = (f(lm), f(rm));
        let left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
        let right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
        if depth == 0 || (left + right - whole).abs() <= 15.0 * tol {
            left + right + (left + right - whole) / 15.0
        } else {
            rec(f, a, m, fa, flm, fm, left, 0.5 * tol, depth - 1)
                + rec(f, m, b, fm, frm, fb, right, 0.5 * tol, depth - 1)
        }
    }
    let (fa, fm, fb) = (f(a), f(0.5 * (a + b)), f(b));
    let whole = (b - a) / 6.0 * (fa + 4.0 * fm + fb);
    rec(f, a, b, fa, fm, fb, whole, tol, 40)
}

#[test]
fn default_path_interpolates_the_table_1_points() {
    let spec = PathSpec::default();
    let path = MillingPath::new(&spec).expect("default path");
    let pts: Vec<Vector3<f64>> = spec.points.iter().map(|p| Vector3::from(*p)).collect();
    let chords: Vec<f64> = pts.windows(2).map(|w| (w[1] - w[0]).norm()).collect();
    let total: f64 = chords.iter().sum();
    let mut u = 0.0;
    for (i, p) in pts.iter().enumerate() {
        if i > 0 {
            u += chords[i - 1] / total;
        }
        let q = path.point(u.min(1.0)).expect("eval");
        assert!((q - p).norm() < 1e-12, "point {i}: {q:?} vs {p:?}");
    }
    assert!(path.plane_deviation() < 1e-12);
    assert!((path.normal() - Vector3::z()).norm() < 1e-12);
    assert!((path.approach() + Vector3::z()).norm() < 1e-12);
}

#[test]
fn equal_arc_length_segments_checked_by_independent_quadrature() {
    let path = MillingPath::new(&PathSpec::default()).expect("path");
    let total = path.total_length();
    let segs = path.segments();
    assert_eq!(segs.len(), 100);
    let speed = |u: f64| path.derivative(u).expect("u in range").norm();
    let mut sum = 0.0;
    let mut worst = 0.0f64;
    for s in segs {
        let len = simpson(&speed, s.u[0], s.u[2], 1e-15);
        worst = worst.max((len - total / 100.0).abs() / (total / 100.0));
        assert!((s.length - len).abs() < 1e-12 * total);
        sum += len;
        // The midpoint halves the segment.
        let half = simpson(&speed, s.u[0], s.u[1], 1e-15);
        assert!((half - 0.5 * len).abs() < 1e-9 * len);
    }
    // A fine polyline (never longer than the curve; error O(h^2)).
    let n = 200_000;
    let mut poly = 0.0;
    let mut prev = path.point(0.0).expect("p");
    for i in 1..=n {
        let p = path.point(i as f64 / n as f64).expect("p");
        poly += (p - prev).norm();
        prev = p;
    }
    println!(
        "total {total:.12} m, sum of segments {sum:.12} m, polyline {poly:.12} m, \
         worst relative segment-length deviation {worst:.3e}"
    );
    assert!(worst < 1e-9);
    assert!((sum - total).abs() < 1e-12 * total);
    assert!(poly <= total + 1e-12 && total - poly < 1e-9 * total);
    // Start and end of consecutive segments coincide.
    for w in segs.windows(2) {
        assert_eq!(w[0].end, w[1].start);
    }
}

#[test]
fn cutting_frames_follow_the_feed_and_the_tool_axis() {
    let path = MillingPath::new(&PathSpec::default()).expect("path");
    for s in path.segments() {
        let f = &s.cutting_frame;
        assert!((s.tangent.norm() - 1.0).abs() < 1e-12);
        assert!((f.x + s.tangent).norm() < 1e-15, "x_c = -tangent");
        assert!(
            (f.z - Vector3::z()).norm() < 1e-15,
            "z_c from tip to spindle"
        );
        assert!((f.x.cross(&f.y) - f.z).norm() < 1e-12, "right-handed");
        assert!(f.x.dot(&f.z).abs() < 1e-12);
        // The tangent agrees with the chord direction of the segment.
        let chord = (s.end - s.start).normalize();
        assert!(chord.dot(&s.tangent) > 0.999);
        // Tool pose at g = 0: x = feed direction, z = approach (down).
        let pose = path.tool_pose(s.index, 0.0).expect("pose");
        let r = pose.rotation.to_rotation_matrix();
        assert!((r * Vector3::x() - s.tangent).norm() < 1e-12);
        assert!((r * Vector3::z() + Vector3::z()).norm() < 1e-12);
        assert!((pose.translation.vector - s.mid).norm() < 1e-15);
        // g turns the tool about its own axis: at g = pi/2 x is R0's y.
        let pose = path
            .tool_pose(s.index, std::f64::consts::FRAC_PI_2)
            .expect("pose");
        let r90 = pose.rotation.to_rotation_matrix();
        assert!((r90 * Vector3::x() - r * Vector3::y()).norm() < 1e-12);
        assert!((r90 * Vector3::z() - r * Vector3::z()).norm() < 1e-12);
    }
}

#[test]
fn two_points_make_a_straight_line() {
    let spec = PathSpec {
        points: vec![[1.5, 0.0, 1.2], [1.9, 0.3, 1.2]],
        segments: 8,
        ..PathSpec::default()
    };
    let path = MillingPath::new(&spec).expect("line");
    assert!((path.total_length() - 0.5).abs() < 1e-14);
    for s in path.segments() {
        assert!((s.length - 0.0625).abs() < 1e-14);
        let expect = Vector3::new(1.5, 0.0, 1.2)
            + (s.index as f64 + 0.5) / 8.0 * Vector3::new(0.4, 0.3, 0.0);
        assert!((s.mid - expect).norm() < 1e-13);
    }
    assert!((path.normal() - Vector3::z()).norm() < 1e-12);
}

#[test]
fn an_inclined_plane_from_below() {
    // A plane tilted 30 deg about x, tool from below: approach = +normal.
    let (s, c) = (30f64.to_radians().sin(), 30f64.to_radians().cos());
    let p = |x: f64, y: f64| [x, y * c, 1.0 + y * s];
    let spec = PathSpec {
        points: vec![
            p(1.4, -0.3),
            p(1.6, -0.05),
            p(1.8, 0.1),
            p(2.0, 0.35),
            p(2.2, 0.3),
        ],
        segments: 20,
        approach_from_above: false,
        up: [0.0, 0.0, 1.0],
    };
    let path = MillingPath::new(&spec).expect("path");
    let n = Vector3::new(0.0, -s, c);
    assert!((path.normal() - n).norm() < 1e-12);
    assert!((path.approach() - n).norm() < 1e-12);
    for seg in path.segments() {
        assert!(seg.tangent.dot(&n).abs() < 1e-12);
        assert!((seg.cutting_frame.z + n).norm() < 1e-12);
        assert!((seg.length - path.total_length() / 20.0).abs() < 1e-9 * seg.length);
    }
}

#[test]
fn bad_inputs_are_reported() {
    let base = PathSpec::default();
    let one = PathSpec {
        points: vec![[0.0; 3]],
        ..base.clone()
    };
    assert!(matches!(
        MillingPath::new(&one),
        Err(MillError::InvalidParameter { .. })
    ));
    let mut nan = base.clone();
    nan.points[2][1] = f64::NAN;
    let msg = MillingPath::new(&nan).expect_err("nan").to_string();
    assert!(msg.contains("path.points[2][1]"), "{msg}");
    let mut rep = base.clone();
    rep.points[2] = rep.points[1];
    let msg = MillingPath::new(&rep).expect_err("repeat").to_string();
    assert!(msg.contains("repeats point 1"), "{msg}");
    let zero = PathSpec {
        segments: 0,
        ..base.clone()
    };
    assert!(MillingPath::new(&zero).is_err());
    let skew = PathSpec {
        points: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.01],
        ],
        ..base.clone()
    };
    match MillingPath::new(&skew) {
        Err(MillError::NotCoplanar {
            distance,
            worst_point,
            ..
        }) => {
            println!("non-coplanar: point {worst_point} at {distance:.6e} m");
            // Orthogonal regression of this saddle: every point 0.0025 m off.
            assert!((distance - 0.0025).abs() < 1e-5);
        }
        other => panic!("expected NotCoplanar, got {other:?}"),
    }
    let vertical_line = PathSpec {
        points: vec![[1.0, 0.0, 1.0], [1.0, 0.0, 2.0]],
        ..base
    };
    assert!(matches!(
        MillingPath::new(&vertical_line),
        Err(MillError::InvalidConfig { .. })
    ));
}
