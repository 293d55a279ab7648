//! Cost of the constant-delay chatter indicator |μ|max (issue 4 figures):
//!
//! * one evaluation at m = 40 for the seed 004 default process (2 teeth,
//!   R = 0.04 m, a_p = 3 mm, K_t = 6.44e8, K_n = 2.37e8 N/m², engagement
//!   [0.75π, π]) at 3000 rpm on a representative robot tool tip: two
//!   uncoupled modes f_n = 30 Hz, ζ = 0.05, k = 1e6 N/m (modal mass
//!   k/ω_n² = 28.1 kg) — split into the per-speed precompute
//!   (`Discretization::new` + the directional averages) and the evaluation
//!   given it (fast Arnoldi path), with the dense reference for comparison;
//! * a lobe diagram of 100 speeds (2000–4000 rpm) × coarse scan and
//!   bisection on depth (0–20 mm, 20 scan intervals, 1 µm tolerance);
//! * the state-dependent indicator (seed 004 eq. 1-8: periodic equilibrium,
//!   linearization, discretization, spectral radius; nothing precomputed) on
//!   the same modes at 3000 rpm, 0.04 m/s, with the default cell's force law
//!   (x_F = 0.75 at h_ref = 0.224 mm) and wall term.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::f64::consts::PI;
use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use kerf_chatter::{
    chatter_indicator, constant_delay_dde, spectral_radius_dense, stability_lobes, DelayModel,
    Discretization, IndicatorSettings, LobeOptions, MillingProcess, Modal2, Mode,
};

fn robot_modal() -> Modal2 {
    let wn = 2.0 * PI * 30.0;
    let mode = Mode {
        natural_frequency_hz: 30.0,
        damping_ratio: 0.05,
        modal_mass: 1e6 / (wn * wn),
    };
    Modal2::from_modes(mode, mode).expect("valid modes")
}

fn seed_process() -> MillingProcess {
    MillingProcess {
        teeth: 2,
        radius: 0.04,
        axial_depth: 3e-3,
        kt: 6.44e8,
        kn: 2.37e8,
        entry_angle: 0.75 * PI,
        exit_angle: PI,
    }
}

fn bench(c: &mut Criterion) {
    let modal = robot_modal();
    let process = seed_process();
    let rpm = 3000.0;
    let m = 40;
    c.bench_function("indicator m=40: precompute per speed", |b| {
        b.iter(|| {
            let dde = constant_delay_dde(black_box(&process), black_box(rpm), m).expect("dde");
            let disc = Discretization::new(&modal, dde.period, m, dde.period).expect("disc");
            (dde, disc)
        })
    });
    let dde = constant_delay_dde(&process, rpm, m).expect("dde");
    let disc = Discretization::new(&modal, dde.period, m, dde.period).expect("disc");
    eprintln!(
        "|mu|max = {} (fast), {} (dense)",
        disc.spectral_radius(&dde).expect("rho"),
        spectral_radius_dense(&disc.monodromy(&dde).expect("monodromy"), 10_000).expect("rho")
    );
    c.bench_function("indicator m=40: evaluation (Arnoldi)", |b| {
        b.iter(|| disc.spectral_radius(black_box(&dde)).expect("rho"))
    });
    c.bench_function("indicator m=40: evaluation (dense monodromy + QR)", |b| {
        b.iter(|| {
            let phi = disc.monodromy(black_box(&dde)).expect("monodromy");
            spectral_radius_dense(&phi, 10_000).expect("rho")
        })
    });
    let rpms: Vec<f64> = (0..100)
        .map(|i| 2000.0 + 2000.0 * i as f64 / 99.0)
        .collect();
    let opts = LobeOptions {
        max_depth: 0.02,
        ..LobeOptions::default()
    };
    let lobes = stability_lobes(&modal, &process, &rpms, &opts).expect("lobes");
    let evaluations: usize = lobes.iter().map(|p| p.evaluations).sum();
    eprintln!("lobe diagram: {evaluations} spectral radii for 100 speeds");
    let mut group = c.benchmark_group("lobes");
    group.sample_size(10);
    group.bench_function("100 speeds x scan+bisection, m=40", |b| {
        b.iter(|| stability_lobes(&modal, &process, black_box(&rpms), &opts).expect("lobes"))
    });
    group.finish();
}

fn bench_state_dependent(c: &mut Criterion) {
    let modal = robot_modal();
    let process = seed_process();
    let settings = IndicatorSettings::default()
        .model(DelayModel::StateDependent)
        .force_law(0.75, 2.24e-4);
    let (rpm, feed) = (3000.0, 0.04);
    let ind = chatter_indicator(&modal, &process, rpm, feed, &settings).expect("indicator");
    eprintln!(
        "state-dependent |mu|max = {} ({} equilibrium iterations)",
        ind.spectral_radius, ind.equilibrium_iterations
    );
    c.bench_function(
        "indicator m=40: state-dependent (equilibrium + linearization + eigen)",
        |b| {
            b.iter(|| {
                chatter_indicator(&modal, &process, black_box(rpm), black_box(feed), &settings)
                    .expect("indicator")
            })
        },
    );
}

criterion_group!(benches, bench, bench_state_dependent);
criterion_main!(benches);
