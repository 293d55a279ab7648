//! Tests of the full discretization (`kerf_chatter::fdm`) and of the
//! constant-delay model (`kerf_chatter::directional`) against independent
//! references: closed-form free vibration, integral identities, brute-force
//! quadrature, the characteristic equation of an autonomous DDE, and
//! self-consistency under re-expressions of the same equation.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use std::f64::consts::PI;

use approx::assert_relative_eq;
use kerf_chatter::{
    chip_direction, constant_delay_dde, constant_delay_dde_unit_depth, directional_averages,
    force_direction, scale_dde, spectral_radius_dense, stability_lobes, ChatterError, DdeSample,
    DelayTerm, Discretization, LobeOptions, MillingProcess, Modal2, Mode, PeriodicDde,
};
use nalgebra::{Complex, Matrix2, Matrix4};

fn textbook_modal() -> Modal2 {
    common::textbook_modal()
}

fn textbook_process(axial_depth: f64) -> MillingProcess {
    common::textbook_process(0.05, 0.005, axial_depth)
}

/// Closed-form free response of `ẍ + 2ζω ẋ + ω² x = 0` over `t`:
/// the 2×2 transition matrix acting on (x, ẋ).
fn oscillator_transition(fnat: f64, zeta: f64, t: f64) -> Matrix2<f64> {
    let w = 2.0 * PI * fnat;
    let wd = w * (1.0 - zeta * zeta).sqrt();
    let e = (-zeta * w * t).exp();
    let (s, c) = (wd * t).sin_cos();
    Matrix2::new(
        e * (c + zeta * w / wd * s),
        e * s / wd,
        -e * w * w / wd * s,
        e * (c - zeta * w / wd * s),
    )
}

#[test]
fn matrix_exponential_matches_closed_form_free_vibration() {
    // Two different uncoupled modes, rotated by 0.4 rad (equal masses, so
    // p = R q decouples the modal coordinates q): a coupled K and C.
    let (fx, zx, fy, zy, mass) = (922.0, 0.011, 610.0, 0.05, 0.7);
    let rot = nalgebra::Rotation2::new(0.4).into_inner();
    let wx = 2.0 * PI * fx;
    let wy = 2.0 * PI * fy;
    let kd = Matrix2::new(mass * wx * wx, 0.0, 0.0, mass * wy * wy);
    let cd = Matrix2::new(2.0 * zx * mass * wx, 0.0, 0.0, 2.0 * zy * mass * wy);
    let modal = Modal2 {
        mass: Matrix2::identity() * mass,
        damping: rot * cd * rot.transpose(),
        stiffness: rot * kd * rot.transpose(),
    };
    for &dt in &[1e-5, 3.3e-4, 2.1e-3] {
        let disc = Discretization::new(&modal, 40.0 * dt, 40, 40.0 * dt).unwrap();
        let tx = oscillator_transition(fx, zx, dt);
        let ty = oscillator_transition(fy, zy, dt);
        // Modal coordinates: (qx, qy, q̇x, q̇y).
        let mut diag = Matrix4::zeros();
        for (a, b, t) in [(0, 0, tx), (1, 1, ty)] {
            diag[(a, b)] = t[(0, 0)];
            diag[(a, b + 2)] = t[(0, 1)];
            diag[(a + 2, b)] = t[(1, 0)];
            diag[(a + 2, b + 2)] = t[(1, 1)];
        }
        let mut big_r = Matrix4::zeros();
        big_r.fixed_view_mut::<2, 2>(0, 0).copy_from(&rot);
        big_r.fixed_view_mut::<2, 2>(2, 2).copy_from(&rot);
        let reference = big_r * diag * big_r.transpose();
        let err = (disc.phi0() - reference).abs().max();
        let scale = reference.abs().max();
        assert!(
            err <= 1e-11 * scale,
            "dt {dt}: |Φ0 − ref| = {err:e} (scale {scale:e})"
        );
    }
}

