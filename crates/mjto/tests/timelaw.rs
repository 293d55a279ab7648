//! The jerk-limited feed profile and the chain rule of seed 001 eq. 6/7.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use approx::assert_abs_diff_eq;
use kerf_mjto::timelaw::{chain_rule, TimeLaw};
use kerf_mjto::PlanError;

/// Case study 2 of seed 001 (Table 1): 15 m/min, 8 m/s², 80 m/s³.
const FEED: f64 = 0.25;
const ACC: f64 = 8.0;
const JERK: f64 = 80.0;

/// Dense check of one law: end values, limits, and continuity of s, ṡ, s̈
/// (jumps across a step h bounded by what the next derivative allows).
fn check_law(law: &TimeLaw, sigma: f64, acc: f64, jerk: f64) {
    let total = law.duration();
    assert_eq!(law.eval(0.0), [0.0, 0.0, 0.0, jerk]);
    let end = law.eval(total);
    assert_abs_diff_eq!(end[0], sigma, epsilon = 1e-15 * sigma.max(1.0));
    assert_abs_diff_eq!(end[1], 0.0, epsilon = 1e-12);
    assert_abs_diff_eq!(end[2], 0.0, epsilon = 1e-9);
    // Clamped outside [0, T].
    assert_eq!(law.eval(-1.0), law.eval(0.0));
    assert_eq!(law.eval(total + 1.0), law.eval(total));

    let n = 200_000;
    let h = total / n as f64;
    let mut prev = law.eval(0.0);
    for i in 1..=n {
        let t = i as f64 * h;
        let x = law.eval(t);
        assert!(
            x[1] >= -1e-12 && x[1] <= law.peak_feed() * (1.0 + 1e-12),
            "ṡ {} at {t}",
            x[1]
        );
        assert!(x[2].abs() <= acc * (1.0 + 1e-12), "s̈ {} at {t}", x[2]);
        assert!(x[3].abs() <= jerk, "s⃛ {} at {t}", x[3]);
        assert!(x[0] >= prev[0] - 1e-15, "s decreases at {t}");
        // Continuity: the change over h is bounded by h times the bound of
        // the next derivative (plus rounding).
        assert!((x[0] - prev[0]).abs() <= h * law.peak_feed() * (1.0 + 1e-9) + 1e-14);
        assert!((x[1] - prev[1]).abs() <= h * acc * (1.0 + 1e-9) + 1e-13);
        assert!(
            (x[2] - prev[2]).abs() <= h * jerk * (1.0 + 1e-9) + 1e-10,
            "s̈ jumps at {t}"
        );
        prev = x;
    }
}

/// The law's own derivatives agree with central differences of the lower
/// ones (away from the jerk switches, checked everywhere for s and ṡ).
fn check_derivatives(law: &TimeLaw) {
    let total = law.duration();
    let h = 1e-6;
    for i in 1..400 {
        let t = total * i as f64 / 400.0;
        let (a, b, x) = (law.eval(t - h), law.eval(t + h), law.eval(t));
        assert_abs_diff_eq!((b[0] - a[0]) / (2.0 * h), x[1], epsilon = 1e-6);
        // A jerk switch within ±h makes the FD of ṡ off by up to J h / 2.
        let tol = if a[3] == b[3] { 1e-8 } else { 1e-4 };
        assert_abs_diff_eq!((b[1] - a[1]) / (2.0 * h), x[2], epsilon = tol);
        if a[3] == b[3] {
            assert_abs_diff_eq!((b[2] - a[2]) / (2.0 * h), x[3], epsilon = 1e-4);
        }
    }
}

