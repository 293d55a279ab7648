//! The corner-smoothing baselines (ICR, CCR, seed 003's NURBS corner by PSO) next to kerf's corner,
//! checked on the shipped outlines and on hand corners: within δ of the polyline (brute force),
//! pieces that chain, curvature against finite differences, determinism of the swarm, bad input.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

#[allow(dead_code)] // each test file uses some of the shared data
mod support;
use support::{corner_points, sampled_deviation};

use kerf_gcode::{read_points, PointUnit};
use kerf_toolpath::baseline::{ccr, icr, nurbs};
use kerf_toolpath::vec3::{cross, dot, norm, sub};
use kerf_toolpath::{
    derivatives_at, plan_feed, point_at, sample_path, smooth_polyline, smooth_polyline_with,
    CornerMethod, CubicSpline, NurbsSettings, Piece, SmoothedPath, ToolpathError,
};

/// A smaller swarm than the default, to keep the outline tests short.
fn quick_swarm() -> NurbsSettings {
    NurbsSettings {
        particles: 8,
        iterations: 12,
        ..NurbsSettings::default()
    }
}

/// The baselines, and kerf's corner for comparison.
fn methods() -> [CornerMethod; 4] {
    [
        CornerMethod::Kerf,
        CornerMethod::Icr,
        CornerMethod::Ccr,
        CornerMethod::Nurbs(quick_swarm()),
    ]
}

/// The shipped outlines (`data/outlines/*.txt`, mm), read as the pipeline bench reads them \[m\].
fn outlines() -> Vec<(String, Vec<[f64; 3]>)> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/outlines");
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "txt"))
        .collect();
    names.sort();
    assert_eq!(names.len(), 4, "the four outlines");
    names
        .iter()
        .map(|p| {
            let text = std::fs::read_to_string(p).unwrap();
            let points = read_points(text.as_bytes(), PointUnit::Millimetre).unwrap();
            (p.file_stem().unwrap().to_string_lossy().to_string(), points)
        })
        .collect()
}

#[test]
fn the_basis_constants_of_the_deviation_formulas_are_the_splines() {
    let at_half = |knots: &[f64]| {
        let n = knots.len() - 4;
        let s = CubicSpline::new(&vec![[0.0; 3]; n], &vec![1.0; n], knots).unwrap();
        let (first, b) = s.basis(0.5);
        let mut full = vec![0.0; n];
        full[first..first + 4].copy_from_slice(&b[0]);
        full
    };
    let icr_half = at_half(&icr::KNOTS);
    assert!(
        (icr_half[3] - icr::MID_WEIGHT).abs() < 1e-15,
        "{icr_half:?}"
    );
    assert!((icr_half[2] - 0.5).abs() < 1e-15 && (icr_half[1] - 0.25).abs() < 1e-15);
    let nurbs_half = at_half(&nurbs::KNOTS);
    assert!(
        (nurbs_half[2] - nurbs::SIDE_WEIGHT).abs() < 1e-15,
        "{nurbs_half:?}"
    );
    assert!((nurbs_half[3] - nurbs::CENTRE_WEIGHT).abs() < 1e-15);
    assert!((nurbs_half[4] - nurbs::SIDE_WEIGHT).abs() < 1e-15);
    // CCR's PEAK: the largest N₃ on ICR's knots, by dense sampling.
    let s = CubicSpline::new(&[[0.0; 3]; 5], &[1.0; 5], &icr::KNOTS).unwrap();
    let mut peak: f64 = 0.0;
    for k in 0..=200_000 {
        let (first, b) = s.basis(k as f64 / 200_000.0);
        if (first..first + 4).contains(&3) {
            peak = peak.max(b[0][3 - first]);
        }
    }
    assert!(peak <= ccr::PEAK * (1.0 + 1e-15), "{peak}");
    assert!(peak >= ccr::PEAK * (1.0 - 1e-9), "{peak}");
    // The basis is a partition of unity with derivatives summing to zero.
    for k in 0..=100 {
        let (_, b) = s.basis(k as f64 / 100.0);
        assert!((b[0].iter().sum::<f64>() - 1.0).abs() < 1e-14);
        assert!(b[1].iter().sum::<f64>().abs() < 1e-12);
        assert!(b[2].iter().sum::<f64>().abs() < 1e-10);
    }
}