#[test]
fn exponential_integrals_satisfy_their_identities() {
    // Φ1 = A0⁻¹(Φ0 − I) and Φ2 = A0⁻¹(Φ1/Δt − I) (integration by parts of
    // the definitions in the fdm module documentation).
    let modal = textbook_modal();
    let m_inv = modal.mass.try_inverse().unwrap();
    let mut a0 = Matrix4::zeros();
    a0.fixed_view_mut::<2, 2>(0, 2)
        .copy_from(&Matrix2::identity());
    a0.fixed_view_mut::<2, 2>(2, 0)
        .copy_from(&(-m_inv * modal.stiffness));
    a0.fixed_view_mut::<2, 2>(2, 2)
        .copy_from(&(-m_inv * modal.damping));
    let a0_inv = a0.try_inverse().unwrap();
    let period = 60.0 / (2.0 * 11_000.0);
    let disc = Discretization::new(&modal, period, 40, period).unwrap();
    let dt = disc.dt();
    let phi1 = a0_inv * (disc.phi0() - Matrix4::identity());
    let phi2 = a0_inv * (disc.phi1() / dt - Matrix4::identity());
    assert_relative_eq!(*disc.phi1(), phi1, max_relative = 1e-9, epsilon = 1e-14);
    assert_relative_eq!(*disc.phi2(), phi2, max_relative = 1e-7, epsilon = 1e-13);
}

#[test]
fn directional_averages_match_brute_force_quadrature() {
    // Midpoint rule with 20 000 points per sub-interval on the definition
    // H = Σ_j g(φ_j) b(φ_j) c(φ_j)ᵀ (model.rs), including the sub-interval
    // that contains the entry angle.
    for (process, m) in [(textbook_process(1e-3), 40), (seed_process(), 47)] {
        let exact = directional_averages(&process, m).unwrap();
        let dphi = 2.0 * PI / (process.teeth as f64 * m as f64);
        let n = 20_000;
        for (i, h) in exact.iter().enumerate() {
            let mut sum = Matrix2::zeros();
            for q in 0..n {
                let phi0 = (i as f64 + (q as f64 + 0.5) / n as f64) * dphi;
                for j in 0..process.teeth {
                    let phi = (phi0 + 2.0 * PI * j as f64 / process.teeth as f64) % (2.0 * PI);
                    if phi >= process.entry_angle && phi <= process.exit_angle {
                        sum += force_direction(phi, process.kt, process.kn)
                            * chip_direction(phi).transpose();
                    }
                }
            }
            sum /= n as f64;
            let err = (sum - h).abs().max();
            assert!(err <= 2e-4 * process.kt, "sub-interval {i}: error {err:e}");
        }
    }
}

fn seed_process() -> MillingProcess {
    common::seed004_process(3e-3)
}

#[test]
fn zero_cutting_gives_the_free_oscillator_multiplier() {
    // a_p = 0: Φ = diag(e^{A0 T}, nilpotent shift), |μ|max = e^{−ζ ω_n T}.
    let modal = textbook_modal();
    for rpm in [5_000.0, 12_345.0, 25_000.0] {
        let dde = scale_dde(
            &constant_delay_dde_unit_depth(&textbook_process(1e-3), rpm, 40).unwrap(),
            0.0,
        )
        .unwrap();
        let disc = Discretization::new(&modal, dde.period, 40, dde.period).unwrap();
        let expected = (-0.011 * 2.0 * PI * 922.0 * dde.period).exp();
        let fast = disc.spectral_radius(&dde).unwrap();
        let dense = spectral_radius_dense(&disc.monodromy(&dde).unwrap(), 10_000).unwrap();
        assert_relative_eq!(fast, expected, max_relative = 1e-9);
        assert_relative_eq!(dense, expected, max_relative = 1e-9);
    }
}

#[test]
fn delay_expression_does_not_change_the_result() {
    let modal = textbook_modal();
    let process = textbook_process(1.5e-3);
    let rpm = 14_000.0;
    let dde = constant_delay_dde(&process, rpm, 40).unwrap();
    let t = dde.period;
    let disc = Discretization::new(&modal, t, 40, t).unwrap();
    let base = disc.spectral_radius(&dde).unwrap();

    // (a) A longer admissible history (r = ⌈2.1 m⌉ + 1) adds only zero multipliers.
    let long = Discretization::new(&modal, t, 40, 2.1 * t).unwrap();
    assert_eq!(long.history_len(), 85);
    assert_relative_eq!(
        long.spectral_radius(&dde).unwrap(),
        base,
        max_relative = 1e-8
    );

    // (b) The delayed term split into two halves with the same delay.
    let split = PeriodicDde {
        period: t,
        samples: dde
            .samples
            .iter()
            .map(|s| DdeSample {
                present: s.present,
                delayed: vec![
                    DelayTerm {
                        gain: s.delayed[0].gain * 0.25,
                        delay: t,
                    },
                    DelayTerm {
                        gain: s.delayed[0].gain * 0.75,
                        delay: t * (1.0 + 1e-13),
                    },
                ],
            })
            .collect(),
    };
    assert_relative_eq!(
        disc.spectral_radius(&split).unwrap(),
        base,
        max_relative = 1e-8
    );

    // (c) The same DDE as `constant_delay_dde` built by hand from
    // `directional_averages` and scaled gains.
    let h = directional_averages(&process, 40).unwrap();
    let by_hand = PeriodicDde {
        period: t,
        samples: h
            .iter()
            .map(|g| DdeSample {
                present: g * process.axial_depth,
                delayed: vec![DelayTerm {
                    gain: g * process.axial_depth,
                    delay: t,
                }],
            })
            .collect(),
    };
    assert_relative_eq!(
        disc.spectral_radius(&by_hand).unwrap(),
        base,
        max_relative = 1e-12
    );
}

