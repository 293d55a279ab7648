//! The state-dependent model of seed 004 section 2: equilibrium
//! (eq. 1-7) and linearization (eq. 8), checked against independent
//! references (analytic chip expansion, Newton on eq. 3, a finer RK4
//! integration, finite differences of the exact tooth-path geometry of
//! `trochoid.rs`).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use std::f64::consts::PI;

use kerf_chatter::equilibrium::{Equilibrium, EquilibriumSettings, ForceLaw};
use kerf_chatter::linearize::{chip_sensitivity, linearize, LinearizeSettings};
use kerf_chatter::trochoid::{chip_thickness, tangential_residual};
use kerf_chatter::{
    constant_delay_dde, force_direction, ChatterError, Discretization, MillingProcess, Modal2,
};
use nalgebra::{Matrix2, Vector2, Vector4};

/// Seed 004 Table 1: 2 teeth, R 0.04 m, a_p 3 mm, down milling [0.75π, π].
fn seed_process() -> MillingProcess {
    common::seed004_process(3e-3)
}

/// A representative robot tool tip: 25 Hz, ζ 0.05, 50 kg per direction.
fn robot() -> Modal2 {
    common::symmetric_modal(25.0, 0.05, 50.0)
}

/// A near-rigid tool: 3 kHz, 20 kg.
fn stiff() -> Modal2 {
    common::symmetric_modal(3000.0, 0.05, 20.0)
}

fn engaged_times(eq: &Equilibrium, tooth: usize) -> Vec<f64> {
    let p = eq.process();
    eq.node_times()
        .windows(2)
        .map(|w| 0.5 * (w[0] + w[1]))
        .filter(|&t| {
            let phi = eq.angle(tooth, t).rem_euclid(2.0 * PI);
            phi >= p.entry_angle && phi <= p.exit_angle
        })
        .collect()
}

/// Eq. 3 holds along the RK4-integrated delays (eq. 6), and they agree
/// with Newton's solution of eq. 3 at every node inside the cut.
#[test]
fn rk4_delays_satisfy_eq3_and_match_newton() {
    let eq = Equilibrium::compute(
        &robot(),
        &seed_process(),
        2000.0,
        0.06,
        &EquilibriumSettings::default(),
    )
    .unwrap();
    let period = eq.period();
    let mut worst_res: f64 = 0.0;
    let mut worst_diff: f64 = 0.0;
    let mut count = 0;
    for j in 0..2 {
        for &t in eq.node_times() {
            let phi = eq.angle(j, t).rem_euclid(2.0 * PI);
            if !(0.75 * PI..=PI).contains(&phi) {
                continue;
            }
            let Some(rk4) = eq.delay_rk4(j, t) else {
                continue;
            };
            let newton = eq.solve_delay(j, 1, t).unwrap();
            worst_res = worst_res.max(eq.eq3_residual(j, 1, t, rk4).abs());
            worst_diff = worst_diff.max((rk4 - newton).abs() / period);
            count += 1;
        }
    }
    // 2 teeth, engagement a quarter turn: one tooth cuts during [0.75T, T]
    // of each tooth period (≈ 50 of the 200 nodes).
    assert!(count >= 45, "{count} nodes checked");
    println!("eq. 3 residual {worst_res:e} m, RK4 vs Newton {worst_diff:e} T");
    // measured: residual 6.5e-10 m, |Δτ|/T 5e-9 (RK4 meets the kink of õ̇
    // where t − τ crosses the entry, just after each track starts)
    assert!(worst_res < 5e-9, "eq. 3 residual {worst_res:e} m");
    assert!(worst_diff < 5e-8, "RK4 vs Newton {worst_diff:e} T");
    // Older surfaces (multiple regeneration, seed 004 Fig. 1b): the tooth
    // two back left a surface 2 f_z sin φ deep with twice the delay shift,
    // so the chip min_m h^m is the order-1 chip here.
    let fz = eq.feed_per_tooth();
    for frac in [0.8, 0.9, 0.97] {
        let t = frac * period;
        let (tau1, h1) = eq.chip_of_order(0, 1, t).unwrap();
        let (tau2, h2) = eq.chip_of_order(0, 2, t).unwrap();
        let (tau3, h3) = eq.chip_of_order(0, 3, t).unwrap();
        let s = eq.angle(0, t).sin();
        assert!(
            (h2 - 2.0 * fz * s).abs() < 0.05 * fz,
            "h2 {h2:e} vs {:e}",
            2.0 * fz * s
        );
        assert!((h3 - 3.0 * fz * s).abs() < 0.1 * fz);
        assert!(
            ((tau2 - 2.0 * period) - 2.0 * (tau1 - period)).abs() < 0.05 * (tau1 - period).abs()
        );
        assert!(
            ((tau3 - 3.0 * period) - 3.0 * (tau1 - period)).abs() < 0.1 * (tau1 - period).abs()
        );
        let cs = eq.chip_state(0, t).unwrap();
        assert_eq!(cs.order, 1);
        assert!((cs.chip - h1).abs() < 1e-7 * fz); // RK4 vs Newton delay
    }
    // The delay does differ from T: it is state dependent.
    let tau = eq.solve_delay(0, 1, 0.9 * period).unwrap();
    assert!((tau - period).abs() > 1e-4 * period);
}

