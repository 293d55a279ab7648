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
//!   `training_curve.svg` (seed 004 Fig. 5, [`crate::mill_plots::training_curve`]).
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
    fmt::Write as _,
    io::{IsTerminal, Write as _},
    path::{Path, PathBuf},
    sync::Arc,
    time::Instant,
};

use clap::{Args, Subcommand};
use kerf_mill::MillCell;
use kerf_millplan::{
    plan::Plan, policy::metadata_path, status_of, train, DdpgSettings, EnvConfig, Environment,
    EpisodeReport, IndicatorCache, MillEnv, MillPlanError, Policy,
};

use crate::mill_plots;

/// Exit code of every `kerf train` failure (as `kerf plan`).
pub const EXIT_FAILURE: u8 = 2;

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
    /// episode reports, as the `train_policy` example's `.history.json`).
    #[arg(long)]
    history: PathBuf,
    /// Write training_curve.svg into this directory (created if missing).
    #[arg(long)]
    plots: PathBuf,
    /// Episodes of the moving average.
    #[arg(long, default_value_t = 50)]
    window: usize,
}

/// Arguments of `kerf train mill`.
#[derive(Args, Debug)]
pub struct MillTrainArgs {
    /// Where to save the actor (safetensors); the JSON sidecar goes next to it (.json).
    #[arg(long)]
    out: PathBuf,
    /// Number of episodes (seed 004 Table 2: 1000).
    #[arg(long, default_value_t = 1000)]
    episodes: usize,
    /// Steps per episode (default: every step of the path, N − 1 for N segments).
    #[arg(long)]
    steps: Option<usize>,
    /// Seed of every random number of the run (weights, noise, replay sampling).
    #[arg(long, default_value_t = 1)]
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
    /// Milling cell YAML (default: the shipped urdf/irb6660_milling.yaml).
    #[arg(long)]
    cell: Option<PathBuf>,
    /// Indicator cache built for the cell (default: the shipped cache, if it fits the cell).
    #[arg(long, conflicts_with = "no_cache")]
    cache: Option<PathBuf>,
    /// Evaluate |mu|max directly at every step (no cache; much slower).
    #[arg(long)]
    no_cache: bool,
    /// Hidden layer widths of actor and critic, comma-separated (Table 2: 256,256).
    #[arg(long, value_delimiter = ',')]
    hidden: Option<Vec<usize>>,
    /// Actor learning rate (Table 2: 1e-4).
    #[arg(long, allow_hyphen_values = true)]
    actor_lr: Option<f64>,
    /// Critic learning rate (Table 2: 1e-3).
    #[arg(long, allow_hyphen_values = true)]
    critic_lr: Option<f64>,
    /// Discount factor gamma in [0, 1] (Table 2: 0.99).
    #[arg(long, allow_hyphen_values = true)]
    discount: Option<f64>,
    /// Soft target update rate tau in (0, 1] (Table 2: 0.005).
    #[arg(long, allow_hyphen_values = true)]
    tau: Option<f64>,
    /// Replay buffer capacity (Table 2: 10000).
    #[arg(long)]
    buffer: Option<usize>,
    /// Minibatch size (Table 2: 64); learning starts once the buffer holds one batch.
    #[arg(long)]
    batch_size: Option<usize>,
    /// Initial exploration noise standard deviation, normalized action units (Table 2: 0.1).
    #[arg(long, allow_hyphen_values = true)]
    noise: Option<f64>,
    /// Per-episode noise decay factor in (0, 1] (Table 2: 0.999).
    #[arg(long, allow_hyphen_values = true)]
    noise_decay: Option<f64>,
    /// Episodes at full noise before the decay starts (Table 2: 50).
    #[arg(long)]
    noise_decay_start: Option<usize>,
    /// Inertia coefficient alpha in (0, 1] of the action filter (seed 004 eq. 11; default 0.5).
    #[arg(long, allow_hyphen_values = true)]
    alpha: Option<f64>,
    /// Weight of kerf's joint-acceleration shaping (EnvConfig::acceleration_penalty; the
    /// committed policy's 1.0 by default, 0 turns it off): w * sum_j (|a_j|/a_max_j - 1)+ at
    /// each segment midpoint is subtracted from the step reward.
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    acceleration_penalty: f64,
    /// Episodes of the moving average of the progress line and the training curve.
    #[arg(long, default_value_t = 50)]
    window: usize,
    /// When stderr is not a terminal: one progress line every this many episodes
    /// (default: episodes / 20, at least 1).
    #[arg(long)]
    log_every: Option<usize>,
}

/// Runs `kerf train`.
///
/// # Errors
/// The message to print; the caller exits with [`EXIT_FAILURE`].
pub fn run(a: TrainArgs) -> Result<(), String> {
    match a.command {
        TrainCommand::Mill(m) => mill(*m),
        TrainCommand::Curve(c) => curve(c),
    }
}

