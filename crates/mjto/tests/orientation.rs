//! Path frames and lead/tilt angles (seed 001 section 2.4, Figure 4).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_2, FRAC_PI_4, PI};

use approx::assert_abs_diff_eq;
use kerf_mjto::orientation::{any_perpendicular, axis_from_lead_tilt, slerp_unit, PathFrames};
use kerf_mjto::PlanError;
use nalgebra::Vector3;

mod common;
use common::Rng;

/// Normalised arc length of a polyline.
fn arc_u(points: &[Vector3<f64>]) -> Vec<f64> {
    let mut s = vec![0.0];
    for w in points.windows(2) {
        s.push(s.last().unwrap() + (w[1] - w[0]).norm());
    }
    let total = *s.last().unwrap();
    s.iter().map(|v| v / total).collect()
}

fn frames(points: Vec<Vector3<f64>>, axes: Vec<Vector3<f64>>) -> PathFrames {
    let u = arc_u(&points);
    PathFrames::try_new(&points, &axes, &u).unwrap()
}

/// A helix around z with axes tilted from the vertical toward the
/// centre by an angle that varies along the path.
fn helix(n: usize) -> PathFrames {
    let points: Vec<_> = (0..n)
        .map(|i| {
            let a = 0.1 * i as f64;
            Vector3::new(0.3 * a.cos(), 0.3 * a.sin(), 0.02 * a)
        })
        .collect();
    let axes: Vec<_> = (0..n)
        .map(|i| {
            let a = 0.1 * i as f64;
            let tilt = 0.4 * (0.05 * i as f64).sin();
            Vector3::new(-tilt.sin() * a.cos(), -tilt.sin() * a.sin(), tilt.cos())
        })
        .collect();
    frames(points, axes)
}

fn straight_x() -> PathFrames {
    let points = (0..5)
        .map(|i| Vector3::new(0.1 * i as f64, 0.2, 0.0))
        .collect();
    frames(points, vec![Vector3::z(); 5])
}

#[test]
fn straight_path_has_the_expected_frame_and_angles() {
    let f = straight_x();
    for u in [0.0, 0.3, 0.5, 1.0] {
        let (t, n, b) = f.frame(u);
        assert_abs_diff_eq!(t, Vector3::x(), epsilon = 1e-15);
        assert_abs_diff_eq!(n, Vector3::z(), epsilon = 1e-15);
        assert_abs_diff_eq!(b, Vector3::y(), epsilon = 1e-15);
    }
    // Leaning 0.2 rad toward the feed direction (+x): lead +0.2, tilt 0.
    let o = Vector3::new(0.2f64.sin(), 0.0, 0.2f64.cos());
    let (lead, tilt) = f.lead_tilt(0.4, &o);
    assert_abs_diff_eq!(lead, 0.2, epsilon = 1e-15);
    assert_abs_diff_eq!(tilt, 0.0, epsilon = 1e-15);
    // Leaning backward: negative lead.
    let (lead, _) = f.lead_tilt_at(2, &Vector3::new(-(0.1f64.sin()), 0.0, 0.1f64.cos()));
    assert_abs_diff_eq!(lead, -0.1, epsilon = 1e-15);
    // Leaning 0.15 rad to the left of the feed (+y seen from above): tilt +0.15.
    let o = Vector3::new(0.0, 0.15f64.sin(), 0.15f64.cos());
    let (lead, tilt) = f.lead_tilt(0.9, &o);
    assert_abs_diff_eq!(lead, 0.0, epsilon = 1e-15);
    assert_abs_diff_eq!(tilt, 0.15, epsilon = 1e-15);
    // Both: tan φ = O_x / O_z and tan ϕ = O_y / O_z.
    let o = Vector3::new(0.1, -0.2, 0.9).normalize();
    let (lead, tilt) = f.lead_tilt(0.1, &o);
    assert_abs_diff_eq!(lead, (0.1f64 / 0.9).atan(), epsilon = 1e-15);
    assert_abs_diff_eq!(tilt, (-0.2f64 / 0.9).atan(), epsilon = 1e-15);
    // Reversing the feed flips the sign of both angles.
    let points = (0..5)
        .map(|i| Vector3::new(0.4 - 0.1 * i as f64, 0.2, 0.0))
        .collect();
    let back = frames(points, vec![Vector3::z(); 5]);
    let (lead_r, tilt_r) = back.lead_tilt(0.1, &o);
    assert_abs_diff_eq!(lead_r, -lead, epsilon = 1e-15);
    assert_abs_diff_eq!(tilt_r, -tilt, epsilon = 1e-15);
}

