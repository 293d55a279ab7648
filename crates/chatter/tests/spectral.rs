//! The fast matrix-free spectral radius (restarted Arnoldi) against the
//! dense reference (real Schur form) and against prescribed spectra:
//! complex-pair (Hopf), real negative (flip), real positive and clustered
//! dominant multipliers; milling monodromy matrices on both sides of the
//! stability boundary, with single and multiple (fractional) delays; and
//! the iteration caps.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use std::f64::consts::PI;

use kerf_chatter::{
    constant_delay_dde, constant_delay_dde_unit_depth, scale_dde, spectral_radius_arnoldi,
    spectral_radius_dense, ArnoldiOptions, ChatterError, DdeSample, DelayTerm, Discretization,
    MillingProcess, Modal2, Mode, PeriodicDde,
};
use nalgebra::{DMatrix, Matrix2};

/// xorshift64* in [0, 1).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.next()
    }
}

/// A real matrix with the prescribed eigenvalues: block diagonal (2×2
/// rotation-scaling blocks for complex pairs) under a random
/// well-conditioned similarity `S = I + 0.3 G/√n`.
fn with_spectrum(rng: &mut Rng, real: &[f64], pairs: &[(f64, f64)]) -> DMatrix<f64> {
    let n = real.len() + 2 * pairs.len();
    let mut d = DMatrix::zeros(n, n);
    let mut k = 0;
    for &(r, theta) in pairs {
        let (s, c) = theta.sin_cos();
        d[(k, k)] = r * c;
        d[(k, k + 1)] = -r * s;
        d[(k + 1, k)] = r * s;
        d[(k + 1, k + 1)] = r * c;
        k += 2;
    }
    for &v in real {
        d[(k, k)] = v;
        k += 1;
    }
    let scale = 0.3 / (n as f64).sqrt();
    let s = DMatrix::from_fn(n, n, |i, j| {
        (if i == j { 1.0 } else { 0.0 }) + scale * rng.range(-1.0, 1.0)
    });
    let s_inv = s.clone().try_inverse().unwrap();
    s * d * s_inv
}

fn arnoldi_of(a: &DMatrix<f64>) -> Result<f64, ChatterError> {
    spectral_radius_arnoldi(
        a.nrows(),
        |v, out| {
            let y = a * nalgebra::DVector::from_column_slice(v);
            out.copy_from_slice(y.as_slice());
            Ok(())
        },
        &ArnoldiOptions::default(),
    )
}

#[test]
fn arnoldi_matches_prescribed_spectra() {
    let mut rng = Rng(0x1234_5678_9abc_def1);
    let mut cases = 0;
    for n in [30usize, 84, 150] {
        for trial in 0..6 {
            let r = rng.range(0.3, 1.5);
            // Bulk: many small eigenvalues (like the shift part of a
            // monodromy matrix) and a few moderate ones.
            let bulk = n - 8;
            let mut real: Vec<f64> = (0..bulk)
                .map(|i| {
                    let small = if i % 3 == 0 { 0.6 } else { 0.05 };
                    r * small * rng.range(-1.0, 1.0)
                })
                .collect();
            let mut pairs = vec![(0.7 * r, rng.range(0.1, 3.0))];
            match trial {
                // Hopf: a dominant complex pair.
                0 => {
                    pairs.push((r, rng.range(0.2, 2.9)));
                    real.extend([0.5 * r, -0.4 * r]);
                }
                // Flip: dominant real negative.
                1 => {
                    pairs.push((0.8 * r, 1.0));
                    real.extend([-r, 0.3 * r]);
                }
                // Real positive dominant.
                2 => {
                    pairs.push((0.8 * r, 2.0));
                    real.extend([r, -0.3 * r]);
                }
                // Clustered: pair at r, flip at −0.999 r, pair at 0.998 r.
                3 => {
                    pairs.push((0.998 * r, 0.7));
                    pairs.push((r, 1.3));
                    real.push(-0.999 * r);
                }
                // Two pairs of nearly equal modulus, nearby angles.
                4 => {
                    pairs.push((r, 1.0));
                    pairs.push((0.999_9 * r, 1.02));
                }
                // Nearly defective: a close pair of real dominant values.
                _ => {
                    pairs.push((0.9 * r, 0.4));
                    real.extend([r, 0.999_99 * r]);
                }
            }
            let (real, pairs) = fit(real, pairs, n);
            let a = with_spectrum(&mut rng, &real, &pairs);
            let exact = real
                .iter()
                .map(|v| v.abs())
                .chain(pairs.iter().map(|p| p.0))
                .fold(0.0, f64::max);
            let dense = spectral_radius_dense(&a, 10_000).unwrap();
            let fast = arnoldi_of(&a).unwrap();
            assert!(
                (dense - exact).abs() <= 1e-8 * exact,
                "n {n} trial {trial}: dense {dense} exact {exact}"
            );
            assert!(
                (fast - exact).abs() <= 1e-6 * exact,
                "n {n} trial {trial}: Arnoldi {fast} exact {exact}"
            );
            cases += 1;
        }
    }
    assert_eq!(cases, 18);
}

