//! The near time-optimal feed plan (`plan_feed_optimal`) on the shipped outlines and on hand
//! paths: every limit holds on the output sampled at the interpolation period (`check_plan`, and
//! an independent check by finite differences of the interpolated positions), T ≥ T_lb, the time
//! against T_lb, per-sample feeds across a change without stopping, axis limits that bind, and bad
//! input refused.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

#[allow(dead_code)] // each test file uses some of the shared data
mod support;
use support::{feed_limits, outlines, seed_000_limits, t_lb, ZIG_ZAG};

use kerf_toolpath::scurve::{reachable, reachable_closed_form, scurve_distance};
use kerf_toolpath::{
    check_plan, plan_feed, plan_feed_optimal, point_at, sample_path, smooth_polyline, AxisLimits,
    FeedConstraints, FeedMethod, FeedPlan, PathSample, Piece, SmoothedPath,
};

/// Rounding margin on every ratio of `check_plan`.
const MARGIN: f64 = 1e-9;

/// The independent check: positions on the geometry at the plan's arc length every period,
/// then finite differences. A central difference of order k over the period is a weighted mean
/// (positive B-spline weights) of the k-th derivative over the points it spans, so it cannot
/// exceed the largest value there: the speed |Δp|/T ≤ F, per axis the differences ≤ the axis
/// limits, and the differences of s(t) ≤ A_t, J_t. The last point (at T_m, not a multiple of the
/// period) is left out.
fn finite_difference_check(
    path: &SmoothedPath,
    samples: &[PathSample],
    plan: &FeedPlan,
    c: &FeedConstraints<'_>,
) {
    let period = c.limits.curvature.interpolation_period;
    let mut timed = plan.sample(period);
    timed.pop();
    let s: Vec<f64> = timed.iter().map(|p| p.s).collect();
    let p: Vec<[f64; 3]> = s.iter().map(|&s| point_at(path, samples, s)).collect();
    let (t2, t3) = (period * period, period * period * period);
    let tol = 1.0 + 1e-6;
    for w in s.windows(3) {
        let a = (w[2] - 2.0 * w[1] + w[0]) / t2;
        assert!(a.abs() <= c.limits.tangential_acceleration * tol, "a {a}");
    }
    for w in s.windows(4) {
        let j = (w[3] - 3.0 * w[2] + 3.0 * w[1] - w[0]) / t3;
        assert!(j.abs() <= c.limits.tangential_jerk * tol, "j {j}");
    }
    for (k, w) in p.windows(2).enumerate() {
        let d = kerf_toolpath::vec3::norm(kerf_toolpath::vec3::sub(w[1], w[0])) / period;
        assert!(d <= c.limits.curvature.feed * tol, "speed {d} at {k}");
    }
    let Some(axes) = &c.axes else { return };
    for i in 0..3 {
        for w in p.windows(2) {
            let v = (w[1][i] - w[0][i]) / period;
            assert!(v.abs() <= axes.velocity[i] * tol, "axis {i} v {v}");
        }
        for w in p.windows(3) {
            let a = (w[2][i] - 2.0 * w[1][i] + w[0][i]) / t2;
            assert!(a.abs() <= axes.acceleration[i] * tol, "axis {i} a {a}");
        }
        for w in p.windows(4) {
            let j = (w[3][i] - 3.0 * w[2][i] + 3.0 * w[1][i] - w[0][i]) / t3;
            assert!(j.abs() <= axes.jerk[i] * tol, "axis {i} j {j}");
        }
    }
}

/// Plans, checks (check_plan and finite differences) and returns the plan and T_lb.
fn plan_and_check(
    path: &SmoothedPath,
    samples: &[PathSample],
    c: &FeedConstraints<'_>,
) -> (FeedPlan, kerf_toolpath::PlanCheck) {
    let plan = plan_feed_optimal(samples, c).unwrap();
    let period = c.limits.curvature.interpolation_period;
    let check = check_plan(path, samples, &plan, c, period).unwrap();
    assert!(check.holds(MARGIN), "{:?}", check.worst());
    finite_difference_check(path, samples, &plan, c);
    let end = plan.sample(period).last().copied().unwrap();
    assert!((end.s - plan.length).abs() < 1e-9, "{end:?}");
    assert!(end.v.abs() < 1e-9, "{end:?}");
    (plan, check)
}