/// For a near-rigid tool the equilibrium chip is the exact trochoid chip,
/// `h ≈ f_z sin φ − N f_z² sin φ cos φ /(2π R) + f_z² cos² φ /(2R)`
/// (second-order expansion of eq. 3-4 with o = 0: δ ≈ −f_z cos φ / R,
/// τ = T + δ/Ω), and to first order the classic `f_z sin φ`.
#[test]
fn stiff_tool_chip_is_the_trochoid_chip() {
    let process = seed_process();
    let eq = Equilibrium::compute(
        &stiff(),
        &process,
        3000.0,
        0.04,
        &EquilibriumSettings::default(),
    )
    .unwrap();
    let fz = eq.feed_per_tooth();
    let (r, n) = (process.radius, process.teeth as f64);
    let mut worst2: f64 = 0.0;
    let mut worst1: f64 = 0.0;
    for t in engaged_times(&eq, 0) {
        let cs = eq.chip_state(0, t).unwrap();
        let (s, c) = cs.phi.sin_cos();
        let h2 = fz * s - n * fz * fz * s * c / (2.0 * PI * r) + fz * fz * c * c / (2.0 * r);
        worst2 = worst2.max((cs.chip - h2).abs() / fz);
        worst1 = worst1.max((cs.chip - fz * s).abs() / fz);
        assert!(cs.in_contact || s < 1e-3);
        assert_eq!(cs.order, 1);
    }
    println!("stiff tool: 2nd-order error {worst2:e} f_z, 1st-order {worst1:e} f_z");
    // measured: 2nd-order expansion within 5.2e-5 f_z (third-order terms,
    // (f_z/R)² = 1e-4), 1st order within ~5e-3 f_z
    assert!(worst2 < 2e-4, "second-order chip error {worst2:e} f_z");
    assert!(worst1 < 1e-2, "first-order chip error {worst1:e} f_z");
    assert!(
        worst1 > 10.0 * worst2,
        "the second-order terms matter: {worst1:e} vs {worst2:e}"
    );
    assert!(eq.forced_amplitude() < 1e-3 * fz);
}

/// On the flexible robot the forced vibration is large, yet the
/// regenerative terms cancel in the T-periodic equilibrium:
/// h̃ ≈ f_z sin φ within O(õ̇ / RΩ), no loss of contact inside the cut.
#[test]
fn flexible_tool_chip_still_close_to_nominal() {
    let eq = Equilibrium::compute(
        &robot(),
        &seed_process(),
        2000.0,
        0.06,
        &EquilibriumSettings::default(),
    )
    .unwrap();
    let fz = eq.feed_per_tooth();
    let diag = eq.diagnostics().unwrap();
    // measured: forced amplitude ~0.25 f_z (static deflection excluded)
    assert!(
        diag.forced_amplitude > 0.05 * fz,
        "amplitude {:e} m",
        diag.forced_amplitude
    );
    let mut worst: f64 = 0.0;
    let times = engaged_times(&eq, 0);
    assert!(times.len() > 40);
    for t in times {
        let cs = eq.chip_state(0, t).unwrap();
        worst = worst.max((cs.chip - fz * cs.phi.sin()).abs() / fz);
    }
    println!(
        "robot: forced amplitude {:e} m = {:.3} f_z, chip deviation {worst:e} f_z, {diag:?}",
        diag.forced_amplitude,
        diag.forced_amplitude / fz
    );
    assert!(worst < 2e-2, "chip deviation {worst:e} f_z");
    assert!(diag.min_chip > 0.0);
    assert_eq!(diag.contact_fraction, 1.0);
    assert_eq!(diag.max_order, 1);
    assert!(diag.max_delay_deviation < 1e-2);
}

