//! `sample_path_adaptive`: steps bounded in length and turning, samples at every extremum of a
//! corner's curvature (so the curvature is monotone between neighbours), and feed plans on these
//! samples hold every limit on the output.
#![allow(clippy::unwrap_used, clippy::expect_used)]

#[allow(dead_code)] // the tests' shared data; this file uses some of it
mod support;
use support::{feed_limits, outlines, program_polyline, seed_000_limits, t_lb};

use kerf_toolpath::{
    check_plan, plan_feed_optimal, sample_path, sample_path_adaptive, smooth_polyline,
    smooth_polyline_with, AxisLimits, CornerMethod, FeedConstraints, FeedLimits, PathSample, Piece,
    Sampling, SmoothedPath, ToolpathError,
};

const STEP: f64 = 1e-3;
const TURN_DEG: f64 = 2.0;

fn turn() -> f64 {
    TURN_DEG.to_radians()
}

/// The shipped G-code programs' G01 polylines \[m\].
fn programs() -> Vec<(&'static str, Vec<[f64; 3]>)> {
    ["w_shape", "dress", "torch", "rosette_dense_g64"]
        .into_iter()
        .map(|name| (name, program_polyline(name)))
        .collect()
}

/// Every property of the samples of one path: arc lengths growing, steps within the bounds (an
/// inserted extremum only splits a step), every corner's largest curvature sampled, and the
/// curvature between neighbours at most the larger of their two values (256 points per step).
/// Returns the largest relative excess over that value (an extremum pair inside one step, on
/// the flat top of a curvature plateau).
fn check_samples(name: &str, path: &SmoothedPath, samples: &[PathSample]) -> f64 {
    let mut excess = 0.0f64;
    let mut slope_excess = 0.0f64;
    for w in samples.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        assert!(b.s > a.s, "{name}: arc length not growing at s {}", a.s);
        assert!(a.monotone, "{name}: an adaptive sample not marked monotone");
        let Some(Piece::Corner(c)) = path.pieces.get(b.piece) else {
            assert_eq!(b.curvature, 0.0, "{name}: a line's sample");
            continue;
        };
        let ua = if a.piece == b.piece { a.u } else { 0.0 };
        assert!(
            b.s - a.s <= STEP * (1.0 + 1e-9),
            "{name}: step {}",
            b.s - a.s
        );
        // The march bounds the angle between a step's end tangents. A sample inserted at an
        // extremum splits a step; where a baseline's corner turns back and forth inside it (CCR's
        // circumscribed curves have inflections) the halves may turn more, so the baselines are
        // held to 1.5 times the bound and kerf's corners (no inflection) to the bound itself.
        let bound = if name.ends_with("icr") || name.ends_with("ccr") {
            1.5 * turn()
        } else {
            turn()
        };
        let inflection = a.curvature.min(b.curvature) < 1e-3 * c.max_curvature;
        let cos = a
            .tangent
            .iter()
            .zip(b.tangent)
            .map(|(x, y)| x * y)
            .sum::<f64>();
        assert!(
            inflection || cos >= bound.cos() - 1e-12,
            "{name}: turn {}° from {a:?} to {b:?}",
            cos.acos().to_degrees()
        );
        let hi = a.curvature.max(b.curvature);
        let slope_hi = a.curvature_slope.max(b.curvature_slope);
        for k in 1..256 {
            let u = ua + (b.u - ua) * k as f64 / 256.0;
            let kappa = c.curve.curvature(u);
            // |dκ/ds| by a central difference over 1/1000 of the step.
            let h = 1e-3 * (b.u - ua);
            let speed = c.curve.d1(u).iter().map(|x| x * x).sum::<f64>().sqrt();
            let slope =
                (c.curve.curvature(u + h) - c.curve.curvature(u - h)).abs() / (2.0 * h * speed);
            if slope > slope_hi * (1.0 + 1e-3) + 1e-6 {
                slope_excess = slope_excess.max((slope - slope_hi) / slope_hi);
            }
            if kappa > hi {
                if (kappa - hi) / hi > 0.1 {
                    println!("{name}: {kappa} at u {u} between {a:?} and {b:?}");
                }
                excess = excess.max((kappa - hi) / hi);
            }
        }
    }
    for (index, piece) in path.pieces.iter().enumerate() {
        let Piece::Corner(c) = piece else { continue };
        let sampled = samples
            .iter()
            .filter(|p| p.piece == index)
            .map(|p| p.curvature)
            .fold(0.0, f64::max);
        assert!(
            sampled >= c.max_curvature * (1.0 - 1e-6),
            "{name}: corner {index}: sampled κ_max {sampled} < {}",
            c.max_curvature
        );
    }
    println!("{name}: |dκ/ds| between samples up to {slope_excess:.2e} above its ends'");
    assert!(
        slope_excess < kerf_toolpath::adaptive::SLOPE_SLACK,
        "{name}: |dκ/ds| between samples {slope_excess} above the larger of its ends'"
    );
    excess
}

