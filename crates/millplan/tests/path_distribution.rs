//! The distribution of planar paths (kerf_millplan::path_distribution, issue 13 item 4):
//! deterministic from a seed, every accepted path machinable from the initial state, the
//! held-out paths apart from the training ones.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::sync::Arc;

use kerf_mill::{MillCell, PathSpec};
use kerf_millplan::path_distribution::{
    check_path, sample_path, training_paths, PathDistribution, PathSetEnv, HELD_OUT_SEEDS,
    TRAINING_SEED,
};
use kerf_millplan::{EnvConfig, Environment};

#[test]
fn paths_are_deterministic_reachable_and_held_out_apart() {
    let base = MillCell::default_cell().unwrap();
    let dist = PathDistribution::default();
    let a = sample_path(&base, &dist, 42).unwrap();
    let b = sample_path(&base, &dist, 42).unwrap();
    assert_eq!(a.spec, b.spec, "a seed names one path");
    assert_ne!(a.spec, sample_path(&base, &dist, 43).unwrap().spec);
    // Three of the ten held-out paths (the bench draws all ten), and two training paths.
    let held: Vec<_> = HELD_OUT_SEEDS[..3]
        .iter()
        .map(|&seed| sample_path(&base, &dist, seed).unwrap())
        .collect();
    let train = training_paths(&base, &dist, 2).unwrap();
    for p in held.iter().chain(&train) {
        assert_eq!(p.cell.path().segments().len(), 100);
        assert!(check_path(&p.cell, 0.0, 0.35).unwrap().is_none());
        // Every segment has a g with 1/K >= 0.35 (independent sweep, the planner's
        // check_reachable made stricter), and the IVP is feasible.
        assert!(p.cell.evaluate(0, 0.0, None).unwrap().condition_indicator >= 0.35);
        for s in (0..100).step_by(9).chain([99]) {
            let ok = (0..=64).any(|k| {
                let g = -std::f64::consts::PI + std::f64::consts::TAU * k as f64 / 64.0;
                p.cell
                    .evaluate(s, g, None)
                    .is_ok_and(|c| c.condition_indicator >= 0.35)
            });
            assert!(ok, "seed {} segment {s}", p.seed);
        }
        let length = p.cell.path().total_length();
        assert!((0.35..1.3).contains(&length), "{length}");
    }
    for p in &held {
        assert!(HELD_OUT_SEEDS.contains(&p.seed));
        assert!(!(TRAINING_SEED..TRAINING_SEED + 10_000).contains(&p.seed));
        assert!(train.iter().all(|t| t.spec != p.spec));
    }
    // The planes differ: not every held-out path lies at one height.
    let zs: Vec<f64> = held.iter().map(|p| p.spec.points[0][2]).collect();
    assert!(zs.iter().any(|z| (z - zs[0]).abs() > 0.05), "{zs:?}");
    // A path out of reach is refused by the check.
    let far = base
        .with_path(&PathSpec {
            points: vec![[3.5, 0.0, 1.7], [3.9, 0.2, 1.7]],
            ..PathSpec::default()
        })
        .unwrap();
    assert!(check_path(&far, 0.0, 0.35).unwrap().is_some());
}

#[test]
fn path_set_environment_runs_the_paths_in_turn() {
    let base = MillCell::default_cell().unwrap();
    let dist = PathDistribution::default();
    let cells: Vec<Arc<MillCell>> = training_paths(&base, &dist, 2)
        .unwrap()
        .into_iter()
        .map(|p| p.cell)
        .collect();
    let mut env = PathSetEnv::new(&cells, EnvConfig::default()).unwrap();
    assert_eq!(env.len(), 2);
    let mut first = Vec::new();
    for k in 0..4 {
        let o = env.reset().unwrap();
        assert_eq!(
            env.active().cell().path().total_length(),
            cells[k % 2].path().total_length()
        );
        if k < 2 {
            first.push(o);
        } else {
            assert_eq!(
                o,
                first[k - 2],
                "the same path gives the same initial observation"
            );
        }
    }
    assert_ne!(first[0], first[1]);
    assert!(PathSetEnv::new(&[], EnvConfig::default()).is_err());
}
