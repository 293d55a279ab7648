//! Planning latency of the milling planner (issue 5 figure: "planning one
//! 100-segment path with the trained policy, IK and trajectory included:
//! goal ≤ 50 ms"): [`MillPlanner::plan`] on the default 100-segment
//! request, for the `naive` and `ddpg` planners, with the plan evaluation
//! (direct |μ|max of every segment, the dominant cost) on one thread and on
//! the default number of threads ([`default_eval_threads`]).
//!
//! * The `ddpg` policy is `crates/millplan/policies/ddpg.safetensors` when
//!   it exists and plans the default request; otherwise a policy is
//!   trained here for 5 episodes (Table 2 settings, the first seed from 1
//!   whose rollout stays feasible) and the output says so — its rollout
//!   costs the same as the shipped policy's (same network sizes), its plan
//!   differs.
//! * Before criterion's numbers, each configuration is planned 5 times and
//!   the mean wall time of each step ([`MillPlanOutput::phases`]: setup =
//!   validation, request cell and reachability; planner = rollout or naive
//!   search; evaluation; trajectory) is printed, with the process CPU time
//!   per plan (Linux `clock_gettime`): on the shared 2-core machine the
//!   wall time includes waiting for other jobs, the CPU time does not (for
//!   several threads it is their sum). The load average is printed too.
//! * The plans of 1 and of the default number of threads are checked to be
//!   identical (bit for bit) before timing.
//! * The evaluation step alone, 1 and the default number of threads
//!   alternately (10 rounds; median wall, mean CPU), for a speed-up that
//!   both sides measure under the same load.
//! * A third configuration plans with [`IndicatorSource::Cache`]: |μ|max
//!   interpolated from the indicator cache where it applies, with its
//!   stated bound in the answer (printed): NOT the direct evaluation.
//!
//! Run (small sample counts, the machine is shared):
//! `cargo bench -p kerf_millplan --bench plan_latency -- --warm-up-time 1 --measurement-time 5`
//! (`KERF_BENCH_PLANNERS=ddpg` in the environment: that planner only).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::path::PathBuf;
use std::time::Instant;

use criterion::{criterion_group, Criterion};
use kerf_millplan::cache::cell_fingerprint;
use kerf_millplan::plan::{default_eval_threads, IndicatorSource, Plan};
use kerf_millplan::planner::PlanningPhases;
use kerf_millplan::{
    default_policy_path, execute, train, DdpgSettings, EnvConfig, MillEnv, MillPlanError,
    MillPlanOutput, MillPlanner, MillRequest, PlannerKind, Policy,
};

#[allow(dead_code)] // each bench uses some of the shared helpers
mod common;
use common::process_cpu_time;

/// The 1-minute load average (Linux), for reading the wall times.
fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().map(str::to_string))
        .unwrap_or_else(|| "unknown".to_string())
}

/// The shipped ddpg policy when its greedy rollout stays feasible on the
/// current model, else one trained here for 5 episodes (seeds 1, 2, …
/// until its greedy rollout stays feasible, at most 6 seeds), and a
/// sentence saying which.
fn ddpg_policy(planner: &MillPlanner) -> Result<(PathBuf, String), MillPlanError> {
    let mut shipped_note = String::new();
    if let Some(p) = default_policy_path(PlannerKind::Ddpg).filter(|p| p.exists()) {
        let request = MillRequest {
            planner: "ddpg".to_string(),
            policy_file: Some(p.display().to_string()),
            ..MillRequest::default()
        };
        match planner.plan(&request) {
            Ok(_) => {
                let note = format!("the shipped policy {}", p.display());
                return Ok((p, note));
            }
            Err(e) => {
                eprintln!(
                    "ddpg policy: the shipped policy {} is rejected: {e}",
                    p.display()
                );
                shipped_note = format!(
                    "the shipped policy {} is rejected by this model; ",
                    p.display()
                );
            }
        }
    }
    let dir = std::env::temp_dir().join(format!("kerf_plan_latency_{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| MillPlanError::Io {
        path: dir.display().to_string(),
        message: e.to_string(),
    })?;
    let mut last = None;
    for seed in 1..=6u64 {
        let mut env = MillEnv::new(
            planner.cell().clone(),
            planner.cache().cloned(),
            EnvConfig::default(),
        )?;
        let settings = DdpgSettings::default().with_episodes(5).with_seed(seed);
        let start = Instant::now();
        let agent = train(&mut env, &settings, &mut |_| {})?;
        let mut policy = Policy::from_agent(&agent, "plan_latency bench: 5 episodes")?;
        let path = dir.join(format!("ddpg_seed{seed}.safetensors"));
        policy.save(&path)?;
        let request = MillRequest {
            planner: "ddpg".to_string(),
            policy_file: Some(path.display().to_string()),
            ..MillRequest::default()
        };
        match planner.plan(&request) {
            Ok(_) => {
                let note = format!(
                    "{shipped_note}NOT the shipped policy: a policy trained in this bench for 5 \
                     episodes (seed {seed}, 2×256, {:.1} s) — same network sizes as the shipped \
                     one, so the same rollout cost; its plan differs",
                    start.elapsed().as_secs_f64()
                );
                return Ok((path, note));
            }
            Err(e) => {
                eprintln!("ddpg policy of seed {seed} (5 episodes) rejected: {e}");
                last = Some(e);
            }
        }
    }
    Err(last.unwrap_or_else(|| MillPlanError::InvalidConfig {
        name: "bench policy".to_string(),
        reason: "no seed tried".to_string(),
    }))
}

