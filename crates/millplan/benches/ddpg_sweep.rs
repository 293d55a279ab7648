//! Does the learned policy earn its place (issue 28, item 4)? Variants of the shipped DDPG
//! policy and of "a policy that proposes and a short lookahead search that refines"
//! (`kerf_millplan::propose_refine`) against the baselines, on the default path of seed 004
//! Table 1 and the ten held-out paths of `kerf_millplan::path_distribution`, every plan judged
//! AS EXECUTED (`kerf_millplan::execute` / `MillPlanOutput::executed`).
//!
//! ```sh
//! cargo bench -p kerf_millplan --bench ddpg_sweep
//! cargo bench -p kerf_millplan --bench ddpg_sweep -- --paths 2     # default + first held-out
//! ```
//!
//! Variants (all from the request's initial state, seed 004's IVP by default):
//! * `ddpg`: the shipped policy through `MillPlanner::plan` (chatter shield and rounds, 1/K
//!   minimum 0.35), `allow_chatter: true`;
//! * `ddpg, no 1/K minimum`: the same planner with `EnvConfig::min_condition_indicator: None`;
//! * `ddpg, no shield`: with `EnvConfig::chatter_shield: None`;
//! * `ddpg g + refine L` (L = 0, 2): the `ddpg` plan's g per segment, Ω and f chosen by
//!   `propose_refine::refine_with_g` with lookahead L (0 = greedy's rule along that g), the
//!   states evaluated with `Plan::evaluate_with_threads` and executed with `execute`;
//! * `g0 + refine 2`: g = g0 on every segment, lookahead 2 (the search without the policy);
//! * the baselines `naive`, `greedy`, `fixed_g` through `MillPlanner::plan`, `allow_chatter`.
//!
//! Bounds, no plans: `ceiling, g0` and `ceiling, ddpg g` are the fastest feed schedule any
//! planner bound by the IVP and the step bounds can have, chatter ignored: f_t = min(f0 + t·Δf,
//! f_max) (Δf = `max_feed_step`, 1e-3 m/s, f_max 0.06 m/s on the default cell: 20 segments of
//! ramp from f0 = 0.04 m/s), Ω held at Ω0, g = g0 resp. the `ddpg` plan's g, executed as the
//! plans (Ω does not enter the time). Where a ceiling's executed duration is above 0.97 × the
//! fastest chatter-free baseline, no plan that starts at the IVP along that g can meet the
//! goal there (`naive` is a constant setting and does not start at the IVP).
//!
//! Figures of a plan: the executed duration from rest to rest (`scaling.duration()`),
//! chatter-free as executed (`!executed.chatters()`: every control-period sample in the
//! material), max |μ|max as executed, min 1/K along the trajectory, the wall time (and the
//! indicator evaluations of the refine search). A failure prints its status and message.
//!
//! Summary per variant over the held-out paths: chatter-free wherever any baseline is (and
//! wherever any run of this sweep is), and duration ≤ 0.97 × the fastest chatter-free
//! baseline (naive, greedy, fixed_g) while chatter-free. The goal of issue 28 item 4: chatter-
//! free wherever any planner is, and ≤ 0.97 × on at least 8 of the 10.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench binary reports failures by panicking

use std::time::Instant;

use kerf_budget::Budget;
use kerf_mill::{MillCell, PathSpec};
#[allow(dead_code)] // each bench uses some of the shared helpers
mod common;

use kerf_millplan::propose_refine::refine_with_g_report;
use kerf_millplan::status::status_name;
use kerf_millplan::{
    execute, status_of, EnvConfig, Executed, MillPlanError, MillPlanner, MillRequest,
    PhysicalState, Plan,
};

/// The variants, in the order of the table; the last [`BOUNDS`] are no plans but the feed
/// ceiling of the IVP (module documentation).
const VARIANTS: [&str; 11] = [
    "ddpg",
    "ddpg, no 1/K minimum",
    "ddpg, no shield",
    "ddpg g + refine 0",
    "ddpg g + refine 2",
    "g0 + refine 2",
    "naive",
    "greedy",
    "fixed_g",
    "ceiling, g0",
    "ceiling, ddpg g",
];

/// The feed-ceiling bounds (the last variants): not counted as runs of the sweep.
const BOUNDS: usize = 2;

/// The baselines (the last three variants).
const BASELINES: [&str; 3] = ["naive", "greedy", "fixed_g"];

/// The goal: at most this fraction of the fastest chatter-free baseline.
const GOAL_RATIO: f64 = 0.97;

/// Held-out paths that must meet the ratio.
const GOAL_COUNT: usize = 8;

