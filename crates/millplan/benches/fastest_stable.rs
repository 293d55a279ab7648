//! The fastest stable plan, every planner on every path AS EXECUTED (issue 28, item 4): the
//! default path of seed 004 Table 1, the ten held-out paths of
//! `kerf_millplan::path_distribution` (`HELD_OUT_SEEDS`) and three hand-made planar paths, each
//! planned through `MillPlanner::plan` (one planner for all) with `allow_chatter: true`, so a
//! plan that chatters as executed is answered (status CHATTER) and its figures can be shown.
//!
//! ```sh
//! cargo bench -p kerf_millplan --bench fastest_stable -- --no-dp     # without the per-path DP
//! cargo bench -p kerf_millplan --bench fastest_stable                # with dp (a cache per path)
//! cargo bench -p kerf_millplan --bench fastest_stable -- --paths 1 --planners dp
//! cargo bench -p kerf_millplan --bench fastest_stable -- --planners ddpg,naive,greedy,fixed_g
//! cargo bench -p kerf_millplan --bench fastest_stable -- --check     # only the paths' checks
//! ```
//!
//! Options: `--paths N` keeps the first N paths (in the order default, the ten held-out paths,
//! `arc`, `S`, `tilted line`); `--planners a,b,c` plans with those planners only (default:
//! `ddpg, fixed_g, naive, greedy, greedy_best_g, best, dp`); `--no-dp` leaves `dp` out.
//!
//! The hand-made paths lie in the horizontal plane z = 1.7 m, inside the default path's region
//! (x 1.4–2.1 m, y −0.4…0.4 m), with 100 segments as the cell's default:
//! * `arc`: a circular arc of radius 0.35 m over 90° about (1.75, 0.0), from −135° to −45°
//!   (5 points, 0.55 m);
//! * `S`: two opposite bends of 0.1 m on a 0.7 m chord along x at y = 0 (5 points);
//! * `tilted line`: a straight line at a 30° heading, 0.6 m long from (1.4, −0.35) to
//!   (1.92, −0.05) (4 collinear points: the path accepts collinear points and takes the plane
//!   through the line whose normal is closest to +z, here the horizontal plane). Further
//!   towards +y the line's start is too close to a singularity at g0 = 0 (from (1.45, −0.2):
//!   1/K 0.28 at segment 0, below the distribution's 0.35).
//!
//! Each is checked as the path distribution checks its draws
//! (`path_distribution::check_path`: segment 0 machinable at g0, and a corridor of g with 1/K
//! ≥ the distribution's minimum through every segment), and the check is printed.
//!
//! Figures of a plan, all of `MillPlanOutput::executed`: the trajectory's duration from rest
//! to rest (`executed.scaling.duration()`, the time to compare), chatter-free and max |μ|max of
//! the executed plan (they include the chatter judge of every control-period sample in the
//! material), the worst judged sample (segment, feed), the smallest 1/K along the trajectory,
//! the planning wall time and, for `best`, the planner it chose. Status: SUCCESS when
//! chatter-free, CHATTER otherwise, or the error's status (`status::status_name`).
//!
//! After the table: per path, ddpg's duration over the fastest chatter-free plan of `naive`,
//! `greedy` and `fixed_g`; on the held-out paths, the goal of issue 28 item 4 (ddpg chatter-free
//! wherever any planner is, and ddpg ≤ 0.97 × the fastest chatter-free of naive, greedy and
//! fixed_g, on ≥ 8 of 10); per planner, SUCCESS / CHATTER / other over all paths.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench binary reports failures by panicking

use std::f64::consts::PI;
use std::time::Instant;

#[allow(dead_code)] // each bench uses some of the shared helpers
mod common;

use kerf_mill::{MillCell, PathSpec};
use kerf_millplan::path_distribution::{check_path, PathDistribution};
use kerf_millplan::planner::BEST_MIN_CONDITION_INDICATOR;
use kerf_millplan::status::status_name;
use kerf_millplan::{status_of, MillPlanOutput, MillPlanner, MillRequest};

/// Every planner, in the order of the table.
const PLANNERS: [&str; 7] = [
    "ddpg",
    "fixed_g",
    "naive",
    "greedy",
    "greedy_best_g",
    "best",
    "dp",
];

/// The planners ddpg is compared with.
const OTHERS: [&str; 3] = ["naive", "greedy", "fixed_g"];

/// ddpg's goal: at most this fraction of the fastest chatter-free other.
const GOAL_RATIO: f64 = 0.97;

/// Height of the hand-made paths' plane \[m\].
const Z: f64 = 1.7;

fn value(args: &[String], name: &str) -> Option<String> {
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1).cloned())
}

