//! Bench binary: seed 001's cases and the job-shop cuts (issue 16) under both time laws.
//!
//! ```text
//! cargo bench -p kerf_mjto --bench feed_cases
//! KERF_PLAN_RUNS=10 cargo bench -p kerf_mjto --bench feed_cases
//! KERF_CASES=saddle,slot cargo bench -p kerf_mjto --bench feed_cases
//! KERF_ORIENTATION_CORRIDOR=none cargo bench -p kerf_mjto --bench feed_cases
//! ```
//!
//! `KERF_ORIENTATION_CORRIDOR` (`none` or `allowance`, default the request's default) sets
//! `options.orientation_corridor` of every request: `none` is seed 001's rotary QPs.
//!
//! Per case: the constant feed's outcome (seed 001 eq. 13 with kerf's S-curve ramps on the
//! sample grid) and its time, the time-optimal law's outcome, cycle time, peak tool-tip feed and
//! what holds the feed, the planning time (median of `KERF_PLAN_RUNS`, default 5, after a
//! warm-up run), then MJTO against QI (same RTOs, same s(t)): the peak jerk of the rotary axes.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench reports failures by panicking

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use kerf_mjto::optimal_feed::FeedMode;
use kerf_mjto::planner::Planner;
use kerf_mjto::request::OrientationCorridor;
use kerf_mjto::{CutPlan, CutRequest, LaserMachine, PlanError};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

/// The outcome in a few words.
fn outcome(r: &Result<CutPlan, PlanError>) -> String {
    match r {
        Ok(p) => format!("{:.3} s", p.feed.cycle_time),
        Err(e) => {
            let text = e.to_string();
            let short: String = text.chars().take(70).collect();
            format!("{} ({short}…)", status_name(e))
        }
    }
}

fn status_name(e: &PlanError) -> &'static str {
    match e.status() {
        1 => "INVALID_REQUEST",
        2 => "MESH_ERROR",
        3 => "UNREACHABLE",
        4 => "INFEASIBLE",
        5 => "COLLISION",
        6 => "LIMIT_VIOLATION",
        8 => "TIMEOUT",
        _ => "INTERNAL_ERROR",
    }
}

/// The limits that hold the feed, by path length covered, largest first (at most three).
fn held_by(plan: &CutPlan) -> String {
    let mut by: BTreeMap<&str, f64> = BTreeMap::new();
    for l in &plan.feed.limits {
        *by.entry(l.limited_by.as_str()).or_default() += l.s_end - l.s_start;
    }
    let mut v: Vec<(&str, f64)> = by.into_iter().collect();
    v.sort_by(|a, b| b.1.total_cmp(&a.1));
    v.iter()
        .take(3)
        .map(|(k, len)| format!("{k} {:.0} mm", len * 1e3))
        .collect::<Vec<_>>()
        .join(", ")
}

fn main() {
    let runs: usize = std::env::var("KERF_PLAN_RUNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(5)
        .max(1);
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases");
    let mut files: Vec<_> = vec![dir.join("case1.yaml"), dir.join("case2.yaml")];
    let mut jobshop: Vec<_> = std::fs::read_dir(dir.join("jobshop"))
        .expect("cases/jobshop")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "yaml"))
        .collect();
    jobshop.sort();
    files.extend(jobshop);
    // KERF_CASES=saddle,slot plans only the cases whose name contains one of the words.
    if let Ok(filter) = std::env::var("KERF_CASES") {
        let words: Vec<String> = filter.split(',').map(str::to_string).collect();
        files.retain(|f| {
            let name = f.file_stem().unwrap().to_string_lossy();
            words.iter().any(|w| name.contains(w.as_str()))
        });
    }
    let corridor = std::env::var("KERF_ORIENTATION_CORRIDOR")
        .map(|v| OrientationCorridor::parse(&v).expect("KERF_ORIENTATION_CORRIDOR"))
        .unwrap_or_default();
    println!("options.orientation_corridor: {}", corridor.as_str());
    println!();
    let mut planner =
        Planner::new(LaserMachine::default_machine().expect("machine")).expect("planner");
    println!("| case | σ (m) | f (m/min) | constant feed (seed 001) | time-optimal | peak tip feed (m/min) | feed held by | q5 RMS / peak jerk (rad/s³) | iterations | planning (median of {runs}) |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let mut peaks: Vec<(String, CutPlan)> = Vec::new();
    for file in &files {
        let name = file.file_stem().unwrap().to_string_lossy().to_string();
        let text = std::fs::read_to_string(file).expect("case file");
        let mut request = CutRequest::from_yaml(&text).expect("request");
        request.options.orientation_corridor = corridor;
        let sigma = request.validate().map(|v| v.sigma).unwrap_or(f64::NAN);
        request.options.feed_law = FeedMode::Constant;
        let constant = planner.plan(&request);
        request.options.feed_law = FeedMode::TimeOptimal;
        let first = planner.plan(&request);
        let mut wall = Vec::with_capacity(runs);
        for _ in 0..runs {
            let t = Instant::now();
            let _ = planner.plan(&request);
            wall.push(t.elapsed().as_secs_f64());
        }
        let constant_time = first
            .as_ref()
            .map(|p| p.feed.constant_feed_time)
            .unwrap_or(f64::NAN);
        println!(
            "| {name} | {sigma:.3} | {:.1} | {} (S-curve {constant_time:.3} s) | {} | {} | {} | {} | {} | {:.1} ms |",
            request.feedrate * 60.0,
            outcome(&constant),
            outcome(&first),
            first
                .as_ref()
                .map(|p| format!("{:.2}", p.feed.peak_feed * 60.0))
                .unwrap_or_default(),
            first.as_ref().map(held_by).unwrap_or_default(),
            first
                .as_ref()
                .map(|p| format!(
                    "{:.2} / {:.2}",
                    p.metrics.rms_jerk[4], p.metrics.peak_jerk[4]
                ))
                .unwrap_or_default(),
            first
                .as_ref()
                .map(|p| p.iterations.to_string())
                .unwrap_or_default(),
            median(wall) * 1e3
        );
        if let Ok(plan) = first {
            peaks.push((name, plan));
        }
    }
    println!();
    println!("MJTO against QI on the same RTOs and s(t): peak |jerk| (rad/s³) and peak |acceleration| (rad/s²) of the rotary axes, and whether each is within Table 2.");
    println!();
    println!("| case | q4 jerk MJTO / QI | q5 jerk MJTO / QI | q4 acc MJTO / QI | q5 acc MJTO / QI | within limits MJTO / QI |");
    println!("|---|---|---|---|---|---|");
    for (name, p) in &peaks {
        let (m, q) = (&p.metrics, &p.qi_metrics);
        println!(
            "| {name} | {:.1} / {:.1} | {:.1} / {:.1} | {:.2} / {:.2} | {:.2} / {:.2} | {} / {} |",
            m.peak_jerk[3],
            q.peak_jerk[3],
            m.peak_jerk[4],
            q.peak_jerk[4],
            m.peak_acceleration[3],
            q.peak_acceleration[3],
            m.peak_acceleration[4],
            q.peak_acceleration[4],
            m.within_limits,
            q.within_limits
        );
    }
}