#[test]
fn every_corner_is_within_its_stated_deviation_and_the_tolerance() {
    let delta = 1e-4;
    for deg in [0.5, 5.0, 30.0, 60.0, 90.0, 120.0, 150.0, 170.0, 179.0] {
        let [a, v, b] = corner_points(deg);
        for available in [0.010, 0.0005] {
            for method in &methods() {
                let c = method
                    .transition(a, v, b, delta, available, 1)
                    .unwrap()
                    .unwrap();
                assert!(c.deviation <= delta * (1.0 + 1e-12), "{method:?} {deg}");
                let worst = sampled_deviation(&c.curve, a, v, b);
                let name = method.name();
                assert!(
                    worst <= c.deviation * (1.0 + 1e-9),
                    "{name} {deg}: sampled {worst} > {}",
                    c.deviation
                );
                // ICR's, NURBS's (and kerf's) are exact, CCR's up to 90°.
                if !matches!(method, CornerMethod::Ccr) || deg <= 90.0 {
                    assert!(
                        worst >= c.deviation * (1.0 - 1e-6),
                        "{name} {deg}: sampled {worst} < {}",
                        c.deviation
                    );
                }
                // Within the length it was given on each side.
                assert!(norm(sub(c.curve.start(), v)) <= available * (1.0 + 1e-12));
                assert!(norm(sub(c.curve.end(), v)) <= available * (1.0 + 1e-12));
                assert!(c.tangent_length <= available * (1.0 + 1e-12));
            }
        }
    }
}

/// Every method's path on every outline at both of the bench's tolerances.
fn outline_paths(method: &CornerMethod) -> Vec<(String, f64, SmoothedPath)> {
    let mut out = Vec::new();
    for (name, points) in outlines() {
        for delta in [1e-4, 5e-4] {
            out.push((
                name.clone(),
                delta,
                smooth_polyline_with(&points, delta, method).unwrap(),
            ));
        }
    }
    out
}

#[test]
fn on_the_outlines_every_method_stays_within_the_tolerance_and_chains() {
    for method in &methods() {
        let name = method.name();
        for (outline, delta, path) in outline_paths(method) {
            assert!(path.corners().count() > 150, "{name} {outline}");
            // Brute force: dense samples of every piece against every segment.
            let worst = path.distance_from_polyline(&path.sample(64));
            assert!(
                worst <= delta * (1.0 + 1e-9),
                "{name} {outline} {delta}: {worst}"
            );
            assert!(worst <= path.max_deviation() * (1.0 + 1e-9) + 1e-15);
            // Pieces chain end to start, tangents agree, and the curvature is zero at a
            // corner's ends (G2 with the lines).
            let ends = |p: &Piece| match p {
                Piece::Line { start, end } => (*start, *end, sub(*end, *start), sub(*end, *start)),
                Piece::Corner(c) => (
                    c.curve.point(0.0),
                    c.curve.point(1.0),
                    c.curve.d1(0.0),
                    c.curve.d1(1.0),
                ),
            };
            assert_eq!(ends(&path.pieces[0]).0, path.polyline[0]);
            assert_eq!(
                ends(path.pieces.last().unwrap()).1,
                *path.polyline.last().unwrap()
            );
            for w in path.pieces.windows(2) {
                let (_, end, _, t_end) = ends(&w[0]);
                let (start, _, t_start, _) = ends(&w[1]);
                assert!(norm(sub(end, start)) <= 1e-12, "{name} {outline}: {w:?}");
                if norm(t_end) > 1e-6 && norm(t_start) > 1e-6 {
                    let angle = norm(cross(t_end, t_start)).atan2(dot(t_end, t_start));
                    assert!(angle < 1e-9, "{name} {outline}: {angle}");
                }
            }
            for p in &path.pieces {
                if let Piece::Corner(c) = p {
                    let ends = c.curve.curvature(0.0).max(c.curve.curvature(1.0));
                    // (Rounding of the control points on the lines leaves ~1e-8 of κ_max; a G1 corner
                    // would start at a fair fraction of it.)
                    assert!(
                        ends <= 1e-7 * c.max_curvature + 1e-6,
                        "{name} {outline} {delta}: {ends} vs {} at turn {}",
                        c.max_curvature,
                        c.turn
                    );
                    assert!(c.max_curvature.is_finite() && c.max_curvature > 0.0);
                }
            }
        }
    }
}

