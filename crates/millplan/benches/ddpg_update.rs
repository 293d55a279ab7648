//! Cost of DDPG (issue 5 figures): one update with seed 004 Table 2's
//! sizes — batch 64, actor and critic 2×256 — with the milling environment's
//! observation (37 path-independent entries, `kerf_millplan::observation`) and
//! 3 actions — and the training time it implies for
//! 1000 episodes × 100 steps (issue goal: ≤ 5 min on the 2-core machine).
//!
//! * `ddpg update, tuned`: under [`CpuTuning`] (one thread, FTZ/DAZ,
//!   raised mmap threshold), as `train` runs. For comparison, a child
//!   process times the same update with candle as it comes (its thread
//!   count, no flush-to-zero, glibc's default malloc thresholds): the tuning
//!   cannot be undone within one process.
//! * `ddpg actor forward (candle, 1 row)`: the per-step action of training.
//! * `policy: 100 actions (plain forward)`: a 100-step greedy rollout's
//!   actor cost with the saved policy.
//!
//! Besides criterion's numbers, a plain timing of 300 updates prints the
//! estimated training time: 100 000 × (update + candle action), without the
//! environment's own step cost (see `examples/ddpg_mill_smoke.rs`), from the
//! wall time and from the thread's CPU time (Linux `clock_gettime`; the
//! wall time on the shared 2-core machine includes waiting for other
//! jobs).
//!
//! Run: `cargo bench -p kerf_millplan --bench ddpg_update -- --quick`.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::hint::black_box;
use std::time::Instant;

use criterion::{criterion_group, Criterion};
use kerf_millplan::ddpg::{train, update_benchmark, DdpgSettings};
use kerf_millplan::nets::CpuTuning;
use kerf_millplan::policy::Policy;
use kerf_millplan::{Environment, MillPlanError, Transition};

const OBS: usize = kerf_millplan::observation::OBSERVATION_DIM;
const ACT: usize = 3;

#[allow(dead_code)] // each bench uses some of the shared helpers
mod common;
use common::thread_cpu_time;

/// Mean wall seconds and mean thread-CPU seconds per update over `n`
/// updates after 20 warm-up updates.
fn time_updates(
    update: &mut dyn FnMut() -> Result<(), MillPlanError>,
    n: usize,
) -> (f64, Option<f64>) {
    for _ in 0..20 {
        update().expect("update");
    }
    let cpu0 = thread_cpu_time();
    let start = Instant::now();
    for _ in 0..n {
        update().expect("update");
    }
    let wall = start.elapsed().as_secs_f64() / n as f64;
    let cpu = cpu0.zip(thread_cpu_time()).map(|(a, b)| (b - a) / n as f64);
    (wall, cpu)
}

/// An OBS-observation, 3-action environment with trivial dynamics, to get a
/// trained (one update) agent of the right sizes.
struct Dummy {
    t: usize,
}

impl Environment for Dummy {
    fn observation_dim(&self) -> usize {
        OBS
    }
    fn action_dim(&self) -> usize {
        ACT
    }
    fn max_steps(&self) -> usize {
        100
    }
    fn reset(&mut self) -> Result<Vec<f32>, MillPlanError> {
        self.t = 0;
        Ok(vec![0.0; OBS])
    }
    fn step(&mut self, action: &[f32]) -> Result<Transition, MillPlanError> {
        self.t += 1;
        let x = self.t as f32 / 100.0;
        Ok(Transition {
            observation: (0..OBS)
                .map(|k| match k {
                    0 => x,
                    1..=3 => action[k - 1],
                    _ => 0.0,
                })
                .collect(),
            reward: f64::from(-x * x),
            done: false,
        })
    }
}

/// Environment variable that makes the bench binary time the untuned
/// update in a child process and print the mean seconds.
const CHILD: &str = "KERF_DDPG_BENCH_UNTUNED_CHILD";

/// Mean seconds per update with candle's default CPU settings, measured in
/// a fresh child process (the tuning of this process cannot be undone:
/// candle's element-wise pool keeps the size it was created with).
fn untuned_in_child() -> Option<f64> {
    let exe = std::env::current_exe().ok()?;
    let out = std::process::Command::new(exe)
        .env(CHILD, "1")
        .env_remove("RAYON_NUM_THREADS")
        .output()
        .ok()?;
    String::from_utf8_lossy(&out.stdout).trim().parse().ok()
}

fn bench(c: &mut Criterion) {
    let settings = DdpgSettings::default();
    let user_threads = std::env::var("RAYON_NUM_THREADS").ok();
    let untuned = untuned_in_child();

    let tuning = CpuTuning::apply(true);
    eprintln!(
        "CPU tuning: {:?} (RAYON_NUM_THREADS before: {user_threads:?})",
        tuning.report()
    );
    let mut update = update_benchmark(OBS, ACT, &settings).expect("setup");
    let (tuned, tuned_cpu) = time_updates(&mut update, 300);
    c.bench_function("ddpg update, tuned", |b| {
        b.iter(|| update().expect("update"))
    });

    // An agent of the right sizes for the per-step action costs.
    let mut env = Dummy { t: 0 };
    let small = settings
        .clone()
        .with_episodes(1)
        .with_steps_per_episode(2)
        .with_batch_size(1);
    let agent = train(&mut env, &small, &mut |_| {}).expect("train");
    let obs: Vec<f32> = (0..OBS).map(|k| 0.1 * (k % 5) as f32 - 0.2).collect();
    let start = Instant::now();
    for _ in 0..1000 {
        black_box(agent.act(black_box(&obs)).expect("act"));
    }
    let act = start.elapsed().as_secs_f64() / 1000.0;
    c.bench_function("ddpg actor forward (candle, 1 row)", |b| {
        b.iter(|| agent.act(black_box(&obs)).expect("act"))
    });
    let policy = Policy::from_agent(&agent, "dummy").expect("policy");
    c.bench_function("policy: 100 actions (plain forward)", |b| {
        b.iter(|| {
            for _ in 0..100 {
                black_box(policy.act(black_box(&obs)).expect("act"));
            }
        })
    });
    drop(tuning);

    let steps = 1000.0 * 100.0;
    match untuned {
        Some(u) => eprintln!(
            "one update (batch 64, 2×256): {:.3} ms tuned, {:.3} ms with candle's defaults \
             ({:.2}× faster tuned); candle action {:.1} µs",
            tuned * 1e3,
            u * 1e3,
            u / tuned,
            act * 1e6
        ),
        None => eprintln!(
            "one update (batch 64, 2×256): {:.3} ms tuned (untuned child failed); \
             candle action {:.1} µs",
            tuned * 1e3,
            act * 1e6
        ),
    }
    eprintln!(
        "estimated 1000 × 100 training time without environment steps: {:.0} s tuned \
         ({:.1} min; goal ≤ 5 min)",
        steps * (tuned + act),
        steps * (tuned + act) / 60.0,
    );
    if let Some(cpu) = tuned_cpu {
        eprintln!(
            "thread CPU time per update {:.3} ms (wall {:.3} ms): {:.0} s ({:.1} min) for \
             1000 × 100 updates on an idle core",
            cpu * 1e3,
            tuned * 1e3,
            steps * (cpu + act),
            steps * (cpu + act) / 60.0
        );
    }
}

criterion_group!(benches, bench);

fn main() {
    if std::env::var_os(CHILD).is_some() {
        let settings = DdpgSettings::default();
        let mut update = update_benchmark(OBS, ACT, &settings).expect("setup");
        println!("{}", time_updates(&mut update, 200).0);
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
