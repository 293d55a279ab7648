//! When the teeth are in the cut: entry/exit breakpoints of the nominal
//! engagement.

use std::f64::consts::PI;

use crate::model::MillingProcess;

/// Sorted entry/exit times of all teeth in [0, T), with 0 and T.
pub(super) fn engagement_breakpoints(
    process: &MillingProcess,
    omega: f64,
    period: f64,
) -> Vec<f64> {
    let nt = process.teeth as f64;
    let mut pts = vec![0.0, period];
    for j in 0..process.teeth {
        let phase = 2.0 * PI * j as f64 / nt;
        for phib in [process.entry_angle, process.exit_angle] {
            // φ_j(t) = Ω t + phase ≡ φ_b (mod 2π)
            let t = ((phib - phase).rem_euclid(2.0 * PI)) / omega;
            // one period covers 2π/N_t of angle: at most one solution in [0, T)
            if t < period {
                pts.push(t);
            }
        }
    }
    pts.sort_by(|a, b| a.total_cmp(b));
    let tol = 1e-9 * period;
    let mut out: Vec<f64> = Vec::with_capacity(pts.len());
    for p in pts {
        if out.last().is_none_or(|&q| p - q > tol) {
            out.push(p);
        } else if (p - period).abs() <= tol {
            if let Some(last) = out.last_mut() {
                *last = period;
            }
        }
    }
    out
}

/// Whether angle φ (any real) lies in the engagement [φ_en, φ_ex] (mod 2π).
pub(crate) fn engaged(process: &MillingProcess, phi: f64) -> bool {
    let p = super::interp::wrap(phi, 2.0 * PI);
    p >= process.entry_angle && p <= process.exit_angle
}