#[test]
fn samples_bound_steps_and_hold_every_curvature_extremum() {
    let mut paths: Vec<(String, SmoothedPath)> = Vec::new();
    for (name, points) in outlines() {
        paths.push((
            format!("{name} kerf"),
            smooth_polyline(&points, 1e-4).unwrap(),
        ));
        for (m, method) in [("icr", CornerMethod::Icr), ("ccr", CornerMethod::Ccr)] {
            let p = smooth_polyline_with(&points, 1e-4, &method).unwrap();
            paths.push((format!("{name} {m}"), p));
        }
    }
    for (name, points) in programs() {
        paths.push((name.to_string(), smooth_polyline(&points, 1e-4).unwrap()));
    }
    let mut worst = (0.0, String::new());
    for (name, path) in &paths {
        let samples = sample_path_adaptive(path, STEP, turn()).unwrap();
        let excess = check_samples(name, path, &samples);
        if excess > worst.0 {
            worst = (excess, name.clone());
        }
        let fixed = sample_path(path, 1e-5);
        let (end, fixed_end) = (samples.last().unwrap().s, fixed.last().unwrap().s);
        assert!(
            (end - fixed_end).abs() < 1e-9 * end,
            "{name}: length {end} vs {fixed_end}"
        );
    }
    println!("largest curvature between samples over their larger value: {worst:?}");
    assert!(
        worst.0 <= kerf_toolpath::adaptive::MONOTONE_SLACK,
        "{worst:?} exceeds the limit curve's slack"
    );
}

/// The near time-optimal plan on adaptive samples holds every limit on the output (`check_plan`
/// at the interpolation period), with and without the laser cutter's axis limits, for the
/// outlines under both seeds' limits and for the programs, and is never slower than on the fixed
/// 10 µm samples by more than 3 % (with kerf's jerk-shaped corner the torch is 2.7 % and the W-shape 1.3 % slower on them).
#[test]
fn plans_on_adaptive_samples_hold_every_limit() {
    let (l000, d000) = seed_000_limits();
    let mut cases: Vec<(String, Vec<[f64; 3]>, f64, FeedLimits)> = Vec::new();
    for (name, points) in outlines() {
        cases.push((format!("{name} seed 000"), points.clone(), d000, l000));
        cases.push((format!("{name} seed 003"), points, 1e-4, feed_limits()));
    }
    for (name, points) in programs() {
        cases.push((name.to_string(), points, 1e-4, feed_limits()));
    }
    for (name, points, delta, limits) in &cases {
        let path = smooth_polyline(points, *delta).unwrap();
        let c = FeedConstraints::new(*limits);
        let period = limits.curvature.interpolation_period;
        let samples = sample_path_adaptive(&path, STEP, turn()).unwrap();
        let plan = plan_feed_optimal(&samples, &c).unwrap();
        let check = check_plan(&path, &samples, &plan, &c, period).unwrap();
        assert!(check.holds(1e-9), "{name}: {:?}", check.worst());
        // With the laser cutter's axis limits: the axis jerk bound of a monotone interval
        // (|κ′| + κ², κ′ from the samples' slopes) holds on the output too.
        let axes = FeedConstraints {
            axes: Some(AxisLimits::laser_cutter()),
            ..c
        };
        let with_axes = plan_feed_optimal(&samples, &axes).unwrap();
        let check = check_plan(&path, &samples, &with_axes, &axes, period).unwrap();
        assert!(check.holds(1e-9), "{name} with axes: {:?}", check.worst());
        let lb = t_lb(&samples, limits);
        println!(
            "{name}: {} samples, T_m {:.4} s, T_m/T_lb {:.4}",
            samples.len(),
            plan.time,
            plan.time / lb
        );
        assert!(plan.time >= lb * (1.0 - 1e-9), "{name}: below T_lb");
        // Against the fixed 10 µm samples (seed 003's limits; with seed 000's δ = 0.5 mm the
        // butterfly alone has 172 000 fixed samples, a long test in a debug build).
        if limits.curvature.servo.is_some() {
            let fixed = sample_path(&path, 1e-5);
            let fixed_plan = plan_feed_optimal(&fixed, &c).unwrap();
            println!(
                "  fixed: {} samples, T_m {:.4} s",
                fixed.len(),
                fixed_plan.time
            );
            assert!(
                plan.time <= fixed_plan.time * 1.03,
                "{name}: {} s against {} s on fixed samples",
                plan.time,
                fixed_plan.time
            );
        }
    }
}

