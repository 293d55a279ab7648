//! What feed does to the chatter indicator |μ|max (issue 4 §4; seed 004
//! Fig. 4 and 7), compared with the feed-independent constant-delay model.
//!
//! Process: seed 004 Table 1 (2 teeth, R 0.04 m, K_t 6.44e8, K_n 2.37e8
//! N/m², down milling [0.75π, π], a_p 3 mm unless stated). Two
//! representative robot tool tips (the pose-dependent one comes from
//! kerf_mill), uncoupled x/y modes:
//!
//! * robot A: 25 Hz, ζ 0.05, 50 kg (k = 1.23e6 N/m) — tooth frequency
//!   (67-133 Hz) far above the mode; stable at 3 mm, so it is tested at the
//!   constant-delay critical depth a_lim(Ω).
//! * robot B: 80 Hz, ζ 0.03, 6 kg (k = 1.52e6 N/m) — tooth frequency
//!   crosses the mode at 2400 rpm; near |μ| = 1 at the seed's 3 mm.
//!
//! Measured, faithful model with the paper's LINEAR force law (m = 40,
//! 200 equilibrium nodes; contact fraction of the equilibrium in brackets):
//!
//! | robot B, rpm | constant | f = 0.01 | 0.02 | 0.04 | 0.06 m/s |
//! |---|---|---|---|---|---|
//! | 2000 | 0.7525 | 0.7556 (1.00) | 0.7589 (1.00) | 0.7657 (1.00) | 0.7727 (1.00) |
//! | 2200 | 0.7329 | 0.7362 (1.00) | 0.7394 (1.00) | 0.7454 (1.00) | 0.7510 (1.00) |
//! | 2400 | 0.8638 | 0.8657 (1.00) | 0.8668 (0.98) | 0.8674 (0.96) | 0.8660 (0.94) |
//! | 2600 | 0.9361 | 0.9306 (1.00) | 0.9253 (0.98) | 0.9148 (0.98) | 0.9176 (0.96) |
//! | 2800 | 1.0193 | 1.0153 (1.00) | 1.0113 (1.00) | 1.0033 (1.00) | 0.9954 (0.98) |
//! | 3000 | 1.0658 | 1.0630 | 1.0603 | 1.0548 | 1.0493 |
//! | 3500 | 1.0927 | 1.0916 | 1.0906 | 1.0885 | 1.0863 |
//! | 4000 | 1.0653 | 1.0650 | 1.0647 | 1.0641 | 1.0634 |
//!
//! | robot A at a_lim, rpm | a_lim | f = 0 | 0.02 | 0.04 | 0.06 m/s |
//! |---|---|---|---|---|---|
//! | 2000 | 3.88 mm | 1.0000 | 1.0016 | 1.0031 | 1.0044 |
//! | 3000 | 15.0 mm | 1.0000 | 1.0034 | 1.0067 | 1.0098 |
//! | 4000 | 34.4 mm | 1.0000 | 1.0045 | 1.0089 | 1.0131 |
//!
//! So the sign of the feed effect of the faithful model depends on the
//! tool-tip mode and the speed: for robot B above its resonance speed
//! (2600-4000 rpm) raising the feed lowers |μ|max — at 2800 rpm from 1.019
//! to 0.995, a feed lower bound near 0.048 m/s, the effect of seed 004
//! Fig. 4/7 — while below it and for robot A it rises by up to 1-3 %.
//! Switching the terms of linearize.rs off one at a time: the workpiece
//! wall term (entry at φ_en = 0.75π with a finite chip) is the stabilizing
//! part (at 0.06 m/s: −1.6 … −2.3 % for robot A, −1.8 % for robot B at
//! 2800 rpm), the delay-variation term κ w adds +2 … +3.5 % for robot A,
//! the delay shift τ − T +0.2-0.3 %.
//! These numbers agree with the independent nonlinear time-domain
//! simulation of timedomain.rs (growth factor per period vs |μ|, within
//! 5e-4 … 5e-3). Loss of contact in the equilibrium appears only near the
//! exit and near resonance (contact fraction ≥ 0.94 above).
//!
//! With the power-law (Kienzle) force x_F = 0.75 (Stépán 2001; an option,
//! not the paper's law) the cutting stiffness falls like f_z^(x_F − 1) and
//! the decrease with feed is strong at every speed (robot A at a_lim:
//! 2000 rpm 1.046 → 0.948, 3000 rpm 1.152 → 0.948 from 0.005 to 0.06 m/s).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use kerf_chatter::indicator::{chatter_indicator, indicator_map, DelayModel, IndicatorSettings};
use kerf_chatter::{MillingProcess, Modal2};

fn process(ap: f64) -> MillingProcess {
    common::seed004_process(ap)
}