/// Plans `request` `n` times; prints the mean phases, wall and CPU time.
fn report(name: &str, planner: &MillPlanner, request: &MillRequest, n: usize) -> Option<f64> {
    let mut sum = PlanningPhases::default();
    let mut total = 0.0;
    let cpu0 = process_cpu_time();
    for _ in 0..n {
        let out = match planner.plan(request) {
            Ok(o) => o,
            Err(e) => {
                eprintln!("{name}: plan failed: {e}");
                return None;
            }
        };
        let p = out.phases;
        sum.setup += p.setup;
        sum.planner += p.planner;
        sum.evaluation += p.evaluation;
        sum.trajectory += p.trajectory;
        total += out.planning_seconds;
    }
    let cpu = cpu0
        .zip(process_cpu_time())
        .map(|(a, b)| format!("{:.1} ms", (b - a) / n as f64 * 1e3))
        .unwrap_or_else(|| "unknown".to_string());
    let k = 1e3 / n as f64;
    eprintln!(
        "{name}: {:.1} ms per plan (mean of {n}; process CPU {cpu}) = setup {:.2} + planner {:.2} \
         + evaluation {:.1} + trajectory {:.2} ms",
        total * k,
        sum.setup * k,
        sum.planner * k,
        sum.evaluation * k,
        sum.trajectory * k
    );
    Some(total / n as f64)
}

/// Mean wall ms of the parts of the setup step (validation, request cell,
/// reachability) for the default request, from the public APIs the planner
/// calls: the request's path ([`kerf_mill::MillCell::with_path`], B-spline
/// fit and arc-length segments), the cell fingerprint (cache
/// applicability), and 100 cell states (IK, Jacobian, K, tool-tip
/// dynamics: what the reachability check costs when g0 is feasible
/// everywhere). One cell state is also what the evaluation step pays per
/// segment besides the indicator.
fn setup_parts(planner: &MillPlanner, n: usize) {
    let cell = planner.cell();
    let segments = cell.path().segments().len();
    let spec = MillRequest::default().path_spec(segments);
    let start = Instant::now();
    for _ in 0..n {
        if let Err(e) = cell.with_path(&spec) {
            eprintln!("setup parts: with_path failed: {e}");
            return;
        }
    }
    let with_path = start.elapsed().as_secs_f64() / n as f64;
    let start = Instant::now();
    for _ in 0..n {
        if let Err(e) = cell.with_state_limits(*cell.state_limits()) {
            eprintln!("setup parts: with_state_limits failed: {e}");
            return;
        }
    }
    let with_limits = start.elapsed().as_secs_f64() / n as f64;
    let start = Instant::now();
    for _ in 0..n {
        std::hint::black_box(cell_fingerprint(cell));
    }
    let fingerprint = start.elapsed().as_secs_f64() / n as f64;
    let start = Instant::now();
    for _ in 0..n {
        for i in 0..segments {
            std::hint::black_box(cell.evaluate(i, 0.0, None).ok());
        }
    }
    let states = start.elapsed().as_secs_f64() / n as f64;
    eprintln!(
        "setup parts (mean of {n}): request path (with_path) {:.2} ms, cell clone \
         (with_state_limits) {:.2} ms, cell fingerprint {:.2} ms, {segments} cell states (IK, J, \
         K, dynamics) {:.2} ms",
        with_path * 1e3,
        with_limits * 1e3,
        fingerprint * 1e3,
        states * 1e3
    );
}

