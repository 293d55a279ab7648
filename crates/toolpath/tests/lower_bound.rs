//! T_lb (the bang-bang bound) against exact answers on straight lines, its limits obeyed on a
//! smoothed zig-zag, and the arc-length samples against the pieces' lengths.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

#[allow(dead_code)] // each test file uses some of the shared data
mod support;
use support::ZIG_ZAG;

use kerf_toolpath::{bang_bang, sample_path, smooth_polyline, BangBangLimits, Piece};

fn limits(feed: f64, at: f64, an: f64) -> BangBangLimits {
    BangBangLimits {
        feed,
        tangential_acceleration: at,
        normal_acceleration: an,
    }
}

#[test]
fn straight_lines_give_the_trapezoid_and_the_triangle() {
    // 0.1 m at F = 0.05 m/s, A = 1 m/s²: L/F + F/A = 2.05 s.
    let path = smooth_polyline(&[[0.0; 3], [0.1, 0.0, 0.0]], 1e-4).unwrap();
    let lim = limits(0.05, 1.0, 1.0);
    let t = bang_bang(&sample_path(&path, 1e-3), &lim).unwrap().time;
    assert!((t - 2.05).abs() < 1e-12, "{t}");
    // 1 mm never reaches F: 2 √(L/A).
    let short = smooth_polyline(&[[0.0; 3], [0.0, 0.001, 0.0]], 1e-4).unwrap();
    let t = bang_bang(&sample_path(&short, 1e-6), &lim).unwrap().time;
    assert!((t - 2.0 * (0.001f64).sqrt()).abs() < 1e-12, "{t}");
}

#[test]
fn a_smoothed_zig_zag_obeys_every_limit_and_slows_in_its_corners() {
    let poly = ZIG_ZAG;
    let path = smooth_polyline(&poly, 1e-4).unwrap();
    let samples = sample_path(&path, 2e-5);
    // The samples' arc length matches the pieces' lengths.
    let total: f64 = path
        .pieces
        .iter()
        .map(|p| match p {
            Piece::Line { start, end } => {
                kerf_toolpath::vec3::norm(kerf_toolpath::vec3::sub(*end, *start))
            }
            Piece::Corner(c) => c.curve.length(64),
        })
        .sum();
    let last = samples.last().unwrap().s;
    assert!((last - total).abs() < 1e-12, "{last} vs {total}");
    let lim = limits(0.1, 2.0, 0.5);
    let b = bang_bang(&samples, &lim).unwrap();
    for (i, w) in samples.windows(2).enumerate() {
        let (v0, v1) = (b.speed[i], b.speed[i + 1]);
        let a = (v1 * v1 - v0 * v0) / (2.0 * (w[1].s - w[0].s));
        assert!(a.abs() <= 2.0 * (1.0 + 1e-9), "sample {i}: {a}");
        assert!(v1 <= 0.1 + 1e-15);
        assert!(v1 * v1 * w[1].curvature <= 0.5 * (1.0 + 1e-9));
    }
    // The corners bind: the speed falls below F somewhere inside, and tighter limits take longer.
    assert!(b
        .speed
        .iter()
        .zip(&b.limit)
        .any(|(v, l)| *v < 0.1 && (v - l).abs() < 1e-15));
    let slower = bang_bang(&samples, &limits(0.1, 2.0, 0.1)).unwrap();
    assert!(slower.time > b.time);
    let faster = bang_bang(&samples, &limits(0.1, 2.0, 5.0)).unwrap();
    assert!(faster.time < b.time);
}

#[test]
fn bad_limits_and_samples_are_refused() {
    let path = smooth_polyline(&[[0.0; 3], [0.1, 0.0, 0.0], [0.1, 0.1, 0.0]], 1e-4).unwrap();
    let samples = sample_path(&path, 1e-3);
    for bad in [
        limits(0.0, 1.0, 1.0),
        limits(0.1, -1.0, 1.0),
        limits(0.1, 1.0, f64::NAN),
    ] {
        assert!(bang_bang(&samples, &bad).is_err());
    }
    assert!(bang_bang(&samples[..1], &limits(0.1, 1.0, 1.0)).is_err());
    let mut reversed = samples.clone();
    reversed.swap(1, 2);
    let e = bang_bang(&reversed, &limits(0.1, 1.0, 1.0)).unwrap_err();
    assert!(e.to_string().contains("arc length"), "{e}");
}

/// `point_at` puts a point on the geometry at its arc length: at the samples it is the sample,
/// between samples of a corner its arc length from the sample before is the requested one.
#[test]
fn points_at_arc_lengths_are_on_the_geometry() {
    let poly = [[0.0, 0.0, 0.0], [0.02, 0.0, 0.0], [0.03, 0.01, 0.0]];
    let path = smooth_polyline(&poly, 1e-4).unwrap();
    let samples = sample_path(&path, 2e-4);
    let mut checked = 0;
    for w in samples.windows(2) {
        let at = kerf_toolpath::point_at(&path, &samples, w[1].s);
        let off = kerf_toolpath::vec3::norm(kerf_toolpath::vec3::sub(at, w[1].point));
        assert!(off < 1e-12, "{off}");
        if w[0].piece == w[1].piece {
            if let Piece::Corner(c) = &path.pieces[w[1].piece] {
                let s = 0.5 * (w[0].s + w[1].s);
                let p = kerf_toolpath::point_at(&path, &samples, s);
                // Find its parameter by bisection on the distance along the chord direction.
                let (mut lo, mut hi) = (w[0].u, w[1].u);
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if c.curve.length_between(w[0].u, mid) < s - w[0].s {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let exact = c.curve.point(0.5 * (lo + hi));
                let err = kerf_toolpath::vec3::norm(kerf_toolpath::vec3::sub(p, exact));
                assert!(err < 1e-12, "{err}");
                checked += 1;
            }
        }
    }
    assert!(checked > 3);
}
