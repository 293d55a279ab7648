//! `kerf train mill`: trains the DDPG milling policy of seed 004 (Algorithm 1, Table 2) on the
//! milling environment of a cell and saves it (issue 5 section 2).
//!
//! ```sh
//! kerf train mill --out policy.safetensors [--episodes 1000] [--steps N] [--seed 1]
//!                 [--fixed-g] [--acceleration-penalty W] [--history FILE.csv|FILE.json]
//!                 [--plots DIR]
//!                 [--cell FILE] [--cache FILE | --no-cache] [DDPG and environment knobs]
//! ```
//!
//! * Environment: [`kerf_millplan::MillEnv`] on the cell (default `urdf/irb6660_milling.yaml`)
//!   with its indicator cache (default `crates/millplan/data/indicator_cache.bin`; when the
//!   default cache does not load for the cell — stale after a cell change — training goes on
//!   with direct |μ|max evaluation, much slower, and says so; an explicit `--cache` that does
//!   not load is an error). `--fixed-g` is the paper's g = 0 ablation (action (ΔΩ, Δf)).
//! * Learning: [`kerf_millplan::train`] with [`DdpgSettings`] (Table 2 defaults; `--episodes`,
//!   `--steps` per episode, default every step of the path, `--seed`, and the knobs below).
//! * Progress on stderr after every episode: a progress bar redrawn in place (`\r`) when stderr
//!   is a terminal, otherwise one line every `--log-every` episodes (default: 20 lines per
//!   run) and the last: episode k/N, episode reward, its moving average over `--window`
//!   episodes, exploration noise σ, elapsed and estimated remaining wall time.
//! * Output: the actor as safetensors at `--out` and its JSON sidecar (same path, `.json`:
//!   the sizes, every DDPG setting, the environment — cell, cache, [`EnvConfig`] — and the
//!   exact command line) by [`Policy::save`]; `--history`: one row per episode (CSV when
//!   the name ends in `.csv`, else a JSON array of [`EpisodeReport`]); `--plots DIR`:
//!   `training_curve.svg` (seed 004 Fig. 5, [`crate::plots::training::training_curve`]).
//! * Summary on stdout: the greedy (noise-free) rollout of the trained policy over the whole
//!   path, evaluated directly ([`Plan::evaluate`]): machining time, max |μ|max, min 1/K and
//!   total reward (eq. 12); or where it left the feasible set.
//!
//! `kerf train curve --history FILE --plots DIR [--window N]` draws the same training curve
//! from a saved history (CSV or JSON, e.g. the `train_policy` example's `.history.json` of a
//! committed policy) without training.
//!
//! Every output path is checked (created and writable) BEFORE training, so a long run never
//! ends on an unwritable file. Invalid arguments (0 episodes, NaN or out-of-range settings,
//! an unreadable cell or cache, an unwritable path) exit with code 2 and a message.

use std::{
    io::{IsTerminal, Write as _},
    path::PathBuf,
    sync::Arc,
    time::Instant,
};

use clap::{Args, Subcommand};
use kerf_mill::MillCell;
use kerf_millplan::{
    history::history_csv, plan::Plan, policy::metadata_path, train, DdpgSettings, EnvConfig,
    Environment, IndicatorCache, MillEnv, Policy,
};

use crate::{
    bounds::{Count, Real},
    input::{self, InputFile},
    lobes::load_cell,
    output_paths::{check_dir_writable, check_writable},
    plan_mill::describe,
    plots::training,
};
use progress::{format_duration, Progress};

mod curve;
mod progress;

/// A count of episodes: [1, 1000000] episodes.
const EPISODES: Count<usize> = Count::new(1, 1_000_000, "episodes");

/// A rate or factor in (0, 1].
const UNIT_OPEN: Real = Real::above(0.0, 1.0, "");

/// Arguments of `kerf train`.
#[derive(Args, Debug)]
pub struct TrainArgs {
    #[command(subcommand)]
    command: TrainCommand,
}

/// What `kerf train` trains.
#[derive(Subcommand, Debug)]
enum TrainCommand {
    /// Train the DDPG milling policy (seed 004) and save it as safetensors + JSON.
    Mill(Box<MillTrainArgs>),
    /// Draw the training curve (seed 004 Fig. 5) of a saved history (CSV or JSON).
    Curve(CurveArgs),
}

/// Arguments of `kerf train curve`.
#[derive(Args, Debug)]
pub struct CurveArgs {
    /// History file written by `kerf train mill --history` (CSV, or JSON: an array of
    /// episode reports, as the `train_policy` example's `.history.json`; at most 16 MiB, `-`
    /// reads standard input as JSON).
    #[arg(long)]
    history: InputFile,
    /// Write training_curve.svg into this directory (created if missing).
    #[arg(long)]
    plots: PathBuf,
    /// Episodes of the moving average; [1, 1000000] episodes.
    #[arg(long, default_value_t = 50, value_parser = EPISODES)]
    window: usize,
}