/// "STATUS (code): message" of a library error (the planner's status names).
fn describe(e: &MillPlanError) -> String {
    let code = status_of(e);
    let name = kerf_millplan::planner::status_name(code).unwrap_or("?");
    format!("{name} ({code}): {e}")
}

/// Checks that `path` can be written as a file: creates its parent directories, refuses a
/// directory, and opens it for appending (a file created by the check is removed again, an
/// existing one is left untouched).
///
/// # Errors
/// A message naming the option and the path.
pub fn check_writable(option: &str, path: &Path) -> Result<(), String> {
    let fail =
        |e: &dyn std::fmt::Display| format!("{option} {}: cannot write: {e}", path.display());
    if path.as_os_str().is_empty() {
        return Err(format!("{option}: empty path"));
    }
    if path.is_dir() {
        return Err(fail(&"is a directory"));
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| fail(&e))?;
    }
    let existed = path.exists();
    std::fs::OpenOptions::new()
        .append(true)
        .create(true)
        .open(path)
        .map_err(|e| fail(&e))?;
    if !existed {
        let _ = std::fs::remove_file(path);
    }
    Ok(())
}

/// Creates the directory `dir` (and parents) and checks that a file can be written in it.
///
/// # Errors
/// A message naming the option and the directory.
pub fn check_dir_writable(option: &str, dir: &Path) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| {
        format!(
            "{option} {}: cannot create the directory: {e}",
            dir.display()
        )
    })?;
    let probe = dir.join(format!(".kerf_write_check_{}", std::process::id()));
    std::fs::write(&probe, b"")
        .map_err(|e| format!("{option} {}: cannot write in it: {e}", dir.display()))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// `12s`, `4m50s`, `1h02m03s` (rounded to the second; `?` for a non-finite or negative
/// time).
pub fn format_duration(seconds: f64) -> String {
    if !(seconds.is_finite() && seconds >= 0.0) {
        return "?".to_string();
    }
    let s = seconds.round() as u64;
    let (h, m, s) = (s / 3600, (s / 60) % 60, s % 60);
    if h > 0 {
        format!("{h}h{m:02}m{s:02}s")
    } else if m > 0 {
        format!("{m}m{s:02}s")
    } else {
        format!("{s}s")
    }
}

/// The progress display of a run (module documentation).
struct Progress {
    rewards: Vec<f64>,
    /// Running sum over the last `window` rewards.
    window_sum: f64,
    window: usize,
    terminal: bool,
    log_every: usize,
}

/// Width of the progress bar in characters.
const BAR_WIDTH: usize = 20;

impl Progress {
    fn new(window: usize, terminal: bool, log_every: usize) -> Self {
        Self {
            rewards: Vec::new(),
            window_sum: 0.0,
            window: window.max(1),
            terminal,
            log_every: log_every.max(1),
        }
    }

    /// Records an episode and returns the text to print (empty when nothing is due).
    fn update(&mut self, r: &EpisodeReport) -> String {
        self.rewards.push(r.total_reward);
        self.window_sum += r.total_reward;
        let n = self.rewards.len();
        if n > self.window {
            self.window_sum -= self.rewards[n - 1 - self.window];
        }
        let average = self.window_sum / n.min(self.window) as f64;
        let last = r.episode >= r.episodes;
        let stats = format!(
            "reward {:>9.3}, average({}) {:>9.3}, σ {:.4}, {} elapsed, {} left",
            r.total_reward,
            self.window,
            average,
            r.noise_std,
            format_duration(r.elapsed_s),
            format_duration(r.remaining_s)
        );
        if self.terminal {
            let filled = (BAR_WIDTH * r.episode)
                .checked_div(r.episodes)
                .unwrap_or(BAR_WIDTH)
                .min(BAR_WIDTH);
            let bar: String = std::iter::repeat_n('#', filled)
                .chain(std::iter::repeat_n('.', BAR_WIDTH - filled))
                .collect();
            // \r + clear to the end of the line (ANSI), then the bar.
            let mut s = format!("\r\x1b[K[{bar}] {}/{} {stats}", r.episode, r.episodes);
            if last {
                s.push('\n');
            }
            s
        } else if r.episode.is_multiple_of(self.log_every) || last || r.episode == 1 {
            format!("episode {}/{}: {stats}\n", r.episode, r.episodes)
        } else {
            String::new()
        }
    }
}

