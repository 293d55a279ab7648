//! IK with the redundancy angle plus the condition number (seed 004 eq. 13
//! and 14) per path segment, and the full cell evaluation (IK, condition
//! number, tool-tip dynamics).
//!
//! The chatter indicator on the DEFAULT CELL's tool-tip dynamics (segment
//! 50, g = −0.4 rad; the cell's `chatter` settings: m = 40, state-dependent,
//! x_F = 0.75, wall term) — here because kerf_chatter's own benches cannot
//! load the cell (kerf_mill depends on kerf_chatter):
//!
//! * constant delay at 3000 rpm: the per-speed precompute (directional
//!   averages + `Discretization::new`) and the evaluation given it;
//! * state-dependent at 3000 rpm, 0.04 m/s: the whole evaluation
//!   (equilibrium + linearization + discretization + spectral radius), and
//!   its two halves, and each of its five stages given the previous one's
//!   result (group `cell indicator stage`: where the time goes);
//! * lobe diagrams of 100 speeds (2000-4000 rpm) × scan + bisection on depth
//!   (0-20 mm, 20 intervals, 1 µm): constant delay, and state-dependent at
//!   0.04 m/s (`kerf_chatter::lobes::state_dependent_critical_depth`).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use kerf_chatter::{
    chatter_indicator, constant_delay_dde, indicator::indicator_dde, linearize,
    lobes::state_dependent_critical_depth, stability_lobes, DelayModel, Discretization,
    Equilibrium, LinearizeSettings, LobeOptions,
};
use kerf_mill::{condition_number, MillCell};

fn bench(c: &mut Criterion) {
    let cell = MillCell::default_cell().expect("default cell");
    let kin = cell.kinematics();
    let path = cell.path();
    let l = cell.characteristic_length();
    let reference = *cell.reference_joints();
    let n = path.segments().len();
    c.bench_function("ik(g) + condition number, one segment", |b| {
        let mut s = 0usize;
        b.iter(|| {
            s = (s + 1) % n;
            let pose = path.tool_pose(s, 1.0).expect("pose");
            let q = kin.ik_nearest(&pose, &reference).expect("ik");
            let j = kin.jacobian(&q).expect("J");
            condition_number(&j, l).expect("K")
        })
    });
    c.bench_function("cell.evaluate (ik + K + Modal2), one segment", |b| {
        let mut s = 0usize;
        b.iter(|| {
            s = (s + 1) % n;
            cell.evaluate(s, 1.0, None).expect("state")
        })
    });
}

