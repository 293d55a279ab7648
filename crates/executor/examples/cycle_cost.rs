//! Worst-case cost of one control cycle: 10⁶ calls of `Executor::update_into`, 6 joints,
//! 1001 quintic waypoints spanning 4000 s (10⁶ cycles at 250 Hz), each call timed.
//!
//! Run: `cargo run --release -p kerf_executor --example cycle_cost`. Prints mean, p50, p99,
//! p99.9 and max in µs. Timings include `Instant::now()` overhead (tens of ns) and any
//! preemption by the OS; no real-time scheduling is set up.

use std::f64::consts::PI;
use std::time::Instant;

use kerf_executor::{
    Cycle, Executor, ExecutorConfig, GoalTolerances, JointLimits, JointSample, JointTolerance,
    TrajectoryPoint, TrajectoryRequest,
};

const N: usize = 6;
const DT: f64 = 0.004;
const CALLS: usize = 1_000_000;

fn main() -> Result<(), kerf_executor::ExecutorError> {
    let limits: Vec<JointLimits> = (0..N)
        .map(|i| JointLimits {
            name: format!("j{}", i + 1),
            min_position: -3.0,
            max_position: 3.0,
            max_velocity: 2.0,
            max_acceleration: 10.0,
        })
        .collect();
    let points = 1001;
    let end = CALLS as f64 * DT;
    let spacing = end / (points - 1) as f64;
    let amp = 0.5;
    let omega: Vec<f64> = (0..N)
        .map(|j| 2.0 * PI * (50 + 7 * j) as f64 / end)
        .collect();
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
    let req = TrajectoryRequest {
        joint_names: limits.iter().map(|l| l.name.clone()).collect(),
        points: pts,
        start_time: None,
    };
    let tol = |position| -> Vec<JointTolerance> {
        limits
            .iter()
            .map(|l| JointTolerance {
                name: l.name.clone(),
                position,
                velocity: 1.0,
                acceleration: 0.0,
            })
            .collect()
    };
    let tolerances = GoalTolerances {
        path: tol(0.1),
        goal: tol(1e-3),
        goal_time: 1.0,
    };

    let mut exec = Executor::new(limits.clone(), ExecutorConfig::default(), vec![0.0; N])?;
    let t_validate = Instant::now();
    exec.submit(&req, &tolerances, 0.0)?;
    let validate_ms = t_validate.elapsed().as_secs_f64() * 1e3;

    let mut cycle = Cycle::default();
    let mut measured = JointSample::at_rest(vec![0.0; N]);
    let mut times = Vec::with_capacity(CALLS);
    for k in 0..CALLS {
        let t = k as f64 * DT;
        let start = Instant::now();
        exec.update_into(t, &measured, &mut cycle)?;
        times.push(start.elapsed().as_nanos() as f64 / 1e3);
        measured.clone_from(&cycle.reference);
    }
    let moving = exec.active_goal().is_some();
    times.sort_by(f64::total_cmp);
    let mean = times.iter().sum::<f64>() / CALLS as f64;
    let q = |p: f64| times[((CALLS - 1) as f64 * p) as usize];
    println!("validate+submit 6 joints x {points} quintic points: {validate_ms:.2} ms");
    println!(
        "update_into, {CALLS} calls (goal still active at the end: {moving}): mean {mean:.3} µs, p50 {:.3} µs, p99 {:.3} µs, p99.9 {:.3} µs, max {:.3} µs",
        q(0.5),
        q(0.99),
        q(0.999),
        times[CALLS - 1]
    );
    Ok(())
}
