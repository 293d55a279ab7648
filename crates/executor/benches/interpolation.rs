//! Cost of one control cycle and of sampling alone, 6 joints, 1000 quintic waypoints.
//!
//! Run: `cargo bench -p kerf_executor --bench interpolation`. For the worst case per call see
//! `examples/cycle_cost.rs`.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use std::hint::black_box;
use std::time::{Duration, Instant};

use common::{cosine_request, limits, tolerances, DT, N};
use criterion::{criterion_group, criterion_main, Criterion};
use kerf_executor::{validate, Cycle, Executor, ExecutorConfig, JointSample};

fn benches(c: &mut Criterion) {
    let req = cosine_request(1000, 0.1, |j| (3 + j) as f64);
    let cfg = ExecutorConfig::default();
    let rest = JointSample::at_rest(vec![0.0; N]);

    c.bench_function("validate 6 joints x 1000 quintic points", |b| {
        b.iter(|| validate(&limits(), &cfg, black_box(&req), &rest, 0.0))
    });

    let traj = match validate(&limits(), &cfg, &req, &rest, 0.0) {
        Ok(t) => t,
        Err(e) => panic!("benchmark trajectory invalid: {e}"),
    };
    let end = traj.end_time();
    c.bench_function("sample_into 6 joints, 1000 quintic points", |b| {
        let mut out = JointSample::default();
        let mut t = 0.0;
        b.iter(|| {
            traj.sample_into(black_box(t), &mut out);
            t += DT;
            if t >= end {
                t = 0.0;
            }
            black_box(&out);
        })
    });

    // Executor::update_into per cycle; the executor is re-armed (not timed) when the
    // trajectory ends, so every timed cycle samples a moving trajectory and checks tolerances.
    let mut armed = match Executor::new(limits(), cfg.clone(), vec![0.0; N]) {
        Ok(e) => e,
        Err(e) => panic!("{e}"),
    };
    if let Err(e) = armed.submit(&req, &tolerances(), 0.0) {
        panic!("{e}");
    }
    c.bench_function("Executor::update_into 6 joints, 1000 quintic points", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            let mut exec = armed.clone();
            let mut cycle = Cycle::default();
            let mut measured = rest.clone();
            let mut t = 0.0;
            for _ in 0..iters {
                if t >= end {
                    exec = armed.clone();
                    t = 0.0;
                }
                let start = Instant::now();
                let r = exec.update_into(black_box(t), &measured, &mut cycle);
                total += start.elapsed();
                if r.is_err() {
                    panic!("update failed");
                }
                measured.clone_from(&cycle.reference);
                t += DT;
            }
            total
        })
    });
}

criterion_group!(interpolation, benches);
criterion_main!(interpolation);
