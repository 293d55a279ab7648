//! A SHORT DDPG training on the real milling environment (default cell,
//! committed indicator cache), to check the integration of
//! `kerf_millplan::ddpg` with `MillEnv` — sizes, speed per environment step
//! and per training step — not to produce a policy (nothing is saved).
//!
//! ```sh
//! cargo run --release -p kerf_millplan --example ddpg_mill_smoke            # 20 episodes
//! cargo run --release -p kerf_millplan --example ddpg_mill_smoke -- 50      # 50 episodes
//! cargo run --release -p kerf_millplan --example ddpg_mill_smoke -- 20 --fixed-g
//! ```
//!
//! Prints: the environment's sizes; the cost of one environment step alone
//! (a zero-action episode); per-episode reward, losses and σ; the mean wall
//! time per training step (environment + action + update); the greedy
//! return of the trained actor and the time of its 99-step rollout.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use kerf_mill::MillCell;
use kerf_millplan::cache::IndicatorCache;
use kerf_millplan::ddpg::{train, DdpgSettings};
use kerf_millplan::env::{EnvConfig, MillEnv};
use kerf_millplan::policy::Policy;
use kerf_millplan::{Environment, MillPlanError};

fn main() -> Result<(), MillPlanError> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let episodes: usize = args.iter().find_map(|a| a.parse().ok()).unwrap_or(20);
    let fixed_g = args.iter().any(|a| a == "--fixed-g");

    let cell = Arc::new(MillCell::default_cell()?);
    let cache_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/indicator_cache.bin");
    // Without a usable cache the environment evaluates |μ|max directly
    // (slower per step); say so.
    let cache = match IndicatorCache::load(&cache_path, &cell) {
        Ok(c) => Some(Arc::new(c)),
        Err(e) => {
            println!("no indicator cache ({e}); evaluating |μ|max directly");
            None
        }
    };
    let config = EnvConfig {
        fixed_g,
        ..EnvConfig::default()
    };
    let mut env = MillEnv::new(cell, cache, config)?;
    println!(
        "MillEnv: observation {}, action {}, max steps {} (fixed g: {fixed_g})",
        env.observation_dim(),
        env.action_dim(),
        env.max_steps()
    );

    // Environment alone: one zero-action episode.
    let zero = vec![0.0f32; env.action_dim()];
    let start = Instant::now();
    env.reset()?;
    let mut env_steps = 0usize;
    let mut zero_return = 0.0;
    for _ in 0..env.max_steps() {
        let t = env.step(&zero)?;
        zero_return += t.reward;
        env_steps += 1;
        if t.done {
            break;
        }
    }
    let env_step = start.elapsed().as_secs_f64() / env_steps as f64;
    println!(
        "environment alone: {:.1} µs per step ({env_steps} steps, zero-action return {zero_return:.3})",
        env_step * 1e6
    );

    let settings = DdpgSettings::default().with_episodes(episodes).with_seed(1);
    let start = Instant::now();
    let mut steps = 0usize;
    let agent = train(&mut env, &settings, &mut |r| {
        steps += r.steps;
        println!(
            "episode {:>4}/{}: reward {:>9.3}, steps {:>3}, critic loss {}, actor loss {}, σ {:.4}, \
             {:.1} s elapsed, {:.1} s left",
            r.episode,
            r.episodes,
            r.total_reward,
            r.steps,
            r.mean_critic_loss
                .map_or("-".to_string(), |v| format!("{v:.4}")),
            r.mean_actor_loss
                .map_or("-".to_string(), |v| format!("{v:.4}")),
            r.noise_std,
            r.elapsed_s,
            r.remaining_s
        );
    })?;
    let total = start.elapsed().as_secs_f64();
    let per_step = total / steps as f64;
    println!(
        "training: {steps} steps in {total:.1} s = {:.3} ms per step (environment {:.3} ms of it); \
         1000 × 99 steps would take {:.0} s",
        per_step * 1e3,
        env_step * 1e3,
        per_step * 99_000.0
    );

    let policy = Policy::from_agent(&agent, "default cell, committed cache, smoke test")?;
    let start = Instant::now();
    let rollout = policy.rollout(&mut env)?;
    println!(
        "greedy rollout: return {:.3} over {} steps in {:.2} ms (zero action: {zero_return:.3})",
        rollout.total_reward,
        rollout.transitions.len(),
        start.elapsed().as_secs_f64() * 1e3
    );
    Ok(())
}