#[test]
fn curvature_is_finite_and_matches_finite_differences() {
    for deg in [20.0, 90.0, 160.0] {
        let [a, v, b] = corner_points(deg);
        for method in &methods()[1..] {
            let c = method.transition(a, v, b, 1e-4, 0.01, 3).unwrap().unwrap();
            let name = method.name();
            let curve = c.curve;
            let h = 1e-4;
            let mut sampled: f64 = 0.0;
            for k in 1..200 {
                // Off the knots (multiples of 1/4): the parameter derivatives are smooth there.
                let u = (k as f64 + 0.37) / 200.0;
                let (pm, p0, pp) = (curve.point(u - h), curve.point(u), curve.point(u + h));
                let d1: [f64; 3] = std::array::from_fn(|d| (pp[d] - pm[d]) / (2.0 * h));
                let d2: [f64; 3] = std::array::from_fn(|d| (pp[d] - 2.0 * p0[d] + pm[d]) / (h * h));
                let fd = norm(cross(d1, d2)) / norm(d1).powi(3);
                let kappa = curve.curvature(u);
                assert!(kappa.is_finite());
                assert!(
                    (fd - kappa).abs() <= 1e-4 * c.max_curvature,
                    "{name} {deg} u {u}: {fd} vs {kappa}"
                );
                // The parameter derivatives themselves (C″'s part along C′ does not change κ).
                let h1 = 1e-6;
                let (qm, qp) = (curve.point(u - h1), curve.point(u + h1));
                let fd1: [f64; 3] = std::array::from_fn(|d| (qp[d] - qm[d]) / (2.0 * h1));
                let (e1, e2) = (curve.d1(u), curve.d2(u));
                assert!(norm(sub(e1, fd1)) <= 1e-6 * norm(e1), "{name} {deg} u {u}");
                assert!(
                    norm(sub(e2, d2)) <= 1e-4 * (norm(e2) + norm(e1)),
                    "{name} {deg} u {u}: {e2:?} vs {d2:?}"
                );
                sampled = sampled.max(kappa);
            }
            // The stated largest curvature is the curve's (sampled, refined).
            for k in 0..=4000 {
                sampled = sampled.max(curve.curvature(k as f64 / 4000.0));
            }
            assert!(sampled <= c.max_curvature * (1.0 + 1e-6), "{name} {deg}");
            assert!(sampled >= c.max_curvature * (1.0 - 1e-3), "{name} {deg}");
        }
    }
    // CCR passes through the vertex with continuous curvature (G2 there, not only at the lines).
    let [a, v, b] = corner_points(70.0);
    let c = CornerMethod::Ccr
        .transition(a, v, b, 1e-4, 0.01, 1)
        .unwrap()
        .unwrap();
    assert!(norm(sub(c.curve.point(0.5), v)) < 1e-15);
    let (left, right) = (c.curve.curvature(0.5 - 1e-9), c.curve.curvature(0.5 + 1e-9));
    assert!((left - right).abs() <= 1e-6 * left, "{left} {right}");
}