fn robot() -> Modal2 {
    common::symmetric_modal(25.0, 0.05, 50.0)
}

fn robot_b() -> Modal2 {
    common::symmetric_modal(80.0, 0.03, 6.0)
}

/// Constant-delay critical depth a_lim by bisection of |μ| = 1.
fn critical_depth(modal: &Modal2, rpm: f64) -> f64 {
    let cst = IndicatorSettings::default().model(DelayModel::Constant);
    let (mut lo, mut hi) = (1e-4, 0.05);
    for _ in 0..30 {
        let mid = 0.5 * (lo + hi);
        let r = chatter_indicator(modal, &process(mid), rpm, 0.0, &cst)
            .unwrap()
            .spectral_radius;
        if r < 1.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

fn sweep(modal: &Modal2, ap: f64, rpm: f64, feeds: &[f64], s: &IndicatorSettings) -> Vec<f64> {
    feeds
        .iter()
        .map(|&f| {
            chatter_indicator(modal, &process(ap), rpm, f, s)
                .unwrap()
                .spectral_radius
        })
        .collect()
}

/// The paper's qualitative effect with the faithful model and its linear
/// force law (robot B, seed depth 3 mm): at a fixed spindle speed raising
/// the feed lowers |μ|max monotonically, and at 2800 rpm it crosses 1 (a
/// feed lower bound), while the constant-delay model is flat. Every
/// decrease per 0.01 m/s exceeds 5× the m = 40 vs m = 80 difference.
#[test]
fn linear_law_higher_feed_lowers_the_indicator() {
    let modal = robot_b();
    let p = process(3e-3);
    let feeds = [0.0, 0.01, 0.02, 0.03, 0.04, 0.05, 0.06];
    for rpm in [2800.0, 3000.0] {
        let cst = sweep(
            &modal,
            3e-3,
            rpm,
            &feeds,
            &IndicatorSettings::default().model(DelayModel::Constant),
        );
        assert!(
            cst.iter().all(|c| *c == cst[0]),
            "constant-delay model depends on feed"
        );
        let mu40 = sweep(&modal, 3e-3, rpm, &feeds, &IndicatorSettings::default());
        let mu80 = sweep(
            &modal,
            3e-3,
            rpm,
            &feeds,
            &IndicatorSettings::default().steps(80),
        );
        println!(
            "rpm {rpm}: const {:.5} m40 {mu40:.5?}\n  m80 {mu80:.5?}",
            cst[0]
        );
        assert!(
            (mu40[0] - cst[0]).abs() < 1e-7,
            "f = 0 is the constant-delay model"
        );
        let disc = mu40
            .iter()
            .zip(&mu80)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        // measured: |m40 - m80| <= 2.5e-4, drops 2.7e-3 … 4.0e-3 per step
        assert!(disc < 1e-3, "m-convergence {disc:e}");
        for k in 1..feeds.len() {
            let drop = mu40[k - 1] - mu40[k];
            assert!(
                drop > 5.0 * disc,
                "rpm {rpm}: not decreasing at {} ({drop:e})",
                feeds[k]
            );
            assert!(mu80[k - 1] > mu80[k]);
        }
        let ind = chatter_indicator(&modal, &p, rpm, 0.06, &IndicatorSettings::default()).unwrap();
        println!("  diagnostics at 0.06 m/s: {:?}", ind.equilibrium);
    }
    // 2800 rpm: unstable at low feed, stable at 0.06 m/s
    let mu = sweep(
        &modal,
        3e-3,
        2800.0,
        &[0.0, 0.06],
        &IndicatorSettings::default(),
    );
    assert!(mu[0] > 1.01 && mu[1] < 0.998, "{mu:?}");
}

/// The paper's qualitative effect with the power-law force (x_F = 0.75):
/// at a fixed spindle speed, raising the feed lowers |μ|max monotonically
/// and crosses 1 (a feed lower bound), while the constant-delay model is
/// flat at |μ| = 1. The decrease per feed step is checked to exceed 5× the
/// m = 40 vs m = 80 discretization difference, so the trend is not
/// discretization noise.
#[test]
fn power_law_force_higher_feed_lowers_the_indicator() {
    let modal = robot();
    let feeds = [0.005, 0.01, 0.02, 0.03, 0.04, 0.05, 0.06];
    for rpm in [2000.0, 3000.0] {
        let ap = critical_depth(&modal, rpm);
        let cst = sweep(
            &modal,
            ap,
            rpm,
            &feeds,
            &IndicatorSettings::default().model(DelayModel::Constant),
        );
        for c in &cst {
            assert_eq!(*c, cst[0], "constant-delay model depends on feed");
            assert!((c - 1.0).abs() < 1e-6);
        }
        let s40 = IndicatorSettings::default().force_law(0.75, 1e-4);
        let mu40 = sweep(&modal, ap, rpm, &feeds, &s40);
        let mu80 = sweep(&modal, ap, rpm, &feeds, &s40.steps(80));
        let disc = mu40
            .iter()
            .zip(&mu80)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        println!(
            "rpm {rpm} a_p {:.3} mm: m40 {mu40:.5?}\n  m80 {mu80:.5?}",
            ap * 1e3
        );
        // measured: |m40 - m80| <= 1e-3
        assert!(disc < 2e-3, "m-convergence {disc:e}");
        for k in 1..feeds.len() {
            let drop = mu40[k - 1] - mu40[k];
            assert!(
                drop > 5.0 * disc,
                "rpm {rpm}: |μ| not decreasing at feed {} ({drop:e})",
                feeds[k]
            );
            assert!(mu80[k - 1] > mu80[k]);
        }
        // a feed lower bound: unstable at low feed, stable at high feed
        assert!(mu40[0] > 1.02 && mu40[feeds.len() - 1] < 0.96, "{mu40:?}");
    }
}

/// The faithful model with the paper's linear force law on robot A: the
/// state-dependent corrections are O(f/(RΩ), f_z/R) and here RAISE |μ|
/// slightly with feed (module documentation). This pins the measured size and sign,
/// the exact f = 0 reduction, and that the trend exceeds the m = 40/80
/// difference of the increments.
#[test]
fn linear_law_on_robot_a_feed_effect_is_small_and_upward() {
    let modal = robot();
    let feeds = [0.0, 0.02, 0.04, 0.06];
    for rpm in [2000.0, 4000.0] {
        let ap = critical_depth(&modal, rpm);
        let cst = chatter_indicator(
            &modal,
            &process(ap),
            rpm,
            0.0,
            &IndicatorSettings::default().model(DelayModel::Constant),
        )
        .unwrap()
        .spectral_radius;
        let mu40 = sweep(&modal, ap, rpm, &feeds, &IndicatorSettings::default());
        let mu80 = sweep(
            &modal,
            ap,
            rpm,
            &feeds,
            &IndicatorSettings::default().steps(80),
        );
        println!("rpm {rpm}: const {cst:.6} m40 {mu40:.6?} m80 {mu80:.6?}");
        // f = 0: the state-dependent model is the constant-delay model
        assert!((mu40[0] - cst).abs() < 1e-7, "{} vs {cst}", mu40[0]);
        for k in 1..feeds.len() {
            let d40 = mu40[k] - mu40[0];
            let d80 = mu80[k] - mu80[0];
            assert!(
                d40 > 0.0 && (d40 - d80).abs() < 0.2 * d40,
                "rpm {rpm} feed {}: {d40:e} vs {d80:e}",
                feeds[k]
            );
        }
        // measured increase at 0.06 m/s: +0.44 % (2000 rpm), +1.31 % (4000 rpm)
        let rise = mu40[3] - mu40[0];
        assert!(rise > 1e-3 && rise < 3e-2, "rise {rise:e}");
    }
}

/// The Fig. 7 map: one Discretization per speed gives the same values as
/// separate evaluations.
#[test]
fn map_matches_pointwise_indicator() {
    let modal = robot();
    let p = process(3e-3);
    let rpms = [2200.0, 3700.0];
    let feeds = [0.01, 0.05];
    for model in [DelayModel::Constant, DelayModel::StateDependent] {
        let s = IndicatorSettings::default().model(model);
        let map = indicator_map(&modal, &p, &rpms, &feeds, &s).unwrap();
        assert_eq!(map.len(), 2);
        for (i, &rpm) in rpms.iter().enumerate() {
            assert_eq!(map[i].len(), 2);
            for (k, &f) in feeds.iter().enumerate() {
                let r = chatter_indicator(&modal, &p, rpm, f, &s)
                    .unwrap()
                    .spectral_radius;
                assert!(
                    (map[i][k] - r).abs() < 1e-7 * r,
                    "{model:?} {rpm} {f}: {} vs {r}",
                    map[i][k]
                );
            }
        }
    }
    assert!(
        indicator_map(&modal, &p, &[], &feeds, &IndicatorSettings::default())
            .unwrap()
            .is_empty()
    );
    assert!(indicator_map(
        &modal,
        &p,
        &rpms,
        &[0.01, -0.01],
        &IndicatorSettings::default()
    )
    .is_err());
    assert!(indicator_map(
        &modal,
        &p,
        &[3000.0, f64::NAN],
        &feeds,
        &IndicatorSettings::default()
    )
    .is_err());
}

/// Every bad input is an error, never a NaN or a panic.
#[test]
fn indicator_rejects_bad_inputs() {
    let modal = robot();
    let p = process(3e-3);
    let s = IndicatorSettings::default();
    assert!(chatter_indicator(&modal, &p, f64::NAN, 0.01, &s).is_err());
    assert!(chatter_indicator(&modal, &p, 0.0, 0.01, &s).is_err());
    assert!(chatter_indicator(&modal, &p, -100.0, 0.01, &s).is_err());
    assert!(chatter_indicator(&modal, &p, 3000.0, -0.01, &s).is_err());
    assert!(chatter_indicator(&modal, &p, 3000.0, f64::NAN, &s).is_err());
    for model in [DelayModel::Constant, DelayModel::StateDependent] {
        assert!(chatter_indicator(&modal, &p, 3000.0, 0.01, &s.model(model).steps(1)).is_err());
        assert!(chatter_indicator(&modal, &p, 3000.0, -1.0, &s.model(model)).is_err());
    }
    assert!(chatter_indicator(&modal, &p, 3000.0, 0.01, &s.points_per_period(50)).is_err());
    assert!(chatter_indicator(&modal, &p, 3000.0, 0.01, &s.max_regeneration(0)).is_err());
    assert!(chatter_indicator(&modal, &p, 3000.0, 0.01, &s.force_law(f64::NAN, 1e-4)).is_err());
    let mut bad = modal;
    bad.stiffness[(0, 0)] = f64::NAN;
    assert!(chatter_indicator(&bad, &p, 3000.0, 0.01, &s).is_err());
    let mut q = p;
    q.kt = -1.0;
    assert!(chatter_indicator(&modal, &q, 3000.0, 0.01, &s).is_err());
    // a valid call carries the diagnostics
    let ind = chatter_indicator(&modal, &p, 3000.0, 0.03, &s).unwrap();
    let d = ind.equilibrium.unwrap();
    assert!(ind.spectral_radius.is_finite() && ind.spectral_radius > 0.0);
    assert!(d.min_chip > 0.0 && d.contact_fraction == 1.0 && d.forced_amplitude > 0.0);
    assert!(ind.equilibrium_iterations >= 2);
    let c = chatter_indicator(&modal, &p, 3000.0, 0.03, &s.model(DelayModel::Constant)).unwrap();
    assert!(c.equilibrium.is_none());
}

/// Timing report (not asserted): run with `--ignored --nocapture`.
#[test]
#[ignore]
fn timing() {
    let modal = robot();
    let p = process(3e-3);
    let n = 200;
    for (name, s) in [
        (
            "constant",
            IndicatorSettings::default().model(DelayModel::Constant),
        ),
        ("state-dependent", IndicatorSettings::default()),
    ] {
        let t = std::time::Instant::now();
        for i in 0..n {
            let f = 0.06 * (i + 1) as f64 / n as f64;
            chatter_indicator(&modal, &p, 3000.0, f, &s).unwrap();
        }
        println!(
            "{name}: {:.3} ms per evaluation",
            t.elapsed().as_secs_f64() * 1e3 / n as f64
        );
    }
}

/// The feed lower bound of robot B at 2800 rpm seen by the independent
/// nonlinear time-domain simulation (timedomain.rs: exact tooth paths,
/// moving workpiece wall, loss of contact): the per-period growth factor of
/// a perturbation of the forced response is > 1 at low feed and < 1 at
/// 0.06 m/s, like |μ|max, and falls by about as much.
#[test]
fn time_domain_confirms_the_feed_lower_bound() {
    use kerf_chatter::timedomain::{classify, simulate, SimulationSettings};
    let modal = robot_b();
    let p = process(3e-3);
    let settings = SimulationSettings {
        periods: 80,
        perturbation: nalgebra::Vector2::new(1e-7, 1e-7),
        ..SimulationSettings::default()
    };
    let mut factors = Vec::new();
    let mut mus = Vec::new();
    for f in [0.005, 0.06] {
        let g = classify(&simulate(&modal, &p, 2800.0, f, &settings).unwrap()).unwrap();
        let mu = chatter_indicator(
            &modal,
            &p,
            2800.0,
            f,
            &IndicatorSettings::default().steps(80),
        )
        .unwrap()
        .spectral_radius;
        println!("f {f}: time-domain factor {:.5}, |mu| {mu:.5}", g.factor);
        factors.push(g.factor);
        mus.push(mu);
    }
    // measured: factor 1.0151 -> 0.9911, |mu| 1.0175 -> 0.9957
    assert!(factors[0] > 1.005 && factors[1] < 0.997, "{factors:?}");
    assert!(mus[0] > 1.005 && mus[1] < 0.998, "{mus:?}");
    let (dt, dm) = (factors[0] - factors[1], mus[0] - mus[1]);
    assert!(
        (dt - dm).abs() < 0.25 * dm,
        "decrease {dt:e} (time domain) vs {dm:e} (|mu|)"
    );
}
