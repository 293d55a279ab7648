//! Seed 003's speed limits (eqs. 15–22) against their definitions: at each limiting speed the
//! constrained quantity equals its limit, computed independently (the chord's sagitta, the
//! servo's steady-state radius from its transfer function, v²/ρ, v³/ρ²).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_toolpath::{bang_bang, bang_bang_under, sample_path, smooth_polyline, BangBangLimits};
use kerf_toolpath::{CurvatureLimits, Servo};

#[test]
fn each_limit_meets_its_definition() {
    let l = CurvatureLimits::seed_003_table_1();
    l.validate().unwrap();
    for rho in [2e-4, 1e-3, 5e-3, 0.02, 0.1] {
        // Eq. 15: the sagitta of a chord vT at the chord speed is Δ_lim.
        let v = l.chord_speed(rho);
        let half = 0.5 * v * l.interpolation_period;
        let sag = rho - (rho * rho - half * half).sqrt();
        assert!((sag - l.chord_error).abs() < 1e-9 * rho, "{rho}: {sag}");
        // Eq. 17: at the contour speed the servo's radius is ρ − ε.
        let s = l.servo.unwrap();
        let v = l.contour_speed(rho);
        let w = v / rho;
        let wn = s.natural_frequency;
        let gain =
            wn * wn / ((wn * wn - w * w).powi(2) + (2.0 * s.damping * wn * w).powi(2)).sqrt();
        assert!(
            (rho * (1.0 - gain) - s.contour_error).abs() < 1e-9 * rho,
            "{rho}"
        );
        // Eqs. 19 and 21 and their minimum (eq. 22).
        let k = 1.0 / rho;
        let expected = [
            l.feed,
            l.chord_speed(rho),
            (l.normal_acceleration * rho).sqrt(),
            (l.normal_jerk * rho * rho).cbrt(),
            l.contour_speed(rho),
        ]
        .into_iter()
        .fold(f64::INFINITY, f64::min);
        let v = l.speed(k);
        assert_eq!(v, expected);
        assert!(v * v / rho <= l.normal_acceleration * (1.0 + 1e-12));
        assert!(v.powi(3) / (rho * rho) <= l.normal_jerk * (1.0 + 1e-12));
    }
    assert_eq!(l.speed(0.0), l.feed);
    // A radius below the chord error or the contour error: those two do not limit.
    let tiny = 5e-7;
    assert_eq!(l.chord_speed(tiny), 2.0 * tiny / l.interpolation_period);
    assert!(l.contour_speed(1e-5).is_infinite());
}

#[test]
fn bad_limits_are_refused() {
    let good = CurvatureLimits::seed_003_table_1();
    let mut bad = good;
    bad.normal_jerk = 0.0;
    assert!(bad.validate().is_err());
    let mut bad = good;
    bad.servo = Some(Servo {
        damping: 0.5,
        ..good.servo.unwrap()
    });
    let e = bad.validate().unwrap_err();
    assert!(e.to_string().contains("damping"), "{e}");
}

#[test]
fn the_bound_under_the_full_limit_curve_is_slower_than_under_a_n_alone() {
    let poly = [
        [0.0; 3],
        [0.02, 0.0, 0.0],
        [0.03, 0.01, 0.0],
        [0.05, 0.01, 0.0],
    ];
    let path = smooth_polyline(&poly, 1e-4).unwrap();
    let samples = sample_path(&path, 1e-5);
    let l = CurvatureLimits::seed_003_table_1();
    let curve: Vec<f64> = samples.iter().map(|p| l.speed(p.curvature)).collect();
    let full = bang_bang_under(&samples, curve, 0.8).unwrap();
    let an_only = bang_bang(
        &samples,
        &BangBangLimits {
            feed: l.feed,
            tangential_acceleration: 0.8,
            normal_acceleration: l.normal_acceleration,
        },
    )
    .unwrap();
    assert!(full.time >= an_only.time);
    assert!(full.speed.iter().zip(&full.limit).all(|(v, m)| *v <= *m));
    assert!(bang_bang_under(&samples, vec![0.07; 3], 0.8).is_err());
    assert!(bang_bang_under(&samples, vec![0.0; samples.len()], 0.8).is_err());
}