#[test]
fn long_path_cruises_at_the_feedrate() {
    let sigma = 0.6;
    let law = TimeLaw::new(sigma, FEED, ACC, JERK).unwrap();
    assert_eq!(law.peak_feed(), FEED);
    // f = 0.25 ≥ A²/J = 0.8? No: the acceleration limit is not reached;
    // ramp 2√(f/J), covering f·√(f/J) each way.
    let tj = (FEED / JERK).sqrt();
    let ramp = 2.0 * tj;
    let cruise = (sigma - 2.0 * FEED * tj) / FEED;
    assert_abs_diff_eq!(law.cruise_duration(), cruise, epsilon = 1e-15);
    assert_abs_diff_eq!(law.duration(), 2.0 * ramp + cruise, epsilon = 1e-15);
    // Cruise at f with zero acceleration in the middle.
    let mid = law.eval(law.duration() / 2.0);
    assert_abs_diff_eq!(mid[0], sigma / 2.0, epsilon = 1e-15);
    assert_eq!(&mid[1..], &[FEED, 0.0, 0.0]);
    // Peak acceleration √(fJ) at the end of the first jerk phase.
    assert_abs_diff_eq!(law.eval(tj)[2], (FEED * JERK).sqrt(), epsilon = 1e-12);
    check_law(&law, sigma, ACC, JERK);
    check_derivatives(&law);
}

#[test]
fn fast_feed_reaches_the_acceleration_limit() {
    // f = 2 m/s > A²/J = 0.8 m/s: jerk phases A/J, constant A for f/A − A/J.
    let (feed, sigma) = (2.0, 3.0);
    let law = TimeLaw::new(sigma, feed, ACC, JERK).unwrap();
    assert_eq!(law.peak_feed(), feed);
    let ramp = feed / ACC + ACC / JERK;
    assert_abs_diff_eq!(
        law.duration(),
        2.0 * ramp + (sigma - feed * ramp) / feed,
        epsilon = 1e-14
    );
    let t = ACC / JERK + 0.5 * (feed / ACC - ACC / JERK);
    assert_eq!(law.eval(t)[2], ACC);
    assert_eq!(law.eval(t)[3], 0.0);
    check_law(&law, sigma, ACC, JERK);
    check_derivatives(&law);
}

#[test]
fn short_path_lowers_the_peak_exactly() {
    // 1 mm at 0.25 m/s: the jerk-only ramp pair covers
    // 2 v √(v/J) = σ → v = (σ² J / 4)^(1/3) = 0.02714… m/s.
    let sigma = 1e-3;
    let law = TimeLaw::new(sigma, FEED, ACC, JERK).unwrap();
    let v = (sigma * sigma * JERK / 4.0).cbrt();
    assert_abs_diff_eq!(law.peak_feed(), v, epsilon = 1e-15);
    assert!(law.peak_feed() < FEED);
    assert_abs_diff_eq!(law.cruise_duration(), 0.0, epsilon = 1e-12);
    assert_abs_diff_eq!(law.duration(), 4.0 * (v / JERK).sqrt(), epsilon = 1e-12);
    // The peak is reached at T/2.
    assert_abs_diff_eq!(law.eval(law.duration() / 2.0)[1], v, epsilon = 1e-12);
    check_law(&law, sigma, ACC, JERK);
    check_derivatives(&law);

    // Short but long enough to hit A: v (v/A + A/J) = σ.
    let (feed, sigma) = (3.0, 0.5);
    let law = TimeLaw::new(sigma, feed, ACC, JERK).unwrap();
    let v = law.peak_feed();
    assert!(v < feed && v > ACC * ACC / JERK);
    assert_abs_diff_eq!(v * (v / ACC + ACC / JERK), sigma, epsilon = 1e-14);
    check_law(&law, sigma, ACC, JERK);
    // Any larger peak would not fit: 1 % more overshoots the path.
    let v2 = 1.01 * v;
    assert!(v2 * (v2 / ACC + ACC / JERK) > sigma);
}