/// The ratio T_m/T_lb each outline must stay within with seed 003's limits. The goal is
/// 1.10; the gear is above it (1.125): its 24 teeth are 24 rises and falls between binding
/// corners 7 mm apart, and each double S-curve at J_t = 20 m/s³ takes about 1.2 times the
/// bang-bang time (0.161 s instead of 0.135 s from 27 to 24 mm/s over 6.8 mm), which no
/// jerk-limited plan avoids. kerf's default corner is the jerk shape (`corner_jerk`): its
/// κ_max is 5–20 % above the min-κ shape's, which seed 003's limits (v³κ² only) see, so the gear
/// is at 1.141 and the rose at 1.039 with it (1.125 and 1.029 with the min-κ shape).
const SEED_003_RATIO: [(&str, f64); 4] = [
    ("butterfly", 1.07),
    ("gear", 1.15),
    ("heart", 1.05),
    ("rose", 1.045),
];

#[test]
fn every_limit_holds_on_the_outlines_and_t_is_within_its_bound_of_t_lb() {
    let limits = feed_limits();
    for (name, points) in outlines() {
        let path = smooth_polyline(&points, 1e-4).unwrap();
        let samples = sample_path(&path, 1e-5);
        let c = FeedConstraints::new(limits);
        let (plan, check) = plan_and_check(&path, &samples, &c);
        let lb = t_lb(&samples, &limits);
        let old = plan_feed(&samples, &limits).unwrap();
        let ratio = plan.time / lb;
        println!(
            "{name}: T_m {:.3} s, T_lb {:.3} s, T_m/T_lb {ratio:.4} (plan_feed {:.4}), worst {:?}",
            plan.time,
            lb,
            old.time / lb,
            check.worst()
        );
        assert!(plan.time >= lb, "{name}: {} < T_lb {lb}", plan.time);
        let bound = SEED_003_RATIO.iter().find(|(n, _)| *n == name).unwrap().1;
        assert!(ratio <= bound, "{name}: {ratio} > {bound}");
        // Faster than plan_feed, except on the heart: there plan_feed's few sensitive intervals
        // run at the limits of the samples (breaking the normal jerk limit between them by
        // 0.08 %), while the limit curve here bounds the curvature between samples and the
        // chord of a whole period (T_lb under it is 1.8 % above T_lb).
        if name != "heart" {
            assert!(plan.time < old.time, "{name}: not faster than plan_feed");
        }
    }
}

#[test]
fn seed_000_limits_hold_and_stay_near_t_lb() {
    let (limits, delta) = seed_000_limits();
    for (name, points) in outlines()
        .into_iter()
        .filter(|(n, _)| n == "heart" || n == "rose")
    {
        let path = smooth_polyline(&points, delta).unwrap();
        let samples = sample_path(&path, 1e-5);
        let c = FeedConstraints::new(limits);
        let (plan, _) = plan_and_check(&path, &samples, &c);
        let ratio = plan.time / t_lb(&samples, &limits);
        assert!((1.0..=1.005).contains(&ratio), "{name}: {ratio}");
    }
}

#[test]
fn a_smoothed_zig_zag_holds_every_limit_and_binds_in_its_corners() {
    let path = smooth_polyline(&ZIG_ZAG, 1e-4).unwrap();
    let samples = sample_path(&path, 1e-5);
    let limits = feed_limits();
    let c = FeedConstraints::new(limits);
    let (plan, check) = plan_and_check(&path, &samples, &c);
    assert!(plan.time >= t_lb(&samples, &limits));
    // Some curvature limit binds (within 1 %), as does the tangential acceleration.
    let curvature = [
        check.normal_acceleration.ratio,
        check.normal_jerk.ratio,
        check.chord_error.ratio,
        check.contour_error.ratio,
    ];
    assert!(curvature.iter().any(|r| *r > 0.99), "{check:?}");
    assert!(check.tangential_acceleration.ratio > 0.999, "{check:?}");
    assert!(check.tangential_jerk.ratio > 0.999, "{check:?}");
}

#[test]
fn a_straight_line_is_the_s_curve_trapezoid() {
    let path = smooth_polyline(&[[0.0; 3], [0.1, 0.0, 0.0]], 1e-4).unwrap();
    let samples = sample_path(&path, 1e-3);
    let c = FeedConstraints::new(feed_limits());
    let (plan, _) = plan_and_check(&path, &samples, &c);
    let (f, a, j) = (0.070, 0.8, 20.0);
    let t_acc = f / a + a / j;
    let expected = 2.0 * t_acc + (0.1 - f * t_acc) / f;
    assert!((plan.time - expected).abs() < 1e-12, "{}", plan.time);
    // The same as plan_feed there, and as the method enum.
    let old = FeedMethod::ConstantIntervals.plan(&samples, &c).unwrap();
    assert!((plan.time - old.time).abs() < 1e-12);
    assert_eq!(FeedMethod::NearOptimal.plan(&samples, &c).unwrap(), plan);
    assert_eq!(old, plan_feed(&samples, &c.limits).unwrap());
}