/// The history as CSV: a header and one row per episode (empty loss cells in the warm-up).
pub fn history_csv(history: &[EpisodeReport], window: usize) -> String {
    let rewards: Vec<f64> = history.iter().map(|r| r.total_reward).collect();
    let average = mill_plots::moving_average(&rewards, window);
    let mut s = format!(
        "episode,episodes,steps,total_reward,moving_average_{},mean_critic_loss,\
         mean_actor_loss,noise_std,elapsed_s,remaining_s\n",
        window.max(1)
    );
    let opt = |v: Option<f64>| v.map_or(String::new(), |v| v.to_string());
    for (r, avg) in history.iter().zip(&average) {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{}",
            r.episode,
            r.episodes,
            r.steps,
            r.total_reward,
            avg,
            opt(r.mean_critic_loss),
            opt(r.mean_actor_loss),
            r.noise_std,
            r.elapsed_s,
            r.remaining_s
        );
    }
    s
}

/// Reads a history written by `kerf train mill --history`: CSV when `csv`, else a JSON array
/// of [`EpisodeReport`].
///
/// # Errors
/// A message naming the row and column: a missing column, a value that is not a number, a
/// non-finite reward, noise or time (NaN never passes), or no episode at all.
pub fn parse_history(text: &str, csv: bool) -> Result<Vec<EpisodeReport>, String> {
    let history: Vec<EpisodeReport> = if csv {
        let mut lines = text.lines().filter(|l| !l.trim().is_empty());
        let header: Vec<&str> = lines
            .next()
            .ok_or("empty history")?
            .split(',')
            .map(str::trim)
            .collect();
        let col = |name: &str| {
            header
                .iter()
                .position(|h| *h == name)
                .ok_or_else(|| format!("the header has no column `{name}`"))
        };
        let idx = [
            col("episode")?,
            col("episodes")?,
            col("steps")?,
            col("total_reward")?,
            col("mean_critic_loss")?,
            col("mean_actor_loss")?,
            col("noise_std")?,
            col("elapsed_s")?,
            col("remaining_s")?,
        ];
        let mut out = Vec::new();
        for (row, line) in lines.enumerate() {
            let cells: Vec<&str> = line.split(',').map(str::trim).collect();
            let cell = |k: usize| -> Result<&str, String> {
                cells
                    .get(idx[k])
                    .copied()
                    .ok_or_else(|| format!("row {}: column `{}` missing", row + 1, header[idx[k]]))
            };
            let num = |k: usize| -> Result<f64, String> {
                let c = cell(k)?;
                c.parse::<f64>().map_err(|_| {
                    format!(
                        "row {}: `{}` = `{c}` is not a number",
                        row + 1,
                        header[idx[k]]
                    )
                })
            };
            let whole = |k: usize| -> Result<usize, String> {
                let c = cell(k)?;
                c.parse::<usize>().map_err(|_| {
                    format!(
                        "row {}: `{}` = `{c}` is not a whole number",
                        row + 1,
                        header[idx[k]]
                    )
                })
            };
            let opt = |k: usize| -> Result<Option<f64>, String> {
                if cell(k)?.is_empty() {
                    Ok(None)
                } else {
                    num(k).map(Some)
                }
            };
            out.push(EpisodeReport {
                episode: whole(0)?,
                episodes: whole(1)?,
                steps: whole(2)?,
                total_reward: num(3)?,
                mean_critic_loss: opt(4)?,
                mean_actor_loss: opt(5)?,
                noise_std: num(6)?,
                elapsed_s: num(7)?,
                remaining_s: num(8)?,
            });
        }
        out
    } else {
        serde_json::from_str(text)
            .map_err(|e| format!("not a JSON array of episode reports: {e}"))?
    };
    if history.is_empty() {
        return Err("no episode in the history".to_string());
    }
    for r in &history {
        for (name, v) in [
            ("total_reward", Some(r.total_reward)),
            ("noise_std", Some(r.noise_std)),
            ("elapsed_s", Some(r.elapsed_s)),
            ("remaining_s", Some(r.remaining_s)),
            ("mean_critic_loss", r.mean_critic_loss),
            ("mean_actor_loss", r.mean_actor_loss),
        ] {
            if let Some(v) = v.filter(|v| !v.is_finite()) {
                return Err(format!(
                    "episode {}: {name} is {v}, must be finite",
                    r.episode
                ));
            }
        }
    }
    Ok(history)
}