/// The evaluation step alone ([`Plan::evaluate_with_threads`]) on the
/// states of `out`, 1 thread and `threads` alternately (`rounds` each, so
/// that both see the same changes of the machine's load): median wall ms
/// and mean process-CPU ms of each.
fn evaluation_ab(planner: &MillPlanner, out: &MillPlanOutput, threads: usize, rounds: usize) {
    let states = out.plan.states();
    let weights = planner.env_config().weights;
    let cell = planner.cell();
    let mut wall = [Vec::new(), Vec::new()];
    let mut cpu = [0.0, 0.0];
    for _ in 0..rounds {
        for (k, t) in [1, threads].into_iter().enumerate() {
            let c0 = process_cpu_time();
            let start = Instant::now();
            if let Err(e) = Plan::evaluate_with_threads(cell, &weights, &states, "ab", t) {
                eprintln!("evaluation A/B failed: {e}");
                return;
            }
            wall[k].push(start.elapsed().as_secs_f64());
            if let Some(d) = c0.zip(process_cpu_time()).map(|(a, b)| b - a) {
                cpu[k] += d;
            }
        }
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (w1, wn) = (median(&mut wall[0]), median(&mut wall[1]));
    eprintln!(
        "evaluation step alone, {rounds} alternating rounds: 1 thread median {:.1} ms (CPU {:.1} \
         ms), {threads} threads median {:.1} ms (CPU {:.1} ms): {:.2}x; load average {}",
        w1 * 1e3,
        cpu[0] / rounds as f64 * 1e3,
        wn * 1e3,
        cpu[1] / rounds as f64 * 1e3,
        w1 / wn,
        load_average()
    );
}

/// Plans `request` with 1 thread and with `threads`; `true` when both
/// succeed with identical plans and trajectories.
fn same_plan(one: &MillPlanner, many: &MillPlanner, request: &MillRequest) -> bool {
    match (one.plan(request), many.plan(request)) {
        (Ok(a), Ok(b)) => identical(&a, &b),
        (a, b) => {
            eprintln!("plan failed: 1 thread {:?}, several {:?}", a.err(), b.err());
            false
        }
    }
}

/// Whether the planner's answer (its steps 5–7 overlapped on threads) is the
/// sequential route's, bit for bit: the plan of [`Plan::evaluate_with_threads`]
/// on 1 thread from the same states, and what [`execute`] (time scaling, then
/// the re-evaluation of the slowed segments, 1 thread) makes of it. Only for a
/// direct |μ|max answer (the cache source takes other values).
fn same_as_sequential(planner: &MillPlanner, request: &MillRequest) -> bool {
    let out = match planner.plan(request) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("plan failed: {e}");
            return false;
        }
    };
    let cell = planner.cell();
    let weights = planner.env_config().weights;
    let states = out.plan.states();
    let sequential = Plan::evaluate_with_threads(cell, &weights, &states, &out.plan.planner, 1)
        .and_then(|plan| execute(cell, &plan, &weights, 1).map(|e| (plan, e)));
    match sequential {
        Ok((plan, executed)) => {
            let bits = |p: &Plan| -> Vec<u64> {
                p.segments
                    .iter()
                    .flat_map(|s| [s.spectral_radius, s.reward.total, s.time, s.feed])
                    .map(f64::to_bits)
                    .collect()
            };
            plan == out.plan
                && bits(&plan) == bits(&out.plan)
                && executed.plan == out.executed.plan
                && bits(&executed.plan) == bits(&out.executed.plan)
                && executed.scaling == out.executed.scaling
                && executed.cached_segments == out.executed.cached_segments
        }
        Err(e) => {
            eprintln!("sequential route failed: {e}");
            false
        }
    }
}