#[test]
fn contour_speed_does_not_cancel_on_nearly_straight_paths() {
    // Where two corners meet, rounding leaves κ ~ 1e-14 1/m: the speed there
    // must be huge, not 0 (the literal form of eq. 17 cancels to 0).
    let l = CurvatureLimits::seed_003_table_1();
    for kappa in [3e-14, 1e-10, 1e-6] {
        let v = l.contour_speed(1.0 / kappa);
        assert!(v > 1.0, "kappa {kappa}: v {v}");
        assert!(l.speed(kappa) > 0.0);
    }
}

/// Eq. 17 falls with the radius down to ρ* and rises below it (radii of a few ε): the critical
/// radius is the least of a dense log grid, and the least speed over a curvature range is at ρ*
/// where the range holds it, else at the range's end nearer to it (the laser cutter's torch run
/// once broke its contour limit by 2·10⁻⁶ where the limit curve took the speed at the largest
/// curvature, 12 447 1/m with ε = 50 µm, beyond 1/ρ*).
#[test]
fn the_contour_law_has_one_minimum_and_ranges_take_it() {
    let l = CurvatureLimits::seed_003_table_1();
    let e = l.servo.unwrap().contour_error;
    let star = l.contour_critical_radius().unwrap();
    assert!(star > e && star < 100.0 * e, "ρ* {star} against ε {e}");
    let grid: Vec<f64> = (0..4000)
        .map(|k| e * (1.0 + 10f64.powf(-6.0 + 12.0 * k as f64 / 4000.0)))
        .collect();
    let speeds: Vec<f64> = grid.iter().map(|&r| l.contour_speed(r)).collect();
    let (k_min, v_min) =
        speeds
            .iter()
            .copied()
            .enumerate()
            .fold(
                (0, f64::INFINITY),
                |b, (k, v)| if v < b.1 { (k, v) } else { b },
            );
    assert!(l.contour_speed(star) <= v_min * (1.0 + 1e-12));
    assert!(
        (grid[k_min] - star).abs() < 0.01 * star,
        "{} vs {star}",
        grid[k_min]
    );
    // Falling towards ρ* from above, rising towards ε from ρ*.
    for w in speeds.windows(2).take(k_min) {
        assert!(w[1] <= w[0] * (1.0 + 1e-12), "not falling below ρ*");
    }
    for w in speeds.windows(2).skip(k_min + 1) {
        assert!(w[1] >= w[0] * (1.0 - 1e-12), "not rising above ρ*");
    }
    let k_star = 1.0 / star;
    let over = |lo: f64, hi: f64| l.contour_speed_over(lo, hi, Some(star));
    let dense = |lo: f64, hi: f64| {
        (0..=1000)
            .map(|k| l.contour_speed(1.0 / (lo + (hi - lo) * k as f64 / 1000.0)))
            .fold(f64::INFINITY, f64::min)
    };
    for (lo, hi) in [
        (0.2 * k_star, 0.5 * k_star),
        (0.5 * k_star, 2.0 * k_star),
        (1.5 * k_star, 3.0 * k_star),
        (0.9 * k_star, 0.99 * k_star),
    ] {
        let (a, b) = (over(lo, hi), dense(lo, hi));
        assert!(
            a <= b * (1.0 + 1e-12) && a >= b * (1.0 - 1e-6),
            "[{lo}, {hi}]: {a} vs {b}"
        );
    }
    assert!(over(0.0, 0.0).is_infinite());
    assert!(CurvatureLimits { servo: None, ..l }
        .contour_critical_radius()
        .is_none());
}
