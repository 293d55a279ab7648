//! Chooses the grid of the per-path indicator cache (`kerf_millplan::path_cache`) from the
//! committed default cache: each candidate grid is a subset of the default cache's nodes
//! (`IndicatorCache::subgrid`, nothing evaluated), and its interpolation error is measured at
//! every other feasible node of the default cache (the nodes the coarser grid does not have),
//! overall and for g on one of its g nodes (the DP's queries). The cost of a grid is its number
//! of feasible nodes (one indicator evaluation each).
//!
//! ```sh
//! cargo run --release -p kerf_millplan --example path_cache_grid
//! ```
#![allow(clippy::unwrap_used, clippy::expect_used)] // an example reports failures by panicking

use kerf_mill::MillCell;
use kerf_millplan::{GridSpec, IndicatorCache};

fn every(nodes: &[f64], k: usize) -> Vec<f64> {
    let mut out: Vec<f64> = nodes.iter().copied().step_by(k).collect();
    if out.last() != nodes.last() {
        out.push(*nodes.last().unwrap());
    }
    out
}

fn main() {
    let cell = MillCell::default_cell().unwrap();
    let full = IndicatorCache::load(&IndicatorCache::default_path(), &cell).unwrap();
    let grid = full.grid().clone();
    println!(
        "full grid: {} nodes, {} infeasible",
        grid.node_count(),
        full.header().infeasible_nodes
    );
    let segs = |k: usize| -> Vec<usize> {
        let mut s: Vec<usize> = grid.segments.iter().copied().step_by(k).collect();
        if s.last() != grid.segments.last() {
            s.push(*grid.segments.last().unwrap());
        }
        s
    };
    let feeds_all = grid.feed.clone();
    let feed_sets: Vec<(&str, Vec<f64>)> = vec![
        ("all 9", feeds_all.clone()),
        (
            "0.01 0.03 0.04 0.05 0.06",
            vec![0.01, 0.03, 0.04, 0.05, 0.06],
        ),
        (
            "0.01 0.02 0.03 0.04 0.05 0.06",
            vec![0.01, 0.02, 0.03, 0.04, 0.05, 0.06],
        ),
        ("0.01 0.03 0.045 0.06", vec![0.01, 0.03, 0.045, 0.06]),
        ("0.01 0.035 0.06", vec![0.01, 0.035, 0.06]),
    ];
    println!("| segments | rpm step | feeds | g step | feasible nodes | max | p99 | mean | g on nodes: max | p99 |");
    println!("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|");
    let mut configs = Vec::new();
    for sk in [1usize, 2, 4] {
        for rk in [1usize, 2, 4] {
            for (fname, f) in &feed_sets {
                for gk in [1usize, 2] {
                    configs.push((sk, rk, fname.to_string(), f.clone(), gk));
                }
            }
        }
    }
    for (sk, rk, fname, feeds, gk) in configs {
        let spec = GridSpec {
            segments: segs(sk),
            rpm: every(&grid.rpm, rk),
            feed: feeds,
            g: every(&grid.g, gk),
        };
        let sub = full.subgrid(&spec).unwrap();
        let feasible = spec.node_count() - sub.header().infeasible_nodes;
        let mut all = Vec::new();
        let mut on_g = Vec::new();
        for (si, &s) in grid.segments.iter().enumerate() {
            for (ri, &r) in grid.rpm.iter().enumerate() {
                for (fi, &f) in grid.feed.iter().enumerate() {
                    for (gi, &g) in grid.g.iter().enumerate() {
                        let Some(v) = full.node_value(si, ri, fi, gi) else {
                            continue;
                        };
                        if let Some(c) = sub.try_query(s, r, f, g).unwrap() {
                            let e = (c - v).abs();
                            all.push(e);
                            if spec.g.contains(&g) {
                                on_g.push(e);
                            }
                        }
                    }
                }
            }
        }
        let stats = |e: &mut Vec<f64>| {
            e.sort_by(f64::total_cmp);
            let n = e.len().max(1);
            let p99 = e
                .get(((0.99 * n as f64).ceil() as usize).clamp(1, n) - 1)
                .copied()
                .unwrap_or(0.0);
            (
                e.last().copied().unwrap_or(0.0),
                p99,
                e.iter().sum::<f64>() / n as f64,
            )
        };
        let (m, p, a) = stats(&mut all);
        let (mg, pg, _) = stats(&mut on_g);
        println!(
            "| every {} | {} | {} | {:.1} | {} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} |",
            5 * sk,
            100 * rk,
            fname,
            0.2 * gk as f64,
            feasible,
            m,
            p,
            a,
            mg,
            pg
        );
    }
}