#[test]
fn lead_tilt_round_trips_on_a_curved_path() {
    let f = helix(60);
    let mut rng = Rng(7);
    for _ in 0..2000 {
        let u = rng.next();
        let lead = rng.range(-1.5, 1.5);
        let tilt = rng.range(-1.5, 1.5);
        let (t, n, b) = f.frame(u);
        let o = axis_from_lead_tilt(&t, &n, &b, lead, tilt);
        assert_abs_diff_eq!(o.norm(), 1.0, epsilon = 1e-14);
        let (l2, t2) = f.lead_tilt(u, &o);
        assert_abs_diff_eq!(l2, lead, epsilon = 1e-12);
        assert_abs_diff_eq!(t2, tilt, epsilon = 1e-12);
        // And the other way round: any axis with O·n > 0.
        let o = Vector3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        )
        .normalize();
        if o.dot(&n) > 1e-3 {
            let (l, tl) = f.lead_tilt(u, &o);
            assert_abs_diff_eq!(axis_from_lead_tilt(&t, &n, &b, l, tl), o, epsilon = 1e-12);
        }
    }
    // Zero angles give the nominal axis.
    let (t, n, b) = f.frame(0.37);
    assert_abs_diff_eq!(
        axis_from_lead_tilt(&t, &n, &b, 0.0, 0.0),
        n,
        epsilon = 1e-15
    );
    let (lead, tilt) = f.lead_tilt(0.37, &n);
    assert_abs_diff_eq!(lead, 0.0, epsilon = 1e-15);
    assert_abs_diff_eq!(tilt, 0.0, epsilon = 1e-15);
}

#[test]
fn frames_are_orthonormal_right_handed_and_tangent() {
    let f = helix(60);
    let mut rng = Rng(11);
    for _ in 0..500 {
        let u = rng.next();
        let (t, n, b) = f.frame(u);
        for v in [t, n, b] {
            assert_abs_diff_eq!(v.norm(), 1.0, epsilon = 1e-14);
        }
        assert_abs_diff_eq!(t.dot(&n), 0.0, epsilon = 1e-14);
        assert_abs_diff_eq!(t.dot(&b), 0.0, epsilon = 1e-14);
        assert_abs_diff_eq!(b, n.cross(&t), epsilon = 1e-14);
        assert_abs_diff_eq!(t.cross(&b).dot(&n), 1.0, epsilon = 1e-14);
        assert_abs_diff_eq!(n, f.nominal_axis(u), epsilon = 1e-15);
    }
    // At a CL point the tangent is the central difference projected ⊥ n:
    // on the helix it points along the feed (positive dot with the chord).
    for i in 1..59 {
        let (t, n, _) = f.frame_at(i);
        let chord = f.points()[i + 1] - f.points()[i - 1];
        let expected = (chord - chord.dot(&n) * n).normalize();
        assert_abs_diff_eq!(t, expected, epsilon = 1e-14);
        assert_abs_diff_eq!(f.frame(f.u_values()[i]).0, t, epsilon = 1e-14);
    }
    // One-sided at the ends.
    let (t0, n0, _) = f.frame_at(0);
    let chord = f.points()[1] - f.points()[0];
    assert_abs_diff_eq!(
        t0,
        (chord - chord.dot(&n0) * n0).normalize(),
        epsilon = 1e-14
    );
}