/// Newton on the characteristic function of the autonomous scalar DDE
/// `m ẍ + c ẋ + k x = −a x + b x(t − τ)`: `D(λ) = mλ² + cλ + k + a − b e^{−λτ}`.
fn characteristic_root(
    m: f64,
    c: f64,
    k: f64,
    a: f64,
    b: f64,
    tau: f64,
    guess: Complex<f64>,
) -> Complex<f64> {
    let mut l = guess;
    for _ in 0..50 {
        let e = (-l * tau).exp();
        let f = l * l * m + l * c + k + a - e * b;
        let df = l * 2.0 * m + c + e * b * tau;
        l -= f / df;
    }
    l
}

#[test]
fn fractional_delay_matches_the_characteristic_equation() {
    // Constant gains along x only (y strongly damped and uncut): an
    // autonomous DDE, whose Floquet multipliers over any period T are e^{λT}
    // with λ the characteristic roots. Delay τ = 1.37 T is not a multiple of
    // Δt, exercising the interpolation; it also exceeds the period.
    let x = Mode {
        natural_frequency_hz: 500.0,
        damping_ratio: 0.02,
        modal_mass: 0.1,
    };
    let y = Mode {
        natural_frequency_hz: 500.0,
        damping_ratio: 0.6,
        modal_mass: 0.1,
    };
    let modal = Modal2::from_modes(x, y).unwrap();
    let (mm, k) = (0.1, 0.1 * (2.0 * PI * 500.0_f64).powi(2));
    let c = 2.0 * 0.02 * 0.1 * 2.0 * PI * 500.0;
    let period = 1.0 / 700.0;
    let tau = 1.37 * period;
    let (a, b) = (0.05 * k, 0.08 * k);
    let gain = |v: f64| Matrix2::new(v, 0.0, 0.0, 0.0);
    let mut previous_error = f64::INFINITY;
    for m in [40, 160] {
        let dde = PeriodicDde {
            period,
            samples: (0..m)
                .map(|_| DdeSample {
                    present: gain(a),
                    delayed: vec![DelayTerm {
                        gain: gain(b),
                        delay: tau,
                    }],
                })
                .collect(),
        };
        let disc = Discretization::new(&modal, period, m, tau).unwrap();
        let phi = disc.monodromy(&dde).unwrap();
        let eig = phi.clone().schur().complex_eigenvalues();
        let mu = eig
            .iter()
            .max_by(|p, q| p.norm().total_cmp(&q.norm()))
            .copied()
            .unwrap();
        let lambda_discrete = mu.ln() / period;
        // Newton from the discrete estimate (the branch of the logarithm is
        // fixed by taking the nearest root to ±i ω_n shifted by 2πk/T).
        let wn = 2.0 * PI * 500.0;
        let mut best = Complex::new(f64::NAN, f64::NAN);
        for kk in -3..=3 {
            let guess = lambda_discrete + Complex::new(0.0, 2.0 * PI * kk as f64 / period);
            if (guess.im.abs() - wn).abs() < 0.3 * wn {
                best = characteristic_root(mm, c, k, a, b, tau, guess);
            }
        }
        assert!(
            best.re.is_finite(),
            "no root found near the discrete multiplier"
        );
        let rho_exact = (best.re * period).exp();
        let rho = disc.spectral_radius(&dde).unwrap();
        let error = (rho - rho_exact).abs() / rho_exact;
        eprintln!(
            "m = {m}: |mu| = {rho:.9}, characteristic root gives {rho_exact:.9}, error {error:.2e}"
        );
        assert!(
            error < 2e-3,
            "m = {m}: |mu| = {rho}, exact {rho_exact}, error {error:e}"
        );
        assert!(error < previous_error, "no convergence with m");
        previous_error = error;
    }
}

