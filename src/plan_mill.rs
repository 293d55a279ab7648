//! `kerf plan mill`: plans one milling request offline, without ROS (issue 5 section 4).
//!
//! ```sh
//! kerf plan mill --request FILE [--plots DIR] [--out plan.json|plan.yaml]
//!                [--planners ddpg,fixed_g,dp,naive] [--ddpg-policy F] [--fixed-g-policy F]
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
//! [`crate::mill_plots::plan_panels`]; the plans as planned). `--out` writes every plan and
//! every failure as JSON, or YAML when the name ends in `.yaml`/`.yml`: per plan the
//! `segments` and `totals` as planned, `executed` (its `totals` and `segments` as executed,
//! and the time scaling: stretch per trajectory interval, intervals slowed, rounds), the
//! `trajectory` the robot runs (executed: from rest to rest, time-scaled to the joint
//! limits) and the `planned_trajectory` (timed by the planned feeds, not from rest).
//!
//! Exit code 0 when every planner succeeded; 2 otherwise (an unreadable or invalid request,
//! any planner's failure — its status name, code and message are printed — or an output
//! that cannot be written).

use std::{fmt::Write as _, path::PathBuf};

use clap::{Args, ValueEnum};
use kerf_millplan::{
    comparison_table,
    plan::{IndicatorSource, Plan},
    planner::status_name,
    status_of, JointTrajectory, MillPlanError, MillPlanOutput, MillPlanner, MillRequest,
    PlannerKind,
};
use serde_json::{json, Value};

use crate::{mill_plots, train_mill};

/// Paths with at most this many segments print every row of the table.
const ALL_ROWS_UP_TO: usize = 20;

/// Row stride of the table of longer paths.
const ROW_STRIDE: usize = 10;

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
    /// `initial`, `planner`, `policy_file`).
    #[arg(long)]
    request: PathBuf,
    /// Write the per-segment plots (SVG, seed 004 Fig. 6 / Fig. 8) into this directory.
    #[arg(long)]
    plots: Option<PathBuf>,
    /// Write the plans as JSON (or YAML for .yaml/.yml) here.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Plan with these planners (comma-separated: ddpg, fixed_g, dp, naive) instead of the
    /// request's.
    #[arg(long, value_delimiter = ',')]
    planners: Vec<String>,
    /// Policy of the ddpg planner (default: the request's policy_file, else the shipped one).
    #[arg(long)]
    ddpg_policy: Option<PathBuf>,
    /// Policy of the fixed_g planner (default: the request's policy_file, else the shipped one).
    #[arg(long)]
    fixed_g_policy: Option<PathBuf>,
    /// Source of the plans' |mu|max values.
    #[arg(long, value_enum, default_value_t = IndicatorArg::Direct)]
    indicator: IndicatorArg,
    /// Print every segment of the table (default: every 10th for paths over 20 segments).
    #[arg(long)]
    all_rows: bool,
}

