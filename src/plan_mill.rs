//! `kerf plan mill`: plans one milling request offline, without ROS (issue 5 section 4).
//!
//! ```sh
//! kerf plan mill --request FILE [--plots DIR] [--out plan.json|plan.yaml]
//!                [--planners ddpg,fixed_g,dp,naive,greedy,greedy_best_g]
//!                [--ddpg-policy F] [--fixed-g-policy F]
//!                [--indicator direct|cache] [--all-rows]
//! ```
//!
//! Reads a [`MillRequest`] (YAML, or JSON when the name ends in `.json`: the schema of the
//! milling planner node's text topic), plans it with [`MillPlanner::with_default_cell`] (the
//! shipped cell and indicator cache) and prints, per planner:
//!
//! * a header: request id, planner, policy file, indicator provenance, planning time;
//! * a per-segment table — segment, Ω \[rpm\], f \[m/s\], g \[rad\], |μ|max, 1/K, segment time
//!   \[s\], reward (eq. 12) — every segment for paths of up to 20 segments (or with
//!   `--all-rows`), else every 10th segment and the last;
//! * the totals: machining time, chatter-free, max |μ|max, min 1/K, total reward;
//! * the same totals AS EXECUTED ([`kerf_millplan::Executed`]): the trajectory the robot runs,
//!   from rest to rest and time-scaled so that its cubic Hermite interpolation stays within
//!   every joint's velocity and acceleration limit, and the plan at the feeds it runs (|μ|max
//!   and reward re-evaluated where the limits lowered a feed; the machining time is the
//!   trajectory's duration), with the number of trajectory intervals slowed, the lowest feed
//!   and, with `--indicator cache`, how many executed |μ|max values are the cache's;
//!
//! and, with several planners, the comparison table of issue 5
//! ([`kerf_millplan::comparison_table`]) of the plans as planned, then the same table of the
//! plans as executed.
//!
//! `--planners` plans the same request with each listed planner instead of the request's
//! `planner`. The policy of `ddpg` is `--ddpg-policy`, else the request's `policy_file` when
//! the request names `ddpg`, else the shipped default; likewise `fixed_g` with
//! `--fixed-g-policy`. A planner that fails prints its status and message and the others
//! still run; the plots and `--out` hold the plans that succeeded.
//!
//! `--plots DIR` writes `mill_plan_<planner>.svg` per plan and, with two or more plans,
//! `mill_plan_comparison.svg` overlaying them (seed 004 Fig. 6 / Fig. 8 panels,
//! [`crate::plots::mill_plan::plan_panels`]; the plans as planned). `--out` writes every plan and
//! every failure as JSON, or YAML when the name ends in `.yaml`/`.yml`: per plan the
//! `segments` and `totals` as planned, `executed` (its `totals` and `segments` as executed,
//! and the time scaling: stretch per trajectory interval, intervals slowed, rounds), the
//! `trajectory` the robot runs (executed: from rest to rest, time-scaled to the joint
//! limits) and the `planned_trajectory` (timed by the planned feeds, not from rest).
//!
//! Exit code 0 when every planner succeeded; 2 otherwise (an unreadable or invalid request,
//! any planner's failure — its status name, code and message are printed — or an output
//! that cannot be written).

mod document;
mod report;

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use kerf_millplan::{
    comparison_table,
    plan::{IndicatorSource, Plan},
    planner::status_name,
    status_of, MillPlanError, MillPlanOutput, MillPlanner, MillRequest, PlannerKind,
};

use crate::{
    input::{self, InputFile},
    output_paths,
    plots::mill_plan,
};

pub use report::describe;
use report::{plan_report, request_label, totals_title};

/// Where the plans' |μ|max values come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum IndicatorArg {
    /// Every segment evaluated directly with the chatter model (default).
    Direct,
    /// The indicator cache's interpolation where it applies, with its stated error bound.
    Cache,
}

/// Arguments of `kerf plan mill`.
#[derive(Args, Debug)]
pub struct MillArgs {
    /// Request file, YAML or JSON (`points`, optional `segments`, `process`, `limits`,
    /// `initial`, `planner`, `policy_file`; at most 4 MiB, `-` reads standard input as YAML).
    #[arg(long)]
    request: InputFile,
    /// Write the per-segment plots (SVG, seed 004 Fig. 6 / Fig. 8) into this directory.
    #[arg(long)]
    plots: Option<PathBuf>,
    /// Write the plans as JSON (or YAML for .yaml/.yml) here.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Plan with these planners (comma-separated: ddpg, fixed_g, dp, naive, greedy,
    /// greedy_best_g) instead of the request's.
    #[arg(long, value_delimiter = ',')]
    planners: Vec<String>,
    /// Policy of the ddpg planner (default: the request's policy_file, else the shipped one;
    /// a regular file of at most 64 MiB).
    #[arg(long)]
    ddpg_policy: Option<InputFile>,
    /// Policy of the fixed_g planner (default: the request's policy_file, else the shipped one;
    /// a regular file of at most 64 MiB).
    #[arg(long)]
    fixed_g_policy: Option<InputFile>,
    /// Source of the plans' |mu|max values.
    #[arg(long, value_enum, default_value_t = IndicatorArg::Direct)]
    indicator: IndicatorArg,
    /// Print every segment of the table (default: every 10th for paths over 20 segments).
    #[arg(long)]
    all_rows: bool,
}

