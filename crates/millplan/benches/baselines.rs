//! The as-executed comparison of the milling planners (issue 13, item 3): every planner on the
//! same request, every figure taken from what the robot runs (`MillPlanOutput::executed`: the
//! time-scaled trajectory from rest to rest, |μ|max re-evaluated directly at its feeds, the tool
//! path measured with the executor's interpolation at the control period).
//!
//! ```sh
//! cargo bench -p kerf_millplan --bench baselines                 # the default request
//! cargo bench -p kerf_millplan --bench baselines -- --shifted    # the shifted, turned path
//! cargo bench -p kerf_millplan --bench baselines -- --planners greedy,greedy_best_g
//! cargo bench -p kerf_millplan --bench baselines -- --planners greedy --candidates  # every fixed g
//! cargo bench -p kerf_millplan --bench baselines -- --planners dp --dp-accel  # + the DP with
//! #   joint accelerations in its state (DpSpec::joint_acceleration_limits), default request only
//! cargo bench -p kerf_millplan --bench baselines -- --planners dp --dp-executed  # + the DP with
//! #   the executed timing in the loop (kerf_millplan::dp_executed), default request only
//! ```
//!
//! The shifted path is the default path turned by 0.3 rad about the vertical through its
//! centroid and moved by (−0.1, 0.05, −0.1) m (`tests/baselines.rs` plans it too): no shipped
//! cache applies to it, so `dp` and `naive` build its per-path cache first
//! (`kerf_millplan::path_cache`).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench binary reports failures by panicking

use std::time::Instant;

use kerf_millplan::path_distribution::moved_points;
use kerf_millplan::{MillPlanOutput, MillPlanner, MillRequest};

struct Row {
    name: String,
    out: Result<MillPlanOutput, String>,
    seconds: f64,
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let shifted = args.iter().any(|a| a == "--shifted");
    let planners: Vec<String> = args
        .iter()
        .position(|a| a == "--planners")
        .and_then(|i| args.get(i + 1))
        .map(|s| s.split(',').map(str::to_string).collect())
        .unwrap_or_else(|| {
            ["ddpg", "fixed_g", "dp", "naive", "greedy", "greedy_best_g"]
                .map(str::to_string)
                .to_vec()
        });
    let planner = MillPlanner::with_default_cell().unwrap();
    let base = if shifted {
        MillRequest {
            points: moved_points(&MillRequest::default().points, 0.3, [-0.1, 0.05, -0.1]),
            ..MillRequest::default()
        }
    } else {
        MillRequest::default()
    };
    let mut rows = Vec::new();
    for name in &planners {
        let request = MillRequest {
            planner: name.clone(),
            ..base.clone()
        };
        let start = Instant::now();
        let out = planner.plan(&request).map_err(|e| e.to_string());
        let seconds = start.elapsed().as_secs_f64();
        if let Ok(o) = &out {
            let e = &o.executed.plan;
            let first = &e.segments[0];
            let last = e.segments.last().unwrap();
            let g: Vec<f64> = e.segments.iter().map(|s| s.g).collect();
            eprintln!(
                "{name}: {seconds:.2} s to plan (phases: planner {:.2} s, evaluation {:.2} s, \
                 trajectory {:.2} s); first segment {:.0} rpm {:.4} m/s g {:+.2}; last {:.0} rpm \
                 {:.4} m/s g {:+.2}; g in [{:+.2}, {:+.2}]; planned {:.3} s; slowed {}",
                o.phases.planner,
                o.phases.evaluation,
                o.phases.trajectory,
                first.rpm,
                first.feed,
                first.g,
                last.rpm,
                last.feed,
                last.g,
                g.iter().copied().fold(f64::INFINITY, f64::min),
                g.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                o.plan.total_time,
                o.executed.scaling.slowed_segments()
            );
            let chatter: Vec<usize> = e
                .segments
                .iter()
                .filter(|s| s.spectral_radius >= 1.0)
                .map(|s| s.segment)
                .collect();
            if !chatter.is_empty() {
                eprintln!("  chattering segments as executed: {chatter:?}");
            }
        } else if let Err(e) = &out {
            eprintln!("{name}: {e}");
        }
        rows.push(Row {
            name: name.clone(),
            out,
            seconds,
        });
    }
    println!(
        "| planner | time as executed (s) | chatter-free | max \\|μ\\|max | min 1/K (segments / trajectory) | max tool-tip deviation: path / plane (mm) | total reward (eq. 12) | planning (s) |"
    );
    println!("|---|---:|---|---:|---|---|---:|---:|");
    for r in &rows {
        match &r.out {
            Ok(o) => println!(
                "{}",
                row(&r.name, &o.executed, &format!("{:.1}", r.seconds))
            ),
            Err(e) => println!("| {} | failed: {e} | | | | | | {:.1} |", r.name, r.seconds),
        }
    }
    if args.iter().any(|a| a == "--dp-accel") && !shifted {
        dp_with_accelerations(&planner);
    }
    if args.iter().any(|a| a == "--dp-executed") && !shifted {
        dp_executed(&planner);
    }
    if args.iter().any(|a| a == "--candidates") {
        candidates(&planner, &base);
    }
    // The paper's claim, as executed: optimized g at least 5 % faster than g = 0, chatter-free.
    let time = |name: &str| {
        rows.iter()
            .find(|r| r.name == name)
            .and_then(|r| r.out.as_ref().ok())
            .map(|o| (o.executed.plan.total_time, o.executed.plan.chatter_free))
    };
    for (free, fixed) in [
        ("ddpg", "fixed_g"),
        ("greedy_best_g", "greedy"),
        ("dp", "greedy"),
    ] {
        if let (Some((a, ca)), Some((b, cb))) = (time(free), time(fixed)) {
            println!(
                "claim: {free} {a:.2} s (chatter-free {ca}) vs {fixed} {b:.2} s (chatter-free \
                 {cb}): {free} is {:+.1} % faster (the paper: >= 5 %, chatter-free)",
                100.0 * (b - a) / b
            );
        }
    }
}