/// "STATUS (code): message" of a planner error.
pub fn describe(e: &MillPlanError) -> String {
    let code = status_of(e);
    let name = status_name(code).unwrap_or("?");
    format!("{name} ({code}): {e}")
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
            .map_err(|e| format!("{}: {}", a.request.display(), describe(&e)));
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
    let path = |p: &Option<PathBuf>| p.as_ref().map(|p| p.display().to_string());
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
        PlannerKind::Dp | PlannerKind::Naive => None,
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
        train_mill::check_writable("--out", o)?;
    }
    if let Some(d) = &a.plots {
        train_mill::check_dir_writable("--plots", d)?;
    }
    let text = std::fs::read_to_string(&a.request)
        .map_err(|e| format!("cannot read {}: {e}", a.request.display()))?;
    let parsed = if a
        .request
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
    {
        MillRequest::from_json_str(&text)
    } else {
        MillRequest::from_yaml_str(&text)
    };
    let request = parsed.map_err(|e| format!("{}: {}", a.request.display(), describe(&e)))?;
    let kinds = planner_list(&a, &request)?;
    let planner = MillPlanner::with_default_cell()
        .map_err(|e| format!("milling cell: {}", describe(&e)))?
        .with_indicator_source(match a.indicator {
            IndicatorArg::Direct => IndicatorSource::Direct,
            IndicatorArg::Cache => IndicatorSource::Cache,
        });

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
        println!("\nas executed (time-scaled to the joint limits, from rest to rest):");
        print!("{}", comparison_table(&executed));
        for (kind, e) in &failures {
            println!("{}: failed: {}", kind.name(), describe(e));
        }
    }

    if let (Some(path), Some(format)) = (&a.out, format) {
        let doc = document(&request, &outputs, &failures);
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
            mill_plots::plan_panels(
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
            mill_plots::plan_panels(&file, &plans, &format!("{id}planners compared"))?;
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

/// `request 'ID', ` for a request with an id, nothing otherwise.
fn request_label(id: &str) -> String {
    if id.is_empty() {
        String::new()
    } else {
        format!("request '{id}', ")
    }
}

/// Short totals for a plot title.
fn totals_title(p: &Plan) -> String {
    format!(
        "time {:.2} s, max |mu|max {:.3}, min 1/K {:.3}, reward {:.2}",
        p.total_time, p.max_spectral_radius, p.min_condition_indicator, p.total_reward
    )
}

/// The segments a table shows: all when `all` or the path is short, else every
/// [`ROW_STRIDE`]th and the last.
pub fn table_rows(n: usize, all: bool) -> Vec<usize> {
    if all || n <= ALL_ROWS_UP_TO {
        return (0..n).collect();
    }
    let mut rows: Vec<usize> = (0..n).step_by(ROW_STRIDE).collect();
    if rows.last() != Some(&(n - 1)) {
        rows.push(n - 1);
    }
    rows
}

/// The totals line of a plan (parsed by `tests/mill_cli.rs`: keep the wording).
pub fn totals_line(p: &Plan) -> String {
    format!(
        "totals: machining time {:.6} s, chatter-free {}, max |μ|max {:.6}, min 1/K {:.6}, \
         total reward {:.6}",
        p.total_time,
        if p.chatter_free { "yes" } else { "no" },
        p.max_spectral_radius,
        p.min_condition_indicator,
        p.total_reward
    )
}

/// The totals line of a plan as executed (`o.executed`; parsed by `tests/mill_cli.rs`: keep
/// the wording): the totals of [`totals_line`] and how much the joint limits slowed it.
pub fn executed_line(o: &MillPlanOutput) -> String {
    let (p, sc) = (&o.executed.plan, &o.executed.scaling);
    let lowest_feed = p
        .segments
        .iter()
        .map(|g| g.feed)
        .fold(f64::INFINITY, f64::min);
    let cached = match o.executed.cached_segments.len() {
        0 => String::new(),
        k => format!(", |μ|max of {k} segments from the indicator cache"),
    };
    format!(
        "as executed (time-scaled to the joint limits, from rest to rest): machining time \
         {:.6} s, chatter-free {}, max |μ|max {:.6}, min 1/K {:.6}, total reward {:.6}, {} of \
         {} trajectory intervals slowed, lowest feed {:.5} m/s{cached}",
        p.total_time,
        if p.chatter_free { "yes" } else { "no" },
        p.max_spectral_radius,
        p.min_condition_indicator,
        p.total_reward,
        sc.stretched_intervals(),
        sc.interval_stretch.len(),
        lowest_feed
    )
}

/// The printed report of one plan: header, table, totals as planned and as executed, branch
/// jumps.
fn plan_report(o: &MillPlanOutput, all_rows: bool) -> String {
    let mut s = String::new();
    let p = &o.plan;
    let _ = writeln!(
        s,
        "{}planner {}: SUCCESS (0): {} segments, planned in {:.3} s{}",
        request_label(&o.request_id),
        o.planner.name(),
        p.segments.len(),
        o.planning_seconds,
        o.policy_file
            .as_ref()
            .map_or(String::new(), |f| format!(", policy {}", f.display()))
    );
    let _ = writeln!(
        s,
        "  indicator: {}; default cell's cache {}",
        o.indicator.note,
        if o.cache_used {
            "applied"
        } else {
            "not applied"
        }
    );
    let _ = writeln!(
        s,
        "  {:>7} {:>9} {:>9} {:>8} {:>8} {:>7} {:>8} {:>8}",
        "segment", "Ω [rpm]", "f [m/s]", "g [rad]", "|μ|max", "1/K", "time [s]", "reward"
    );
    let rows = table_rows(p.segments.len(), all_rows);
    for &i in &rows {
        let g = &p.segments[i];
        let _ = writeln!(
            s,
            "  {:>7} {:>9.2} {:>9.5} {:>8.4} {:>8.4} {:>7.4} {:>8.4} {:>8.4}",
            g.segment,
            g.rpm,
            g.feed,
            g.g,
            g.spectral_radius,
            g.condition_indicator,
            g.time,
            g.reward.total
        );
    }
    if rows.len() < p.segments.len() {
        let _ = writeln!(
            s,
            "  ({} of {} segments shown; --all-rows shows every one)",
            rows.len(),
            p.segments.len()
        );
    }
    let _ = writeln!(s, "  {}", totals_line(p));
    let _ = writeln!(s, "  {}", executed_line(o));
    if o.plan.chatter_free && !o.executed.plan.chatter_free {
        let _ = writeln!(
            s,
            "  warning: chatter-free as planned but NOT as executed: the joint limits slow it \
             to feeds where |μ|max >= 1"
        );
    }
    for j in &o.branch_jumps {
        let _ = writeln!(
            s,
            "  warning: {} jumps {:.4} rad at trajectory point {} (IK branch change?)",
            j.joint, j.step, j.index
        );
    }
    s
}

/// The totals of a plan in the `--out` document.
fn totals_json(p: &Plan) -> Value {
    json!({
        "machining_time_s": p.total_time,
        "chatter_free": p.chatter_free,
        "max_spectral_radius": p.max_spectral_radius,
        "min_condition_indicator": p.min_condition_indicator,
        "total_reward": p.total_reward,
    })
}

/// A joint trajectory in the `--out` document.
fn trajectory_json(t: &JointTrajectory) -> Value {
    json!({
        "joint_names": t.joint_names,
        "points": t.points.iter().map(|t| json!({
            "time_from_start_s": t.time_from_start,
            "positions_rad": t.positions,
            "velocities_rad_per_s": t.velocities,
            "arc_length_m": t.arc_length,
            "segment": t.segment,
        })).collect::<Vec<_>>(),
    })
}

/// The `--out` document (module documentation): the request id, every plan and every
/// failure.
fn document(
    request: &MillRequest,
    outputs: &[MillPlanOutput],
    failures: &[(PlannerKind, MillPlanError)],
) -> Value {
    let plans: Vec<Value> = outputs
        .iter()
        .map(|o| {
            let p = &o.plan;
            let (x, sc) = (&o.executed.plan, &o.executed.scaling);
            json!({
                "planner": o.planner.name(),
                "policy_file": o.policy_file.as_ref().map(|f| f.display().to_string()),
                "status": 0,
                "status_name": "SUCCESS",
                "planning_seconds": o.planning_seconds,
                "cache_used": o.cache_used,
                "indicator": {
                    "requested": o.indicator.requested.name(),
                    "cached_segments": o.indicator.cached_segments,
                    "error_bound": o.indicator.error_bound,
                    "note": o.indicator.note,
                },
                "totals": totals_json(p),
                "segments": p.segments.iter().map(|g| json!({
                    "segment": g.segment,
                    "spindle_rpm": g.rpm,
                    "feed_m_per_s": g.feed,
                    "g_rad": g.g,
                    "spectral_radius": g.spectral_radius,
                    "condition_number": g.condition_number,
                    "condition_indicator": g.condition_indicator,
                    "joints_rad": g.joints,
                    "time_s": g.time,
                    "reward": {
                        "operational": g.reward.operational,
                        "efficiency": g.reward.efficiency,
                        "stability": g.reward.stability,
                        "total": g.reward.total,
                    },
                })).collect::<Vec<_>>(),
                "executed": {
                    "totals": totals_json(x),
                    "segments": x.segments.iter().map(|g| json!({
                        "segment": g.segment,
                        "feed_m_per_s": g.feed,
                        "spectral_radius": g.spectral_radius,
                        "time_s": g.time,
                        "reward": g.reward.total,
                    })).collect::<Vec<_>>(),
                    "cached_segments": o.executed.cached_segments,
                    "time_scaling": {
                        "interval_stretch": sc.interval_stretch,
                        "stretched_intervals": sc.stretched_intervals(),
                        "rounds": sc.rounds,
                        "uniform": sc.uniform,
                        "duration_s": sc.duration(),
                    },
                },
                "trajectory": trajectory_json(&sc.trajectory),
                "planned_trajectory": trajectory_json(&o.trajectory),
                "branch_jumps": o.branch_jumps.iter().map(|j| json!({
                    "index": j.index, "joint": j.joint, "step_rad": j.step,
                })).collect::<Vec<_>>(),
            })
        })
        .collect();
    let failed: Vec<Value> = failures
        .iter()
        .map(|(k, e)| {
            let code = status_of(e);
            json!({
                "planner": k.name(),
                "status": code,
                "status_name": status_name(code).unwrap_or("?"),
                "message": e.to_string(),
            })
        })
        .collect();
    json!({
        "request_id": request.request_id,
        "plans": plans,
        "failures": failed,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_tables_show_every_tenth_segment_and_the_last() {
        assert_eq!(table_rows(5, false), vec![0, 1, 2, 3, 4]);
        assert_eq!(table_rows(20, false).len(), 20);
        assert_eq!(
            table_rows(100, false),
            vec![0, 10, 20, 30, 40, 50, 60, 70, 80, 90, 99]
        );
        assert_eq!(table_rows(91, false).last(), Some(&90));
        assert_eq!(table_rows(91, false).len(), 10);
        assert_eq!(table_rows(100, true).len(), 100);
    }

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

    #[test]
    fn errors_name_status_and_code() {
        let e = MillPlanError::Policy {
            path: "p.safetensors".into(),
            reason: "weights file not found".into(),
        };
        assert_eq!(
            describe(&e),
            "POLICY_ERROR (3): policy p.safetensors: weights file not found"
        );
    }
}
