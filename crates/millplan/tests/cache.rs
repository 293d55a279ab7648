//! The indicator cache against direct evaluation of the chatter indicator:
//! a small grid built here, the file format, and the committed default
//! cache's stated error bound.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::path::Path;

use kerf_mill::MillCell;
use kerf_millplan::cache::{direct_indicator, GridSpec, IndicatorCache, SplitMix64};
use kerf_millplan::env::{EnvConfig, MillEnv};
use kerf_millplan::Environment;

fn small_spec() -> GridSpec {
    GridSpec {
        segments: vec![40, 45, 50],
        rpm: vec![2800.0, 3000.0, 3200.0],
        feed: vec![0.04, 0.05, 0.06],
        g: vec![0.0, 0.2, 0.4],
    }
}

fn temp(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("kerf_millplan_{}_{name}", std::process::id()))
}

#[test]
fn small_grid_exact_at_nodes_and_within_the_curvature_bound_between() {
    let cell = MillCell::default_cell().unwrap();
    let spec = small_spec();
    let cache = IndicatorCache::build(&cell, &spec, 2).unwrap();
    assert_eq!(cache.header().infeasible_nodes, 0);
    // Thread count does not change the result.
    let one = IndicatorCache::build(&cell, &spec, 1).unwrap();
    for s in 0..3 {
        for r in 0..3 {
            for f in 0..3 {
                for g in 0..3 {
                    assert_eq!(one.node_value(s, r, f, g), cache.node_value(s, r, f, g));
                }
            }
        }
    }
    // Exact at nodes (a query on a node skips the zero-weight corners).
    for (s, seg) in spec.segments.iter().enumerate() {
        for (r, rpm) in spec.rpm.iter().enumerate() {
            for (f, feed) in spec.feed.iter().enumerate().step_by(2) {
                for (g, gv) in spec.g.iter().enumerate().step_by(2) {
                    let direct = direct_indicator(&cell, *seg, *rpm, *feed, *gv, None)
                        .unwrap()
                        .unwrap();
                    assert_eq!(cache.query(*seg, *rpm, *feed, *gv).unwrap(), direct);
                    assert_eq!(cache.node_value(s, r, f, g), Some(direct));
                }
            }
        }
    }
    // Between nodes: within the a-priori bound, which must be small enough
    // to mean something here.
    let bound = cache.curvature_bound();
    assert!(bound > 0.0 && bound < 0.05, "bound {bound}");
    let mut rng = SplitMix64::new(11);
    let mut worst: f64 = 0.0;
    for _ in 0..25 {
        let seg = rng.integer(40, 50);
        let rpm = rng.uniform(2800.0, 3200.0);
        let feed = rng.uniform(0.04, 0.06);
        let g = rng.uniform(0.0, 0.4);
        let c = cache.query(seg, rpm, feed, g).unwrap();
        let d = direct_indicator(&cell, seg, rpm, feed, g, None)
            .unwrap()
            .unwrap();
        worst = worst.max((c - d).abs());
    }
    assert!(worst <= bound, "worst {worst} > bound {bound}");
    // Outside the grid: reported, NaN refused.
    assert_eq!(cache.try_query(39, 3000.0, 0.05, 0.2).unwrap(), None);
    assert_eq!(cache.try_query(45, 3300.0, 0.05, 0.2).unwrap(), None);
    assert!(cache.query(45, 3000.0, 0.07, 0.2).is_err());
    assert!(cache.try_query(45, f64::NAN, 0.05, 0.2).is_err());
}

#[test]
fn infeasible_nodes_are_never_mixed_in() {
    let cell = MillCell::default_cell().unwrap();
    // g = 3.0 rad is out of the reachable band at segment 10 (kerf_mill's
    // doc example: joint_5 limit).
    let spec = GridSpec {
        segments: vec![10],
        rpm: vec![3000.0, 3100.0],
        feed: vec![0.05, 0.06],
        g: vec![1.0, 3.0],
    };
    assert!(cell.evaluate(10, 3.0, None).is_err());
    let cache = IndicatorCache::build(&cell, &spec, 1).unwrap();
    assert_eq!(cache.header().infeasible_nodes, 4);
    assert_eq!(cache.node_value(0, 0, 0, 1), None);
    // On the feasible node: exact; between the feasible and the infeasible
    // g node: reported, never a number.
    let direct = direct_indicator(&cell, 10, 3000.0, 0.05, 1.0, None)
        .unwrap()
        .unwrap();
    assert_eq!(cache.query(10, 3000.0, 0.05, 1.0).unwrap(), direct);
    assert_eq!(cache.try_query(10, 3000.0, 0.05, 1.5).unwrap(), None);
    let err = cache.query(10, 3000.0, 0.05, 1.5).unwrap_err().to_string();
    assert!(err.contains("infeasible"), "{err}");
}