#[test]
fn degenerate_tangents_fall_back_to_the_neighbour_then_any_perpendicular() {
    // A plunge along the (vertical) tool axis, then a move along x.
    let points = vec![
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(0.0, 0.0, 0.1),
        Vector3::new(0.0, 0.0, 0.2),
        Vector3::new(0.1, 0.0, 0.2),
        Vector3::new(0.2, 0.0, 0.2),
    ];
    let f = frames(points, vec![Vector3::z(); 5]);
    for i in 0..5 {
        let (t, n, b) = f.frame_at(i);
        assert_abs_diff_eq!(t, Vector3::x(), epsilon = 1e-15);
        assert_abs_diff_eq!(n, Vector3::z(), epsilon = 1e-15);
        assert_abs_diff_eq!(b, Vector3::y(), epsilon = 1e-15);
    }
    // Everything along the axis: some perpendicular, still a valid frame.
    let points = (0..4)
        .map(|i| Vector3::new(0.0, 0.0, 0.1 * i as f64))
        .collect();
    let f = frames(points, vec![Vector3::z(); 4]);
    for u in [0.0, 0.5, 1.0] {
        let (t, n, b) = f.frame(u);
        assert_abs_diff_eq!(t.norm(), 1.0, epsilon = 1e-15);
        assert_abs_diff_eq!(t.dot(&n), 0.0, epsilon = 1e-15);
        assert_abs_diff_eq!(b, n.cross(&t), epsilon = 1e-15);
    }
    let p = any_perpendicular(&Vector3::new(0.3, -0.4, 0.5).normalize());
    assert_abs_diff_eq!(p.norm(), 1.0, epsilon = 1e-15);
    assert_abs_diff_eq!(p.dot(&Vector3::new(0.3, -0.4, 0.5)), 0.0, epsilon = 1e-15);
}

#[test]
fn locate_nearest_and_cl_point_follow_the_polyline() {
    let points = vec![
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(0.1, 0.0, 0.0),
        Vector3::new(0.1, 0.3, 0.0),
    ];
    let f = frames(points, vec![Vector3::z(); 3]);
    assert_eq!(f.len(), 3);
    assert_eq!(f.u_values(), &[0.0, 0.25, 1.0]);
    assert_eq!(f.locate(0.0), (0, 0.0));
    assert_eq!(f.locate(0.125), (0, 0.5));
    assert_eq!(f.locate(0.25), (1, 0.0));
    assert_eq!(f.locate(0.625), (1, 0.5));
    assert_eq!(f.locate(1.0), (1, 1.0));
    assert_eq!(f.locate(-0.5), (0, 0.0));
    assert_eq!(f.locate(1.5), (1, 1.0));
    assert_eq!(f.nearest_index(0.1), 0);
    assert_eq!(f.nearest_index(0.2), 1);
    assert_eq!(f.nearest_index(0.7), 2);
    assert_abs_diff_eq!(
        f.cl_point(0.125),
        Vector3::new(0.05, 0.0, 0.0),
        epsilon = 1e-15
    );
    assert_abs_diff_eq!(
        f.cl_point(0.625),
        Vector3::new(0.1, 0.15, 0.0),
        epsilon = 1e-15
    );
    assert_abs_diff_eq!(
        f.cl_point(2.0),
        Vector3::new(0.1, 0.3, 0.0),
        epsilon = 1e-15
    );
    // NaN is never hidden.
    assert!(f.locate(f64::NAN).1.is_nan());
    assert!(f.cl_point(f64::NAN).iter().all(|v| v.is_nan()));
    assert!(f.nominal_axis(f64::NAN).iter().all(|v| v.is_nan()));
    assert!(f.lead_tilt(f64::NAN, &Vector3::z()).0.is_nan());
}