/// The equilibrium is a T-periodic solution of eq. 1: integrating
/// `M ö + C ȯ + K o = F(t)` from õ(0) with an independent RK4 of 4× finer
/// steps (forces from the equilibrium's chips) returns to õ(0) after one
/// period and stays on õ.
#[test]
fn equilibrium_is_a_periodic_solution() {
    let modal = robot();
    let process = seed_process();
    let eq = Equilibrium::compute(
        &modal,
        &process,
        2500.0,
        0.05,
        &EquilibriumSettings::default(),
    )
    .unwrap();
    assert!(eq.iterations() <= 10, "{} iterations", eq.iterations());
    let minv = modal.mass.try_inverse().unwrap();
    let force = |t: f64, side: f64| -> Vector2<f64> {
        let mut f = Vector2::zeros();
        for j in 0..process.teeth {
            // evaluate the engagement just inside the step (force jumps sit on nodes)
            let cs = eq.chip_state(j, t + side).unwrap();
            let cs_t = eq.chip_state(j, t).unwrap();
            if cs.in_contact {
                f += force_direction(cs_t.phi, process.kt, process.kn)
                    * (process.axial_depth * cs_t.chip.max(0.0));
            }
        }
        f
    };
    let rhs = |z: &Vector4<f64>, f: Vector2<f64>| {
        let a = minv
            * (f - modal.damping * Vector2::new(z[2], z[3])
                - modal.stiffness * Vector2::new(z[0], z[1]));
        Vector4::new(z[2], z[3], a.x, a.y)
    };
    let p0 = eq.position(0.0);
    let v0 = eq.velocity(0.0);
    let mut z = Vector4::new(p0.x, p0.y, v0.x, v0.y);
    let mut worst: f64 = 0.0;
    for w in eq.node_times().windows(2) {
        let h = (w[1] - w[0]) / 4.0;
        let eps = 1e-6 * h;
        for i in 0..4 {
            let ta = w[0] + i as f64 * h;
            let (fa, fm, fb) = (
                force(ta, eps),
                force(ta + 0.5 * h, 0.0),
                force(ta + h, -eps),
            );
            let k1 = rhs(&z, fa);
            let k2 = rhs(&(z + k1 * (0.5 * h)), fm);
            let k3 = rhs(&(z + k2 * (0.5 * h)), fm);
            let k4 = rhs(&(z + k3 * h), fb);
            z += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
        }
        let p = eq.position(w[1]);
        worst = worst.max((Vector2::new(z[0], z[1]) - p).norm());
    }
    let amp = eq.forced_amplitude();
    println!(
        "independent RK4: deviation {worst:e} m, amplitude {amp:e} m, {} iterations",
        eq.iterations()
    );
    // measured: ~1e-7 of the forced amplitude
    assert!(
        worst < 1e-5 * amp,
        "deviation {worst:e} m, amplitude {amp:e} m"
    );
    let back = (Vector2::new(z[0], z[1]) - p0).norm();
    assert!(back < 1e-5 * amp, "periodicity defect {back:e} m");
}