#[test]
fn save_load_round_trip_and_bad_files() {
    let cell = MillCell::default_cell().unwrap();
    let spec = GridSpec {
        segments: vec![0, 99],
        rpm: vec![2000.0, 4000.0],
        feed: vec![0.03, 0.06],
        g: vec![0.0, 0.2],
    };
    let mut cache = IndicatorCache::build(&cell, &spec, 2).unwrap();
    cache
        .set_error((None, Some(0.01)), (None, None), "test")
        .unwrap();
    let path = temp("cache.bin");
    cache.save(&path).unwrap();
    let loaded = IndicatorCache::load(&path, &cell).unwrap();
    assert_eq!(loaded, cache);
    assert_eq!(loaded.header().error_bound, Some(0.01));

    let bytes = std::fs::read(&path).unwrap();
    // Corrupt: one data byte flipped -> checksum error.
    let mut corrupt = bytes.clone();
    if let Some(last) = corrupt.last_mut() {
        *last ^= 0x5a;
    }
    let err = IndicatorCache::from_bytes(&corrupt, "x")
        .unwrap_err()
        .to_string();
    assert!(err.contains("checksum"), "{err}");
    // Truncated.
    let err = IndicatorCache::from_bytes(&bytes[..bytes.len() - 8], "x")
        .unwrap_err()
        .to_string();
    assert!(err.contains("truncated"), "{err}");
    // Not a cache file.
    assert!(IndicatorCache::from_bytes(b"hello\n{}\n", "x").is_err());
    assert!(IndicatorCache::from_bytes(b"", "x").is_err());
    // Missing file.
    assert!(IndicatorCache::load(Path::new("/nonexistent/cache.bin"), &cell).is_err());

    // Stale: the same file against a cell with another damping ratio.
    let yaml = std::fs::read_to_string(MillCell::default_path()).unwrap();
    let edited = yaml.replace("damping_ratio: 0.05\n", "damping_ratio: 0.06\n");
    assert_ne!(yaml, edited);
    let dir = MillCell::default_path().parent().unwrap().to_path_buf();
    let other = MillCell::from_yaml_str(&edited, &dir, Path::new("edited.yaml")).unwrap();
    let err = IndicatorCache::load(&path, &other).unwrap_err().to_string();
    assert!(err.contains("stale"), "{err}");
    let _ = std::fs::remove_file(&path);

    // Bad grids and thread counts.
    let mut bad = spec.clone();
    bad.rpm = vec![3000.0, 2000.0];
    assert!(IndicatorCache::build(&cell, &bad, 1).is_err());
    assert!(IndicatorCache::build(&cell, &spec, 3).is_err());
    let mut far = spec.clone();
    far.segments = vec![0, 100];
    assert!(IndicatorCache::build(&cell, &far, 1).is_err());
}