#[test]
fn nominal_axis_is_the_great_circle_between_neighbours() {
    let points = vec![Vector3::zeros(), Vector3::new(0.1, 0.0, 0.0)];
    let axes = vec![Vector3::z(), Vector3::x()];
    let f = frames(points, axes);
    for s in [0.0, 0.2, 0.5, 0.9, 1.0] {
        let a = f.nominal_axis(s);
        let angle = s * FRAC_PI_2;
        assert_abs_diff_eq!(
            a,
            Vector3::new(angle.sin(), 0.0, angle.cos()),
            epsilon = 1e-15
        );
    }
    assert_abs_diff_eq!(
        f.nominal_axis(0.5),
        Vector3::new(FRAC_1_SQRT_2, 0.0, FRAC_1_SQRT_2),
        epsilon = 1e-15
    );
    // The tool leaning 45° toward the feed at u = 0.5 is the nominal
    // axis there: zero lead. The original z axis is then 45° behind.
    let (lead, tilt) = f.lead_tilt(0.5, &Vector3::z());
    assert_abs_diff_eq!(lead, -FRAC_PI_4, epsilon = 1e-15);
    assert_abs_diff_eq!(tilt, 0.0, epsilon = 1e-15);
}

#[test]
fn slerp_handles_tiny_and_antipodal_angles() {
    let a = Vector3::new(1.0, 2.0, 3.0).normalize();
    let b = Vector3::new(-0.5, 0.2, 1.0).normalize();
    let theta = a.angle(&b);
    for s in [0.0, 0.3, 0.7, 1.0] {
        let v = slerp_unit(&a, &b, s);
        assert_abs_diff_eq!(v.norm(), 1.0, epsilon = 1e-15);
        assert_abs_diff_eq!(a.angle(&v), s * theta, epsilon = 1e-12);
        assert_abs_diff_eq!(v.angle(&b), (1.0 - s) * theta, epsilon = 1e-12);
    }
    assert_eq!(slerp_unit(&a, &a, 0.4), a);
    let mid = slerp_unit(&Vector3::z(), &-Vector3::z(), 0.5);
    assert_abs_diff_eq!(mid.norm(), 1.0, epsilon = 1e-15);
    assert_abs_diff_eq!(mid.z, 0.0, epsilon = 1e-15);
    assert_abs_diff_eq!(
        slerp_unit(&Vector3::z(), &-Vector3::z(), 1.0),
        -Vector3::z(),
        epsilon = 1e-15
    );
    assert_abs_diff_eq!(
        Vector3::z().angle(&slerp_unit(&Vector3::z(), &-Vector3::z(), 0.25)),
        PI / 4.0,
        epsilon = 1e-15
    );
}

#[test]
fn try_new_rejects_bad_inputs_and_new_never_panics() {
    let p = vec![Vector3::zeros(), Vector3::x()];
    let a = vec![Vector3::z(), Vector3::z()];
    let u = vec![0.0, 1.0];
    let bad = |r: Result<PathFrames, PlanError>, field: &str| match r {
        Err(PlanError::InvalidRequest { field: f, .. }) => assert_eq!(f, field),
        other => panic!("expected InvalidRequest {field}, got {other:?}"),
    };
    bad(PathFrames::try_new(&p, &a[..1], &u), "points");
    bad(PathFrames::try_new(&p[..1], &a[..1], &u[..1]), "points");
    bad(
        PathFrames::try_new(&[Vector3::zeros(), Vector3::repeat(f64::NAN)], &a, &u),
        "points[1]",
    );
    bad(
        PathFrames::try_new(&p, &[Vector3::z(), Vector3::new(0.0, 0.0, 2.0)], &u),
        "axes[1]",
    );
    bad(PathFrames::try_new(&p, &a, &[0.0, 0.0]), "u");
    // Unchecked construction of nonsense: no panic, NaN answers.
    let empty = PathFrames::new(&[], &[], &[]);
    assert!(empty.is_empty());
    assert!(empty.cl_point(0.5).x.is_nan());
    assert!(empty.frame(0.5).0.x.is_nan());
    assert!(empty.lead_tilt_at(3, &Vector3::z()).0.is_nan());
    let short = PathFrames::new(&p, &a[..1], &u);
    assert_eq!(short.len(), 1);
    assert_eq!(short.cl_point(0.7), Vector3::zeros());
}
