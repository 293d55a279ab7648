//! The naive constant-(Ω, f) planner against direct evaluation.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_mill::MillCell;
use kerf_millplan::cache::{direct_indicator, GridSpec, IndicatorCache};
use kerf_millplan::naive;

/// |μ| at every segment for constant (Ω, f, g), directly, IK branch
/// continuous.
fn direct_all(cell: &MillCell, rpm: f64, feed: f64, g: f64) -> Vec<f64> {
    let mut reference: Option<[f64; 6]> = None;
    (0..cell.path().segments().len())
        .map(|seg| {
            let cs = cell.evaluate(seg, g, reference.as_ref()).unwrap();
            reference = Some(cs.joints);
            direct_indicator(cell, seg, rpm, feed, g, reference.as_ref())
                .unwrap()
                .unwrap()
        })
        .collect()
}

#[test]
fn naive_pair_is_chatter_free_directly_and_nothing_faster_is() {
    let cell = MillCell::default_cell().unwrap();
    let cache = IndicatorCache::load(&IndicatorCache::default_path(), &cell).unwrap();
    let r = naive::solve(&cell, &cache, 0.0).unwrap();
    assert!(r.chatter_free);
    assert_eq!(r.states.len(), 100);
    assert!(r
        .states
        .iter()
        .all(|s| s.rpm == r.rpm && s.feed == r.feed && s.g == 0.0));
    // Independent check at every segment.
    let mus = direct_all(&cell, r.rpm, r.feed, 0.0);
    let max = mus.iter().copied().fold(0.0, f64::max);
    assert!(max < 1.0, "max |mu| {max}");
    assert!((max - r.max_spectral_radius).abs() < 1e-12);
    // At its feed, the first verified candidate has the lowest cached
    // max |mu| of all grid speeds (the tie-break rule).
    let cached_max = |rpm: f64, f: f64| {
        (0..100)
            .map(|seg| {
                cache
                    .try_query(seg, rpm, f, 0.0)
                    .unwrap()
                    .unwrap_or(f64::INFINITY)
            })
            .fold(0.0, f64::max)
    };
    if r.verified == 1 {
        let chosen = cached_max(r.rpm, r.feed);
        for k in 0..=100 {
            assert!(cached_max(2000.0 + 20.0 * k as f64, r.feed) >= chosen);
        }
    }
    // No faster grid feed is chatter-free per the cache at any speed
    // (vacuous when the naive feed is already f_max, as on the default
    // cell: 4000 rpm, 0.06 m/s).
    let mut f = r.feed + 1e-3;
    while f <= 0.06 + 1e-12 {
        for k in 0..=100 {
            let rpm = 2000.0 + 20.0 * k as f64;
            let worst = (0..100)
                .map(|seg| {
                    cache
                        .try_query(seg, rpm, f, 0.0)
                        .unwrap()
                        .unwrap_or(f64::INFINITY)
                })
                .fold(0.0, f64::max);
            assert!(
                worst >= 1.0,
                "{rpm} rpm, {f} m/s is chatter-free in the cache"
            );
        }
        f += 1e-3;
    }
}

#[test]
fn no_chatter_free_pair_falls_back_to_the_ivp_with_chatter_flagged() {
    let cell = MillCell::default_cell().unwrap();
    // A cache covering only pairs near the IVP, where segment 0 chatters at
    // g = 0 (|mu| about 1.1 at 2000 rpm, 0.04 m/s).
    let spec = GridSpec {
        segments: vec![0, 99],
        rpm: vec![2000.0, 2100.0],
        feed: vec![0.039, 0.041],
        g: vec![0.0, 0.2],
    };
    let cache = IndicatorCache::build(&cell, &spec, 2).unwrap();
    let r = naive::solve(&cell, &cache, 0.0).unwrap();
    assert_eq!((r.rpm, r.feed), (2000.0, 0.04));
    assert!(!r.chatter_free);
    let max = direct_all(&cell, 2000.0, 0.04, 0.0)
        .into_iter()
        .fold(0.0, f64::max);
    assert!(max >= 1.0);
    assert!((max - r.max_spectral_radius).abs() < 1e-12);
    assert!(naive::solve(&cell, &cache, f64::NAN).is_err());
    // g = 3 rad is out of the reachable band at some segments: no
    // constant plan exists, an error rather than a plan.
    let err = naive::solve(&cell, &cache, 3.0).unwrap_err().to_string();
    assert!(err.contains("infeasible"), "{err}");
}