/// Every fixed g* of `greedy_best_g` on the request: the greedy ramp's plan, timed as planned
/// and as executed (the duration of its trajectory, which ranks them).
fn candidates(planner: &MillPlanner, request: &MillRequest) {
    use kerf_budget::Budget;
    use kerf_millplan::greedy::fixed_g_candidates_within;
    let cell = planner
        .cell()
        .with_path(&request.path_spec(planner.cell().path().segments().len()))
        .unwrap();
    let all = fixed_g_candidates_within(
        &cell,
        request.initial_state(),
        kerf_millplan::plan::default_eval_threads(),
        planner.trajectory_settings(),
        &Budget::unlimited(),
    )
    .unwrap();
    println!();
    println!("| g* (rad) | chatter-free as planned | max \\|μ\\|max | time as planned (s) | trajectory duration (s) |");
    println!("|---:|---|---:|---:|---:|");
    let mut sorted: Vec<_> = all.iter().collect();
    sorted.sort_by(|a, b| a.g.total_cmp(&b.g));
    for r in sorted {
        println!(
            "| {:+.1} | {} | {:.4} | {:.3} | {} |",
            r.g,
            if r.chatter_free { "yes" } else { "no" },
            r.max_spectral_radius,
            r.machining_time,
            r.executed_time
                .map(|t| format!("{t:.3}"))
                .unwrap_or_else(|| "not executable".to_string())
        );
    }
    println!();
}