fn curve(a: CurveArgs) -> Result<(), String> {
    if a.window == 0 {
        return Err("--window 0: must be at least 1".to_string());
    }
    let text = std::fs::read_to_string(&a.history)
        .map_err(|e| format!("cannot read {}: {e}", a.history.display()))?;
    let csv = a
        .history
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
    let history = parse_history(&text, csv).map_err(|e| format!("{}: {e}", a.history.display()))?;
    check_dir_writable("--plots", &a.plots)?;
    let file = a.plots.join("training_curve.svg");
    let name = a
        .history
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    mill_plots::training_curve(
        &file,
        &history,
        a.window,
        &format!("DDPG training, {name} ({} episodes)", history.len()),
    )?;
    println!(
        "training curve of {} episodes written to {}",
        history.len(),
        file.display()
    );
    Ok(())
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
        |p| p.display().to_string(),
    );
    let cell = match &a.cell {
        Some(p) => MillCell::load(p),
        None => MillCell::default_cell(),
    }
    .map_err(|e| format!("cell {cell_name}: {e}"))?;
    let cell = Arc::new(cell);
    let (cache, cache_name) = if a.no_cache {
        (None, "none (--no-cache)".to_string())
    } else if let Some(p) = &a.cache {
        let c = IndicatorCache::load(p, &cell).map_err(|e| format!("--cache: {e}"))?;
        (Some(Arc::new(c)), p.display().to_string())
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
        mill_plots::training_curve(&file, agent.history(), a.window, &title)?;
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

#[cfg(test)]
mod tests {
    use super::*;

    fn report(episode: usize, episodes: usize, reward: f64) -> EpisodeReport {
        EpisodeReport {
            episode,
            episodes,
            steps: 10,
            total_reward: reward,
            mean_critic_loss: (episode > 1).then_some(0.5),
            mean_actor_loss: (episode > 1).then_some(-1.5),
            noise_std: 0.1,
            elapsed_s: 2.0 * episode as f64,
            remaining_s: 2.0 * (episodes - episode) as f64,
        }
    }

    #[test]
    fn durations_read_as_hours_minutes_seconds() {
        assert_eq!(format_duration(12.4), "12s");
        assert_eq!(format_duration(290.0), "4m50s");
        assert_eq!(format_duration(3723.0), "1h02m03s");
        assert_eq!(format_duration(f64::NAN), "?");
        assert_eq!(format_duration(-1.0), "?");
    }

    #[test]
    fn progress_lines_every_n_episodes_with_the_moving_average() {
        let mut p = Progress::new(2, false, 2);
        let first = p.update(&report(1, 4, 1.0));
        assert!(
            first.starts_with("episode 1/4: reward     1.000, average(2)     1.000"),
            "{first}"
        );
        assert!(first.contains("2s elapsed, 6s left"), "{first}");
        assert!(p
            .update(&report(2, 4, 3.0))
            .contains("average(2)     2.000"));
        assert!(p.update(&report(3, 4, 5.0)).is_empty());
        let last = p.update(&report(4, 4, 7.0));
        // Average of the last two: (5 + 7) / 2.
        assert!(last.contains("average(2)     6.000"), "{last}");
    }

    #[test]
    fn terminal_progress_is_a_bar_redrawn_in_place() {
        let mut p = Progress::new(10, true, 1);
        let s = p.update(&report(1, 4, -2.0));
        assert!(s.starts_with("\r\x1b[K[#####...............] 1/4"), "{s:?}");
        assert!(s.contains("] 1/4 reward"), "{s:?}");
        assert!(!s.ends_with('\n'));
        for k in 2..4 {
            p.update(&report(k, 4, -2.0));
        }
        let s = p.update(&report(4, 4, -2.0));
        assert!(
            s.contains(&"#".repeat(BAR_WIDTH)) && s.ends_with('\n'),
            "{s:?}"
        );
    }

    #[test]
    fn csv_and_json_histories_read_back_exactly_and_nan_is_refused() {
        let h = vec![report(1, 2, -1.25), report(2, 2, 0.1 + 0.2)];
        assert_eq!(parse_history(&history_csv(&h, 50), true), Ok(h.clone()));
        let json = serde_json::to_string(&h).expect("json");
        assert_eq!(parse_history(&json, false), Ok(h.clone()));
        let mut bad = h.clone();
        bad[1].total_reward = f64::NAN;
        let e = parse_history(&history_csv(&bad, 50), true).unwrap_err();
        assert_eq!(e, "episode 2: total_reward is NaN, must be finite");
        assert!(parse_history("episode,steps\n1,2\n", true)
            .unwrap_err()
            .contains("no column `episodes`"));
        let header = history_csv(&h, 50)
            .lines()
            .next()
            .expect("header")
            .to_string();
        let e = parse_history(&format!("{header}\n1,2,10,x,1,,,0.1,2,2\n"), true).unwrap_err();
        assert_eq!(e, "row 1: `total_reward` = `x` is not a number");
        assert_eq!(
            parse_history("[]", false).unwrap_err(),
            "no episode in the history"
        );
    }

    #[test]
    fn history_csv_has_a_row_per_episode_and_empty_warm_up_losses() {
        let h = [report(1, 2, 1.0), report(2, 2, 3.0)];
        let csv = history_csv(&h, 50);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 3);
        assert!(lines[0].starts_with("episode,episodes,steps,total_reward,moving_average_50,"));
        assert_eq!(lines[1], "1,2,10,1,1,,,0.1,2,2");
        assert_eq!(lines[2], "2,2,10,3,2,0.5,-1.5,0.1,4,0");
    }
}