#[test]
fn samples_cover_zero_to_t_with_t_last() {
    let law = TimeLaw::new(0.6, FEED, ACC, JERK).unwrap();
    let total = law.duration();
    let dt = 0.004;
    let ts = law.sample_times(dt);
    assert_eq!(ts[0], 0.0);
    assert_eq!(*ts.last().unwrap(), total);
    assert!(ts.windows(2).all(|w| w[1] > w[0]));
    for (i, t) in ts[..ts.len() - 1].iter().enumerate() {
        assert_eq!(*t, i as f64 * dt);
    }
    let last_gap = ts[ts.len() - 1] - ts[ts.len() - 2];
    assert!(last_gap > dt * 1e-6 && last_gap <= dt * (1.0 + 1e-12));
    assert_eq!(ts.len(), (total / dt).ceil() as usize + 1);
    // A grid point within dt·1e-6 of T is replaced by T.
    let dt = total / 100.0 * (1.0 - 1e-9);
    let ts = law.sample_times(dt);
    assert_eq!(ts.len(), 101);
    assert_eq!(*ts.last().unwrap(), total);
    // Bad periods.
    assert_eq!(law.sample_times(0.0), vec![0.0, total]);
    assert!(law.checked_sample_times(f64::NAN, 1000).is_err());
    assert!(law.checked_sample_times(1e-9, 1000).is_err());
    assert_eq!(
        law.checked_sample_times(0.004, 1_000_000).unwrap(),
        law.sample_times(0.004)
    );
}

#[test]
fn invalid_parameters_are_rejected() {
    let field = |r: Result<TimeLaw, PlanError>| match r {
        Err(PlanError::InvalidRequest { field, .. }) => field,
        other => panic!("{other:?}"),
    };
    assert_eq!(field(TimeLaw::new(0.0, FEED, ACC, JERK)), "path length");
    assert_eq!(field(TimeLaw::new(1.0, f64::NAN, ACC, JERK)), "feedrate");
    assert_eq!(
        field(TimeLaw::new(1.0, FEED, -1.0, JERK)),
        "feed_acceleration"
    );
    assert_eq!(
        field(TimeLaw::new(1.0, FEED, ACC, f64::INFINITY)),
        "feed_jerk"
    );
    let law = TimeLaw::new(1.0, FEED, ACC, JERK).unwrap();
    assert!(law.eval(f64::NAN).iter().all(|v| v.is_nan()));
}

#[test]
fn chain_rule_matches_finite_differences_of_q_of_u_of_t() {
    // q(u) = sin(3u) + u³ on the short law (non-trivial s̈ and s⃛ throughout).
    let sigma = 0.02;
    let law = TimeLaw::new(sigma, FEED, ACC, JERK).unwrap();
    let qu = |u: f64| {
        [
            (3.0 * u).sin() + u.powi(3),
            3.0 * (3.0 * u).cos() + 3.0 * u * u,
            -9.0 * (3.0 * u).sin() + 6.0 * u,
            -27.0 * (3.0 * u).cos() + 6.0,
        ]
    };
    let q_of_t = |t: f64| qu(law.eval(t)[0] / sigma)[0];
    let total = law.duration();
    let h = 1e-4;
    for i in 1..50 {
        let t = total * i as f64 / 50.0;
        let s = law.eval(t);
        let d = chain_rule(qu(s[0] / sigma), s, sigma);
        let f = |k: f64| q_of_t(t + k * h);
        // Velocity with a 100× smaller step: its O(h²) error is
        // h² q⃛ / 6 ≈ 2e-5 at h = 1e-4 early in the ramp.
        let v = (f(0.01) - f(-0.01)) / (0.02 * h);
        let a = (f(1.0) - 2.0 * f(0.0) + f(-1.0)) / (h * h);
        let j = (f(2.0) - 2.0 * f(1.0) + 2.0 * f(-1.0) - f(-2.0)) / (2.0 * h.powi(3));
        assert_eq!(d[0], f(0.0));
        // Jerk switches inside the stencil spoil the FD acceleration and
        // jerk (O(h) errors); skip those samples.
        let switch = (-2..=2).any(|k| law.eval(t + k as f64 * h)[3] != s[3]);
        assert_abs_diff_eq!(d[1], v, epsilon = 1e-7 * d[1].abs().max(1.0));
        if !switch {
            assert_abs_diff_eq!(d[2], a, epsilon = 1e-4 * d[2].abs().max(1.0));
            assert_abs_diff_eq!(d[3], j, epsilon = 1e-3 * d[3].abs().max(1.0));
        }
    }
    // Constant feed (eq. 13): velocity scales with f/σ, etc.
    let d = chain_rule([1.0, 2.0, 3.0, 4.0], [0.0, 0.5, 0.0, 0.0], 2.0);
    assert_eq!(d, [1.0, 0.5, 3.0 * 0.0625, 4.0 * 0.015625]);
}