/// The figures of one executed plan.
struct Figures {
    duration: f64,
    chatter_free: bool,
    max_mu: f64,
    min_ci: f64,
    wall: f64,
    evaluations: Option<usize>,
}

/// One variant on one path.
enum Outcome {
    Ran(Figures),
    Failed { status: String, message: String },
}

impl Outcome {
    fn failed(e: &MillPlanError) -> Self {
        Self::Failed {
            status: status_name(status_of(e))
                .unwrap_or("UNKNOWN_STATUS")
                .to_string(),
            message: e.to_string(),
        }
    }

    fn from_executed(e: &Executed, wall: f64, evaluations: Option<usize>) -> Self {
        Self::Ran(Figures {
            duration: e.scaling.duration(),
            chatter_free: !e.chatters(),
            max_mu: e.plan.max_spectral_radius,
            min_ci: e.scaling.min_condition_indicator.0,
            wall,
            evaluations,
        })
    }

    /// The executed duration when chatter-free.
    fn free_duration(&self) -> Option<f64> {
        match self {
            Self::Ran(f) if f.chatter_free => Some(f.duration),
            _ => None,
        }
    }

    fn cell(&self) -> String {
        match self {
            Self::Ran(f) => format!(
                "{}{:.2} s, {:.3}, 1/K {:.3}",
                if f.chatter_free { "" } else { "CHATTER " },
                f.duration,
                f.max_mu,
                f.min_ci
            ),
            Self::Failed { status, .. } => status.clone(),
        }
    }
}

fn truncate(text: &str, chars: usize) -> String {
    if text.chars().count() <= chars {
        text.to_string()
    } else {
        format!("{}…", text.chars().take(chars).collect::<String>())
    }
}

/// A plan through the planner, executed (the planner's step 7).
fn through_planner(planner: &MillPlanner, points: &[[f64; 3]], kind: &str) -> (Outcome, Vec<f64>) {
    let request = MillRequest {
        request_id: format!("ddpg_sweep/{kind}"),
        points: points.to_vec(),
        planner: kind.into(),
        allow_chatter: true,
        ..MillRequest::default()
    };
    let t = Instant::now();
    match planner.plan(&request) {
        Ok(out) => {
            let g = out.plan.segments.iter().map(|s| s.g).collect();
            (
                Outcome::from_executed(&out.executed, t.elapsed().as_secs_f64(), None),
                g,
            )
        }
        Err(e) => (Outcome::failed(&e), Vec::new()),
    }
}

/// Propose (the g schedule) and refine (Ω, f), evaluated and executed.
fn refined(
    planner: &MillPlanner,
    cell: &MillCell,
    g: &[f64],
    lookahead: usize,
    name: &str,
) -> Outcome {
    let t = Instant::now();
    let weights = planner.env_config().weights;
    let threads = planner.eval_threads();
    let initial = MillRequest::default().initial_state();
    let run = || -> Result<(Executed, usize), MillPlanError> {
        let r = refine_with_g_report(cell, initial, g, lookahead, &Budget::unlimited())?;
        let plan = Plan::evaluate_with_threads(cell, &weights, &r.states, name, threads)?;
        Ok((execute(cell, &plan, &weights, threads)?, r.evaluations))
    };
    match run() {
        Ok((e, evaluations)) => {
            Outcome::from_executed(&e, t.elapsed().as_secs_f64(), Some(evaluations))
        }
        Err(e) => Outcome::failed(&e),
    }
}

/// The feed ceiling of the IVP along `g` (module documentation), executed.
fn ceiling(planner: &MillPlanner, cell: &MillCell, g: &[f64], name: &str) -> Outcome {
    let t = Instant::now();
    let weights = planner.env_config().weights;
    let threads = planner.eval_threads();
    let [rpm0, f0, _] = MillRequest::default().initial_state();
    let lim = cell.state_limits();
    let states: Vec<PhysicalState> = g
        .iter()
        .enumerate()
        .map(|(segment, &g)| PhysicalState {
            segment,
            rpm: rpm0,
            feed: (f0 + segment as f64 * lim.max_feed_step).min(lim.feed[1]),
            g,
        })
        .collect();
    let run = || -> Result<Executed, MillPlanError> {
        let plan = Plan::evaluate_with_threads(cell, &weights, &states, name, threads)?;
        execute(cell, &plan, &weights, threads)
    };
    match run() {
        Ok(e) => Outcome::from_executed(&e, t.elapsed().as_secs_f64(), None),
        Err(e) => Outcome::failed(&e),
    }
}

