//! Builds the chatter-indicator cache of the DEFAULT cell
//! (`urdf/irb6660_milling.yaml`) into `crates/millplan/data/indicator_cache.bin`
//! and measures its interpolation error against direct evaluation.
//!
//! ```sh
//! cargo run --release -p kerf_millplan --example build_cache
//! cargo run --release -p kerf_millplan --example build_cache -- --probe   # timing only
//! ```
//!
//! The grid (kerf_millplan::cache, `DEFAULT_*` below): every 5th segment and
//! the last (21 nodes), Ω every 100 rpm over 2000–4000 (21), f at 0.01,
//! 0.02, 0.03 and every 5e-3 m/s from 0.035 to 0.06 (9), g every 0.2 rad over
//! −3.0…3.0 rad (31; the DP's g grid, so DP queries are on g nodes). The
//! stated error bound is 1.5 × the largest error measured at 1000 random
//! points (seed 2025), rounded up to 1e-3.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::time::Instant;

use kerf_chatter::indicator::chatter_indicator;
use kerf_mill::MillCell;
use kerf_millplan::cache::{GridSpec, IndicatorCache};
use kerf_millplan::MillPlanError;

const DEFAULT_STRIDE: usize = 5;
const DEFAULT_RPM: (f64, f64, usize) = (2000.0, 4000.0, 21);
/// Feed nodes [m/s]: denser where plans run (|μ| is curved in f at low
/// feed, f^(x_F − 1) cutting stiffness).
const DEFAULT_FEEDS: [f64; 9] = [0.01, 0.02, 0.03, 0.035, 0.04, 0.045, 0.05, 0.055, 0.06];
const DEFAULT_G: (f64, f64, usize) = (-3.0, 3.0, 31);
const ERROR_POINTS: usize = 1000;
const ERROR_SEED: u64 = 2025;

fn probe(cell: &MillCell) -> Result<(), MillPlanError> {
    let process = cell.milling_process();
    let settings = cell.indicator_settings();
    let n = 40;
    let state = cell.evaluate(50, 0.0, None)?;
    let t = Instant::now();
    for i in 0..n {
        let rpm = 2000.0 + 50.0 * i as f64;
        chatter_indicator(&state.modal, &process, rpm, 0.04, settings)?;
    }
    let per = t.elapsed().as_secs_f64() / n as f64;
    println!(
        "indicator: {:.3} ms per evaluation (release, one thread)",
        per * 1e3
    );
    for seg in [0usize, 50, 99] {
        for g in [0.0, 1.0] {
            let Ok(state) = cell.evaluate(seg, g, None) else {
                continue;
            };
            let mut line = format!("segment {seg:2} g {g:.1}:");
            for rpm in [2000.0, 3000.0, 4000.0] {
                for feed in [0.0, 0.001, 0.005, 0.01, 0.03, 0.06] {
                    let v = chatter_indicator(&state.modal, &process, rpm, feed, settings)
                        .map(|i| format!("{:.3}", i.spectral_radius))
                        .unwrap_or_else(|e| format!("err({e})"));
                    line.push_str(&format!(" [{rpm:.0},{feed}]={v}"));
                }
            }
            println!("{line}");
        }
    }
    Ok(())
}

/// Prints the largest interpolation errors of the committed cache.
fn worst(cell: &MillCell) -> Result<(), MillPlanError> {
    use kerf_millplan::cache::{direct_indicator, SplitMix64};
    let cache = IndicatorCache::load(&IndicatorCache::default_path(), cell)?;
    let grid = cache.grid().clone();
    let mut rng = SplitMix64::new(7);
    let mut rows = Vec::new();
    for _ in 0..600 {
        let seg = rng.integer(0, 99);
        let rpm = rng.uniform(2000.0, 4000.0);
        let feed = rng.uniform(grid.feed[0], 0.06);
        let g = rng.uniform(-1.0, 2.2);
        if let (Some(c), Some(d)) = (
            cache.try_query(seg, rpm, feed, g)?,
            direct_indicator(cell, seg, rpm, feed, g, None)
                .ok()
                .flatten(),
        ) {
            rows.push(((c - d).abs(), seg, rpm, feed, g, d));
        }
    }
    rows.sort_by(|a, b| b.0.total_cmp(&a.0));
    for r in rows.iter().take(25) {
        println!(
            "err {:.4} seg {} rpm {:.0} feed {:.4} g {:.3} direct {:.4}",
            r.0, r.1, r.2, r.3, r.4, r.5
        );
    }
    Ok(())
}

fn main() -> Result<(), MillPlanError> {
    let cell = MillCell::default_cell()?;
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.iter().any(|a| a == "--probe") {
        return probe(&cell);
    }
    if args.iter().any(|a| a == "--worst") {
        return worst(&cell);
    }
    if args.iter().any(|a| a == "--remeasure") {
        let mut cache = IndicatorCache::load(&IndicatorCache::default_path(), &cell)?;
        return measure_and_save(&cell, &mut cache);
    }
    let mut spec = GridSpec::uniform(
        cell.path().segments().len(),
        DEFAULT_STRIDE,
        DEFAULT_RPM,
        (DEFAULT_FEEDS[0], DEFAULT_FEEDS[8], 2),
        DEFAULT_G,
    )?;
    spec.feed = DEFAULT_FEEDS.to_vec();
    spec.validate()?;
    println!(
        "grid: {} segment nodes x {} rpm x {} feed x {} g = {} nodes",
        spec.segments.len(),
        spec.rpm.len(),
        spec.feed.len(),
        spec.g.len(),
        spec.node_count()
    );
    let t = Instant::now();
    let mut cache = IndicatorCache::build(&cell, &spec, 2)?;
    let build = t.elapsed().as_secs_f64();
    println!(
        "built in {build:.1} s (2 threads), {} infeasible nodes",
        cache.header().infeasible_nodes
    );
    measure_and_save(&cell, &mut cache)
}

/// Measures the error (general queries and g on nodes), sets the stated
/// bounds and writes the file.
fn measure_and_save(cell: &MillCell, cache: &mut IndicatorCache) -> Result<(), MillPlanError> {
    let mut results = Vec::new();
    for g_on_nodes in [false, true] {
        let t = Instant::now();
        let stats = cache.measure_error(cell, ERROR_POINTS, ERROR_SEED, g_on_nodes)?;
        let bound = (1.5 * stats.max_abs * 1e3).ceil() / 1e3;
        println!(
            "error vs direct (g on nodes: {g_on_nodes}) at {} random points ({} skipped, {:.1} s): \
             max {:.5}, p99 {:.5}, mean {:.6}; stated bound {bound:.3}",
            stats.points,
            stats.skipped,
            t.elapsed().as_secs_f64(),
            stats.max_abs,
            stats.p99_abs,
            stats.mean_abs
        );
        results.push((Some(stats), Some(bound)));
    }
    println!("a-priori curvature estimate {:.4}", cache.curvature_bound());
    let g_nodes = results.pop().unwrap_or((None, None));
    let general = results.pop().unwrap_or((None, None));
    cache.set_error(
        general,
        g_nodes,
        "cargo run --release -p kerf_millplan --example build_cache",
    )?;
    let path = IndicatorCache::default_path();
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| MillPlanError::Io {
            path: dir.display().to_string(),
            message: e.to_string(),
        })?;
    }
    cache.save(&path)?;
    println!("wrote {}", path.display());
    Ok(())
}