#[test]
fn the_swarm_is_deterministic_and_optimizes() {
    let points = &outlines()[1].1;
    let method = CornerMethod::Nurbs(quick_swarm());
    let a = smooth_polyline_with(points, 1e-4, &method).unwrap();
    let b = smooth_polyline_with(points, 1e-4, &method).unwrap();
    let bits = |p: &SmoothedPath| -> Vec<u64> {
        p.sample(16).iter().flatten().map(|x| x.to_bits()).collect()
    };
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(a, b);
    // Another seed draws other particles: a different path.
    let other = CornerMethod::Nurbs(NurbsSettings {
        seed: 7,
        ..quick_swarm()
    });
    assert_ne!(
        bits(&a),
        bits(&smooth_polyline_with(points, 1e-4, &other).unwrap())
    );
    // More iterations of the same stream can only lower the optimum, and do.
    let [p, v, n] = corner_points(90.0);
    let kappa = |iterations| {
        let s = NurbsSettings {
            iterations,
            ..NurbsSettings::default()
        };
        CornerMethod::Nurbs(s)
            .transition(p, v, n, 1e-4, 0.01, 1)
            .unwrap()
            .unwrap()
    };
    let (short, long) = (kappa(1), kappa(40));
    assert!(
        long.max_curvature < 0.999 * short.max_curvature,
        "{} vs {}",
        long.max_curvature,
        short.max_curvature
    );
    // The weight solves eq. 7's last line: the deviation is δ where the tolerance binds.
    assert!(
        (long.deviation - 1e-4).abs() <= 1e-12 * 1e-4,
        "{}",
        long.deviation
    );
}

#[test]
fn kerf_through_the_method_is_smooth_polyline() {
    for (_, points) in outlines() {
        for delta in [1e-4, 5e-4] {
            assert_eq!(
                smooth_polyline_with(&points, delta, &CornerMethod::Kerf).unwrap(),
                smooth_polyline(&points, delta).unwrap()
            );
        }
    }
}

#[test]
fn bad_input_is_refused_by_name() {
    let [a, v, b] = corner_points(90.0);
    for method in &methods() {
        for delta in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let e = smooth_polyline_with(&[a, v, b], delta, method).unwrap_err();
            assert!(e.to_string().contains("tolerance"), "{e}");
        }
        let e = smooth_polyline_with(&[a, [f64::NAN, 0.0, 0.0], b], 1e-4, method).unwrap_err();
        assert!(matches!(e, ToolpathError::BadPoint { index: 1, .. }), "{e}");
        let e = smooth_polyline_with(&[a, v, v, b], 1e-4, method).unwrap_err();
        assert!(matches!(e, ToolpathError::BadPoint { index: 2, .. }), "{e}");
        // A reversal cannot be smoothed within a tolerance.
        let reversal = [[0.0; 3], [0.01, 0.0, 0.0], [0.0, 0.0, 0.0]];
        let e = smooth_polyline_with(&reversal, 1e-4, method).unwrap_err();
        assert!(e.to_string().contains("reversal"), "{e}");
        assert!(smooth_polyline_with(&[a], 1e-4, method).is_err());
    }
    let base = NurbsSettings::default();
    let bad = [
        (
            "particles",
            NurbsSettings {
                particles: 1,
                ..base
            },
        ),
        (
            "iterations",
            NurbsSettings {
                iterations: 0,
                ..base
            },
        ),
        (
            "inertia",
            NurbsSettings {
                inertia: 1.0,
                ..base
            },
        ),
        (
            "inertia",
            NurbsSettings {
                inertia: f64::NAN,
                ..base
            },
        ),
        (
            "c1",
            NurbsSettings {
                c1: f64::INFINITY,
                ..base
            },
        ),
        ("c3", NurbsSettings { c3: -0.1, ..base }),
        (
            "c1 + c2",
            NurbsSettings {
                c1: 0.0,
                c2: 0.0,
                ..base
            },
        ),
        (
            "min_weight",
            NurbsSettings {
                min_weight: 0.0,
                ..base
            },
        ),
        (
            "max_weight",
            NurbsSettings {
                max_weight: 0.005,
                ..base
            },
        ),
    ];
    for (name, settings) in bad {
        // Refused even on a path without a corner.
        let e = smooth_polyline_with(&[a, v], 1e-4, &CornerMethod::Nurbs(settings)).unwrap_err();
        assert!(
            matches!(&e, ToolpathError::InvalidParameter { name: n, .. } if n.ends_with(name)),
            "{name}: {e}"
        );
    }
    // Spline construction refuses what it cannot evaluate.
    assert!(CubicSpline::new(&[[0.0; 3]; 3], &[1.0; 3], &[0.0; 7]).is_err());
    assert!(CubicSpline::new(&[[0.0; 3]; 5], &[1.0, 1.0, 0.0, 1.0, 1.0], &icr::KNOTS).is_err());
    let unclamped = [0.0, 0.0, 0.0, 0.1, 0.5, 1.0, 1.0, 1.0, 1.0];
    assert!(CubicSpline::new(&[[0.0; 3]; 5], &[1.0; 5], &unclamped).is_err());
}