/// Arguments of `kerf train mill`.
#[derive(Args, Debug)]
pub struct MillTrainArgs {
    /// Where to save the actor (safetensors); the JSON sidecar goes next to it (.json).
    #[arg(long)]
    out: PathBuf,
    /// Number of episodes (seed 004 Table 2: 1000); [1, 1000000] episodes.
    #[arg(long, default_value_t = 1000, value_parser = EPISODES)]
    episodes: usize,
    /// Steps per episode (default: every step of the path, N − 1 for N segments);
    /// [1, 1000000] steps.
    #[arg(long, value_parser = Count::<usize>::new(1, 1_000_000, "steps"))]
    steps: Option<usize>,
    /// Seed of every random number of the run (weights, noise, replay sampling);
    /// [0, 18446744073709551615].
    #[arg(long, default_value_t = 1, value_parser = Count::<u64>::new(0, u64::MAX, ""))]
    seed: u64,
    /// The paper's ablation: g fixed at g0 = 0, the policy sets only Ω and f.
    #[arg(long)]
    fixed_g: bool,
    /// Write the per-episode history here (CSV if the name ends in .csv, else JSON).
    #[arg(long)]
    history: Option<PathBuf>,
    /// Write training_curve.svg (seed 004 Fig. 5) into this directory (created if missing).
    #[arg(long)]
    plots: Option<PathBuf>,
    /// Milling cell YAML (default: the shipped urdf/irb6660_milling.yaml; at most 1 MiB).
    #[arg(long)]
    cell: Option<InputFile>,
    /// Indicator cache built for the cell (default: the shipped cache, if it fits the cell; a
    /// regular file of at most 64 MiB).
    #[arg(long, conflicts_with = "no_cache")]
    cache: Option<InputFile>,
    /// Evaluate |mu|max directly at every step (no cache; much slower).
    #[arg(long)]
    no_cache: bool,
    /// Hidden layer widths of actor and critic, comma-separated (Table 2: 256,256); each
    /// [1, 512] units (an episode's cost grows with the width: about 2 s at 256, 4 s at 512,
    /// measured with `--episodes 2`; a progress line follows every slow episode).
    #[arg(long, value_delimiter = ',', value_parser = Count::<usize>::new(1, 512, "units"))]
    hidden: Option<Vec<usize>>,
    /// Actor learning rate (Table 2: 1e-4); (0, 1].
    #[arg(long, allow_hyphen_values = true, value_parser = UNIT_OPEN)]
    actor_lr: Option<f64>,
    /// Critic learning rate (Table 2: 1e-3); (0, 1].
    #[arg(long, allow_hyphen_values = true, value_parser = UNIT_OPEN)]
    critic_lr: Option<f64>,
    /// Discount factor gamma (Table 2: 0.99); [0, 1].
    #[arg(long, allow_hyphen_values = true, value_parser = Real::closed(0.0, 1.0, ""))]
    discount: Option<f64>,
    /// Soft target update rate tau (Table 2: 0.005); (0, 1].
    #[arg(long, allow_hyphen_values = true, value_parser = UNIT_OPEN)]
    tau: Option<f64>,
    /// Replay buffer capacity (Table 2: 10000); [1, 1000000] transitions.
    #[arg(long, value_parser = Count::<usize>::new(1, 1_000_000, "transitions"))]
    buffer: Option<usize>,
    /// Minibatch size (Table 2: 64); learning starts once the buffer holds one batch;
    /// [1, 256] transitions (an episode's cost grows with it: about 2 s at 256, measured with
    /// `--episodes 4`).
    #[arg(long, value_parser = Count::<usize>::new(1, 256, "transitions"))]
    batch_size: Option<usize>,
    /// Initial exploration noise standard deviation, normalized action units (Table 2: 0.1);
    /// [0, 10].
    #[arg(long, allow_hyphen_values = true, value_parser = Real::closed(0.0, 10.0, ""))]
    noise: Option<f64>,
    /// Per-episode noise decay factor (Table 2: 0.999); (0, 1].
    #[arg(long, allow_hyphen_values = true, value_parser = UNIT_OPEN)]
    noise_decay: Option<f64>,
    /// Episodes at full noise before the decay starts (Table 2: 50); [0, 1000000] episodes.
    #[arg(long, value_parser = Count::<usize>::new(0, 1_000_000, "episodes"))]
    noise_decay_start: Option<usize>,
    /// Inertia coefficient alpha of the action filter (seed 004 eq. 11; default 0.5); (0, 1].
    #[arg(long, allow_hyphen_values = true, value_parser = UNIT_OPEN)]
    alpha: Option<f64>,
    /// Weight of kerf's joint-acceleration shaping (EnvConfig::acceleration_penalty; the
    /// committed policy's 1.0 by default, 0 turns it off): w * sum_j (|a_j|/a_max_j - 1)+ at
    /// each segment midpoint is subtracted from the step reward; [0, 1000].
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true,
          value_parser = Real::closed(0.0, 1000.0, ""))]
    acceleration_penalty: f64,
    /// Episodes of the moving average of the progress line and the training curve;
    /// [1, 1000000] episodes.
    #[arg(long, default_value_t = 50, value_parser = EPISODES)]
    window: usize,
    /// When stderr is not a terminal: one progress line every this many episodes
    /// (default: episodes / 20, at least 1); [1, 1000000] episodes.
    #[arg(long, value_parser = EPISODES)]
    log_every: Option<usize>,
}

