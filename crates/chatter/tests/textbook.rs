//! Textbook validation of the constant-delay stability lobes against
//! references we did not write.
//!
//! The classic 2-DOF milling example of Insperger & Stépán (2004, Int. J.
//! Numer. Meth. Eng. 61:117, §5) that Ding, Zhu, Zhang & Ding (2010, Int.
//! J. Mach. Tools Manuf. 50:502, §4, the two-DOF stability-lobe figure)
//! reuse: 2 teeth, K_t = 6e8 N/m², K_n = 2e8 N/m², f_n = 922 Hz, ζ = 0.011,
//! m = 0.03993 kg in x and y (uncoupled), a/D = 0.05, down milling,
//! 5000–25000 rpm, 0–10 mm.
//!
//! 1. **Published script.** The reference boundary values below were
//!    produced by running, in GNU Octave 7.3, the publicly distributed
//!    MATLAB implementation of that paper's method for exactly this example
//!    (`FulldisTwoDOFMilling.m` of github.com/leekunhwee/Dynamics,
//!    `Cutting/Stability/TimeDomain/FullDis/`, set to down milling,
//!    unchanged otherwise; a small driver bisected its |μ| = 1 contour at
//!    each speed after a 0.1 mm scan from 0 to 10 mm, exactly as
//!    [`kerf_chatter::stability_lobes`] does). The script's own figure is
//!    the contour plot of Ding et al. 2010's 2-DOF example; its values are
//!    data here, not code. Where it finds no instability below 10 mm (the
//!    lobe peaks at 12 500, 22 500, 25 000 rpm), so must we.
//! 2. **Zeroth-order approximation** (Altintas & Budak 1995, CIRP Annals
//!    44:357): the analytic frequency-domain lobes from the mean
//!    directional matrix, for slot milling (a/D = 1), where the time-averaged
//!    approximation is accurate on the lobe flanks; an independent method
//!    (frequency domain, no time discretization).
//!    The same script also gives the slot-milling boundary, peaks included.
//! 3. **Convergence** of our own method: m = 40 against m = 200.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use std::f64::consts::PI;

use kerf_chatter::{mean_directional_matrix, stability_lobes, LobeOptions, MillingProcess, Modal2};
use nalgebra::Complex;

const SPEEDS: [f64; 9] = [
    5_000.0, 7_500.0, 10_000.0, 12_500.0, 15_000.0, 17_500.0, 20_000.0, 22_500.0, 25_000.0,
];

/// a_lim [mm] of the published FDM script at m = 80 (see the module
/// documentation), `None` = stable up to 10 mm.
const PUBLISHED_MM: [Option<f64>; 9] = [
    Some(1.847217),
    Some(1.464990),
    Some(1.483936),
    None,
    Some(1.632568),
    Some(2.604541),
    Some(3.211768),
    None,
    None,
];

/// a_lim [mm] of the same published script for slot milling (a/D = 1,
/// down milling), m = 80, scan 0.01 mm from 0 to 1 mm, then bisection.
const PUBLISHED_SLOT_MM: [f64; 9] = [
    0.048569, 0.055542, 0.072153, 0.149634, 0.115376, 0.048413, 0.063687, 0.149634, 0.533706,
];

fn textbook_modal() -> Modal2 {
    common::textbook_modal()
}

fn textbook_process(radial_immersion: f64) -> MillingProcess {
    // The depth is the unknown of the lobes; 1 mm is a placeholder.
    common::textbook_process(radial_immersion, 0.005, 1e-3)
}

fn lobes_mm(radial_immersion: f64, steps: usize, max_depth: f64) -> Vec<Option<f64>> {
    let opts = LobeOptions {
        steps,
        min_depth: 0.0,
        max_depth,
        scan_points: 100,
        tolerance: 1e-7,
    };
    stability_lobes(
        &textbook_modal(),
        &textbook_process(radial_immersion),
        &SPEEDS,
        &opts,
    )
    .unwrap()
    .iter()
    .map(|p| p.critical_depth.map(|d| d * 1e3))
    .collect()
}