#[test]
fn every_method_runs_through_sampling_and_the_feed_plan() {
    // The butterfly's hairpins with seed 003's limits: every corner's samples must give the
    // planner a positive speed (a CCR end sample once had κ ~ 1e-14 1/m from rounding, where
    // the contour-error speed of seed 003 eq. 17 cancelled to 0 before main's 7462289).
    let points = &outlines()[0].1;
    for method in &methods() {
        let path = smooth_polyline_with(points, 1e-4, method).unwrap();
        let samples = sample_path(&path, 1e-5);
        let plan = plan_feed(&samples, &support::feed_limits()).unwrap();
        assert!(
            plan.time.is_finite() && plan.time > 0.0,
            "{}",
            method.name()
        );
        // And the shared zig-zag of short and long segments, within δ by brute force.
        let zig = smooth_polyline_with(&support::ZIG_ZAG, 5e-5, method).unwrap();
        assert!(zig.distance_from_polyline(&zig.sample(400)) <= 5e-5 * (1.0 + 1e-9));
        let plan = plan_feed(&sample_path(&zig, 1e-5), &support::feed_limits()).unwrap();
        assert!(plan.time > 0.0, "{}", method.name());
    }
}

#[test]
fn arc_length_derivatives_match_central_differences_on_baseline_corners() {
    let polyline = [
        [0.0, 0.0, 0.0],
        [0.01, 0.0, 0.0],
        [0.01, 0.01, 0.0],
        [0.0, 0.012, 0.001],
    ];
    for method in &methods()[1..] {
        let name = method.name();
        let path = smooth_polyline_with(&polyline, 1e-4, method).unwrap();
        let samples = sample_path(&path, 1e-5);
        let length = samples.last().unwrap().s;
        let (h1, h2) = (1e-7, 2e-6);
        // G2 joins, not G3: dκ/ds jumps at a corner's end (ICR's κ grows linearly from it), so a
        // second difference straddling a join is off by about dκ/ds · h; those points are skipped.
        let joins: Vec<f64> = samples
            .windows(2)
            .filter(|w| w[0].piece != w[1].piece)
            .map(|w| w[0].s)
            .collect();
        assert!(joins.len() >= 3, "{name}: {joins:?}");
        let mut on_corners = 0;
        for k in 1..400 {
            let s = length * k as f64 / 400.0;
            if joins.iter().any(|j| (s - j).abs() < 3.0 * h2) {
                continue;
            }
            let (p, d1, d2) = derivatives_at(&path, &samples, s);
            let at = |x: f64| point_at(&path, &samples, x);
            let (pm1, pp1, pm2, pp2) = (at(s - h1), at(s + h1), at(s - h2), at(s + h2));
            for d in 0..3 {
                let first = (pp1[d] - pm1[d]) / (2.0 * h1);
                let second = (pp2[d] - 2.0 * p[d] + pm2[d]) / (h2 * h2);
                assert!(
                    (first - d1[d]).abs() < 1e-5,
                    "{name} s {s}: {first} vs {}",
                    d1[d]
                );
                assert!(
                    (second - d2[d]).abs() < 2e-2 * (1.0 + d2[d].abs()),
                    "{name} s {s}: {second} vs {}",
                    d2[d]
                );
            }
            if d2.iter().any(|v| *v != 0.0) {
                on_corners += 1;
            }
        }
        assert!(on_corners > 10, "{name}: the corners were sampled");
    }
}
