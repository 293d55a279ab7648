//! Trains the committed DDQN weights of seed 002 and measures them.
//!
//! ```text
//! cargo run -p kerf_stepping --release --example train_ddqn
//! ```
//!
//! High density, 15 points, training pair 0 (paths 0 and 1, 120 processes;
//! section 3), architecture 2 (3-24-24-3 tanh), learning rate 10⁻³,
//! γ = 0.99, the Table 3 hyper-parameters (episodes start at a uniformly
//! drawn step of RPRO's recorded run, module `ddqn::env`), seed [`SEED`]. Writes
//! `crates/stepping/weights/ddqn_high_arch2.safetensors`, then prints the
//! training time and the Tables 4–6 measures on the 480 test processes
//! (raw agent in closed loop with paper-style and at-rest completion, RPRO,
//! and the shielded agent).
//!
//! Options: `--episodes N` (default 500), `--seed S`, `--out PATH`,
//! `--no-save` (measure only), `--load PATH` (measure a saved network, no
//! training).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;
use std::time::Instant;

use kerf_stepping::{
    database::{self, Density},
    ddqn::{self, metrics, train::EpisodeEnd, Architecture, DdqnSettings},
    RproSettings,
};

/// The seed of the committed weights.
const SEED: u64 = 2;

fn main() {
    // Small matrices: one rayon thread is faster (kerf_millplan's CpuTuning).
    std::env::set_var("RAYON_NUM_THREADS", "1");
    let args: Vec<String> = std::env::args().skip(1).collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1).cloned())
    };
    let episodes: usize = value("--episodes").map_or(500, |v| v.parse().expect("--episodes N"));
    let seed: u64 = value("--seed").map_or(SEED, |v| v.parse().expect("--seed S"));
    let out = value("--out").map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("weights/ddqn_high_arch2.safetensors"),
        PathBuf::from,
    );
    let load = value("--load").map(PathBuf::from);
    let save = !args.iter().any(|a| a == "--no-save") && load.is_none();

    let subset = database::subset(15, Density::High);
    let (train_set, test_set) = database::split(&subset, 0);
    let train_courses = ddqn::courses(&train_set).unwrap();
    let test_courses = ddqn::courses(&test_set).unwrap();
    let settings = DdqnSettings::default()
        .architecture(Architecture::new(2).unwrap())
        .learning_rate(1e-3)
        .discount(0.99)
        .max_episodes(episodes)
        .seed(seed);

    let t0 = Instant::now();
    if let Some(path) = &load {
        let agent = ddqn::Agent::load(path).unwrap();
        println!("loaded {} ({:?})", path.display(), agent.info());
        measure(&agent, &test_set, &test_courses, t0);
        return;
    }
    let mut completed = 0usize;
    let trained = ddqn::train::train_observed(&settings, &train_courses, &mut |r| {
        completed += usize::from(r.end == EpisodeEnd::Completed);
        if (r.episode + 1) % 50 == 0 {
            println!(
                "episode {:4} (replay of RPRO's run from step {:3}): steps {:3}, matches {:3}, \
                 reward {:7.2}, ε {:.3}, {:?} (completed so far {completed})",
                r.episode + 1,
                r.start,
                r.steps,
                r.matches,
                r.reward,
                r.epsilon,
                r.end
            );
        }
    })
    .unwrap();
    let train_time = t0.elapsed().as_secs_f64();
    println!(
        "trained {} episodes ({} gradient steps) in {train_time:.1} s",
        trained.history.len(),
        trained.learning_steps
    );
    if save {
        let mut agent = trained.agent.clone();
        let mut info = agent.info().clone();
        info.insert("density".into(), "high".into());
        info.insert("points".into(), "15".into());
        info.insert("pair".into(), "0".into());
        info.insert(
            "command".into(),
            "cargo run -p kerf_stepping --release --example train_ddqn".into(),
        );
        agent = ddqn::Agent::new(agent.weights().clone(), info).unwrap();
        agent.save(&out).unwrap();
        println!("wrote {}", out.display());
    }
    measure(&trained.agent, &test_set, &test_courses, t0);
}

/// Prints the Tables 4–6 measures of `agent` on the test processes.
fn measure(
    agent: &ddqn::Agent,
    test_set: &[&database::Process],
    test_courses: &[kerf_stepping::Course],
    t0: Instant,
) {
    let t1 = Instant::now();
    let rpro = metrics::baseline(test_courses, RproSettings::default(), 1_000_000);
    for (k, r) in rpro.iter().enumerate() {
        if let Err(e) = r {
            let p = test_set[k];
            println!(
                "RPRO fails on test process path {} limits #{} ({:?}): {e}",
                p.path, p.limits_index, p.limits
            );
        }
    }
    let e = metrics::evaluate(agent, test_courses, &rpro, Some(RproSettings::default())).unwrap();
    println!("evaluated in {:.1} s", t1.elapsed().as_secs_f64());
    let f = |x: Option<f64>, d: usize| x.map_or("---".to_string(), |v| format!("{v:.d$}"));
    println!(
        "raw agent, paper-style completion (every point within the precision, steps to the \
         last point's pass): completed {}/{}, steps correlation r = {}, median steps {} (RPRO \
         to its last pass on the same processes: {}), median mean error {} µm (those runs)",
        e.paper_completed,
        e.processes,
        f(e.paper_correlation, 3),
        f(e.paper_median_steps, 1),
        f(e.rpro_paper_median_steps_completed, 1),
        f(e.paper_median_error_um, 2),
    );
    println!(
        "raw agent, completion at rest on the last point: completed {}/{}, capped {}, steps \
         correlation r = {}, median mean error {} µm (all runs), points passed {:.1} %, median \
         steps {} (RPRO on the same processes: {}), limit substitutions {} of {} decisions in \
         {} runs",
        e.completed,
        e.processes,
        e.capped,
        f(e.correlation, 3),
        f(e.median_error_um, 2),
        100.0 * e.passed_share,
        f(e.median_steps, 1),
        f(e.rpro_median_steps_completed, 1),
        e.substitutions,
        e.decisions,
        e.substituted_runs
    );
    println!(
        "RPRO: completed {}/{}, median mean error {} µm, median steps {} (to its last pass: {})",
        e.rpro_completed,
        e.processes,
        f(e.rpro_median_error_um, 2),
        f(e.rpro_median_steps, 1),
        f(e.rpro_paper_median_steps, 1)
    );
    if let Some(s) = &e.shielded {
        println!(
            "shielded agent: completed {}/{}, capped {}, r = {}, median mean error {} µm, median \
             steps {}, overrides {:.1} % of decisions",
            s.completed,
            e.processes,
            s.capped,
            f(s.correlation, 3),
            f(s.median_error_um, 2),
            f(s.median_steps, 1),
            100.0 * s.override_fraction
        );
    }
    println!("total {:.1} s", t0.elapsed().as_secs_f64());
}