/// Output format of `--out`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum OutFormat {
    Json,
    Yaml,
}

fn out_format(path: &std::path::Path) -> Result<OutFormat, String> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("json") => Ok(OutFormat::Json),
        Some("yaml" | "yml") => Ok(OutFormat::Yaml),
        _ => Err(format!(
            "--out {}: the name must end in .json, .yaml or .yml",
            path.display()
        )),
    }
}

/// The planners to run: `--planners` (parsed, duplicates dropped) or the request's.
fn planner_list(a: &MillArgs, request: &MillRequest) -> Result<Vec<PlannerKind>, String> {
    if a.planners.is_empty() {
        return request
            .planner_kind()
            .map(|k| vec![k])
            .map_err(|e| format!("{}: {}", a.request, describe(&e)));
    }
    let mut kinds = Vec::new();
    for name in &a.planners {
        let k = PlannerKind::parse(name.trim()).map_err(|e| format!("--planners: {e}"))?;
        if !kinds.contains(&k) {
            kinds.push(k);
        }
    }
    Ok(kinds)
}

/// The request as planned by `kind` (module documentation: which policy file).
fn request_for(a: &MillArgs, request: &MillRequest, kind: PlannerKind) -> MillRequest {
    let mut r = request.clone();
    r.planner = kind.name().to_string();
    let own = request.planner_kind().ok() == Some(kind);
    let path = |p: &Option<InputFile>| p.as_ref().map(|p| p.path().display().to_string());
    r.policy_file = match kind {
        PlannerKind::Ddpg => path(&a.ddpg_policy).or(if own {
            request.policy_file.clone()
        } else {
            None
        }),
        PlannerKind::FixedG => path(&a.fixed_g_policy).or(if own {
            request.policy_file.clone()
        } else {
            None
        }),
        PlannerKind::Dp
        | PlannerKind::Naive
        | PlannerKind::Greedy
        | PlannerKind::GreedyBestG
        | PlannerKind::Best => None,
    };
    r
}