/// Eq. 3 solved by Newton with a secant derivative (independent of the
/// library's analytic derivatives) for a trajectory `õ + ε q`.
fn exact_chip(
    eq: &Equilibrium,
    q: &dyn Fn(f64) -> Vector2<f64>,
    eps: f64,
    tooth: usize,
    t: f64,
) -> f64 {
    let p = eq.process();
    let omega = eq.omega();
    let f = eq.feed();
    let phi = eq.angle(tooth, t);
    let o = |s: f64| eq.position(s) + q(s) * eps;
    let geo = |tau: f64| {
        let d = o(t - tau) - o(t);
        let delta = omega * tau - 2.0 * PI / p.teeth as f64;
        (delta, f * tau + d.x, d.y)
    };
    let g = |tau: f64| {
        let (delta, dx, dy) = geo(tau);
        tangential_residual(p.radius, delta, dx, dy, phi)
    };
    let mut tau = eq.period();
    for _ in 0..60 {
        let dt = 1e-7 * eq.period();
        let slope = (g(tau + dt) - g(tau - dt)) / (2.0 * dt);
        let step = g(tau) / slope;
        tau -= step;
        if step.abs() < 1e-16 * eq.period() {
            break;
        }
    }
    assert!(g(tau).abs() < 1e-15);
    let (delta, dx, dy) = geo(tau);
    chip_thickness(p.radius, delta, dx, dy, phi)
}

/// Seed 004 eq. 8 as derived in linearize.rs: δh = (c − κ w)·(p(t−τ) − p(t))
/// against central finite differences of the exact chip (eq. 3-4 with the
/// delay re-solved) — including the κ term that the constant-delay model
/// lacks.
#[test]
fn chip_linearization_matches_finite_differences() {
    let eq = Equilibrium::compute(
        &robot(),
        &seed_process(),
        2000.0,
        0.06,
        &EquilibriumSettings::default(),
    )
    .unwrap();
    let period = eq.period();
    let q = |s: f64| {
        Vector2::new(
            (2.0 * PI * 37.0 * s + 0.3).cos(),
            (2.0 * PI * 23.0 * s).sin() + 0.5,
        )
    };
    let eps = 1e-7;
    for (tooth, frac) in [
        (0, 0.77),
        (0, 0.80),
        (0, 0.87),
        (0, 0.93),
        (0, 0.99),
        (1, 1.85),
    ] {
        let t = frac * period;
        let sens = chip_sensitivity(&eq, tooth, t).unwrap().expect("in cut");
        let fd = (exact_chip(&eq, &q, eps, tooth, t) - exact_chip(&eq, &q, -eps, tooth, t))
            / (2.0 * eps);
        let dq = q(t - sens.delay) - q(t);
        let pred = sens.direction.dot(&dq);
        let w = Vector2::new(sens.phi.cos(), -sens.phi.sin());
        let kappa_term = (sens.kappa * w.dot(&dq)).abs();
        let err = (fd - pred).abs();
        println!(
            "t/T {frac}: fd {fd:.9} pred {pred:.9} err {err:e} kappa {:e} term {kappa_term:e}",
            sens.kappa
        );
        // measured: err ~1e-9, κ term ~1e-3..1e-2
        assert!(
            err < 1e-7 * pred.abs().max(1.0),
            "t {t:e}: fd {fd} pred {pred}"
        );
        assert!(
            kappa_term > 1e3 * err,
            "κ term {kappa_term:e} not resolved (err {err:e})"
        );
    }
}

/// The Kienzle law scales the cutting stiffness by x_F (h̃/h_ref)^(x_F−1).
#[test]
fn power_law_scales_the_gains() {
    let modal = stiff();
    let process = seed_process();
    let lin = Equilibrium::compute(
        &modal,
        &process,
        3000.0,
        0.03,
        &EquilibriumSettings::default(),
    )
    .unwrap();
    let law = ForceLaw {
        exponent: 0.75,
        reference_chip: 1e-4,
    };
    let pow = Equilibrium::compute(
        &modal,
        &process,
        3000.0,
        0.03,
        &EquilibriumSettings {
            force_law: law,
            ..EquilibriumSettings::default()
        },
    )
    .unwrap();
    let t = 0.85 * lin.period();
    let h = lin.chip_state(0, t).unwrap().chip;
    let gl = kerf_chatter::linearize::tooth_gain(&lin, 0, t)
        .unwrap()
        .unwrap()
        .0;
    let gp = kerf_chatter::linearize::tooth_gain(&pow, 0, t)
        .unwrap()
        .unwrap()
        .0;
    let expected = 0.75 * (h / 1e-4).powf(-0.25);
    assert!(((gp[(1, 0)] / gl[(1, 0)]) - expected).abs() < 1e-4 * expected);
}