fn main() {
    let started = Instant::now();
    let args: Vec<String> = std::env::args().skip(1).collect();

    let base = MillCell::default_cell().unwrap();
    let mut paths = common::default_and_held_out_paths();
    if let Some(i) = args.iter().position(|a| a == "--paths") {
        let n: usize = args
            .get(i + 1)
            .and_then(|v| v.parse().ok())
            .expect("--paths takes a number");
        paths.truncate(n);
    }

    let planner = MillPlanner::with_default_cell().unwrap();
    let config = *planner.env_config();
    let no_min = MillPlanner::with_default_cell()
        .unwrap()
        .with_env_config(EnvConfig {
            min_condition_indicator: None,
            ..config
        });
    let no_shield = MillPlanner::with_default_cell()
        .unwrap()
        .with_env_config(EnvConfig {
            chatter_shield: None,
            ..config
        });
    let g0 = MillRequest::default().initial_state()[2];

    // outcomes[path][variant], in the order of `paths` and VARIANTS.
    let mut outcomes: Vec<Vec<Outcome>> = Vec::new();
    for (name, points, _) in &paths {
        let cell = base
            .with_path(&PathSpec {
                points: points.clone(),
                ..PathSpec::default()
            })
            .unwrap();
        let n = cell.path().segments().len();
        let (ddpg, ddpg_g) = through_planner(&planner, points, "ddpg");
        let mut row = vec![
            ddpg,
            through_planner(&no_min, points, "ddpg").0,
            through_planner(&no_shield, points, "ddpg").0,
        ];
        for lookahead in [0, 2] {
            row.push(if ddpg_g.len() == n {
                refined(
                    &planner,
                    &cell,
                    &ddpg_g,
                    lookahead,
                    &format!("ddpg g + refine {lookahead}"),
                )
            } else {
                Outcome::Failed {
                    status: "NO_DDPG_PLAN".to_string(),
                    message: "the ddpg plan failed: no g schedule to refine".to_string(),
                }
            });
        }
        row.push(refined(&planner, &cell, &vec![g0; n], 2, "g0 + refine 2"));
        for kind in BASELINES {
            row.push(through_planner(&planner, points, kind).0);
        }
        row.push(ceiling(&planner, &cell, &vec![g0; n], "ceiling, g0"));
        row.push(if ddpg_g.len() == n {
            ceiling(&planner, &cell, &ddpg_g, "ceiling, ddpg g")
        } else {
            Outcome::Failed {
                status: "NO_DDPG_PLAN".to_string(),
                message: "the ddpg plan failed: no g schedule".to_string(),
            }
        });
        for (variant, o) in VARIANTS.iter().zip(&row) {
            let extra = match o {
                Outcome::Ran(f) => format!(
                    " ({:.2} s wall{})",
                    f.wall,
                    f.evaluations
                        .map_or(String::new(), |e| format!(", {e} evaluations"))
                ),
                Outcome::Failed { message, .. } => format!(": {message}"),
            };
            eprintln!("{name} / {variant}: {}{extra}", o.cell());
        }
        outcomes.push(row);
    }

    let column = |v: &str| VARIANTS.iter().position(|k| *k == v).unwrap();
    let fastest_baseline = |row: &[Outcome]| {
        BASELINES
            .iter()
            .filter_map(|b| row[column(b)].free_duration().map(|t| (*b, t)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    };

    println!(
        "\nexecuted duration from rest to rest, max |μ|max as executed, min 1/K along the \
         trajectory; CHATTER = some control-period sample in the material at |μ|max >= 1\n"
    );
    println!("| path | {} |", VARIANTS.join(" | "));
    println!("|---|{}", "---|".repeat(VARIANTS.len()));
    for ((name, _, _), row) in paths.iter().zip(&outcomes) {
        let cells: Vec<String> = row.iter().map(Outcome::cell).collect();
        println!("| {name} | {} |", cells.join(" | "));
    }

    println!(
        "\nduration / the fastest chatter-free baseline (naive, greedy, fixed_g); `*` = \
         chatter-free and <= {GOAL_RATIO}; (c) = chatters\n"
    );
    println!("| path | fastest baseline | {} |", VARIANTS.join(" | "));
    println!("|---|---|{}", "---:|".repeat(VARIANTS.len()));
    for ((name, _, _), row) in paths.iter().zip(&outcomes) {
        let best = fastest_baseline(row);
        let cells: Vec<String> = row
            .iter()
            .map(|o| match (o, best) {
                (Outcome::Ran(f), Some((_, t))) => {
                    let r = f.duration / t;
                    format!(
                        "{r:.3}{}",
                        if !f.chatter_free {
                            " (c)"
                        } else if r <= GOAL_RATIO {
                            " *"
                        } else {
                            ""
                        }
                    )
                }
                (Outcome::Ran(f), None) => {
                    if f.chatter_free {
                        "-".to_string()
                    } else {
                        "- (c)".to_string()
                    }
                }
                (Outcome::Failed { status, .. }, _) => status.clone(),
            })
            .collect();
        let b = best.map_or("none chatter-free".to_string(), |(k, t)| {
            format!("{t:.2} s ({k})")
        });
        println!("| {name} | {b} | {} |", cells.join(" | "));
    }

    // The summary over the held-out paths (the bounds are no runs).
    let any_run_free = |r: &[Outcome]| {
        r[..VARIANTS.len() - BOUNDS]
            .iter()
            .any(|o| o.free_duration().is_some())
    };
    let held: Vec<&Vec<Outcome>> = paths
        .iter()
        .zip(&outcomes)
        .filter(|((_, _, h), _)| *h)
        .map(|(_, r)| r)
        .collect();
    let no_baseline = held
        .iter()
        .filter(|r| fastest_baseline(r).is_none())
        .count();
    let none_free = held.iter().filter(|r| !any_run_free(r)).count();
    println!(
        "\nsummary over the {} held-out paths ({no_baseline} without a chatter-free baseline; \
         {none_free} where no run of this sweep is chatter-free):\n",
        held.len()
    );
    println!(
        "| variant | chatter-free | chatter-free wherever a baseline is | chatter-free wherever \
         any run is | <= {GOAL_RATIO} x fastest chatter-free baseline | goal (free wherever any \
         run is, and >= {GOAL_COUNT} at <= {GOAL_RATIO}) | wall (s) |"
    );
    println!("|---|---:|---:|---:|---:|---|---:|");
    for (c, variant) in VARIANTS[..VARIANTS.len() - BOUNDS].iter().enumerate() {
        let free = held
            .iter()
            .filter(|r| r[c].free_duration().is_some())
            .count();
        let where_baseline = held
            .iter()
            .filter(|r| r[c].free_duration().is_some() || fastest_baseline(r).is_none())
            .count();
        let where_any = held
            .iter()
            .filter(|r| r[c].free_duration().is_some() || !any_run_free(r))
            .count();
        let faster = held
            .iter()
            .filter(|r| match (r[c].free_duration(), fastest_baseline(r)) {
                (Some(t), Some((_, b))) => t <= GOAL_RATIO * b,
                _ => false,
            })
            .count();
        let wall: f64 = outcomes
            .iter()
            .map(|r| match &r[c] {
                Outcome::Ran(f) => f.wall,
                Outcome::Failed { .. } => 0.0,
            })
            .sum();
        let goal = where_any == held.len() && faster >= GOAL_COUNT;
        println!(
            "| {variant} | {free} | {where_baseline} | {where_any} | {faster} | {} | {wall:.1} |",
            if goal { "MET" } else { "not met" }
        );
    }
    println!(
        "\nthe bounds (no plans, chatter ignored): held-out paths where the IVP's feed ceiling, \
         executed, is <= {GOAL_RATIO} x the fastest chatter-free baseline (only there can a plan \
         that starts at the IVP along that g meet the goal):\n"
    );
    for (c, variant) in VARIANTS.iter().enumerate().skip(VARIANTS.len() - BOUNDS) {
        let ratios: Vec<f64> = held
            .iter()
            .filter_map(|r| match (&r[c], fastest_baseline(r)) {
                (Outcome::Ran(f), Some((_, b))) => Some(f.duration / b),
                _ => None,
            })
            .collect();
        let reachable = ratios.iter().filter(|r| **r <= GOAL_RATIO).count();
        let min = ratios.iter().copied().fold(f64::INFINITY, f64::min);
        let max = ratios.iter().copied().fold(0.0, f64::max);
        println!(
            "- {variant}: {reachable} of {} held-out paths (of the {} with a chatter-free \
             baseline; ceiling / fastest baseline {min:.3}–{max:.3})",
            held.len(),
            ratios.len()
        );
    }

    let failures: Vec<String> = paths
        .iter()
        .zip(&outcomes)
        .flat_map(|((name, _, _), row)| {
            VARIANTS
                .iter()
                .zip(row)
                .filter_map(move |(variant, o)| match o {
                    Outcome::Failed { status, message } => Some(format!(
                        "- {name}, {variant}: {status}: {}",
                        truncate(message, 300)
                    )),
                    Outcome::Ran(_) => None,
                })
        })
        .collect();
    if !failures.is_empty() {
        println!("\nfailures:\n\n{}", failures.join("\n"));
    }
    println!(
        "\nwall time of the run: {:.1} s",
        started.elapsed().as_secs_f64()
    );
}