/// Runs `kerf plan mill`.
///
/// # Errors
/// The message to print; the caller exits with code 2.
pub fn run(a: MillArgs) -> Result<(), String> {
    let format = a.out.as_deref().map(out_format).transpose()?;
    if let Some(o) = &a.out {
        output_paths::check_writable("--out", o)?;
    }
    if let Some(d) = &a.plots {
        output_paths::check_dir_writable("--plots", d)?;
    }
    let text = input::read_text("--request", &a.request, input::REQUEST_CAP)?;
    // The policies are read by the planner (kerf_robot::file::read_regular); checked here
    // first so that a refusal names the argument.
    for (arg, f) in [
        ("--ddpg-policy", &a.ddpg_policy),
        ("--fixed-g-policy", &a.fixed_g_policy),
    ] {
        // A missing policy is the planner's POLICY_ERROR (the other planners still run).
        if let Some(f) = f.as_ref().filter(|f| f.is_stdin() || f.path().exists()) {
            input::check_file(arg, f, kerf_millplan::policy::MAX_POLICY_BYTES)?;
        }
    }
    let parsed = if a
        .request
        .path()
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
    {
        MillRequest::from_json_str(&text)
    } else {
        MillRequest::from_yaml_str(&text)
    };
    let request = parsed.map_err(|e| format!("--request {}: {}", a.request, describe(&e)))?;
    crate::input::check_offline_start(&format!("--request {}", a.request), &request.start)?;
    let kinds = planner_list(&a, &request)?;
    let mut planner = MillPlanner::with_default_cell()
        .map_err(|e| format!("milling cell: {}", describe(&e)))?
        .with_indicator_source(match a.indicator {
            IndicatorArg::Direct => IndicatorSource::Direct,
            IndicatorArg::Cache => IndicatorSource::Cache,
        });
    // `best` runs ddpg and fixed_g with these policies.
    for (kind, f) in [
        (PlannerKind::Ddpg, &a.ddpg_policy),
        (PlannerKind::FixedG, &a.fixed_g_policy),
    ] {
        if let Some(f) = f {
            planner = planner.with_default_policy(kind, f.path().to_path_buf());
        }
    }

    let mut outputs: Vec<MillPlanOutput> = Vec::new();
    let mut failures: Vec<(PlannerKind, MillPlanError)> = Vec::new();
    for &kind in &kinds {
        let r = request_for(&a, &request, kind);
        match planner.plan(&r) {
            Ok(out) => {
                print!("{}", plan_report(&out, a.all_rows));
                outputs.push(out);
            }
            Err(e) => {
                let msg = format!(
                    "{}planner {}: {}",
                    request_label(&request.request_id),
                    kind.name(),
                    describe(&e)
                );
                // With several planners the failure is part of the report; alone, it is the
                // error message.
                if kinds.len() > 1 {
                    println!("{msg}");
                    eprintln!("kerf: {msg}");
                }
                failures.push((kind, e));
            }
        }
    }
    if kinds.len() > 1 {
        let rows: Vec<_> = outputs.iter().map(|o| o.plan.row()).collect();
        println!(
            "\ncomparison ({} of {} planners planned):",
            rows.len(),
            kinds.len()
        );
        print!("{}", comparison_table(&rows));
        let executed: Vec<_> = outputs.iter().map(|o| o.executed.plan.row()).collect();
        println!(
            "\nas executed (time-scaled to the joint limits; machining time in the material):"
        );
        print!("{}", comparison_table(&executed));
        println!(
            "\ntrajectory from rest to rest (run-in, the path, run-out), as compared by best:"
        );
        for o in &outputs {
            println!(
                "{}: {:.3} s, {}",
                o.planner.name(),
                o.executed.scaling.duration(),
                if o.executed.chatters() {
                    "CHATTERS as executed"
                } else {
                    "chatter-free at every executed sample"
                }
            );
        }
        for (kind, e) in &failures {
            println!("{}: failed: {}", kind.name(), describe(e));
        }
    }

    if let (Some(path), Some(format)) = (&a.out, format) {
        let doc = document::document(&request, &outputs, &failures);
        let text = match format {
            OutFormat::Json => serde_json::to_string_pretty(&doc)
                .map_err(|e| format!("cannot serialize the plans: {e}"))?,
            OutFormat::Yaml => serde_yaml_ng::to_string(&doc)
                .map_err(|e| format!("cannot serialize the plans: {e}"))?,
        };
        std::fs::write(path, text)
            .map_err(|e| format!("--out {}: cannot write: {e}", path.display()))?;
        println!("plans written to {}", path.display());
    }
    if let Some(dir) = &a.plots {
        let id = request_label(&request.request_id);
        let mut files = Vec::new();
        for o in &outputs {
            let name = o.planner.name();
            let file = dir.join(format!("mill_plan_{name}.svg"));
            mill_plan::plan_panels(
                &file,
                &[(name, &o.plan)],
                &format!("{id}planner {name}: {}", totals_title(&o.plan)),
            )?;
            files.push(file);
        }
        if outputs.len() > 1 {
            let file = dir.join("mill_plan_comparison.svg");
            let plans: Vec<(&str, &Plan)> = outputs
                .iter()
                .map(|o| (o.planner.name(), &o.plan))
                .collect();
            mill_plan::plan_panels(&file, &plans, &format!("{id}planners compared"))?;
            files.push(file);
        }
        if !files.is_empty() {
            println!("{} plot(s) written to {}", files.len(), dir.display());
        }
    }

    match failures.as_slice() {
        [] => Ok(()),
        [(kind, e)] if kinds.len() == 1 => Err(format!(
            "{}planner {}: {}",
            request_label(&request.request_id),
            kind.name(),
            describe(e)
        )),
        _ => Err(format!(
            "{} of {} planners failed: {}",
            failures.len(),
            kinds.len(),
            failures
                .iter()
                .map(|(k, e)| format!(
                    "{} ({})",
                    k.name(),
                    status_name(status_of(e)).unwrap_or("?")
                ))
                .collect::<Vec<_>>()
                .join(", ")
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn out_names_choose_the_format() {
        use std::path::Path;
        assert_eq!(out_format(Path::new("a/p.json")), Ok(OutFormat::Json));
        assert_eq!(out_format(Path::new("p.YML")), Ok(OutFormat::Yaml));
        assert_eq!(out_format(Path::new("p.yaml")), Ok(OutFormat::Yaml));
        assert!(out_format(Path::new("p.txt"))
            .unwrap_err()
            .contains("must end in .json, .yaml or .yml"));
    }
}