/// Runs `kerf train`.
///
/// # Errors
/// The message to print; the caller exits with [`crate::EXIT_FAILURE`].
pub fn run(a: TrainArgs) -> Result<(), String> {
    match a.command {
        TrainCommand::Mill(m) => mill(*m),
        TrainCommand::Curve(c) => curve::curve(c),
    }
}

/// The DDPG settings of the arguments over Table 2's.
fn settings(a: &MillTrainArgs, steps: usize) -> DdpgSettings {
    let d = DdpgSettings::default();
    DdpgSettings {
        episodes: a.episodes,
        steps_per_episode: steps,
        hidden_sizes: a.hidden.clone().unwrap_or(d.hidden_sizes),
        actor_learning_rate: a.actor_lr.unwrap_or(d.actor_learning_rate),
        critic_learning_rate: a.critic_lr.unwrap_or(d.critic_learning_rate),
        discount: a.discount.unwrap_or(d.discount),
        soft_update_rate: a.tau.unwrap_or(d.soft_update_rate),
        buffer_capacity: a.buffer.unwrap_or(d.buffer_capacity),
        batch_size: a.batch_size.unwrap_or(d.batch_size),
        noise_std: a.noise.unwrap_or(d.noise_std),
        noise_decay_rate: a.noise_decay.unwrap_or(d.noise_decay_rate),
        noise_decay_start_episode: a.noise_decay_start.unwrap_or(d.noise_decay_start_episode),
        seed: a.seed,
        ..d
    }
}