fn bench_cell_indicator(c: &mut Criterion) {
    let cell = MillCell::default_cell().expect("default cell");
    let state = cell.evaluate(50, -0.4, None).expect("segment 50, g = -0.4");
    let modal = state.modal;
    let process = cell.milling_process();
    let settings = *cell.indicator_settings();
    let m = settings.steps;
    let (rpm, feed) = (3000.0, 0.04);
    eprintln!(
        "cell segment 50, g = -0.4: K = {:.4}, stiffness {:?} N/m, m = {m}",
        state.condition_number, modal.stiffness
    );
    c.bench_function(
        "cell indicator: constant delay, precompute per speed",
        |b| {
            b.iter(|| {
                let dde = constant_delay_dde(&process, black_box(rpm), m).expect("dde");
                let disc = Discretization::new(&modal, dde.period, m, dde.period).expect("disc");
                (dde, disc)
            })
        },
    );
    let dde = constant_delay_dde(&process, rpm, m).expect("dde");
    let disc = Discretization::new(&modal, dde.period, m, dde.period).expect("disc");
    c.bench_function("cell indicator: constant delay, evaluation", |b| {
        b.iter(|| disc.spectral_radius(black_box(&dde)).expect("rho"))
    });
    let sd = chatter_indicator(&modal, &process, rpm, feed, &settings).expect("indicator");
    eprintln!(
        "cell state-dependent |mu|max = {} at {rpm} rpm, {feed} m/s",
        sd.spectral_radius
    );
    c.bench_function("cell indicator: state-dependent, whole evaluation", |b| {
        b.iter(|| {
            chatter_indicator(&modal, &process, black_box(rpm), black_box(feed), &settings)
                .expect("indicator")
        })
    });
    c.bench_function(
        "cell indicator: state-dependent, equilibrium + linearization",
        |b| {
            b.iter(|| {
                indicator_dde(&modal, &process, black_box(rpm), feed, &settings).expect("dde")
            })
        },
    );
    let (sd_dde, _) = indicator_dde(&modal, &process, rpm, feed, &settings).expect("dde");
    c.bench_function(
        "cell indicator: state-dependent, discretization + spectral radius",
        |b| {
            b.iter(|| {
                let disc = Discretization::new(
                    &modal,
                    sd_dde.period,
                    m,
                    sd_dde.max_delay().max(sd_dde.period),
                )
                .expect("disc");
                disc.spectral_radius(black_box(&sd_dde)).expect("rho")
            })
        },
    );
    // Where the time of one whole evaluation goes, stage by stage (each
    // given the previous stage's result).
    let mut stages = c.benchmark_group("cell indicator stage");
    stages.bench_function("1 equilibrium (Equilibrium::compute)", |b| {
        b.iter(|| {
            Equilibrium::compute(
                &modal,
                &process,
                black_box(rpm),
                feed,
                &settings.equilibrium,
            )
            .expect("equilibrium")
        })
    });
    let eq = Equilibrium::compute(&modal, &process, rpm, feed, &settings.equilibrium)
        .expect("equilibrium");
    let lin = LinearizeSettings {
        steps: m,
        wall_term: settings.wall_term,
    };
    stages.bench_function("2 linearization (linearize)", |b| {
        b.iter(|| linearize(black_box(&eq), &lin).expect("dde"))
    });
    stages.bench_function("3 equilibrium diagnostics", |b| {
        b.iter(|| black_box(&eq).diagnostics().expect("diagnostics"))
    });
    let max_delay = sd_dde.max_delay().max(sd_dde.period);
    stages.bench_function("4 Discretization::new", |b| {
        b.iter(|| {
            Discretization::new(&modal, black_box(sd_dde.period), m, max_delay).expect("disc")
        })
    });
    let disc = Discretization::new(&modal, sd_dde.period, m, max_delay).expect("disc");
    stages.bench_function("5 compile + Arnoldi (spectral_radius)", |b| {
        b.iter(|| disc.spectral_radius(black_box(&sd_dde)).expect("rho"))
    });
    stages.finish();
    let rpms: Vec<f64> = (0..100)
        .map(|i| 2000.0 + 2000.0 * i as f64 / 99.0)
        .collect();
    let opts = LobeOptions {
        steps: m,
        max_depth: 0.02,
        ..LobeOptions::default()
    };
    let lobes = stability_lobes(&modal, &process, &rpms, &opts).expect("lobes");
    let evaluations: usize = lobes.iter().map(|p| p.evaluations).sum();
    eprintln!("cell constant-delay lobes: {evaluations} spectral radii for 100 speeds");
    let mut group = c.benchmark_group("cell lobes");
    group.sample_size(10);
    group.bench_function("constant delay, 100 speeds x scan+bisection", |b| {
        b.iter(|| stability_lobes(&modal, &process, black_box(&rpms), &opts).expect("lobes"))
    });
    let sd_settings = settings.model(DelayModel::StateDependent);
    group.bench_function(
        "state-dependent at 0.04 m/s, 100 speeds x scan+bisection",
        |b| {
            b.iter(|| {
                rpms.iter()
                    .map(|&n| {
                        state_dependent_critical_depth(
                            &modal,
                            &process,
                            n,
                            feed,
                            &sd_settings,
                            &opts,
                        )
                        .expect("a_lim")
                    })
                    .collect::<Vec<_>>()
            })
        },
    );
    group.finish();
}

criterion_group!(benches, bench, bench_cell_indicator);
criterion_main!(benches);
