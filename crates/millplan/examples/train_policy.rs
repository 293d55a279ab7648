//! Trains the DDPG policy of the milling planner (seed 004 Algorithm 1, Table 2
//! settings) on a distribution of planar paths (issue 13, item 4:
//! [`kerf_millplan::path_distribution`]) with the path-independent observation
//! ([`kerf_millplan::observation`]), and saves it with its settings sidecar (the
//! observation layout included) and its training history: the committed policies
//! are produced by exactly these commands.
//!
//! ```sh
//! RAYON_NUM_THREADS=1 cargo run --release -p kerf_millplan --example train_policy            # policies/ddpg.safetensors
//! RAYON_NUM_THREADS=1 cargo run --release -p kerf_millplan --example train_policy -- --fixed-g # policies/fixed_g.safetensors
//! ```
//!
//! Options: `--episodes N` (default 1000), `--seed S` (default 1),
//! `--paths P` (training paths drawn besides the default path, default 47: seeds
//! `TRAINING_SEED..TRAINING_SEED + P`; with `--fixed-g` only those feasible at g = 0
//! on every segment are kept), `--acceleration-penalty W`
//! ([`kerf_millplan::EnvConfig::acceleration_penalty`], default 3: with 1, the weight of the
//! policy trained on the default path alone, the first policy trained on the distribution moved
//! g fast enough that 72–100 of the 101 intervals of held-out paths had to be slowed as
//! executed, up to 2.7× the planned time),
//! `--min-condition C` ([`kerf_millplan::EnvConfig::min_condition_indicator`],
//! default 0.35; `none` switches the constraint off: the paper's environment),
//! `--shield L` ([`kerf_millplan::EnvConfig::chatter_shield`] during training, default none:
//! the committed policies were trained without it; the planner shields at plan time either way),
//! `--out FILE` (default `crates/millplan/policies/{ddpg,fixed_g}.safetensors`).
//! Writes FILE, its JSON sidecar and `FILE` with `.history.json` (one
//! [`kerf_millplan::ddpg::EpisodeReport`] per episode, for seed 004 Fig. 5),
//! and prints the greedy plan of the default path evaluated directly.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::path::PathBuf;
use std::sync::Arc;

use kerf_mill::MillCell;
use kerf_millplan::ddpg::{train, DdpgSettings};
use kerf_millplan::env::{EnvConfig, MillEnv};
use kerf_millplan::path_distribution::{
    training_paths, PathDistribution, PathSetEnv, TRAINING_SEED,
};
use kerf_millplan::plan::{comparison_table, Plan};
use kerf_millplan::policy::Policy;
use kerf_millplan::MillPlanError;

/// Default weight of the joint-acceleration shaping (module documentation).
const DEFAULT_ACCELERATION_PENALTY: f64 = 3.0;

fn value<T: std::str::FromStr>(args: &[String], name: &str) -> Result<Option<T>, MillPlanError> {
    match args.iter().position(|a| a == name) {
        None => Ok(None),
        Some(i) => args
            .get(i + 1)
            .and_then(|v| v.parse().ok())
            .map(Some)
            .ok_or_else(|| MillPlanError::InvalidConfig {
                name: name.to_string(),
                reason: "needs a valid value".to_string(),
            }),
    }
}