#[test]
fn boundary_matches_the_published_fdm_script() {
    // Tolerance 5 % on a_lim: the script samples the directional matrix
    // pointwise (the screen function g at grid points), which converges
    // only at first order for a/D = 0.05 — its own value moves by 1.4 % at
    // 7500 rpm from m = 80 to m = 160 (1.465 → 1.485 mm, towards our
    // 1.483 mm) — and our m = 40 is 3.5 % above our converged value at
    // 5000 rpm, where ω_n Δt ≈ 0.87.
    for steps in [40, 200] {
        let ours = lobes_mm(0.05, steps, 0.01);
        for ((rpm, reference), value) in SPEEDS.iter().zip(PUBLISHED_MM).zip(&ours) {
            eprintln!("m = {steps}, {rpm} rpm: ours {value:?} mm, published {reference:?} mm");
            match (reference, value) {
                (Some(r), Some(v)) => assert!(
                    (v - r).abs() <= 0.05 * r,
                    "{rpm} rpm (m = {steps}): {v} mm vs published {r} mm"
                ),
                (None, None) => {}
                _ => panic!("{rpm} rpm (m = {steps}): {value:?} vs published {reference:?}"),
            }
        }
    }
}

#[test]
fn converged_boundary_matches_the_script_at_m_160() {
    // The script refined to m = 160 (bisection to 1e-6 m) at two speeds:
    // 7500 rpm → 1.484912 mm, 17 500 rpm → 2.648535 mm. Both methods
    // converged, the boundaries agree to 1 %.
    let opts = LobeOptions {
        steps: 200,
        min_depth: 0.0,
        max_depth: 0.01,
        scan_points: 100,
        tolerance: 1e-7,
    };
    let reference = [(7_500.0, 1.484912), (17_500.0, 2.648535)];
    let rpms: Vec<f64> = reference.iter().map(|r| r.0).collect();
    let ours = stability_lobes(&textbook_modal(), &textbook_process(0.05), &rpms, &opts).unwrap();
    for (point, (rpm, mm)) in ours.iter().zip(reference) {
        let value = point.critical_depth.expect("unstable below 10 mm") * 1e3;
        eprintln!("{rpm} rpm: ours (m = 200) {value} mm, script (m = 160) {mm} mm");
        assert!(
            (value - mm).abs() <= 0.01 * mm,
            "{rpm} rpm: {value} vs {mm}"
        );
    }
}

#[test]
fn boundary_converges_with_m() {
    let coarse = lobes_mm(0.05, 40, 0.01);
    let fine = lobes_mm(0.05, 200, 0.01);
    for ((rpm, c), f) in SPEEDS.iter().zip(&coarse).zip(&fine) {
        match (c, f) {
            (Some(c), Some(f)) => {
                // ≤ 4 % at 5000 rpm (coarsest Δt relative to the vibration
                // period), ≤ 2 % from 7500 rpm up (measured: 1.5 % at 20 000 rpm).
                let tol = if *rpm < 6_000.0 { 0.04 } else { 0.02 };
                assert!((c - f).abs() <= tol * f, "{rpm} rpm: m=40 {c} vs m=200 {f}");
            }
            (None, None) => {}
            _ => panic!("{rpm} rpm: m = 40 gives {c:?}, m = 200 {f:?}"),
        }
    }
}

