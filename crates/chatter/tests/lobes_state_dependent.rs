//! `kerf_chatter::lobes::state_dependent_critical_depth`: the returned depth
//! is the first |μ|max = 1 crossing of the indicator it searches — checked
//! by direct evaluation of `chatter_indicator` just below and above it and
//! on a scan below it — and, with the constant-delay model, it equals the
//! critical depth of the independent per-unit-depth search of
//! `stability_lobes` (scaled equation on one discretization).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use std::f64::consts::PI;

use kerf_chatter::lobes::state_dependent_critical_depth;
use kerf_chatter::{
    chatter_indicator, stability_lobes, ChatterError, DelayModel, IndicatorSettings, LobeOptions,
    MillingProcess, Modal2,
};

/// A robot tool tip: two uncoupled 30 Hz modes, ζ = 0.05, k = 1e6 N/m
/// (the representative mode of `benches/indicator.rs`).
fn modal() -> Modal2 {
    let wn = 2.0 * PI * 30.0;
    common::symmetric_modal(30.0, 0.05, 1e6 / (wn * wn))
}

/// Seed 004 Table 1 process (2 teeth, R = 40 mm, down milling [0.75π, π]).
fn process() -> MillingProcess {
    common::seed004_process(3e-3)
}

/// The default cell's indicator: state-dependent, x_F = 0.75 at the paper's
/// initial chip 0.224 mm, wall term, m = 40.
fn sd_settings() -> IndicatorSettings {
    IndicatorSettings::default()
        .model(DelayModel::StateDependent)
        .force_law(0.75, 2.24e-4)
}

fn opts() -> LobeOptions {
    LobeOptions {
        max_depth: 0.02,
        scan_points: 20,
        tolerance: 1e-6,
        ..LobeOptions::default()
    }
}

fn rho(depth: f64, rpm: f64, feed: f64, s: &IndicatorSettings) -> f64 {
    let p = MillingProcess {
        axial_depth: depth,
        ..process()
    };
    chatter_indicator(&modal(), &p, rpm, feed, s)
        .expect("indicator")
        .spectral_radius
}

#[test]
fn state_dependent_depth_is_the_first_crossing() {
    let (rpm, feed) = (3000.0, 0.04);
    let s = sd_settings();
    let o = opts();
    let d = state_dependent_critical_depth(&modal(), &process(), rpm, feed, &s, &o)
        .expect("search")
        .expect("unstable below 20 mm");
    assert!(d > o.tolerance && d < o.max_depth, "a_lim = {d}");
    let below = rho(d - o.tolerance, rpm, feed, &s);
    let above = rho(d + o.tolerance, rpm, feed, &s);
    eprintln!("a_lim = {:.4} mm, |mu| = {below:.6} / {above:.6}", d * 1e3);
    assert!(below < 1.0, "|mu|({}) = {below}", d - o.tolerance);
    assert!(above >= 1.0, "|mu|({}) = {above}", d + o.tolerance);
    // First crossing: stable everywhere on a grid below it.
    for k in 1..=8 {
        let dk = d * k as f64 / 9.0;
        let r = rho(dk, rpm, feed, &s);
        assert!(r < 1.0, "|mu|({dk}) = {r} below a_lim = {d}");
    }
}

#[test]
fn constant_model_matches_the_unit_depth_search() {
    let s = IndicatorSettings::default().model(DelayModel::Constant);
    let o = opts();
    for rpm in [2200.0, 3100.0, 3900.0] {
        let direct =
            state_dependent_critical_depth(&modal(), &process(), rpm, 0.0, &s, &o).expect("search");
        let lobes = stability_lobes(&modal(), &process(), &[rpm], &o).expect("lobes");
        let reference = lobes[0].critical_depth;
        eprintln!("{rpm} rpm: {direct:?} vs {reference:?}");
        match (direct, reference) {
            (Some(a), Some(b)) => assert!((a - b).abs() <= 2.0 * o.tolerance, "{a} vs {b}"),
            (None, None) => {}
            other => panic!("{rpm} rpm: {other:?}"),
        }
    }
}

#[test]
fn stable_up_to_max_depth_gives_none() {
    let (rpm, feed) = (3000.0, 0.04);
    let s = sd_settings();
    let o = LobeOptions {
        max_depth: 2e-4,
        scan_points: 4,
        tolerance: 1e-6,
        ..LobeOptions::default()
    };
    let r =
        state_dependent_critical_depth(&modal(), &process(), rpm, feed, &s, &o).expect("search");
    assert_eq!(r, None);
    assert!(rho(o.max_depth, rpm, feed, &s) < 1.0);
}

#[test]
fn bad_inputs_are_refused() {
    let s = sd_settings();
    let o = opts();
    let err = |rpm: f64, feed: f64, o: &LobeOptions| {
        state_dependent_critical_depth(&modal(), &process(), rpm, feed, &s, o)
    };
    assert!(matches!(
        err(3000.0, f64::NAN, &o),
        Err(ChatterError::InvalidParameter { .. })
    ));
    assert!(matches!(
        err(-1.0, 0.04, &o),
        Err(ChatterError::InvalidParameter { .. })
    ));
    let inverted = LobeOptions {
        min_depth: 0.01,
        max_depth: 0.005,
        ..o
    };
    assert!(matches!(
        err(3000.0, 0.04, &inverted),
        Err(ChatterError::InvalidParameter { .. })
    ));
}