/// Ten collinear lines of 10 mm along `dir` (unit), one sample at each joint.
fn straight(dir: [f64; 3]) -> SmoothedPath {
    let pieces = (0..10)
        .map(|k| Piece::Line {
            start: dir.map(|d| d * 0.01 * k as f64),
            end: dir.map(|d| d * 0.01 * (k + 1) as f64),
        })
        .collect();
    SmoothedPath {
        polyline: vec![[0.0; 3], dir.map(|d| d * 0.1)],
        tolerance: 1e-4,
        pieces,
    }
}

#[test]
fn feed_caps_hold_across_a_change_without_stopping() {
    let path = straight([1.0, 0.0, 0.0]);
    let samples = sample_path(&path, 1e-3);
    assert_eq!(samples.len(), 11);
    for (high, low, change) in [(0.05, 0.02, 5), (0.02, 0.05, 5)] {
        let caps: Vec<f64> = (0..11)
            .map(|k| if k <= change { high } else { low })
            .collect();
        let c = FeedConstraints {
            caps: Some(&caps),
            ..FeedConstraints::new(feed_limits())
        };
        let (plan, check) = plan_and_check(&path, &samples, &c);
        assert!(check.feed.ratio > 0.999, "{check:?}");
        let s_change = samples[change].s;
        let ts = plan.sample(0.002);
        // Within the lower cap over the interval of the change (between two samples the lower of
        // their caps), and never stopping between the first and the last 10 mm.
        for p in &ts {
            let k = samples.partition_point(|q| q.s <= p.s).clamp(1, 10);
            let cap = caps[k - 1].min(caps[k]);
            assert!(p.v <= cap * (1.0 + 1e-12), "{p:?}: cap {cap}");
            if p.s > 0.01 && p.s < 0.09 {
                assert!(p.v > 0.019, "stops at {p:?}");
            }
        }
        // The higher cap is used where it holds.
        let before = ts
            .iter()
            .filter(|p| p.s < s_change)
            .fold(0.0, |m, p| p.v.max(m));
        let after = ts
            .iter()
            .filter(|p| p.s > s_change)
            .fold(0.0, |m, p| p.v.max(m));
        assert!(before.max(after) > 0.0499, "{before} {after}");
    }
}

#[test]
fn axis_limits_bind_and_hold() {
    // Axis speed: a diagonal in XY at 0.03 m/s per axis runs at 0.03 √2 < F.
    let d = std::f64::consts::FRAC_1_SQRT_2;
    let path = straight([d, d, 0.0]);
    let samples = sample_path(&path, 1e-3);
    let axes = AxisLimits {
        velocity: [0.03, 0.03, 1.0],
        ..AxisLimits::laser_cutter()
    };
    let c = FeedConstraints {
        axes: Some(axes),
        ..FeedConstraints::new(feed_limits())
    };
    let (plan, check) = plan_and_check(&path, &samples, &c);
    assert!(check.axis_velocity[0].ratio > 0.999, "{check:?}");
    let top = plan.sample(0.002).iter().fold(0.0, |m, p| p.v.max(m));
    assert!((top - 0.03 * 2f64.sqrt()).abs() < 1e-9, "{top}");
    // Axis acceleration and jerk on the zig-zag: lower than the curvature limits allow.
    let path = smooth_polyline(&ZIG_ZAG, 1e-4).unwrap();
    let samples = sample_path(&path, 1e-5);
    let free = plan_feed_optimal(&samples, &FeedConstraints::new(feed_limits())).unwrap();
    let axes = AxisLimits {
        velocity: [1.0; 3],
        acceleration: [0.4; 3],
        jerk: [8.0; 3],
    };
    let c = FeedConstraints {
        axes: Some(axes),
        ..FeedConstraints::new(feed_limits())
    };
    let (plan, check) = plan_and_check(&path, &samples, &c);
    println!("axes: {check:?}");
    assert!(
        plan.time > free.time * 1.05,
        "{} vs {}",
        plan.time,
        free.time
    );
    let a = check
        .axis_acceleration
        .iter()
        .fold(0.0f64, |m, w| m.max(w.ratio));
    let j = check.axis_jerk.iter().fold(0.0f64, |m, w| m.max(w.ratio));
    // The tangential budget takes half of each axis's acceleration and jerk (AxisLimits): on
    // a straight line along an axis the acceleration reaches half, in the corners it may go
    // beyond with the normal part (0.502 with kerf's jerk-shaped corner, where the min-kappa
    // corner stayed at exactly half), and so does the jerk. (With the jerk-shaped corner the
    // axis jerk here is 0.615 of its limit, 0.588 with the limit curve of the adaptive sampling.)
    assert!((0.5 - 1e-9..=1.0 + 1e-9).contains(&a), "a {a}");
    assert!(j > 0.55, "j {j}");
    // The laser cutter's slides on an outline: never faster than without them.
    let (_, points) = outlines().into_iter().find(|(n, _)| n == "rose").unwrap();
    let path = smooth_polyline(&points, 1e-4).unwrap();
    let samples = sample_path(&path, 1e-5);
    let c = FeedConstraints {
        axes: Some(AxisLimits::laser_cutter()),
        ..FeedConstraints::new(feed_limits())
    };
    let (plan, check) = plan_and_check(&path, &samples, &c);
    let free = plan_feed_optimal(&samples, &FeedConstraints::new(feed_limits())).unwrap();
    println!(
        "rose with the laser cutter's axes: T {:.3} s against {:.3} s; {check:?}",
        plan.time, free.time
    );
    assert!(plan.time >= free.time);
}