#[test]
fn spectral_radius_converges_with_m() {
    // A cut near the lobe boundary; the m = 200 value as reference, the
    // m = 40 and m = 80 errors must shrink (second order in Δt expected,
    // at least first order required here).
    let modal = textbook_modal();
    let process = textbook_process(1.0e-3);
    let rho_at = |m: usize| {
        let dde = constant_delay_dde(&process, 10_000.0, m).unwrap();
        Discretization::new(&modal, dde.period, m, dde.period)
            .unwrap()
            .spectral_radius(&dde)
            .unwrap()
    };
    let (r40, r80, r200) = (rho_at(40), rho_at(80), rho_at(200));
    let (e40, e80) = ((r40 - r200).abs(), (r80 - r200).abs());
    eprintln!("|mu| at m = 40, 80, 200: {r40:.8} {r80:.8} {r200:.8}");
    assert!(e40 < 0.02 * r200, "m = 40 differs by {e40}");
    assert!(e80 < 0.6 * e40, "m = 80 error {e80} vs m = 40 error {e40}");
}

#[test]
fn bad_inputs_are_errors() {
    let modal = textbook_modal();
    let dde = constant_delay_dde(&textbook_process(1e-3), 10_000.0, 40).unwrap();
    let t = dde.period;
    let disc = Discretization::new(&modal, t, 40, t).unwrap();

    let mut nan = dde.clone();
    nan.samples[3].delayed[0].gain[(0, 1)] = f64::NAN;
    assert!(matches!(
        disc.spectral_radius(&nan),
        Err(ChatterError::NonFinite { .. })
    ));
    let mut nan = dde.clone();
    nan.samples[7].present[(1, 1)] = f64::INFINITY;
    assert!(matches!(
        disc.monodromy(&nan),
        Err(ChatterError::NonFinite { .. })
    ));

    assert!(matches!(
        Discretization::new(&modal, 0.0, 40, t),
        Err(ChatterError::InvalidParameter { .. })
    ));
    assert!(matches!(
        Discretization::new(&modal, f64::NAN, 40, t),
        Err(ChatterError::InvalidParameter { .. })
    ));
    assert!(matches!(
        Discretization::new(&modal, t, 1, t),
        Err(ChatterError::InvalidParameter { .. })
    ));
    assert!(matches!(
        Discretization::new(&modal, t, 40, t / 80.0),
        Err(ChatterError::InvalidParameter { .. })
    ));
    let mut bad_modal = modal;
    bad_modal.stiffness[(0, 0)] = -1.0;
    assert!(Discretization::new(&bad_modal, t, 40, t).is_err());

    // m mismatch, period mismatch, delay beyond max_delay or below Δt.
    let other = constant_delay_dde(&textbook_process(1e-3), 10_000.0, 41).unwrap();
    assert!(matches!(
        disc.spectral_radius(&other),
        Err(ChatterError::Unsupported { .. })
    ));
    let other = constant_delay_dde(&textbook_process(1e-3), 10_001.0, 40).unwrap();
    assert!(matches!(
        disc.spectral_radius(&other),
        Err(ChatterError::Unsupported { .. })
    ));
    let mut long = dde.clone();
    long.samples[0].delayed[0].delay = 1.5 * t;
    assert!(matches!(
        disc.spectral_radius(&long),
        Err(ChatterError::Unsupported { .. })
    ));
    let mut short = dde.clone();
    short.samples[0].delayed[0].delay = 0.5 * t / 40.0;
    assert!(matches!(
        disc.spectral_radius(&short),
        Err(ChatterError::Unsupported { .. })
    ));
    let mut negative = dde.clone();
    negative.samples[0].delayed[0].delay = -t;
    assert!(disc.spectral_radius(&negative).is_err());
    assert!(scale_dde(&dde, f64::NAN).is_err());
    assert!(constant_delay_dde(&textbook_process(1e-3), -5.0, 40).is_err());
    assert!(directional_averages(&textbook_process(1e-3), 0).is_err());

    // Lobe options and speeds.
    let process = textbook_process(1e-3);
    let bad_range = LobeOptions {
        min_depth: 0.01,
        max_depth: 0.005,
        ..LobeOptions::default()
    };
    assert!(stability_lobes(&modal, &process, &[10_000.0], &bad_range).is_err());
    let no_scan = LobeOptions {
        scan_points: 0,
        ..LobeOptions::default()
    };
    assert!(stability_lobes(&modal, &process, &[10_000.0], &no_scan).is_err());
    let few_steps = LobeOptions {
        steps: 1,
        ..LobeOptions::default()
    };
    assert!(stability_lobes(&modal, &process, &[10_000.0], &few_steps).is_err());
    assert!(stability_lobes(&modal, &process, &[f64::NAN], &LobeOptions::default()).is_err());
}