fn main() -> Result<(), MillPlanError> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let fixed_g = args.iter().any(|a| a == "--fixed-g");
    let episodes: usize = value(&args, "--episodes")?.unwrap_or(1000);
    let seed: u64 = value(&args, "--seed")?.unwrap_or(1);
    let acceleration_penalty: f64 =
        value(&args, "--acceleration-penalty")?.unwrap_or(DEFAULT_ACCELERATION_PENALTY);
    let paths: usize = value(&args, "--paths")?.unwrap_or(47);
    let shield: Option<f64> = value(&args, "--shield")?;
    let min_condition: Option<f64> = match value::<String>(&args, "--min-condition")? {
        None => Some(kerf_millplan::env_config::DEFAULT_MIN_CONDITION_INDICATOR),
        Some(v) if v == "none" => None,
        Some(v) => Some(v.parse().map_err(|_| MillPlanError::InvalidConfig {
            name: "--min-condition".to_string(),
            reason: format!("{v} is not a number or none"),
        })?),
    };
    let out: PathBuf = value::<String>(&args, "--out")?
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(if fixed_g {
                "policies/fixed_g.safetensors"
            } else {
                "policies/ddpg.safetensors"
            })
        });
    let base = Arc::new(MillCell::default_cell()?);
    let config = EnvConfig {
        fixed_g,
        acceleration_penalty: Some(acceleration_penalty),
        min_condition_indicator: min_condition,
        chatter_shield: shield,
        ..EnvConfig::default()
    };
    let started = std::time::Instant::now();
    let dist = PathDistribution::default();
    let mut cells = vec![base.clone()];
    for p in training_paths(&base, &dist, paths)? {
        if fixed_g && !feasible_at_g0(&p.cell, config.initial_g) {
            continue;
        }
        cells.push(p.cell);
    }
    eprintln!(
        "{} training paths (the default one and {} drawn, seeds {TRAINING_SEED}..{}) in {:.1} s",
        cells.len(),
        cells.len() - 1,
        TRAINING_SEED + paths as u64,
        started.elapsed().as_secs_f64()
    );
    let mut env = PathSetEnv::new(&cells, config)?;
    let settings = DdpgSettings::default()
        .with_episodes(episodes)
        .with_seed(seed);
    let agent = train(&mut env, &settings, &mut |r| {
        if r.episode % 25 == 0 || r.episode == r.episodes {
            eprintln!(
                "episode {:>4}/{}: reward {:>9.3}, σ {:.4}, {:.0} s elapsed, {:.0} s left",
                r.episode, r.episodes, r.total_reward, r.noise_std, r.elapsed_s, r.remaining_s
            );
        }
    })?;
    let mut flags = String::new();
    if fixed_g {
        flags.push_str(" --fixed-g");
    }
    if episodes != 1000 {
        flags.push_str(&format!(" --episodes {episodes}"));
    }
    if seed != 1 {
        flags.push_str(&format!(" --seed {seed}"));
    }
    if paths != 47 {
        flags.push_str(&format!(" --paths {paths}"));
    }
    if acceleration_penalty != DEFAULT_ACCELERATION_PENALTY {
        flags.push_str(&format!(" --acceleration-penalty {acceleration_penalty}"));
    }
    if let Some(l) = shield {
        flags.push_str(&format!(" --shield {l}"));
    }
    match min_condition {
        None => flags.push_str(" --min-condition none"),
        Some(c) if c != kerf_millplan::env_config::DEFAULT_MIN_CONDITION_INDICATOR => {
            flags.push_str(&format!(" --min-condition {c}"))
        }
        Some(_) => {}
    }
    let environment = format!(
        "default cell (urdf/irb6660_milling.yaml) with {} paths: the default path and the \
         accepted draws of kerf_millplan::path_distribution (PathDistribution::default(), seeds \
         {TRAINING_SEED}..{}), direct |mu|max, round robin; {config:?}; trained by `cargo run \
         --release -p kerf_millplan --example train_policy --{flags}` in {:.0} s",
        cells.len(),
        TRAINING_SEED + paths as u64,
        started.elapsed().as_secs_f64()
    );
    let mut policy = Policy::from_agent(&agent, &environment)?;
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir).map_err(|e| MillPlanError::Io {
            path: dir.display().to_string(),
            message: e.to_string(),
        })?;
    }
    policy.save(&out)?;
    let history = out.with_extension("history.json");
    let text = serde_json::to_string(agent.history()).map_err(|e| MillPlanError::Io {
        path: history.display().to_string(),
        message: e.to_string(),
    })?;
    std::fs::write(&history, text).map_err(|e| MillPlanError::Io {
        path: history.display().to_string(),
        message: e.to_string(),
    })?;
    let mut default_env = MillEnv::new(base.clone(), None, config)?;
    let rollout = policy.rollout(&mut default_env)?;
    println!(
        "saved {} ({} episodes, seed {seed}); greedy return {:.3} over {} steps",
        out.display(),
        agent.history().len(),
        rollout.total_reward,
        rollout.transitions.len()
    );
    let states = env_rollout_states(&base, config, &policy)?;
    let name = if fixed_g { "DDPG, g = 0" } else { "DDPG" };
    let plan = Plan::evaluate(&base, &config.weights, &states, name)?;
    println!("{}", comparison_table(&[plan.row()]));
    Ok(())
}

/// Whether every segment of `cell`'s path is feasible at `g0` (the fixed-g
/// ablation cannot move g away from an infeasible segment).
fn feasible_at_g0(cell: &MillCell, g0: f64) -> bool {
    let mut reference = None;
    for segment in 0..cell.path().segments().len() {
        match cell.evaluate(segment, g0, reference.as_ref()) {
            Ok(cs) => reference = Some(cs.joints),
            Err(_) => return false,
        }
    }
    true
}

/// The greedy rollout's states on the default path (direct |μ|max), for the
/// direct evaluation.
fn env_rollout_states(
    cell: &Arc<MillCell>,
    config: EnvConfig,
    policy: &Policy,
) -> Result<Vec<kerf_millplan::env::PhysicalState>, MillPlanError> {
    let mut env = MillEnv::new(cell.clone(), None, config)?;
    let rollout = env.rollout(|obs, _| policy.act(obs))?;
    if !rollout.completed {
        return Err(MillPlanError::Policy {
            path: "trained policy".to_string(),
            reason: format!(
                "the greedy rollout did not complete the default path: {}",
                rollout.stop_reason()
            ),
        });
    }
    Ok(rollout.states())
}
