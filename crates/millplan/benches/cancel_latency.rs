//! How long a milling plan takes to stop after its cancellation (issue 11, item 3: Ctrl-C stops
//! a node within 1 s, even mid-plan). Plans the default request with the dp, naive and ddpg
//! planners and cancels each at several times; prints the latency from `CancelToken::cancel` to
//! `plan_within` returning and the stage it stopped in.
//!
//! `cargo bench -p kerf_millplan --bench cancel_latency`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench binary reports failures by panicking

use std::time::{Duration, Instant};

use kerf_budget::{Budget, CancelToken};
use kerf_millplan::{MillPlanError, MillPlanner, MillRequest};

fn run(
    planner: &MillPlanner,
    request: &MillRequest,
    after: Duration,
) -> (Option<Duration>, String) {
    let token = CancelToken::new();
    let budget = Budget::new(None, token.clone());
    std::thread::scope(|scope| {
        let handle = scope.spawn(|| {
            let r = planner.plan_within(request, &budget);
            (Instant::now(), r)
        });
        std::thread::sleep(after);
        let cancelled_at = Instant::now();
        token.cancel();
        let (returned_at, result) = handle.join().unwrap();
        match result {
            Err(e @ MillPlanError::Interrupted(_)) => (
                Some(returned_at.saturating_duration_since(cancelled_at)),
                e.to_string(),
            ),
            Err(e) => (None, format!("failed before the cancel: {e}")),
            Ok(_) => (None, "finished before the cancel".into()),
        }
    })
}

fn main() {
    let planner = MillPlanner::with_default_cell().unwrap();
    println!("| planner | cancelled after (s) | latency (ms) | stopped in |");
    println!("|---|---:|---:|---|");
    let mut worst = Duration::ZERO;
    for (name, times) in [
        ("dp", &[0.05, 0.3, 0.6, 1.0, 1.5, 2.0, 2.5][..]),
        ("naive", &[0.02, 0.05, 0.1][..]),
        ("ddpg", &[0.01, 0.03][..]),
    ] {
        let request = MillRequest {
            planner: name.to_string(),
            ..MillRequest::default()
        };
        for &t in times {
            let (latency, what) = run(&planner, &request, Duration::from_secs_f64(t));
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
            println!("| {name} | {t} | {latency_text} | {stage} |");
        }
    }
    println!("worst latency: {:.2} ms", worst.as_secs_f64() * 1e3);
}
