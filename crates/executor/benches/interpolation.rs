//! Cost of one control cycle and of sampling alone, 6 joints, 1000 quintic waypoints.
//!
//! Run: `cargo bench -p kerf_executor --bench interpolation`. For the worst case per call see
//! `examples/cycle_cost.rs`.

use std::f64::consts::PI;
use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion};
use kerf_executor::{
    validate, Cycle, Executor, ExecutorConfig, GoalTolerances, JointLimits, JointSample,
    JointTolerance, TrajectoryPoint, TrajectoryRequest,
};

const N: usize = 6;
const DT: f64 = 0.004;

fn limits() -> Vec<JointLimits> {
    (0..N)
        .map(|i| JointLimits {
            name: format!("j{}", i + 1),
            min_position: -3.0,
            max_position: 3.0,
            max_velocity: 2.0,
            max_acceleration: 10.0,
        })
        .collect()
}

/// `points` quintic waypoints `spacing` s apart of p_j(t) = A (1 − cos ω_j t), ending at rest.
fn request(points: usize, spacing: f64) -> TrajectoryRequest {
    let end = spacing * (points - 1) as f64;
    let amp = 0.5;
    let omega: Vec<f64> = (0..N).map(|j| 2.0 * PI * (3 + j) as f64 / end).collect();
    let pts = (0..points)
        .map(|k| {
            let t = spacing * k as f64;
            let last = k == points - 1;
            TrajectoryPoint {
                positions: omega.iter().map(|w| amp * (1.0 - (w * t).cos())).collect(),
                velocities: omega
                    .iter()
                    .map(|w| if last { 0.0 } else { amp * w * (w * t).sin() })
                    .collect(),
                accelerations: omega
                    .iter()
                    .map(|w| {
                        if last {
                            0.0
                        } else {
                            amp * w * w * (w * t).cos()
                        }
                    })
                    .collect(),
                effort: vec![],
                time_from_start: t,
            }
        })
        .collect();
    TrajectoryRequest {
        joint_names: limits().iter().map(|l| l.name.clone()).collect(),
        points: pts,
        start_time: None,
    }
}

fn tolerances() -> GoalTolerances {
    let tol = |position| -> Vec<JointTolerance> {
        limits()
            .iter()
            .map(|l| JointTolerance {
                name: l.name.clone(),
                position,
                velocity: 1.0,
                acceleration: 0.0,
            })
            .collect()
    };
    GoalTolerances {
        path: tol(0.1),
        goal: tol(1e-3),
        goal_time: 1.0,
    }
}

fn benches(c: &mut Criterion) {
    let req = request(1000, 0.1);
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
