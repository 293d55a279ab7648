//! Which redundancy angles are reachable within the joint limits along the
//! default path (tool pointing down at z = 1.7 m, 100 segments): the map the
//! milling planner works in. Printed with `--nocapture`.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking
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
    // Every segment is reachable for g in [-1.2, 1.6] (the band the cell
    // file states; the mount angle is calibrated in it) and for none at
    // g = +-pi.
    for (gi, &g) in gs.iter().enumerate() {
        if (-1.2..=1.6).contains(&g) {
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

/// The tool mount's angle about the tool axis only moves the zero of g:
/// the shipped cell (tip x axis turned 0.4 rad about the tool axis) at g
/// is the unturned mount at g + 0.4 — same joints, same condition number,
/// same tool-tip modes.
#[test]
fn mount_angle_is_a_shift_of_g() {
    let cell = MillCell::default_cell().expect("cell");
    let text = std::fs::read_to_string(MillCell::default_path()).expect("cell file");
    let turned = "x_axis: [0.0, 0.3894183423086505, 0.9210609940028851]";
    assert!(text.contains(turned), "the shipped mount changed");
    let dir = MillCell::default_path()
        .parent()
        .expect("urdf directory")
        .to_path_buf();
    let plain = MillCell::from_yaml_str(
        &text.replacen(turned, "x_axis: [0.0, 0.0, 1.0]", 1),
        &dir,
        std::path::Path::new("unturned.yaml"),
    )
    .expect("unturned cell");
    for (segment, g) in [(0, 0.0), (37, -0.8), (50, 0.6), (99, 1.2)] {
        let a = cell.evaluate(segment, g, None).expect("shipped");
        let b = plain.evaluate(segment, g + 0.4, None).expect("unturned");
        for j in 0..6 {
            assert!(
                (a.joints[j] - b.joints[j]).abs() < 1e-9,
                "{segment} {g}: {a:?} {b:?}"
            );
        }
        assert!((a.condition_number - b.condition_number).abs() < 1e-9 * a.condition_number);
        let (ka, kb) = (a.modal.stiffness, b.modal.stiffness);
        assert!(
            (ka - kb).norm() < 1e-9 * ka.norm(),
            "{segment} {g}: {ka} vs {kb}"
        );
        assert!((a.modal.mass - b.modal.mass).norm() < 1e-9 * a.modal.mass.norm());
    }
}