#[test]
fn bad_inputs_are_errors() {
    let modal = robot();
    let process = seed_process();
    let s = EquilibriumSettings::default();
    let inval = |r: Result<Equilibrium, ChatterError>| {
        matches!(r, Err(ChatterError::InvalidParameter { .. }))
    };
    assert!(inval(Equilibrium::compute(
        &modal,
        &process,
        f64::NAN,
        0.01,
        &s
    )));
    assert!(inval(Equilibrium::compute(&modal, &process, 0.0, 0.01, &s)));
    assert!(inval(Equilibrium::compute(
        &modal, &process, -3000.0, 0.01, &s
    )));
    assert!(inval(Equilibrium::compute(
        &modal, &process, 3000.0, -0.01, &s
    )));
    assert!(inval(Equilibrium::compute(
        &modal,
        &process,
        3000.0,
        f64::NAN,
        &s
    )));
    assert!(inval(Equilibrium::compute(
        &modal,
        &process,
        3000.0,
        f64::INFINITY,
        &s
    )));
    let coarse = EquilibriumSettings {
        points_per_period: 100,
        ..s
    };
    assert!(inval(Equilibrium::compute(
        &modal, &process, 3000.0, 0.01, &coarse
    )));
    let bad_law = EquilibriumSettings {
        force_law: ForceLaw {
            exponent: 1.5,
            reference_chip: 1e-4,
        },
        ..s
    };
    assert!(inval(Equilibrium::compute(
        &modal, &process, 3000.0, 0.01, &bad_law
    )));
    let pow = EquilibriumSettings {
        force_law: ForceLaw {
            exponent: 0.75,
            reference_chip: 1e-4,
        },
        ..s
    };
    assert!(inval(Equilibrium::compute(
        &modal, &process, 3000.0, 0.0, &pow
    )));
    let mut p2 = process;
    p2.radius = f64::NAN;
    assert!(inval(Equilibrium::compute(&modal, &p2, 3000.0, 0.01, &s)));
    let cap = EquilibriumSettings {
        max_iterations: 1,
        ..s
    };
    assert!(matches!(
        Equilibrium::compute(&modal, &process, 3000.0, 0.05, &cap),
        Err(ChatterError::NotConverged { .. })
    ));
    let eq = Equilibrium::compute(&modal, &process, 3000.0, 0.01, &s).unwrap();
    assert!(eq.chip_state(2, 0.0).is_err());
    assert!(eq.solve_delay(0, 0, 0.0).is_err());
    assert!(linearize(
        &eq,
        &LinearizeSettings {
            steps: 1,
            wall_term: true
        }
    )
    .is_err());
}

