//! The cell's `chatter` section: the default cell's indicator settings,
//! the paper's model when the section is absent, bad values by name, and
//! the feed lower bound of seed 004 Fig. 4/7 on the default cell's real
//! pose-dependent tool-tip dynamics.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use kerf_chatter::indicator::{chatter_indicator, DelayModel, IndicatorSettings};
use kerf_mill::MillCell;

/// The text without its `chatter:` section (the section is the file's last).
fn without_chatter(text: &str) -> String {
    let cut = text
        .find("\nchatter:")
        .expect("default cell has a chatter section");
    text[..cut].to_string()
}

#[test]
fn default_cell_uses_the_documented_force_law() {
    let cell = MillCell::default_cell().expect("default cell");
    let s = cell.indicator_settings();
    assert_eq!(s.model, DelayModel::StateDependent);
    assert_eq!(s.steps, 40);
    assert_eq!(s.equilibrium.force_law.exponent, 0.75);
    assert_eq!(s.equilibrium.force_law.reference_chip, 2.24e-4);
    assert!(s.wall_term);
}

#[test]
fn absent_section_is_the_papers_model() {
    let cell = common::load_cell_text(&without_chatter(&common::default_cell_text()))
        .expect("cell without chatter");
    assert_eq!(*cell.indicator_settings(), IndicatorSettings::default());
    assert_eq!(
        cell.indicator_settings().equilibrium.force_law.exponent,
        1.0
    );
}

#[test]
fn bad_chatter_values_are_named() {
    let base = common::default_cell_text();
    for (from, to, field) in [
        ("model: state_dependent", "model: quantum", "chatter.model"),
        (
            "force_exponent: 0.75",
            "force_exponent: 1.5",
            "chatter.force_exponent",
        ),
        (
            "force_exponent: 0.75",
            "force_exponent: .nan",
            "chatter.force_exponent",
        ),
        (
            "reference_chip: 2.24e-4",
            "reference_chip: -1.0",
            "chatter.reference_chip",
        ),
        ("steps: 40", "steps: 1", "sub-intervals"),
    ] {
        assert!(base.contains(from), "default cell lacks `{from}`");
        let err = common::load_cell_text(&base.replacen(from, to, 1))
            .expect_err(to)
            .to_string();
        assert!(err.contains(field), "`{to}`: {err}");
    }
}

/// Seed 004 Fig. 4/7: at a fixed spindle speed, raising the feed lowers
/// |μ|max. On the default cell (segment 50, g = −0.4 rad — tool x axis
/// along the flange axis, the mount's reference —, 3500 rpm, the real
/// compliance-model dynamics) the constant-delay model is unstable and
/// feed-independent; the state-dependent model with the cell's force law
/// falls with the feed from 0.03 m/s on and is stable at f_max.
#[test]
fn default_cell_shows_the_feed_lower_bound() {
    let cell = MillCell::default_cell().expect("default cell");
    let state = cell.evaluate(50, -0.4, None).expect("segment 50, g = -0.4");
    let process = cell.milling_process();
    let s = *cell.indicator_settings();
    let rho = |f: f64, settings: &IndicatorSettings| {
        chatter_indicator(&state.modal, &process, 3500.0, f, settings)
            .expect("indicator")
            .spectral_radius
    };
    let constant = s.model(DelayModel::Constant);
    let c0 = rho(0.0, &constant);
    assert!(c0 > 1.0, "constant-delay |mu| {c0}");
    assert!((rho(0.06, &constant) - c0).abs() < 1e-12);
    let feeds = [0.03, 0.04, 0.05, 0.06];
    let mu: Vec<f64> = feeds.iter().map(|&f| rho(f, &s)).collect();
    println!(
        "segment 50, g -0.4, 3500 rpm: constant {c0:.4}, state-dependent {mu:.4?} at {feeds:?} m/s"
    );
    for w in mu.windows(2) {
        assert!(w[1] < w[0] - 1e-3, "not decreasing: {mu:?}");
    }
    assert!(
        mu[0] > 1.0 && mu[3] < 1.0,
        "no feed lower bound inside 0.03..0.06: {mu:?}"
    );
}
