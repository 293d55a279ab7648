//! The per-path indicator cache (`kerf_millplan::path_cache`, issue 13, item 4): its build time
//! on the planner's threads and its error against direct evaluation, for the default path and
//! for a path no shipped cache covers (the default path turned by 0.3 rad about the vertical
//! through its centroid and moved by (−0.1, 0.05, −0.1) m, as `benches/baselines.rs --shifted`).
//!
//! ```sh
//! cargo bench -p kerf_millplan --bench path_cache
//! ```
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench binary reports failures by panicking

use std::time::Instant;

use kerf_budget::Budget;
use kerf_mill::MillCell;
use kerf_millplan::path_cache::path_grid;
use kerf_millplan::path_distribution::moved_points;
use kerf_millplan::plan::default_eval_threads;
use kerf_millplan::{IndicatorCache, MillRequest};

fn main() {
    let base = MillCell::default_cell().unwrap();
    let threads = default_eval_threads();
    println!(
        "| path | grid (segments × Ω × f × g) | nodes | infeasible | build (s, {threads} threads) | error vs direct: any query max / p99 / mean | g on a node: max / p99 / mean |"
    );
    println!("|---|---|---:|---:|---:|---|---|");
    for (name, points) in [
        ("default", MillRequest::default().points),
        (
            "shifted, turned",
            moved_points(&MillRequest::default().points, 0.3, [-0.1, 0.05, -0.1]),
        ),
    ] {
        let request = MillRequest {
            points,
            ..MillRequest::default()
        };
        let cell = base.with_path(&request.path_spec(100)).unwrap();
        let grid = path_grid(&cell, 0.0).unwrap();
        let start = Instant::now();
        let cache =
            IndicatorCache::build_within(&cell, &grid, threads, &Budget::unlimited()).unwrap();
        let build = start.elapsed().as_secs_f64();
        let any = cache.measure_error(&cell, 1000, 2025, false).unwrap();
        let on_g = cache.measure_error(&cell, 1000, 2026, true).unwrap();
        println!(
            "| {name} | {} × {} × {} × {} | {} | {} | {build:.1} | {:.4} / {:.4} / {:.4} ({} points) | {:.4} / {:.4} / {:.4} ({} points) |",
            grid.segments.len(),
            grid.rpm.len(),
            grid.feed.len(),
            grid.g.len(),
            grid.node_count(),
            cache.header().infeasible_nodes,
            any.max_abs,
            any.p99_abs,
            any.mean_abs,
            any.points,
            on_g.max_abs,
            on_g.p99_abs,
            on_g.mean_abs,
            on_g.points
        );
    }
}