/// Pads or trims the bulk so that the total size is `n`.
fn fit(mut real: Vec<f64>, pairs: Vec<(f64, f64)>, n: usize) -> (Vec<f64>, Vec<(f64, f64)>) {
    let want = n - 2 * pairs.len();
    while real.len() > want {
        real.remove(0);
    }
    while real.len() < want {
        real.push(0.0);
    }
    (real, pairs)
}

fn textbook_modal() -> Modal2 {
    common::textbook_modal()
}

fn robot_modal(rng: &mut Rng) -> Modal2 {
    // Coupled robot-like tool tip: two modes 20–40 Hz rotated by a random angle.
    let x = Mode {
        natural_frequency_hz: rng.range(20.0, 40.0),
        damping_ratio: rng.range(0.02, 0.08),
        modal_mass: 30.0,
    };
    let y = Mode {
        natural_frequency_hz: rng.range(20.0, 40.0),
        damping_ratio: rng.range(0.02, 0.08),
        modal_mass: 30.0,
    };
    let d = Modal2::from_modes(x, y).unwrap();
    let rot = nalgebra::Rotation2::new(rng.range(0.0, PI)).into_inner();
    Modal2 {
        mass: d.mass,
        damping: rot * d.damping * rot.transpose(),
        stiffness: rot * d.stiffness * rot.transpose(),
    }
}

#[test]
fn fast_path_matches_dense_on_milling_monodromy_matrices() {
    let mut rng = Rng(0xdead_beef_cafe_f00d);
    let (entry, exit) = MillingProcess::down_milling_angles(0.05).unwrap();
    let textbook = MillingProcess {
        teeth: 2,
        radius: 0.005,
        axial_depth: 1e-3,
        kt: 6e8,
        kn: 2e8,
        entry_angle: entry,
        exit_angle: exit,
    };
    let seed = MillingProcess {
        teeth: 2,
        radius: 0.04,
        axial_depth: 3e-3,
        kt: 6.44e8,
        kn: 2.37e8,
        entry_angle: 0.75 * PI,
        exit_angle: PI,
    };
    let (mut stable, mut unstable) = (0, 0);
    let mut worst: f64 = 0.0;
    for case in 0..40 {
        let (modal, process, rpm, depth) = if case % 2 == 0 {
            (
                textbook_modal(),
                textbook,
                rng.range(5_000.0, 25_000.0),
                rng.range(0.2e-3, 4e-3),
            )
        } else {
            (
                robot_modal(&mut rng),
                seed,
                rng.range(2_000.0, 4_000.0),
                rng.range(0.5e-3, 8e-3),
            )
        };
        let m = if case % 5 == 0 { 60 } else { 40 };
        let dde = scale_dde(
            &constant_delay_dde_unit_depth(&process, rpm, m).unwrap(),
            depth,
        )
        .unwrap();
        let disc = Discretization::new(&modal, dde.period, m, dde.period).unwrap();
        let dense = spectral_radius_dense(&disc.monodromy(&dde).unwrap(), 10_000).unwrap();
        let fast = disc.spectral_radius(&dde).unwrap();
        // The Arnoldi path itself (no dense fallback) must converge.
        let compiled = disc.compile(&dde).unwrap();
        let mut buffer = Vec::new();
        let arnoldi = spectral_radius_arnoldi(
            compiled.dimension(),
            |v, out| compiled.apply(v, out, &mut buffer),
            &ArnoldiOptions::default(),
        )
        .unwrap();
        assert_eq!(arnoldi, fast);
        let rel = (fast - dense).abs() / dense;
        worst = worst.max(rel);
        assert!(
            rel <= 1e-6,
            "case {case}: rpm {rpm} depth {depth}: fast {fast} dense {dense}"
        );
        if dense < 1.0 {
            stable += 1;
        } else {
            unstable += 1;
        }
    }
    eprintln!("40 milling cases: {stable} stable, {unstable} unstable, worst relative difference {worst:e}");
    assert!(
        stable >= 5 && unstable >= 5,
        "{stable} stable / {unstable} unstable"
    );
}