/// As f → 0 (no forced response) the linearized state-dependent model is
/// the constant-delay model of directional.rs (computed there by exact
/// antiderivatives, here by Gauss–Legendre quadrature of W_j): same gains,
/// delays → T, same |μ|max.
#[test]
fn reduces_to_the_constant_delay_model_as_feed_vanishes() {
    let modal = robot();
    let process = seed_process();
    let rpm = 2700.0;
    for steps in [40, 57] {
        let reference = constant_delay_dde(&process, rpm, steps).unwrap();
        let eq = Equilibrium::compute(&modal, &process, rpm, 1e-8, &EquilibriumSettings::default())
            .unwrap();
        let sd = linearize(
            &eq,
            &LinearizeSettings {
                steps,
                wall_term: true,
            },
        )
        .unwrap();
        let scale = reference
            .samples
            .iter()
            .map(|s| s.present.abs().max())
            .fold(0.0, f64::max);
        let mut worst: f64 = 0.0;
        let mut worst_delay: f64 = 0.0;
        for (a, b) in sd.samples.iter().zip(&reference.samples) {
            worst = worst.max((a.present - b.present).abs().max() / scale);
            let sum = a
                .delayed
                .iter()
                .fold(Matrix2::zeros(), |acc, d| acc + d.gain);
            let refsum = b
                .delayed
                .iter()
                .fold(Matrix2::zeros(), |acc, d| acc + d.gain);
            worst = worst.max((sum - refsum).abs().max() / scale);
            for d in &a.delayed {
                worst_delay = worst_delay.max((d.delay - eq.period()).abs() / eq.period());
            }
        }
        println!("m {steps}: gains {worst:e} (relative), delays {worst_delay:e} T");
        assert!(worst < 1e-6, "gains differ by {worst:e}");
        assert!(worst_delay < 1e-6, "delays differ by {worst_delay:e} T");
        let disc = Discretization::new(&modal, eq.period(), steps, sd.max_delay().max(eq.period()))
            .unwrap();
        let mu_sd = disc.spectral_radius(&sd).unwrap();
        let mu_c = disc.spectral_radius(&reference).unwrap();
        println!("m {steps}: |mu| {mu_sd} vs {mu_c}");
        assert!((mu_sd - mu_c).abs() < 1e-6 * mu_c);
    }
}

/// At the resonance speed (tooth frequency = the 25 Hz mode, 750 rpm) the
/// forced response is several f_z and the equilibrium loses contact — next
/// to the exit only; |μ| stays continuous in the feed across it (the
/// contact windows are located by bisection in linearize.rs).
#[test]
fn loss_of_contact_near_resonance() {
    let modal = robot();
    let process = seed_process();
    let eq = Equilibrium::compute(
        &modal,
        &process,
        750.0,
        0.06,
        &EquilibriumSettings::default(),
    )
    .unwrap();
    let d = eq.diagnostics().unwrap();
    let fz = eq.feed_per_tooth();
    println!(
        "750 rpm: {d:?}, amplitude {:.2} f_z, {} iterations",
        d.forced_amplitude / fz,
        eq.iterations()
    );
    // measured: contact fraction 0.86, min chip −0.1 f_z, amplitude 2.3 f_z
    assert!(d.contact_fraction < 0.95 && d.contact_fraction > 0.5);
    assert!(d.min_chip < 0.0 && d.forced_amplitude > fz);
    for t in engaged_times(&eq, 0) {
        let cs = eq.chip_state(0, t).unwrap();
        if !cs.in_contact {
            assert!(cs.phi > 0.9 * PI, "contact lost at φ = {} π", cs.phi / PI);
        }
    }
    // continuity of |μ| in feed across the loss-of-contact onset
    let mu = |f: f64| {
        let eq = Equilibrium::compute(&modal, &process, 750.0, f, &EquilibriumSettings::default())
            .unwrap();
        let dde = linearize(&eq, &LinearizeSettings::default()).unwrap();
        let disc =
            Discretization::new(&modal, eq.period(), 40, dde.max_delay().max(eq.period())).unwrap();
        (
            disc.spectral_radius(&dde).unwrap(),
            eq.diagnostics().unwrap().contact_fraction,
        )
    };
    // 0.02 … 0.06 m/s: the contact fraction falls from 0.98 to 0.86; no
    // step of |μ| may stand out from the trend (a quadrature point switching
    // in or out of contact would)
    let pts: Vec<(f64, f64)> = (0..=20).map(|k| mu(0.02 + 2e-3 * k as f64)).collect();
    println!("{pts:?}");
    assert!(
        pts[0].1 > pts[20].1 + 0.05,
        "contact window must grow: {pts:?}"
    );
    let steps: Vec<f64> = pts.windows(2).map(|w| (w[1].0 - w[0].0).abs()).collect();
    let mean = steps.iter().sum::<f64>() / steps.len() as f64;
    let worst = steps.iter().copied().fold(0.0, f64::max);
    // measured: worst step / mean step ≈ 1.7 (the slope steepens with
    // feed: |μ| 0.798 → 0.766 while contact falls 0.96 → 0.86)
    assert!(
        worst < 3.0 * mean + 1e-6,
        "jump {worst:e} vs mean step {mean:e}"
    );
}
