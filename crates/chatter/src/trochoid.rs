//! Exact tooth-path geometry of seed 004 eq. 2-4: the state-dependent
//! regenerative delay τ and chip thickness h of a tooth cutting the surface
//! left by the tooth m positions earlier.
//!
//! # Derivation (seed 004 eq. 2 → eq. 3, eq. 4)
//!
//! In the workpiece frame the tool centre is `c(t) = (x(t) − f t, y(t))`
//! (feed f along −x) and tooth j points along `u(φ) = −(sin φ, cos φ)`
//! with `v(φ) = du/dφ = (−cos φ, sin φ)` (frame of [`crate::model`]).
//! The tooth m positions earlier passed the current tooth's radial line at
//! `t − τ`, at angle `φ − δ` with `δ = Ω τ − 2π m / N_t` (δ ≈ 0 for
//! τ ≈ m T); since `u(φ − δ) = cos δ u − sin δ v`, its tip was at
//! `c(t) + Δc + R (cos δ u − sin δ v)` with
//! `Δc = c(t − τ) − c(t) = (f τ + x(t − τ) − x(t), y(t − τ) − y(t))`.
//! That point lies on the current radial line at distance R − h from the
//! centre (seed 004 eq. 2). Its component along v must vanish:
//!
//! `R sin δ + Δc_x cos φ − Δc_y sin φ = 0`  (seed 004 eq. 3),
//!
//! and its component along u is R − h:
//!
//! `h = R (1 − cos δ) + Δc_x sin φ + Δc_y cos φ`  (seed 004 eq. 4; the
//! extracted eq. 4 repeats its last term, a typo).
//!
//! Without vibration `Δc = (f τ, 0)` and, to first order in f/(RΩ),
//! `h = f_z sin φ` — the classic circular-tooth-path chip.

/// Residual of seed 004 eq. 3 (tangential condition) [m].
///
/// # Arguments
/// * `radius` — tool radius R [m]
/// * `delta` — δ = Ω τ − 2π m / N_t [rad]
/// * `dcx`, `dcy` — Δc = c(t − τ) − c(t) in the cutting frame [m],
///   feed included (Δc_x = f τ + x(t − τ) − x(t))
/// * `phi` — immersion angle of the current tooth [rad]
pub fn tangential_residual(radius: f64, delta: f64, dcx: f64, dcy: f64, phi: f64) -> f64 {
    let (s, c) = phi.sin_cos();
    radius * delta.sin() + dcx * c - dcy * s
}

/// Chip thickness of seed 004 eq. 4 [m] for the same arguments as
/// [`tangential_residual`]; negative means the tooth is out of the cut
/// (loss of contact).
pub fn chip_thickness(radius: f64, delta: f64, dcx: f64, dcy: f64, phi: f64) -> f64 {
    let (s, c) = phi.sin_cos();
    radius * (1.0 - delta.cos()) + dcx * s + dcy * c
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Without vibration, the exact trochoid gives f_z sin φ to first order
    /// and the delay shifts by −f T cos φ / (R Ω) (eq. 3 linearized).
    #[test]
    fn rigid_tool_gives_the_classic_chip() {
        let (r, teeth, omega, f) = (0.04_f64, 2usize, 3000.0 * std::f64::consts::PI / 30.0, 0.05);
        let period = 2.0 * std::f64::consts::PI / (omega * teeth as f64);
        for k in 1..20 {
            let phi = k as f64 * std::f64::consts::PI / 20.0;
            // Solve eq. 3 for τ by Newton with Δc = (f τ, 0).
            let mut tau = period;
            for _ in 0..50 {
                let delta = omega * tau - 2.0 * std::f64::consts::PI / teeth as f64;
                let res = tangential_residual(r, delta, f * tau, 0.0, phi);
                let d = r * omega * delta.cos() + f * phi.cos();
                tau -= res / d;
            }
            let delta = omega * tau - 2.0 * std::f64::consts::PI / teeth as f64;
            assert!(tangential_residual(r, delta, f * tau, 0.0, phi).abs() < 1e-15);
            let h = chip_thickness(r, delta, f * tau, 0.0, phi);
            let fz = f * period;
            assert!(
                (h - fz * phi.sin()).abs() < 1e-2 * fz,
                "phi {phi}: h {h} vs {}",
                fz * phi.sin()
            );
            let dtau = -f * period * phi.cos() / (r * omega);
            assert!((tau - period - dtau).abs() < 1e-2 * dtau.abs().max(1e-9));
        }
    }
}
