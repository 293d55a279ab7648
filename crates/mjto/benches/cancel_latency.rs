//! How long a cut plan takes to stop after its cancellation (issue 11, item 3: Ctrl-C stops a
//! node within 1 s, even mid-plan). Plans two long requests derived from case 1 and cancels each
//! at several times; prints, per cancel time, the stage it stopped in and the latency from
//! `CancelToken::cancel` to `plan_within` returning.
//!
//! `cargo bench -p kerf_mjto --bench cancel_latency`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench binary reports failures by panicking

use std::path::Path;
use std::time::{Duration, Instant};

use kerf_budget::{Budget, CancelToken};
use kerf_mjto::{planner::Planner, CutRequest, LaserMachine, PlanError};

fn case1() -> CutRequest {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/case1.yaml");
    CutRequest::from_yaml(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Plans `request`, cancels after `after`; returns (plan time without cancel if it finished
/// first, or the latency and the error text).
fn run(request: &CutRequest, after: Duration) -> (Option<Duration>, String) {
    let mut planner = Planner::new(LaserMachine::default_machine().unwrap()).unwrap();
    let token = CancelToken::new();
    let budget = Budget::new(None, token.clone());
    std::thread::scope(|scope| {
        let handle = scope.spawn(move || {
            let r = planner.plan_within(request, &budget);
            (Instant::now(), r)
        });
        std::thread::sleep(after);
        let cancelled_at = Instant::now();
        token.cancel();
        let (returned_at, result) = handle.join().unwrap();
        match result {
            Err(e @ PlanError::Interrupted(_)) => (
                Some(returned_at.saturating_duration_since(cancelled_at)),
                e.to_string(),
            ),
            Err(e) => (None, format!("failed before the cancel: {e}")),
            Ok(_) => (None, "finished before the cancel".into()),
        }
    })
}

fn main() {
    let mut samples = case1();
    samples.request_id = "800k-samples".into();
    samples.feedrate = 0.001;
    samples.sample_period = 0.001;
    let mut grid = case1();
    grid.request_id = "gfd-9375".into();
    grid.options.gfd.q4_steps = 25;
    grid.options.gfd.q5_steps = 25;
    grid.options.gfd.q6_steps = 15;
    println!("| request | cancelled after (s) | latency (ms) | stopped in |");
    println!("|---|---:|---:|---|");
    let mut worst = Duration::ZERO;
    for (request, times) in [
        (
            &samples,
            &[
                0.05, 0.5, 1.0, 2.0, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0, 16.0, 18.0,
            ][..],
        ),
        (&grid, &[0.05, 0.2, 0.4, 0.6, 0.8, 1.0][..]),
    ] {
        for &t in times {
            let (latency, what) = run(request, Duration::from_secs_f64(t));
            let latency_text = match latency {
                Some(l) => {
                    worst = worst.max(l);
                    format!("{:.2}", l.as_secs_f64() * 1e3)
                }
                None => "-".into(),
            };
            let stage = what
                .split("during ")
                .nth(1)
                .map(|s| s.split(':').next().unwrap_or(s).to_string())
                .unwrap_or(what);
            println!(
                "| {} | {t} | {latency_text} | {stage} |",
                request.request_id
            );
        }
    }
    println!("worst latency: {:.2} ms", worst.as_secs_f64() * 1e3);
}