fn mill(a: MillTrainArgs) -> Result<(), String> {
    // Arguments that need no model.
    if a.episodes == 0 {
        return Err("--episodes 0: must be at least 1".to_string());
    }
    if a.steps == Some(0) {
        return Err("--steps 0: must be at least 1".to_string());
    }
    if a.window == 0 {
        return Err("--window 0: must be at least 1".to_string());
    }
    if a.log_every == Some(0) {
        return Err("--log-every 0: must be at least 1".to_string());
    }
    if let Some(alpha) = a.alpha {
        if !(alpha > 0.0 && alpha <= 1.0) {
            return Err(format!("--alpha {alpha}: must be in (0, 1]"));
        }
    }
    if metadata_path(&a.out) == a.out {
        return Err(format!(
            "--out {}: the policy file must not end in .json (that is its settings sidecar)",
            a.out.display()
        ));
    }
    // Settings other than the path-dependent step count, checked before any loading.
    settings(&a, 1)
        .validate()
        .map_err(|e| format!("training settings: {e}"))?;
    check_writable("--out", &a.out)?;
    check_writable("--out (sidecar)", &metadata_path(&a.out))?;
    if let Some(h) = &a.history {
        check_writable("--history", h)?;
    }
    if let Some(d) = &a.plots {
        check_dir_writable("--plots", d)?;
    }

    // The cell, the cache, the environment.
    let cell_name = a.cell.as_ref().map_or_else(
        || "urdf/irb6660_milling.yaml (default cell)".to_string(),
        |f| f.to_string(),
    );
    let cell = match &a.cell {
        Some(f) => load_cell("--cell", f)?,
        None => MillCell::default_cell().map_err(|e| format!("cell {cell_name}: {e}"))?,
    };
    let cell = Arc::new(cell);
    let (cache, cache_name) = if a.no_cache {
        (None, "none (--no-cache)".to_string())
    } else if let Some(f) = &a.cache {
        input::check_file("--cache", f, input::CACHE_CAP)?;
        let c = IndicatorCache::load(f.path(), &cell).map_err(|e| format!("--cache: {e}"))?;
        (Some(Arc::new(c)), f.to_string())
    } else {
        let p = IndicatorCache::default_path();
        match IndicatorCache::load(&p, &cell) {
            Ok(c) => (Some(Arc::new(c)), p.display().to_string()),
            Err(e) => {
                eprintln!(
                    "kerf: the default indicator cache does not apply ({e}); |mu|max is \
                     evaluated directly at every step (much slower)"
                );
                (None, format!("none ({} did not load)", p.display()))
            }
        }
    };
    let defaults = EnvConfig::default();
    let config = EnvConfig {
        fixed_g: a.fixed_g,
        alpha: a.alpha.unwrap_or(defaults.alpha),
        acceleration_penalty: (a.acceleration_penalty != 0.0).then_some(a.acceleration_penalty),
        ..defaults
    };
    let mut env = MillEnv::new(cell.clone(), cache.clone(), config).map_err(|e| describe(&e))?;
    let steps = a.steps.unwrap_or(env.max_steps());
    let settings = settings(&a, steps);
    settings
        .validate()
        .map_err(|e| format!("training settings: {e}"))?;

    // Training with progress.
    let terminal = std::io::stderr().is_terminal();
    let log_every = a.log_every.unwrap_or((a.episodes / 20).max(1));
    let mut progress = Progress::new(a.window, terminal, log_every);
    eprintln!(
        "training {} episodes × {} steps ({}; cell {cell_name}; cache {cache_name}; seed {})",
        settings.episodes,
        steps.min(env.max_steps()),
        if a.fixed_g {
            "g fixed at g0"
        } else {
            "g optimized"
        },
        settings.seed
    );
    let start = Instant::now();
    let agent = train(&mut env, &settings, &mut |r| {
        let text = progress.update(r);
        if !text.is_empty() {
            let mut err = std::io::stderr().lock();
            let _ = err.write_all(text.as_bytes());
            let _ = err.flush();
        }
    })
    .map_err(|e| format!("training failed: {}", describe(&e)))?;
    let seconds = start.elapsed().as_secs_f64();

    // The policy, its sidecar, the history, the curve.
    let command: Vec<String> = std::env::args().skip(1).collect();
    let environment = format!(
        "cell {cell_name}; indicator cache {cache_name}; {config:?}; command: kerf {}",
        command.join(" ")
    );
    let mut policy = Policy::from_agent(&agent, &environment).map_err(|e| describe(&e))?;
    policy.save(&a.out).map_err(|e| describe(&e))?;
    println!(
        "policy written to {} (settings: {}); {} episodes in {}",
        a.out.display(),
        metadata_path(&a.out).display(),
        agent.history().len(),
        format_duration(seconds)
    );
    if let Some(h) = &a.history {
        let text = if h.extension().is_some_and(|e| e.eq_ignore_ascii_case("csv")) {
            history_csv(agent.history(), a.window)
        } else {
            serde_json::to_string_pretty(agent.history())
                .map_err(|e| format!("cannot serialize the history: {e}"))?
                + "\n"
        };
        std::fs::write(h, text)
            .map_err(|e| format!("--history {}: cannot write: {e}", h.display()))?;
        println!("history written to {}", h.display());
    }
    if let Some(d) = &a.plots {
        let file = d.join("training_curve.svg");
        let title = format!(
            "DDPG training, {} ({} episodes, seed {})",
            if a.fixed_g { "g = 0" } else { "g optimized" },
            agent.history().len(),
            settings.seed
        );
        training::training_curve(&file, agent.history(), a.window, &title)?;
        println!("training curve written to {}", file.display());
    }

    // Greedy rollout of the trained policy, evaluated directly.
    let rollout = env
        .rollout(|obs, _| policy.act(obs))
        .map_err(|e| format!("greedy rollout: {}", describe(&e)))?;
    print!("{}", greedy_summary(&cell, &config, &rollout)?);
    Ok(())
}

/// The summary of the greedy rollout: the directly evaluated totals when it machined the
/// whole path, else where it stopped.
fn greedy_summary(
    cell: &MillCell,
    config: &EnvConfig,
    rollout: &kerf_millplan::Rollout,
) -> Result<String, String> {
    if !rollout.completed {
        let why = rollout.stop_reason();
        return Ok(format!(
            "greedy rollout: left the feasible set after {} of {} segments ({why}); return {:.4}\n",
            rollout.steps.len() + 1,
            cell.path().segments().len(),
            rollout.total_reward
        ));
    }
    let name = if config.fixed_g { "fixed_g" } else { "ddpg" };
    let plan = Plan::evaluate(cell, &config.weights, &rollout.states(), name)
        .map_err(|e| format!("greedy plan evaluation: {}", describe(&e)))?;
    Ok(format!(
        "greedy rollout ({} segments, |mu|max evaluated directly): machining time {:.4} s, \
         max |μ|max {:.4} ({}), min 1/K {:.4}, total reward {:.4}\n",
        plan.segments.len(),
        plan.total_time,
        plan.max_spectral_radius,
        if plan.chatter_free {
            "chatter-free"
        } else {
            "CHATTER"
        },
        plan.min_condition_indicator,
        plan.total_reward
    ))
}