#[test]
fn fast_path_matches_dense_with_multiple_fractional_delays() {
    // A state-dependent-like equation: per sub-interval two delayed terms,
    // τ₁ = T(1 + 0.03 sin) (single regeneration, fractional in Δt) and
    // τ₂ ≈ 2T (double regeneration), present gain ≠ sum of delayed gains.
    let mut rng = Rng(42);
    let process = MillingProcess {
        teeth: 2,
        radius: 0.04,
        axial_depth: 3e-3,
        kt: 6.44e8,
        kn: 2.37e8,
        entry_angle: 0.75 * PI,
        exit_angle: PI,
    };
    for _ in 0..8 {
        let modal = robot_modal(&mut rng);
        let rpm = rng.range(2_000.0, 4_000.0);
        let base = constant_delay_dde(&process, rpm, 40).unwrap();
        let t = base.period;
        let share = rng.range(0.5, 0.9);
        let dde = PeriodicDde {
            period: t,
            samples: base
                .samples
                .iter()
                .enumerate()
                .map(|(i, s)| {
                    let phase = 2.0 * PI * i as f64 / 40.0;
                    DdeSample {
                        present: s.present * 1.1,
                        delayed: vec![
                            DelayTerm {
                                gain: s.present * share,
                                delay: t * (1.0 + 0.03 * phase.sin()),
                            },
                            DelayTerm {
                                gain: s.present * (1.1 - share),
                                delay: t * (2.0 + 0.01 * phase.cos()),
                            },
                        ],
                    }
                })
                .collect(),
        };
        let disc = Discretization::new(&modal, t, 40, 2.02 * t).unwrap();
        assert_eq!(disc.dimension(), 4 + 2 * 82);
        let dense = spectral_radius_dense(&disc.monodromy(&dde).unwrap(), 10_000).unwrap();
        let fast = disc.spectral_radius(&dde).unwrap();
        assert!(
            (fast - dense).abs() <= 1e-6 * dense,
            "fast {fast} dense {dense}"
        );
    }
}

#[test]
fn iteration_caps_report_non_convergence() {
    let mut rng = Rng(7);
    // Dense QR with a cap of one sweep on a nonsymmetric 40×40 matrix.
    let a = DMatrix::from_fn(40, 40, |_, _| rng.range(-1.0, 1.0));
    assert!(matches!(
        spectral_radius_dense(&a, 1),
        Err(ChatterError::NotConverged { .. })
    ));
    // Arnoldi on a cyclic shift (all 60 eigenvalues on the unit circle)
    // with a 5-vector basis and 2 restarts cannot converge.
    let n = 60;
    let shift = DMatrix::from_fn(n, n, |i, j| if i == (j + 1) % n { 1.0 } else { 0.0 });
    let opts = ArnoldiOptions {
        max_dimension: 5,
        first_check: 3,
        max_restarts: 2,
        ..ArnoldiOptions::default()
    };
    let result = spectral_radius_arnoldi(
        n,
        |v, out| {
            let y = &shift * nalgebra::DVector::from_column_slice(v);
            out.copy_from_slice(y.as_slice());
            Ok(())
        },
        &opts,
    );
    match result {
        Err(ChatterError::NotConverged {
            iterations,
            residual,
            ..
        }) => {
            assert_eq!(iterations, 2);
            assert!(residual.is_finite() && residual > 1e-10);
        }
        other => panic!("expected NotConverged, got {other:?}"),
    }
    // A product that produces NaN is an error, not a number.
    let nan = spectral_radius_arnoldi(
        10,
        |_, out| {
            out.iter_mut().for_each(|o| *o = f64::NAN);
            Ok(())
        },
        &ArnoldiOptions::default(),
    );
    assert!(matches!(nan, Err(ChatterError::NonFinite { .. })));
    // Dense refuses NaN entries and non-square matrices.
    let mut b = DMatrix::<f64>::identity(4, 4);
    b[(1, 2)] = f64::NAN;
    assert!(matches!(
        spectral_radius_dense(&b, 100),
        Err(ChatterError::NonFinite { .. })
    ));
    assert!(spectral_radius_dense(&DMatrix::zeros(3, 4), 100).is_err());
    // Small sanity: a rotation-scaling block has radius 0.5.
    let r = Matrix2::new(0.0, -0.5, 0.5, 0.0);
    let dm = DMatrix::from_column_slice(2, 2, r.as_slice());
    assert!((arnoldi_of(&dm).unwrap() - 0.5).abs() < 1e-12);
}