#[test]
fn bad_input_is_refused() {
    let path = straight([1.0, 0.0, 0.0]);
    let samples = sample_path(&path, 1e-3);
    let ok = FeedConstraints::new(feed_limits());
    assert!(plan_feed_optimal(&samples, &ok).is_ok());
    let short = vec![0.05; 10];
    let mut bad_caps: Vec<Vec<f64>> = [f64::NAN, 0.0, -0.01, f64::INFINITY]
        .iter()
        .map(|&x| {
            let mut c = vec![0.05; 11];
            c[3] = x;
            c
        })
        .collect();
    bad_caps.push(short);
    for caps in &bad_caps {
        let c = FeedConstraints {
            caps: Some(caps),
            ..ok
        };
        let e = plan_feed_optimal(&samples, &c).unwrap_err();
        assert!(e.to_string().contains("feed cap"), "{e}");
        assert!(check_plan(
            &path,
            &samples,
            &plan_feed_optimal(&samples, &ok).unwrap(),
            &c,
            0.002
        )
        .is_err());
    }
    for (field, value) in [(0, f64::NAN), (1, 0.0), (2, -1.0), (0, f64::INFINITY)] {
        let mut axes = AxisLimits::laser_cutter();
        match field {
            0 => axes.velocity[1] = value,
            1 => axes.acceleration[2] = value,
            _ => axes.jerk[0] = value,
        }
        let c = FeedConstraints {
            axes: Some(axes),
            ..ok
        };
        let e = plan_feed_optimal(&samples, &c).unwrap_err();
        assert!(e.to_string().contains("axis"), "{e}");
    }
    let mut limits = feed_limits();
    limits.tangential_jerk = 0.0;
    assert!(plan_feed_optimal(&samples, &FeedConstraints::new(limits)).is_err());
    assert!(plan_feed_optimal(&samples[..1], &ok).is_err());
    let plan = plan_feed_optimal(&samples, &ok).unwrap();
    assert!(check_plan(&path, &samples, &plan, &ok, 0.0).is_err());
    // The constant-interval planner knows neither caps nor axes: refused, not ignored.
    let caps = vec![0.05; 11];
    let c = FeedConstraints {
        caps: Some(&caps),
        ..ok
    };
    assert!(FeedMethod::ConstantIntervals.plan(&samples, &c).is_err());
    assert!(FeedMethod::NearOptimal.plan(&samples, &c).is_ok());
}

/// check_plan sees a plan that breaks a limit: plan_feed's on the butterfly (its constant
/// interval speeds are the limits at the samples, and between samples the curvature is higher).
#[test]
fn check_plan_finds_a_broken_limit() {
    let (_, points) = outlines()
        .into_iter()
        .find(|(n, _)| n == "butterfly")
        .unwrap();
    // Samples every 100 µm: at 10 µm plan_feed breaks the normal jerk by only 1.3 % on kerf's
    // default corner (κ_max 57/mm on the butterfly), and by 0.3 % on ICR's.
    let path = smooth_polyline(&points, 1e-4).unwrap();
    let samples = sample_path(&path, 1e-4);
    let c = FeedConstraints::new(feed_limits());
    let old = plan_feed(&samples, &c.limits).unwrap();
    let check = check_plan(&path, &samples, &old, &c, 0.002).unwrap();
    assert!(!check.holds(MARGIN), "{check:?}");
    assert!(check.normal_jerk.ratio > 1.1, "{check:?}");
}

