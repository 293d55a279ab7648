//! The state-dependent chatter indicator on the default cell against stored
//! reference values: `tests/data/indicator_reference.txt`, 1000 random cell
//! states (segment, Ω 2000–4000 rpm, f 0.01–0.06 m/s, g over the reachable
//! band; `examples/indicator_sweep.rs`, seed 13) evaluated by the
//! implementation before issue 13's speed-up (main 23f731e). The speed-up
//! (skipped regeneration orders, BENCHMARKS.md "Chatter indicator per
//! evaluation") keeps every value bit-identical; a change of the model or
//! its numerics shows up here and must say so.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_chatter::indicator::chatter_indicator;
use kerf_mill::MillCell;

#[test]
fn indicator_matches_the_stored_reference_sweep() {
    let cell = MillCell::default_cell().expect("default cell");
    let process = cell.milling_process();
    let settings = *cell.indicator_settings();
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/indicator_reference.txt"
    );
    let text = std::fs::read_to_string(path).expect("reference file");
    let (mut compared, mut worst) = (0, 0.0_f64);
    let mut differing = Vec::new();
    for line in text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty())
    {
        let f: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(f.len(), 5, "bad line {line}");
        let seg: usize = f[0].parse().unwrap();
        let (g, rpm, feed): (f64, f64, f64) = (
            f[1].parse().unwrap(),
            f[2].parse().unwrap(),
            f[3].parse().unwrap(),
        );
        let state = cell
            .evaluate(seg, g, None)
            .expect("the reference states are feasible");
        let new = chatter_indicator(&state.modal, &process, rpm, feed, &settings)
            .map(|i| i.spectral_radius);
        match (f[4].parse::<f64>(), new) {
            (Ok(old), Ok(new)) => {
                worst = worst.max((old - new).abs());
                if old.to_bits() != new.to_bits() {
                    differing.push(format!("{line} -> {new:?}"));
                }
            }
            (Err(_), Err(_)) => {}
            (old, new) => panic!("error status changed: {line}: {old:?} -> {new:?}"),
        }
        compared += 1;
    }
    assert_eq!(compared, 1000);
    assert!(
        differing.is_empty(),
        "{} of {compared} values differ (max |d mu| {worst:e}), e.g. {:?}",
        differing.len(),
        &differing[..differing.len().min(5)]
    );
}