#[test]
fn phases_cover_the_path_in_order_with_their_limits() {
    // A long path at a feed above A²/J reaches the acceleration limit and cruises.
    let sigma = 1.0;
    let law = TimeLaw::new(sigma, 1.0, ACC, JERK).unwrap();
    let phases = law.phases();
    let names: Vec<&str> = phases.iter().map(|p| p.2).collect();
    assert_eq!(
        names,
        [
            "path jerk",
            "path acceleration",
            "path jerk",
            "feedrate",
            "path jerk",
            "path acceleration",
            "path jerk"
        ]
    );
    assert_eq!(phases[0].0, 0.0);
    assert!((phases[6].1 - sigma).abs() < 1e-12);
    for w in phases.windows(2) {
        assert!((w[1].0 - w[0].1).abs() < 1e-12, "{w:?}");
    }
    // The cruise starts where the law reaches the feedrate.
    let t_cruise = (law.duration() - law.cruise_duration()) / 2.0;
    assert!((law.eval(t_cruise)[0] - phases[3].0).abs() < 1e-9);
    // Case 1's feed (20 m/min) stays below A²/J: the two jerk phases of each ramp are one
    // stretch. A path too short to cruise is jerk-limited throughout.
    let names: Vec<&str> = TimeLaw::new(0.8, 1.0 / 3.0, ACC, JERK)
        .unwrap()
        .phases()
        .iter()
        .map(|p| p.2)
        .collect();
    assert_eq!(names, ["path jerk", "feedrate", "path jerk"]);
    let short = TimeLaw::new(0.001, 1.0 / 3.0, ACC, JERK).unwrap().phases();
    assert_eq!(short.len(), 1, "{short:?}");
    assert_eq!(short[0].2, "path jerk");
}

#[test]
fn on_grid_puts_every_phase_on_the_sample_grid_within_the_limits() {
    for (sigma, feed, dt) in [
        (0.8, 1.0 / 3.0, 0.01),
        (0.627, 0.25, 0.004),
        (1.0, 1.0, 0.004),
        (0.004, 1.0 / 3.0, 0.01),
    ] {
        let law = TimeLaw::new(sigma, feed, ACC, JERK).unwrap();
        let grid = law.on_grid(dt).unwrap();
        let jerk = grid.eval(0.0)[3];
        assert!(jerk > 0.0 && jerk <= JERK, "{jerk}");
        check_law(&grid, sigma, ACC, jerk);
        assert!(
            grid.peak_feed() <= feed * (1.0 + 1e-12),
            "{sigma} {feed} {dt}"
        );
        assert!(grid.duration() >= law.duration() - 1e-12);
        // Ramps rounded up by at most a period per phase, the cruise by one.
        assert!(
            grid.duration() <= law.duration() + 7.0 * dt,
            "{sigma} {feed} {dt}"
        );
        // The whole law is a whole number of periods, and the jerk is constant within every
        // step: at the two ends of a step's interior it is the same.
        let steps = grid.duration() / dt;
        assert!((steps - steps.round()).abs() < 1e-6, "{steps} steps");
        for k in 0..steps.round() as usize {
            let (a, b) = (k as f64 * dt, (k + 1) as f64 * dt);
            let (ja, jb) = (grid.eval(a + 1e-9)[3], grid.eval(b - 1e-9)[3]);
            assert_eq!(ja, jb, "jerk changes inside step {k} ({a} s)");
        }
    }
    assert!(TimeLaw::new(0.8, 0.3, ACC, JERK)
        .unwrap()
        .on_grid(0.0)
        .is_err());
}
