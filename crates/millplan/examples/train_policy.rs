//! Trains the DDPG policy of the default cell (seed 004 Algorithm 1, Table 2
//! settings) and saves it with its settings sidecar and its training
//! history: the committed policies are produced by exactly these commands.
//!
//! ```sh
//! RAYON_NUM_THREADS=1 cargo run --release -p kerf_millplan --example train_policy            # policies/ddpg.safetensors
//! RAYON_NUM_THREADS=1 cargo run --release -p kerf_millplan --example train_policy -- --fixed-g # policies/fixed_g.safetensors
//! ```
//!
//! Options: `--episodes N` (default 1000), `--seed S` (default 1),
//! `--acceleration-penalty W` ([`kerf_millplan::EnvConfig::acceleration_penalty`], default off),
//! `--out FILE` (default `crates/millplan/policies/{ddpg,fixed_g}.safetensors`).
//! Writes FILE, its JSON sidecar and `FILE` with `.history.json` (one
//! [`kerf_millplan::ddpg::EpisodeReport`] per episode, for seed 004 Fig. 5),
//! and prints the greedy plan evaluated directly.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::path::PathBuf;
use std::sync::Arc;

use kerf_mill::MillCell;
use kerf_millplan::cache::IndicatorCache;
use kerf_millplan::ddpg::{train, DdpgSettings};
use kerf_millplan::env::{EnvConfig, MillEnv};
use kerf_millplan::plan::{comparison_table, Plan};
use kerf_millplan::policy::Policy;
use kerf_millplan::MillPlanError;

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
    let acceleration_penalty: Option<f64> = value(&args, "--acceleration-penalty")?;
    let out: PathBuf = value::<String>(&args, "--out")?
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(if fixed_g {
                "policies/fixed_g.safetensors"
            } else {
                "policies/ddpg.safetensors"
            })
        });
    let cell = Arc::new(MillCell::default_cell()?);
    let cache = Arc::new(IndicatorCache::load(
        &IndicatorCache::default_path(),
        &cell,
    )?);
    let config = EnvConfig {
        fixed_g,
        acceleration_penalty,
        ..EnvConfig::default()
    };
    let mut env = MillEnv::new(cell.clone(), Some(cache), config)?;
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
    let environment = format!(
        "default cell (urdf/irb6660_milling.yaml), committed indicator cache; {config:?}; \
         trained by `cargo run --release -p kerf_millplan --example train_policy --{}{}{}`",
        if fixed_g { " --fixed-g" } else { "" },
        if episodes == 1000 && seed == 1 {
            String::new()
        } else {
            format!(" --episodes {episodes} --seed {seed}")
        },
        acceleration_penalty
            .map(|w| format!(" --acceleration-penalty {w}"))
            .unwrap_or_default()
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
    let rollout = policy.rollout(&mut env)?;
    println!(
        "saved {} ({} episodes, seed {seed}); greedy return {:.3} over {} steps",
        out.display(),
        agent.history().len(),
        rollout.total_reward,
        rollout.transitions.len()
    );
    let states = env_rollout_states(&cell, config, &policy)?;
    let name = if fixed_g { "DDPG, g = 0" } else { "DDPG" };
    let plan = Plan::evaluate(&cell, &config.weights, &states, name)?;
    println!("{}", comparison_table(&[plan.row()]));
    Ok(())
}

/// The greedy rollout's states (environment with the cache), for the
/// direct evaluation.
fn env_rollout_states(
    cell: &Arc<MillCell>,
    config: EnvConfig,
    policy: &Policy,
) -> Result<Vec<kerf_millplan::env::PhysicalState>, MillPlanError> {
    let cache = Arc::new(IndicatorCache::load(&IndicatorCache::default_path(), cell)?);
    let mut env = MillEnv::new(cell.clone(), Some(cache), config)?;
    let rollout = env.rollout(|obs, _| policy.act(obs))?;
    if !rollout.completed {
        return Err(MillPlanError::Policy {
            path: "trained policy".to_string(),
            reason: "the greedy rollout did not complete the path".to_string(),
        });
    }
    Ok(rollout.states())
}
