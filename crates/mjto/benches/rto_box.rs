//! Bench binary: RTOs as equalities (seed 001) against boxes inside the
//! feasible domain (kerf, issue 16 item 3) on case 1, case 2 and a tube
//! saddle beside a rib (6 and 10 m/min): RMS and peak jerk per rotary axis, RTOs,
//! iterations, and the planning time.
//!
//! ```text
//! cargo bench -p kerf_mjto --bench rto_box
//! KERF_PLAN_RUNS=20 cargo bench -p kerf_mjto --bench rto_box
//! KERF_ORIENTATION_CORRIDOR=none cargo bench -p kerf_mjto --bench rto_box
//! ```
//!
//! `KERF_ORIENTATION_CORRIDOR` (`none` or `allowance`, default the request's default) sets
//! `options.orientation_corridor` of every request: `none` is seed 001's rotary QPs.
//!
//! Prints a markdown table (the one in BENCHMARKS.md). Planning times are
//! medians over `KERF_PLAN_RUNS` runs (default 10) after one warm-up run: one
//! `Planner::plan` of a warm planner (mesh cached, collision world kept),
//! wall clock, as in `benches/plan_cases.rs` and `benches/plan_time.rs`.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench reports failures by panicking

use std::path::Path;
use std::time::Instant;

use kerf_mjto::planner::Planner;
use kerf_mjto::request::{OrientationCorridor, RtoConstraint};
use kerf_mjto::{CutRequest, LaserMachine};

#[path = "../tests/common/saddle.rs"]
mod saddle;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn main() {
    let runs: usize = std::env::var("KERF_PLAN_RUNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(10);
    let cases = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases");
    let mut requests: Vec<(String, CutRequest)> = ["case1", "case2"]
        .iter()
        .map(|name| {
            let text = std::fs::read_to_string(cases.join(format!("{name}.yaml"))).unwrap();
            (name.to_string(), CutRequest::from_yaml(&text).unwrap())
        })
        .collect();
    let geometry = saddle::Saddle::default();
    let mesh = saddle::TempMesh::new("bench", &geometry.mesh());
    requests.push((
        "saddle (rib)".into(),
        geometry.request(&mesh.reference(), 0.1),
    ));
    // The issue's feed, 10 m/min.
    requests.push((
        "saddle (rib), 10 m/min".into(),
        geometry.request(&mesh.reference(), 10.0 / 60.0),
    ));
    let corridor = std::env::var("KERF_ORIENTATION_CORRIDOR")
        .map(|v| OrientationCorridor::parse(&v).expect("KERF_ORIENTATION_CORRIDOR"))
        .unwrap_or_default();
    for (_, r) in &mut requests {
        r.options.orientation_corridor = corridor;
    }
    println!("options.orientation_corridor: {}", corridor.as_str());
    println!();
    let mut planner =
        Planner::new(LaserMachine::default_machine().expect("machine")).expect("planner");
    println!("| case | RTO constraint | RMS jerk q4 (rad/s³) | RMS jerk q5 | peak jerk q4 | peak jerk q5 | RTOs (inserted) | iterations | collision queries | GFD + selection + boxes | rotary QPs | M-path QP | dense checks | planning time (median of {runs}) |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (name, request) in &requests {
        for constraint in [RtoConstraint::Equality, RtoConstraint::Box] {
            let mut r = request.clone();
            r.options.rto_constraint = constraint;
            let plan = match planner.plan(&r) {
                Ok(plan) => plan,
                Err(e) => {
                    println!("| {name} | {} | failed: {e} |", constraint.as_str());
                    continue;
                }
            };
            let mut wall = Vec::new();
            let mut stages = Vec::new();
            for _ in 0..runs {
                let t = Instant::now();
                let p = planner.plan(&r).expect("plan");
                wall.push(t.elapsed().as_secs_f64());
                stages.push(p.times_per_stage);
            }
            let stage = |f: &dyn Fn(&kerf_mjto::plan::StageTimes) -> f64| {
                median(stages.iter().map(f).collect()) * 1e3
            };
            let m = &plan.metrics;
            println!(
                "| {name} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {} ({}) | {} | {} | {:.1} ms | {:.1} ms | {:.1} ms | {:.1} ms | {:.1} ms |",
                constraint.as_str(),
                m.rms_jerk[3],
                m.rms_jerk[4],
                m.peak_jerk[3],
                m.peak_jerk[4],
                plan.rtos.len(),
                plan.rtos
                    .iter()
                    .filter(|r| r.inserted_at_iteration > 0)
                    .count(),
                plan.iterations,
                plan.collision_queries,
                stage(&|s| s.gfd + s.selection),
                stage(&|s| s.rotary_qp),
                stage(&|s| s.mpath_qp),
                stage(&|s| s.collision),
                median(wall) * 1e3
            );
        }
    }
}
