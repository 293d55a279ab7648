//! Which redundancy angles are reachable within the joint limits along the
//! default path (tool pointing down at z = 1.7 m, 100 segments): the map the
//! milling planner works in. Printed with `--nocapture`.

#![allow(clippy::needless_range_loop)] // (g, segment) grids read best with indices

use kerf_mill::{MillCell, MillError};

#[test]
fn reachability_map_of_the_default_path() {
    let cell = MillCell::default_cell().expect("cell");
    let n_g = 36;
    let gs: Vec<f64> = (0..=n_g)
        .map(|i| -std::f64::consts::PI + i as f64 * std::f64::consts::TAU / n_g as f64)
        .collect();
    println!("rows: g [rad]; columns: segments 0..99 in steps of 3");
    println!("'o' valid, digit = joint at its limit, 'U' unreachable; K range of the valid ones");
    let mut valid = vec![vec![false; 100]; gs.len()];
    for (gi, &g) in gs.iter().enumerate() {
        let mut line = String::new();
        let (mut kmin, mut kmax) = (f64::INFINITY, 0.0f64);
        for s in 0..100 {
            let c = match cell.evaluate(s, g, None) {
                Ok(st) => {
                    valid[gi][s] = true;
                    kmin = kmin.min(st.condition_number);
                    kmax = kmax.max(st.condition_number);
                    'o'
                }
                Err(MillError::JointLimit { joint, .. }) => joint.chars().last().unwrap_or('?'),
                Err(MillError::Unreachable { .. }) => 'U',
                Err(e) => panic!("unexpected error {e}"),
            };
            if s % 3 == 0 {
                line.push(c);
            }
        }
        if kmin.is_finite() {
            println!("g = {g:+.3}  {line}  K in [{kmin:.2}, {kmax:.2}]");
        } else {
            println!("g = {g:+.3}  {line}  (no valid segment)");
        }
    }
    // Every segment is reachable for g in [0, 2] (the paper's g stays in
    // 0..2 rad) and for none at g = +-pi.
    for (gi, &g) in gs.iter().enumerate() {
        if (0.0..=2.0).contains(&g) {
            assert!(valid[gi].iter().all(|&v| v), "g = {g}");
        }
        if g.abs() > 3.1 {
            assert!(valid[gi].iter().all(|&v| !v), "g = {g}");
        }
    }
    // Per segment the reachable g form one band; report its extent.
    let mut band_lo = f64::INFINITY;
    let mut band_hi = f64::NEG_INFINITY;
    for s in 0..100 {
        let reach: Vec<f64> = gs
            .iter()
            .enumerate()
            .filter(|(gi, _)| valid[*gi][s])
            .map(|(_, g)| *g)
            .collect();
        let (lo, hi) = (reach[0], reach[reach.len() - 1]);
        band_lo = band_lo.min(lo);
        band_hi = band_hi.max(hi);
        if s % 33 == 0 || s == 99 {
            println!(
                "segment {s}: reachable g in [{lo:.3}, {hi:.3}] (grid {:.3} rad)",
                std::f64::consts::TAU / n_g as f64
            );
        }
    }
    println!("union of the bands: [{band_lo:.3}, {band_hi:.3}]");
}