/// The DP with joint accelerations in its state (`DpSpec::joint_acceleration_limits`) on the
/// default request with the committed cache, evaluated directly and executed as the planner
/// would (`kerf_millplan::execute`): one more row of the table.
fn dp_with_accelerations(planner: &MillPlanner) {
    use kerf_millplan::dp::{self, DpSpec};
    use kerf_millplan::plan::{default_eval_threads, Plan};
    let cell = planner.cell();
    let cache = planner.cache().expect("the committed cache");
    let weights = planner.env_config().weights;
    for (name, accel) in [
        ("dp (same, via dp::solve)", false),
        ("dp, joint accelerations in the state", true),
    ] {
        let spec = DpSpec {
            joint_acceleration_limits: accel,
            ..DpSpec::full(cell, weights, false)
        };
        let start = Instant::now();
        let r = dp::solve(cell, cache, &spec).unwrap();
        let seconds = start.elapsed().as_secs_f64();
        let plan = Plan::evaluate(cell, &weights, &r.states, name).unwrap();
        let out = kerf_millplan::execute(cell, &plan, &weights, default_eval_threads()).unwrap();
        let g: Vec<f64> = plan.segments.iter().map(|s| s.g).collect();
        eprintln!(
            "{name}: DP {seconds:.1} s; planned {:.3} s (chatter-free {}, max |mu| {:.4}); \
             g in [{:+.2}, {:+.2}]; slowed {}",
            plan.total_time,
            plan.chatter_free,
            plan.max_spectral_radius,
            g.iter().copied().fold(f64::INFINITY, f64::min),
            g.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            out.scaling.slowed_segments()
        );
        println!("{}", row(name, &out, &format!("{seconds:.1} (DP)")));
    }
}

/// The DP with the executed timing in the loop (`kerf_millplan::dp_executed::solve_executed`), plain
/// and with joint accelerations in its state, on the default request with the committed cache:
/// every round (moves held, as planned, as executed) and the answered round as one more row.
fn dp_executed(planner: &MillPlanner) {
    use kerf_budget::Budget;
    use kerf_millplan::dp::DpSpec;
    use kerf_millplan::dp_executed::solve_executed;
    use kerf_millplan::plan::default_eval_threads;
    let cell = planner.cell();
    let cache = planner.cache().expect("the committed cache");
    let weights = planner.env_config().weights;
    for (name, accel) in [
        ("dp, executed timing in the loop", false),
        (
            "dp, accelerations in the state and executed timing in the loop",
            true,
        ),
    ] {
        let spec = DpSpec {
            joint_acceleration_limits: accel,
            ..DpSpec::full(cell, weights, false)
        };
        let start = Instant::now();
        let r = solve_executed(
            cell,
            cache,
            &spec,
            default_eval_threads(),
            &Budget::unlimited(),
        )
        .unwrap();
        let seconds = start.elapsed().as_secs_f64();
        for (k, round) in r.rounds.iter().enumerate() {
            let e = &round.executed.plan;
            eprintln!(
                "{name}, round {k}: {} moves held; planned {:.3} s, reward {:.3}; executed {:.3} s \
                 (chatter-free {}, max |mu| {:.4}), reward {:.3}, {} segments slowed",
                round.held.iter().filter(|h| **h).count(),
                round.plan.total_time,
                round.plan.total_reward,
                e.total_time,
                e.chatter_free,
                e.max_spectral_radius,
                e.total_reward,
                round.executed.scaling.slowed_segments()
            );
        }
        let best = r.best().unwrap();
        let name = format!(
            "{name} (round {} of {}; {:.2} s as planned)",
            r.best,
            r.rounds.len(),
            best.plan.total_time
        );
        println!(
            "{}",
            row(&name, &best.executed, &format!("{seconds:.1} (all rounds)"))
        );
    }
}

/// One row of the as-executed table: the plan the robot runs (`Executed`), its name and its
/// planning time as text.
fn row(name: &str, executed: &kerf_millplan::Executed, planning: &str) -> String {
    let e = &executed.plan;
    let d = &executed.scaling.deviation;
    format!(
        "| {name} | {:.2} | {} | {:.4} | {:.3} / {:.3} | {:.3} / {:.3} | {:.3} | {planning} |",
        e.total_time,
        if e.chatter_free { "yes" } else { "no" },
        e.max_spectral_radius,
        e.min_condition_indicator,
        executed.scaling.min_condition_indicator.0,
        d.max_off_path * 1e3,
        d.max_off_plane * 1e3,
        e.total_reward
    )
}
