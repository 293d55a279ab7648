//! Bench binary: whole MJTO plans of the two committed cases (seed 001
//! section 3), with the time of every stage and the MJTO-versus-QI table.
//!
//! ```text
//! cargo bench -p kerf_mjto --bench plan_cases
//! KERF_PLAN_RUNS=50 cargo bench -p kerf_mjto --bench plan_cases
//! ```
//!
//! Prints markdown tables (the ones in BENCHMARKS.md). Timings are medians
//! over `KERF_PLAN_RUNS` runs (default 20) after one warm-up run, which also
//! loads the mesh into the planner's cache and builds its collision world (a
//! node plans with a warm planner). The planning time is that of
//! `benches/plan_time.rs` and `benches/rto_box.rs`: one `Planner::plan` of a
//! warm planner, wall clock; "total" is the plan's own `StageTimes::total`
//! (the executability check included), "wall" the bench's clock around the
//! call. `plan_time` also gives CPU time and the cold planner.
//! The last table times the three collision paths on each final plan's
//! samples (one thread): parry's composite test per sample
//! (`colliding_links_exhaustive`), with the separating-axis first stage
//! (`colliding_links`), and conservative advancement in the planner's runs
//! of 256 samples (`colliding_links_along`); it also checks that the three
//! agree.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::path::Path;
use std::time::Instant;

use kerf_mjto::collision::{CollisionWorld, HeadModel};
use kerf_mjto::mesh::MeshCache;
use kerf_mjto::plan::{CutPlan, StageTimes};
use kerf_mjto::planner::{Planner, BUDGET_STRIDE};
use kerf_mjto::{CutRequest, LaserMachine};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn stage(times: &[StageTimes], f: impl Fn(&StageTimes) -> f64) -> f64 {
    median(times.iter().map(f).collect()) * 1e3
}

fn main() {
    let runs: usize = std::env::var("KERF_PLAN_RUNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(20);
    let cases = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases");
    let mut planner =
        Planner::new(LaserMachine::default_machine().expect("machine")).expect("planner");
    println!("| case | CL points | n+1 | iterations | RTOs | collision queries | setup | Hessian | GFD | selection | rotary QPs | M-path QP | dense checks | evaluation (QI, metrics) | total (median of {runs}) | wall (median) |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut plans: Vec<(String, CutPlan)> = Vec::new();
    for (name, control_points) in [
        ("case1", 0usize),
        ("case2", 0),
        ("case1", 241),
        ("case2", 628),
    ] {
        let text = std::fs::read_to_string(cases.join(format!("{name}.yaml"))).expect("case file");
        let mut request = CutRequest::from_yaml(&text).expect("request");
        request.options.control_points = control_points;
        let t = Instant::now();
        let first = match planner.plan(&request) {
            Ok(plan) => plan,
            Err(e) => {
                println!(
                    "| {name} | {} | {control_points} | failed after {:.0} ms: {e} |",
                    request.points.len(),
                    t.elapsed().as_secs_f64() * 1e3
                );
                continue;
            }
        };
        // The paper's one coefficient per CL point is slow: fewer runs.
        let runs = if control_points > 200 {
            runs.min(3)
        } else {
            runs
        };
        let mut stages = Vec::new();
        let mut wall = Vec::new();
        for _ in 0..runs {
            let t = Instant::now();
            let plan = planner.plan(&request).expect("plan");
            wall.push(t.elapsed().as_secs_f64());
            stages.push(plan.times_per_stage.clone());
        }
        println!(
            "| {name} | {} | {} | {} | {} | {} | {:.2} ms | {:.2} ms | {:.2} ms | {:.2} ms | {:.2} ms | {:.2} ms | {:.2} ms | {:.2} ms | {:.2} ms | {:.2} ms |",
            request.points.len(),
            first.control_points,
            first.iterations,
            first.rtos.len(),
            first.collision_queries,
            stage(&stages, |s| s.setup),
            stage(&stages, |s| s.hessian),
            stage(&stages, |s| s.gfd),
            stage(&stages, |s| s.selection),
            stage(&stages, |s| s.rotary_qp),
            stage(&stages, |s| s.mpath_qp),
            stage(&stages, |s| s.collision),
            stage(&stages, |s| s.evaluation),
            stage(&stages, |s| s.total),
            median(wall) * 1e3,
        );
        if control_points == 0 {
            plans.push((name.to_string(), first));
        }
    }
    println!();
    for (name, plan) in &plans {
        let (m, q) = (&plan.metrics, &plan.qi_metrics);
        println!("{name}: MJTO within limits: {}, colliding samples MJTO {} / QI {}, max CL error MJTO {:.2e} m / QI {:.2e} m, max lead {:.2}° / {:.2}°, max tilt {:.2}° / {:.2}°", m.within_limits, m.colliding_samples, q.colliding_samples, m.max_cl_error, q.max_cl_error, m.max_lead_angle.to_degrees(), q.max_lead_angle.to_degrees(), m.max_tilt_angle.to_degrees(), q.max_tilt_angle.to_degrees());
        println!();
        println!("| {name} | axis | peak acc MJTO | peak acc QI | peak jerk MJTO | peak jerk QI | RMS jerk MJTO | RMS jerk QI | limit acc / jerk |");
        println!("|---|---|---|---|---|---|---|---|---|");
        let limits = planner.machine().limits();
        for (j, limit) in limits.iter().enumerate() {
            println!(
                "| | {} | {:.3} | {:.3} | {:.2} | {:.2} | {:.2} | {:.2} | {} / {} |",
                plan.joint_names[j],
                m.peak_acceleration[j],
                q.peak_acceleration[j],
                m.peak_jerk[j],
                q.peak_jerk[j],
                m.rms_jerk[j],
                q.rms_jerk[j],
                limit.acc,
                limit.jerk
            );
        }
        println!();
    }
    println!("| case | samples | exhaustive (µs/sample) | first stage (µs/sample) | advancement (µs/sample) | verdicts equal |");
    println!("|---|---|---|---|---|---|");
    for (name, plan) in &plans {
        let text = std::fs::read_to_string(cases.join(format!("{name}.yaml"))).expect("case file");
        let request = CutRequest::from_yaml(&text).expect("request");
        let v = request.validate().expect("valid");
        let mesh = MeshCache::new().get(&request.mesh).expect("mesh");
        let head = HeadModel::from_urdf(planner.machine().robot().urdf()).expect("head");
        let w = CollisionWorld::new(head, &mesh, &v.workpiece_pose, request.options.clearance)
            .expect("world");
        let qs = &plan.positions;
        let per_sample = |f: &dyn Fn() -> Vec<Vec<&'static str>>| {
            let mut t = Vec::new();
            let mut out = Vec::new();
            for _ in 0..runs {
                let start = Instant::now();
                out = f();
                t.push(start.elapsed().as_secs_f64() / qs.len() as f64 * 1e6);
            }
            (median(t), out)
        };
        let (te, e) = per_sample(&|| qs.iter().map(|q| w.colliding_links_exhaustive(q)).collect());
        let (tf, f) = per_sample(&|| qs.iter().map(|q| w.colliding_links(q)).collect());
        let (ta, a) = per_sample(&|| {
            qs.chunks(BUDGET_STRIDE)
                .flat_map(|c| w.colliding_links_along(c))
                .collect()
        });
        println!(
            "| {name} | {} | {te:.2} | {tf:.2} | {ta:.2} | {} |",
            qs.len(),
            e == f && e == a
        );
    }
}