/// A circular arc of radius 0.35 m over 90° about (1.75, 0.0), 5 points.
fn arc() -> Vec<[f64; 3]> {
    let (cx, cy, r) = (1.75, 0.0, 0.35);
    (0..5)
        .map(|k| {
            let a = -0.75 * PI + 0.5 * PI * k as f64 / 4.0;
            [cx + r * a.cos(), cy + r * a.sin(), Z]
        })
        .collect()
}

/// An S-curve: two opposite bends of 0.1 m on a 0.7 m chord along x, 5 points.
fn s_curve() -> Vec<[f64; 3]> {
    [0.0, 0.1, 0.0, -0.1, 0.0]
        .iter()
        .enumerate()
        .map(|(k, &y)| [1.4 + 0.175 * k as f64, y, Z])
        .collect()
}

/// A straight line at a 30° heading, 0.6 m long from (1.4, −0.35), 4 collinear points.
fn tilted_line() -> Vec<[f64; 3]> {
    let (x0, y0, len) = (1.4, -0.35, 0.6);
    let (s, c) = (PI / 6.0).sin_cos();
    (0..4)
        .map(|k| {
            let t = len * k as f64 / 3.0;
            [x0 + t * c, y0 + t * s, Z]
        })
        .collect()
}

/// The figures of one plan (or its failure).
enum Outcome {
    Plan(Box<MillPlanOutput>),
    Failed {
        status: &'static str,
        message: String,
    },
}

impl Outcome {
    fn plan(&self) -> Option<&MillPlanOutput> {
        match self {
            Self::Plan(o) => Some(o),
            Self::Failed { .. } => None,
        }
    }