#[test]
fn committed_default_cache_within_its_stated_bounds() {
    let cell = MillCell::default_cell().unwrap();
    let cache = IndicatorCache::load(&IndicatorCache::default_path(), &cell).unwrap();
    let h = cache.header();
    let bound = h.error_bound.unwrap();
    let bound_nodes = h.error_bound_g_nodes.unwrap();
    assert!(h.error.unwrap().points >= 500);
    assert!(bound < 0.2 && bound_nodes < 0.1);
    let grid = cache.grid().clone();
    let mut rng = SplitMix64::new(99);
    let mut compared = 0;
    while compared < 20 {
        let seg = rng.integer(0, 99);
        let rpm = rng.uniform(2000.0, 4000.0);
        let feed = rng.uniform(grid.feed[0], 0.06);
        // The reachable band of every segment.
        let g = rng.uniform(-1.2, 1.6);
        let (Some(c), Some(d)) = (
            cache.try_query(seg, rpm, feed, g).unwrap(),
            direct_indicator(&cell, seg, rpm, feed, g, None).unwrap(),
        ) else {
            continue;
        };
        assert!((c - d).abs() <= bound, "{seg} {rpm} {feed} {g}: {c} vs {d}");
        // And with g on its nearest node, the tighter bound.
        let gn = (g / 0.2).round() * 0.2;
        if let (Some(c), Some(d)) = (
            cache.try_query(seg, rpm, feed, gn).unwrap(),
            direct_indicator(&cell, seg, rpm, feed, gn, None).unwrap(),
        ) {
            assert!(
                (c - d).abs() <= bound_nodes,
                "{seg} {rpm} {feed} {gn}: {c} vs {d}"
            );
        }
        compared += 1;
    }
}

#[test]
fn env_branch_continuity_gives_the_cache_reference_dynamics() {
    // The cache (and the DP's K table) evaluate each (segment, g) with the
    // cell's reference joints; the environment follows the previous
    // state's joints. Along an episode sweeping g over the band they may
    // pick different IK branches (measured: 59 of 99 steps, wrist flips),
    // but K and the tool-tip dynamics — all the cache depends on — must be
    // the same, so the cache describes the environment.
    let cell = std::sync::Arc::new(MillCell::default_cell().unwrap());
    let cache = IndicatorCache::load(&IndicatorCache::default_path(), &cell).unwrap();
    let mut env = MillEnv::new(
        cell.clone(),
        Some(std::sync::Arc::new(cache)),
        EnvConfig {
            alpha: 1.0,
            // The sweep crosses the wrist region fast; joint speeds and the distance to the
            // singular set are not what this test is about.
            joint_speed_limits: false,
            min_condition_indicator: None,
            ..EnvConfig::default()
        },
    )
    .unwrap();
    let rollout = env
        .rollout(|_, s| {
            // Up to 1.2 rad, then down to -1.2 rad, and up again.
            let phase = ((s.segment + 6) / 12) % 2;
            Ok(vec![1.0, 1.0, if phase == 0 { 1.0 } else { -1.0 }])
        })
        .unwrap();
    assert!(rollout.completed);
    assert_eq!(rollout.steps.len(), env.max_steps());
    let mut cached = 0;
    let mut other_branch = 0;
    let mut reference_joints = rollout.initial.evaluation.unwrap().joints;
    for st in &rollout.steps {
        let ev = st.evaluation.unwrap();
        let seg = st.state.segment;
        let by_reference = cell.evaluate(seg, st.state.g, None).unwrap();
        let by_continuity = cell
            .evaluate(seg, st.state.g, Some(&reference_joints))
            .unwrap();
        reference_joints = by_continuity.joints;
        assert_eq!(ev.joints, by_continuity.joints);
        if ev
            .joints
            .iter()
            .zip(by_reference.joints)
            .any(|(a, b)| (a - b).abs() > 1e-9)
        {
            other_branch += 1;
        }
        // What the cache depends on must be the same on both branches.
        let rel = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1.0);
        assert!(
            rel(
                by_reference.condition_number,
                by_continuity.condition_number
            ),
            "segment {seg}: K {} vs {}",
            by_reference.condition_number,
            by_continuity.condition_number
        );
        let (m1, m2) = (by_reference.modal, by_continuity.modal);
        for (a, b) in m1.stiffness.iter().zip(m2.stiffness.iter()) {
            assert!(rel(*a, *b), "segment {seg}: stiffness {a} vs {b}");
        }
        for (a, b) in m1.mass.iter().zip(m2.mass.iter()) {
            assert!(rel(*a, *b), "segment {seg}: mass {a} vs {b}");
        }
        for (a, b) in m1.damping.iter().zip(m2.damping.iter()) {
            assert!(rel(*a, *b), "segment {seg}: damping {a} vs {b}");
        }
        if ev.from_cache {
            cached += 1;
        }
    }
    println!("{other_branch} steps on another IK branch than the reference's");
    assert!(cached > 90, "{cached} steps from the cache");
}