/// Bit-for-bit equality of the plan and the trajectory (timings aside).
fn identical(a: &MillPlanOutput, b: &MillPlanOutput) -> bool {
    let bits = |o: &MillPlanOutput| -> Vec<u64> {
        o.plan
            .segments
            .iter()
            .flat_map(|s| {
                [
                    s.spectral_radius,
                    s.reward.total,
                    s.condition_number,
                    s.time,
                ]
            })
            .chain(
                o.trajectory
                    .points()
                    .iter()
                    .flat_map(|p| p.positions.iter().copied()),
            )
            .map(f64::to_bits)
            .collect()
    };
    a.plan == b.plan && a.trajectory == b.trajectory && bits(a) == bits(b)
}

fn bench(c: &mut Criterion) {
    let threads = default_eval_threads();
    let one = match MillPlanner::with_default_cell().and_then(|p| p.with_eval_threads(1)) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("plan_latency: no planner: {e}");
            return;
        }
    };
    let many = match MillPlanner::with_default_cell().and_then(|p| p.with_eval_threads(threads)) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("plan_latency: no planner: {e}");
            return;
        }
    };
    eprintln!(
        "plan_latency: default request, {} segments, indicator cache {}, {threads} evaluation \
         threads by default, load average {}",
        many.cell().path().segments().len(),
        if many.cache().is_some() {
            "loaded"
        } else {
            "NOT loaded (naive fails; ddpg's rollout evaluates directly)"
        },
        load_average()
    );
    let mut requests = vec![(
        "naive".to_string(),
        MillRequest {
            planner: "naive".to_string(),
            ..MillRequest::default()
        },
    )];
    match ddpg_policy(&many) {
        Ok((path, note)) => {
            eprintln!("ddpg policy: {note}");
            requests.push((
                "ddpg".to_string(),
                MillRequest {
                    planner: "ddpg".to_string(),
                    policy_file: Some(path.display().to_string()),
                    ..MillRequest::default()
                },
            ));
        }
        Err(e) => eprintln!("ddpg policy: none ({e}); ddpg not benchmarked"),
    }
    let cached = match MillPlanner::with_default_cell().and_then(|p| p.with_eval_threads(threads)) {
        Ok(p) => p.with_indicator_source(IndicatorSource::Cache),
        Err(e) => {
            eprintln!("plan_latency: no planner: {e}");
            return;
        }
    };
    setup_parts(&many, 5);
    let planners: [(&MillPlanner, String); 3] = [
        (&one, "1 evaluation thread, direct |mu|".to_string()),
        (&many, format!("{threads} evaluation threads, direct |mu|")),
        (
            &cached,
            "cache source (|mu| interpolated, bound reported)".to_string(),
        ),
    ];
    // KERF_BENCH_PLANNERS=ddpg runs only those (a short run for a quiet moment of the machine).
    let only = std::env::var("KERF_BENCH_PLANNERS").ok();
    for (name, request) in &requests {
        if only
            .as_deref()
            .is_some_and(|o| !o.split(',').any(|x| x == name))
        {
            continue;
        }
        if !same_plan(&one, &many, request) {
            eprintln!("{name}: 1-thread and {threads}-thread plans differ or failed; skipped");
            continue;
        }
        let sequential = same_as_sequential(&many, request);
        eprintln!(
            "{name}: the {threads}-thread plan and executed plan {} the sequential route's (bit \
             for bit)",
            if sequential { "are" } else { "are NOT" }
        );
        if let Ok(out) = many.plan(request) {
            evaluation_ab(&many, &out, threads, 10);
        }
        for (planner, what) in &planners {
            let label = format!("plan {name}, {what}");
            if report(&label, planner, request, 5).is_none() {
                continue;
            }
            if let Ok(out) = planner.plan(request) {
                eprintln!("  {}", out.indicator.note);
            }
            c.bench_function(&label, |b| {
                b.iter(|| planner.plan(request).expect("plan"));
            });
        }
    }
    eprintln!("load average after: {}", load_average());
}

criterion_group! {
    name = benches;
    // Few samples: one plan takes 0.1-0.5 s and the machine is shared.
    config = Criterion::default().sample_size(10);
    targets = bench
}

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}