#[test]
fn bad_bounds_are_refused() {
    let path = smooth_polyline(&[[0.0; 3], [0.01, 0.0, 0.0], [0.01, 0.01, 0.0]], 1e-4).unwrap();
    for (step, turn) in [
        (0.0, 0.01),
        (-1e-3, 0.01),
        (f64::NAN, 0.01),
        (f64::INFINITY, 0.01),
        (1e-3, 0.0),
        (1e-3, 2.0),
        (1e-3, f64::NAN),
    ] {
        let e = sample_path_adaptive(&path, step, turn).unwrap_err();
        assert!(matches!(e, ToolpathError::InvalidParameter { .. }), "{e}");
        let e = Sampling::Adaptive {
            max_step: step,
            max_turn: turn,
        }
        .sample(&path)
        .unwrap_err();
        assert!(matches!(e, ToolpathError::InvalidParameter { .. }), "{e}");
    }
    for step in [0.0, -1e-5, f64::NAN, f64::INFINITY] {
        let e = Sampling::Fixed { step }.sample(&path).unwrap_err();
        assert!(matches!(e, ToolpathError::InvalidParameter { .. }), "{e}");
    }
    // Finer divides every bound.
    assert_eq!(
        Sampling::adaptive().finer(4.0),
        Sampling::Adaptive {
            max_step: 2.5e-4,
            max_turn: 0.5f64.to_radians(),
        }
    );
}

/// Positions and derivatives by arc length (`derivatives_at`) on adaptive samples agree with
/// those on 1 µm fixed samples: the Newton steps on the arc length converge from the farther
/// guess.
#[test]
fn positions_by_arc_length_match_fine_fixed_samples() {
    for (name, points) in outlines()
        .into_iter()
        .chain(programs().into_iter().map(|(n, p)| (n.to_string(), p)))
    {
        let path = smooth_polyline(&points, 1e-4).unwrap();
        let adaptive = sample_path_adaptive(&path, STEP, turn()).unwrap();
        let fine = sample_path(&path, 1e-6);
        let length = adaptive.last().unwrap().s;
        let mut worst = (0.0f64, 0.0f64);
        for k in 0..20_000 {
            let s = length * (k as f64 + 0.5) / 20_000.0;
            let (p, t, n) = kerf_toolpath::derivatives_at(&path, &adaptive, s);
            let (q, u, m) = kerf_toolpath::derivatives_at(&path, &fine, s);
            let d = (0..3).map(|i| (p[i] - q[i]).abs()).fold(0.0, f64::max);
            let dt = (0..3).map(|i| (t[i] - u[i]).abs()).fold(0.0, f64::max);
            let dn = (0..3)
                .map(|i| (n[i] - m[i]).abs() / (1.0 + m[i].abs()))
                .fold(0.0, f64::max);
            worst = (worst.0.max(d), worst.1.max(dt.max(dn)));
        }
        println!(
            "{name}: position {:.3e} m, derivatives {:.3e}",
            worst.0, worst.1
        );
        assert!(worst.0 < 1e-10 && worst.1 < 1e-6, "{name}: {worst:?}");
    }
}