    fn status(&self) -> &'static str {
        match self {
            Self::Plan(o) if o.executed.plan.chatter_free => "SUCCESS",
            Self::Plan(_) => "CHATTER",
            Self::Failed { status, .. } => status,
        }
    }

    /// The executed duration of a chatter-free plan.
    fn chatter_free_duration(&self) -> Option<f64> {
        self.plan()
            .filter(|o| o.executed.plan.chatter_free)
            .map(|o| o.executed.scaling.duration())
    }

    /// The executed duration of a chatter-free plan whose 1/K stays at or above `min`.
    fn acceptable_duration(&self, min: f64) -> Option<f64> {
        self.plan()
            .filter(|o| o.executed.scaling.min_condition_indicator.0 >= min)
            .and(self.chatter_free_duration())
    }

    /// The table cell.
    fn cell(&self) -> String {
        match self {
            Self::Plan(o) => {
                let e = &o.executed;
                let figures = format!(
                    "{:.2} s, {}{:.3}, 1/K {:.3}",
                    e.scaling.duration(),
                    if e.plan.chatter_free { "yes " } else { "" },
                    e.plan.max_spectral_radius,
                    e.scaling.min_condition_indicator.0
                );
                // Only `best` lists its candidates.
                let chosen = if !o.candidates.is_empty() {
                    format!(" → {}", o.planner.name())
                } else {
                    String::new()
                };
                if e.plan.chatter_free {
                    format!("{figures}{chosen}")
                } else {
                    format!("CHATTER {figures}{chosen}")
                }
            }
            Self::Failed { status, message } => {
                format!("{status}: {}", truncate(message, 80).replace('|', "/"))
            }
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

fn main() {
    let started = Instant::now();
    let args: Vec<String> = std::env::args().skip(1).collect();
    let flag = |name: &str| args.iter().any(|a| a == name);
    let planners: Vec<&str> = match value(&args, "--planners") {
        Some(list) => list
            .split(',')
            .map(str::trim)
            .filter(|p| !p.is_empty())
            .map(|p| {
                *PLANNERS
                    .iter()
                    .find(|k| **k == p)
                    .unwrap_or_else(|| panic!("unknown planner `{p}`: one of {PLANNERS:?}"))
            })
            .collect(),
        None => PLANNERS.to_vec(),
    };
    let planners: Vec<&str> = planners
        .into_iter()
        .filter(|p| !(flag("--no-dp") && *p == "dp"))
        .collect();

    let base = MillCell::default_cell().unwrap();
    let dist = PathDistribution::default();
    let mut paths = common::default_and_held_out_paths();
    for (name, points) in [
        ("arc", arc()),
        ("S", s_curve()),
        ("tilted line", tilted_line()),
    ] {
        let spec = PathSpec {
            points: points.clone(),
            ..PathSpec::default()
        };
        let label = match base.with_path(&spec) {
            Ok(cell) => {
                let verdict = match check_path(&cell, dist.initial_g, dist.min_condition_indicator)
                {
                    Ok(None) => "accepted by check_path".to_string(),
                    Ok(Some(why)) => {
                        let first = match cell.evaluate(0, dist.initial_g, None) {
                            Ok(c) => format!("1/K {:.3}", c.condition_indicator),
                            Err(e) => e.to_string(),
                        };
                        format!(
                            "refused by check_path: {why} (segment 0 at g0: {first}); planned \
                             all the same"
                        )
                    }
                    Err(e) => format!("check_path failed: {e}"),
                };
                println!(
                    "hand-made path `{name}` ({:.2} m): {points:.3?}: {verdict}",
                    cell.path().total_length()
                );
                format!("{name} ({:.2} m)", cell.path().total_length())
            }
            Err(e) => {
                println!("hand-made path `{name}`: {points:.3?}: the cell refuses it: {e}");
                name.to_string()
            }
        };
        paths.push((label, points, false));
    }
    if flag("--check") {
        return;
    }
    if let Some(n) = value(&args, "--paths") {
        paths.truncate(n.parse().expect("--paths takes a number"));
    }

    let planner = MillPlanner::with_default_cell().unwrap();
    // outcomes[path][planner], in the order of `paths` and `planners`.
    let mut outcomes: Vec<Vec<Outcome>> = Vec::new();
    for (name, points, _) in &paths {
        let mut row = Vec::new();
        for kind in &planners {
            let request = MillRequest {
                request_id: format!("{name}/{kind}"),
                points: points.clone(),
                planner: (*kind).into(),
                allow_chatter: true,
                ..MillRequest::default()
            };
            let t = Instant::now();
            let outcome = match planner.plan(&request) {
                Ok(out) => Outcome::Plan(Box::new(out)),
                Err(e) => Outcome::Failed {
                    status: status_name(status_of(&e)).unwrap_or("UNKNOWN_STATUS"),
                    message: e.to_string(),
                },
            };
            eprintln!(
                "{name} {kind}: {} ({:.2} s wall)",
                outcome.cell(),
                t.elapsed().as_secs_f64()
            );
            if let Outcome::Failed { status, .. } = &outcome {
                if matches!(*status, "INTERNAL_ERROR" | "POLICY_ERROR") {
                    eprintln!("  BUG? {name} {kind}: {status}");
                }
            }
            row.push(outcome);
        }
        outcomes.push(row);
    }

    // The table: a path per row, a planner per column.
    println!(
        "\nexecuted duration from rest to rest, chatter-free (yes) and max |μ|max as executed, \
         min 1/K along the trajectory; `best` → the planner it chose\n"
    );
    println!("| path | {} |", planners.join(" | "));
    println!("|---|{}", "---|".repeat(planners.len()));
    for ((name, _, _), row) in paths.iter().zip(&outcomes) {
        let cells: Vec<String> = row.iter().map(Outcome::cell).collect();
        println!("| {name} | {} |", cells.join(" | "));
    }

    // Every plan in detail.
    println!(
        "\n| path | planner | status | duration (s) | chatter-free | max \\|μ\\|max | worst sample \
         (segment, feed mm/s) | samples / evaluations | min 1/K (at m) | chosen | planning (s) |"
    );
    println!("|---|---|---|---:|---|---:|---|---:|---|---|---:|");
    for ((name, _, _), row) in paths.iter().zip(&outcomes) {
        for (kind, outcome) in planners.iter().zip(row) {
            match outcome {
                Outcome::Plan(o) => {
                    let e = &o.executed;
                    let worst = e.chatter.worst.as_ref().map_or("-".to_string(), |w| {
                        format!("{}, {:.2}", w.segment, w.feed * 1e3)
                    });
                    let (ci, at) = e.scaling.min_condition_indicator;
                    println!(
                        "| {name} | {kind} | {} | {:.2} | {} | {:.3} | {worst} | {} / {} | {ci:.3} \
                         ({at:.3}) | {} | {:.2} |",
                        outcome.status(),
                        e.scaling.duration(),
                        if e.plan.chatter_free { "yes" } else { "**no**" },
                        e.plan.max_spectral_radius,
                        e.chatter.samples,
                        e.chatter.evaluations,
                        o.planner.name(),
                        o.planning_seconds
                    );
                }
                Outcome::Failed { status, message } => println!(
                    "| {name} | {kind} | {status} | | | | | | | | {} |",
                    message.replace('|', "/")
                ),
            }
        }
    }

    // ddpg against the fastest chatter-free other, per path.
    let column = |p: &str| planners.iter().position(|k| *k == p);
    println!(
        "\nddpg / fastest chatter-free of naive, greedy, fixed_g (executed durations); in \
         brackets: / the fastest of them that is chatter-free and keeps 1/K >= \
         {BEST_MIN_CONDITION_INDICATOR} (`best`'s criterion):"
    );
    let mut held = 0;
    let mut free_where_any = 0;
    let mut faster = 0;
    let mut faster_conditioned = 0;
    let mut no_other = 0;
    for ((name, _, held_out), row) in paths.iter().zip(&outcomes) {
        let Some(d) = column("ddpg").map(|c| &row[c]) else {
            println!("- {name}: ddpg not run");
            continue;
        };
        let fastest = |duration: &dyn Fn(&Outcome) -> Option<f64>| {
            OTHERS
                .iter()
                .filter_map(|p| column(p).map(|c| (*p, &row[c])))
                .filter_map(|(p, o)| duration(o).map(|t| (p, t)))
                .min_by(|a, b| a.1.total_cmp(&b.1))
        };
        let other = fastest(&Outcome::chatter_free_duration);
        let conditioned =
            fastest(&|o: &Outcome| o.acceptable_duration(BEST_MIN_CONDITION_INDICATOR));
        let any_free = row.iter().any(|o| o.chatter_free_duration().is_some());
        let ddpg_free = d.chatter_free_duration();
        let ratio_to = |other: Option<(&str, f64)>| match (d.plan(), other) {
            (Some(o), Some((p, t))) => {
                let r = o.executed.scaling.duration() / t;
                format!(
                    "{:.2} s / {t:.2} s ({p}) = {r:.3}{}",
                    o.executed.scaling.duration(),
                    if r <= GOAL_RATIO { " (<= 0.97)" } else { "" }
                )
            }
            (Some(o), None) => format!(
                "{:.2} s / none of them qualifies",
                o.executed.scaling.duration()
            ),
            (None, _) => format!("ddpg {}", d.status()),
        };
        println!(
            "- {name}: {} [{}]; ddpg chatter-free: {}",
            ratio_to(other),
            ratio_to(conditioned),
            if ddpg_free.is_some() { "yes" } else { "no" }
        );
        if *held_out {
            held += 1;
            if ddpg_free.is_some() || !any_free {
                free_where_any += 1;
            }
            if other.is_none() {
                no_other += 1;
            }
            if let (Some(t), Some((_, best))) = (ddpg_free, other) {
                if t <= GOAL_RATIO * best {
                    faster += 1;
                }
            }
            if let (Some(t), Some((_, best))) = (ddpg_free, conditioned) {
                if t <= GOAL_RATIO * best {
                    faster_conditioned += 1;
                }
            }
        }
    }
    if column("ddpg").is_some() && held > 0 {
        println!(
            "\nheld-out paths where ddpg is chatter-free wherever any planner is: {free_where_any} \
             of {held}; where ddpg is chatter-free and its duration <= {GOAL_RATIO} x the fastest \
             chatter-free of naive, greedy and fixed_g: {faster} of {held} (goal of issue 28 item \
             4: >= 8 of 10; {no_other} of the {held} have no chatter-free naive, greedy or \
             fixed_g to compare with); against those of them with 1/K >= \
             {BEST_MIN_CONDITION_INDICATOR} too: {faster_conditioned} of {held}"
        );
    }

    println!("\nper planner over {} paths:", paths.len());
    println!("\n| planner | SUCCESS | CHATTER | other |");
    println!("|---|---:|---:|---|");
    for (c, kind) in planners.iter().enumerate() {
        let count = |s: &str| outcomes.iter().filter(|r| r[c].status() == s).count();
        let others: Vec<String> = outcomes
            .iter()
            .zip(&paths)
            .filter(|(r, _)| !matches!(r[c].status(), "SUCCESS" | "CHATTER"))
            .map(|(r, (name, _, _))| format!("{name}: {}", r[c].status()))
            .collect();
        println!(
            "| {kind} | {} | {} | {} |",
            count("SUCCESS"),
            count("CHATTER"),
            if others.is_empty() {
                "0".to_string()
            } else {
                format!("{}: {}", others.len(), others.join("; "))
            }
        );
    }
    let failures: Vec<String> = paths
        .iter()
        .zip(&outcomes)
        .flat_map(|((name, _, _), row)| {
            planners
                .iter()
                .zip(row)
                .filter_map(move |(kind, o)| match o {
                    Outcome::Failed { status, message } => {
                        Some(format!("- {name}, {kind}: {status}: {message}"))
                    }
                    Outcome::Plan(_) => None,
                })
        })
        .collect();
    if !failures.is_empty() {
        println!("\nplans that failed, with their messages in full:\n");
        println!("{}", failures.join("\n"));
    }
    println!(
        "\nwall time of the run: {:.1} s",
        started.elapsed().as_secs_f64()
    );
}