/// Zeroth-order approximation lobes (Altintas & Budak 1995): with the mean
/// directional matrix H̄₀, `(K − ω²M + iωC) P = −a H̄₀ (1 − e^{−iωT}) P`, so
/// with λ an eigenvalue of `G(iω) H̄₀` (`G` the FRF matrix),
/// `a = −1/(λ (1 − e^{−iωT}))` must be real and positive. Since
/// `1 − e^{−iθ} = 2i sin(θ/2) e^{−iθ/2}`, that happens for
/// `θ = ωT ≡ 2 arg λ − π (mod 2π)`, giving `a = 1/(2 |λ| sin(ε/2))` with
/// ε the principal value in (0, 2π) and `T = (ε + 2πk)/ω`, k = 0, 1, …
/// Equal x and y modes make `G = g(ω) I`, so `λ = g(ω) η` with η the
/// eigenvalues of H̄₀. Returns the smallest a over lobes k at `rpm` [m].
fn zeroth_order_limit(process: &MillingProcess, rpm: f64) -> f64 {
    let h0 = mean_directional_matrix(process).unwrap();
    let (tr, det) = (h0.trace(), h0.determinant());
    let root = Complex::new(tr * tr / 4.0 - det, 0.0).sqrt();
    let half = Complex::new(tr / 2.0, 0.0);
    let (mass, wn, zeta) = (0.03993, 2.0 * PI * 922.0, 0.011);
    let samples = 40_000;
    let omega = |i: usize| wn * (0.5 + 1.5 * i as f64 / samples as f64);
    let mut best = f64::INFINITY;
    for eta in [half + root, half - root] {
        if eta.norm() == 0.0 {
            continue;
        }
        let lobe = |w: f64, k: i32| -> (f64, f64) {
            let g = Complex::new(1.0, 0.0)
                / Complex::new(mass * (wn * wn - w * w), 2.0 * zeta * mass * wn * w);
            let lambda = g * eta;
            let eps = (2.0 * lambda.arg() - PI).rem_euclid(2.0 * PI);
            let a = 1.0 / (2.0 * lambda.norm() * (eps / 2.0).sin());
            let period = (eps + 2.0 * PI * k as f64) / w;
            (60.0 / (process.teeth as f64 * period), a)
        };
        for k in 0..30 {
            let mut prev = lobe(omega(0), k);
            for i in 1..=samples {
                let cur = lobe(omega(i), k);
                // A sign change of (rpm − target) between neighbours, not
                // across the 2π wrap of ε.
                if (prev.0 - rpm) * (cur.0 - rpm) < 0.0 && (prev.0 - cur.0).abs() < 0.2 * rpm {
                    let f = (rpm - prev.0) / (cur.0 - prev.0);
                    let a = prev.1 + f * (cur.1 - prev.1);
                    if a > 0.0 {
                        best = best.min(a);
                    }
                }
                prev = cur;
            }
        }
    }
    best
}

#[test]
fn slot_milling_flanks_match_the_zeroth_order_approximation() {
    // Slotting (a/D = 1): the ZOA is accurate on the lobe flanks; at the
    // lobe peaks (12 500, 20 000–25 000 rpm here) the time-periodic
    // coefficients matter and the ZOA is not a reference, but the
    // published FDM script is (it agrees with us within 1.3 % at all nine
    // speeds). Tolerance 5 % against the ZOA on the flanks, 3 % against
    // the script.
    let process = textbook_process(1.0);
    let ours = lobes_mm(1.0, 40, 0.002);
    for ((rpm, value), published) in SPEEDS.iter().zip(&ours).zip(PUBLISHED_SLOT_MM) {
        let zoa = zeroth_order_limit(&process, *rpm) * 1e3;
        eprintln!(
            "slot, {rpm} rpm: ours {value:?} mm, published script {published} mm, zeroth-order {zoa:.4} mm"
        );
        let value = value.expect("slotting is unstable below 2 mm at every speed");
        // The published script everywhere (peaks included), 3 %.
        assert!(
            (value - published).abs() <= 0.03 * published,
            "{rpm} rpm: {value} mm vs published script {published} mm"
        );
        if [5_000.0, 7_500.0, 10_000.0, 15_000.0, 17_500.0].contains(rpm) {
            assert!(
                (value - zoa).abs() <= 0.05 * zoa,
                "{rpm} rpm: {value} mm vs zeroth-order {zoa} mm"
            );
        } else {
            // At the peaks the ZOA boundary lies below ours.
            assert!(
                value > zoa,
                "{rpm} rpm: {value} mm vs zeroth-order {zoa} mm"
            );
        }
    }
}
