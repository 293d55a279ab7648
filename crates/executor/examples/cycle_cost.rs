//! Worst-case cost of one control cycle: 10⁶ calls of `Executor::update_into`, 6 joints,
//! 1001 quintic waypoints spanning 4000 s (10⁶ cycles at 250 Hz), each call timed.
//!
//! Run: `cargo run --release -p kerf_executor --example cycle_cost`. Prints mean, p50, p99,
//! p99.9 and max in µs. Timings include `Instant::now()` overhead (tens of ns) and any
//! preemption by the OS; no real-time scheduling is set up.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

#[path = "../benches/common/mod.rs"]
mod common;

use std::time::Instant;

use common::{cosine_request, limits, tolerances, DT, N};
use kerf_executor::{Cycle, Executor, ExecutorConfig, JointSample};

const CALLS: usize = 1_000_000;

fn main() -> Result<(), kerf_executor::ExecutorError> {
    let limits = limits();
    let points = 1001;
    let end = CALLS as f64 * DT;
    let spacing = end / (points - 1) as f64;
    let req = cosine_request(points, spacing, |j| (50 + 7 * j) as f64);
    let tolerances = tolerances();

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