#[test]
fn closed_form_reach_matches_bisection() {
    for &(a, j) in &[(0.8, 20.0), (0.1, 10.0)] {
        for &v0 in &[0.0, 0.001, 0.01, 0.03, 0.2] {
            for &d in &[1e-7, 1e-5, 1e-4, 1e-3, 1e-2, 0.1] {
                let r1 = reachable(v0, d, 1.0, a, j);
                let r2 = reachable_closed_form(v0, d, 1.0, a, j);
                assert!(scurve_distance(v0, r2, a, j) <= d, "{v0} {d}");
                assert!(
                    (r1 - r2).abs() <= 1e-9 * r1.max(1e-3),
                    "{v0} {d}: {r1} vs {r2}"
                );
            }
        }
    }
}

/// The ratio T_m/T_lb each program must stay within (measured: 1.064, 1.057, 1.110, 1.236; the
/// torch and the rosette are above the 1.10, plan_feed gives 1.106 and 1.281 there). The
/// rosette's 1999 micro-segment corners have a few samples each, so the limit curve takes the
/// whole curvature change as the peak between two samples (`limit_curve`).
const PROGRAM_RATIO: [(&str, f64); 4] = [
    ("w_shape", 1.07),
    ("dress", 1.06),
    ("torch", 1.115),
    ("rosette_dense_g64", 1.24),
];

/// The G-code programs of `crates/gcode/data/programs` (W-shape, dress, torch, the dense rosette of
/// 1999 micro-segment corners): every limit holds on the output and T ≥ T_lb. The dress has
/// joints where κ ≈ 3·10⁻¹⁴ 1/m (where plan_feed once failed).
#[test]
fn every_limit_holds_on_the_programs() {
    let limits = feed_limits();
    for name in ["w_shape", "dress", "torch", "rosette_dense_g64"] {
        let polyline = support::program_polyline(name);
        let path = smooth_polyline(&polyline, 1e-4).unwrap();
        let samples = sample_path(&path, 1e-5);
        let c = FeedConstraints::new(limits);
        let (plan, check) = plan_and_check(&path, &samples, &c);
        let lb = t_lb(&samples, &limits);
        let old = plan_feed(&samples, &limits).unwrap();
        println!(
            "{name}: T_m {:.3} s, T_lb {lb:.3} s, T_m/T_lb {:.4} (plan_feed {:.4}), worst {:?}",
            plan.time,
            plan.time / lb,
            old.time / lb,
            check.worst()
        );
        assert!(plan.time >= lb, "{name}");
        let bound = PROGRAM_RATIO.iter().find(|(n, _)| *n == name).unwrap().1;
        assert!(plan.time / lb <= bound, "{name}: {}", plan.time / lb);
    }
}

/// Random polylines (a fixed linear congruential sequence): segments of 0.05–20 mm at any angle,
/// in 3-D, with random per-sample feeds and random axis limits; every limit holds on the output
/// and T ≥ T_lb.
#[test]
fn random_polylines_hold_every_limit() {
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for case in 0..12 {
        let mut p = [0.0f64; 3];
        let mut points = vec![p];
        for _ in 0..8 {
            let len = 5e-5 + 0.02 * next() * next();
            let d = [
                next() - 0.5,
                next() - 0.5,
                if case % 3 == 0 { next() - 0.5 } else { 0.0 },
            ];
            let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt().max(1e-9);
            p = std::array::from_fn(|i| p[i] + len * d[i] / n);
            points.push(p);
        }
        let Ok(path) = smooth_polyline(&points, 1e-4) else {
            continue;
        };
        let samples = sample_path(&path, 1e-5);
        let limits = if case % 2 == 0 {
            feed_limits()
        } else {
            seed_000_limits().0
        };
        let caps: Vec<f64> = samples
            .iter()
            .map(|_| limits.curvature.feed * (0.3 + 0.7 * next()))
            .collect();
        let axes = AxisLimits {
            velocity: std::array::from_fn(|_| 0.02 + next()),
            acceleration: std::array::from_fn(|_| 0.2 + 10.0 * next()),
            jerk: std::array::from_fn(|_| 5.0 + 100.0 * next()),
        };
        let c = FeedConstraints {
            limits,
            axes: (case % 4 < 2).then_some(axes),
            caps: (case % 3 != 1).then_some(&caps[..]),
            whole_normal_jerk: false,
        };
        let (plan, _) = plan_and_check(&path, &samples, &c);
        assert!(plan.time >= t_lb(&samples, &limits), "case {case}");
    }
}
