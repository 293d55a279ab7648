//! `kerf plan cut`: plans one laser cut offline, without ROS.
//!
//! ```sh
//! kerf plan cut --request cut.yaml [--out plan.json] [--plots DIR] [--urdf U --limits L]
//! ```
//!
//! Reads a YAML or JSON request ([`kerf_mjto::CutRequest`], the schema of the planner node's
//! `~/cut_request_text`), plans it with [`kerf_mjto::planner::Planner`] for the shipped laser
//! cutter (or `--urdf` / `--limits`), prints a summary (status, RTOs, metrics against the QI
//! baseline of seed 001), writes the plan as JSON to `--out` (every sample, the RTOs, the
//! metrics and stage times) and SVG plots per axis to `--plots` ([`crate::plots::joints`],
//! of [`kerf_mjto::series::JointSeries`]). Any failure
//! exits with code 2 and the planner's message (status name and code first).

use std::{fmt::Write as _, path::PathBuf};

use clap::{Args, Subcommand};
use kerf_mjto::{
    machine::JOINT_NAMES, plan::Metrics, planner::Planner, series::JointSeries, CutPlan,
    CutRequest, LaserMachine, PlanError,
};
use kerf_msgs::msg::CutPlan as CutPlanMsg;
use kerf_robot::RobotModel;

use crate::input::{self, InputFile};

/// Arguments of `kerf plan`.
#[derive(Args, Debug)]
pub struct PlanArgs {
    #[command(subcommand)]
    command: PlanCommand,
}

/// What `kerf plan` plans.
#[derive(Subcommand, Debug)]
enum PlanCommand {
    /// Plan a laser cut (MJTO, seed 001) from a request file.
    Cut(CutArgs),
    /// Plan a milling path (DDPG, fixed g, DP or naive; seed 004) from a request file.
    Mill(crate::plan_mill::MillArgs),
    /// Plan a G-code program for the laser cutter or the IRB 6660.
    Gcode(crate::plan_gcode::GcodeArgs),
}

/// Arguments of `kerf plan cut`.
#[derive(Args, Debug)]
pub struct CutArgs {
    /// Request file, YAML or JSON (`points`, `axes`, `feedrate`, `sample_period`,
    /// `max_lead_angle`, `max_tilt_angle`, `mesh`, optional `workpiece_pose` and `options`;
    /// at most 4 MiB, `-` reads standard input).
    #[arg(long)]
    request: InputFile,
    /// Write the plan as JSON here.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Write q1.svg … q6.svg (position, velocity, acceleration, jerk; MJTO vs QI) here.
    #[arg(long)]
    plots: Option<PathBuf>,
    /// Machine URDF (default: the shipped urdf/laser_cutter.urdf; at most 4 MiB).
    #[arg(long, requires = "limits")]
    urdf: Option<InputFile>,
    /// Machine limits YAML with acceleration and jerk limits (with --urdf; at most 4 MiB).
    #[arg(long, requires = "urdf")]
    limits: Option<InputFile>,
}

/// Runs `kerf plan`.
///
/// # Errors
/// The message to print; the caller exits with [`crate::EXIT_FAILURE`].
pub fn run(a: PlanArgs) -> Result<(), String> {
    match a.command {
        PlanCommand::Cut(c) => cut(c),
        PlanCommand::Mill(m) => crate::plan_mill::run(m),
        PlanCommand::Gcode(g) => crate::plan_gcode::run(g),
    }
}

/// "STATUS (code): message" of a planner error.
fn describe(e: &PlanError) -> String {
    let code = e.status();
    let name = CutPlanMsg::status_name(code).unwrap_or("?");
    let mut s = format!("{name} ({code}): {e}");
    if let PlanError::Collision { collisions, .. } = e {
        for c in collisions.iter().take(10) {
            let _ = write!(
                s,
                "\n  u = {:.4}, t = {:.3} s, CL point {}: {}",
                c.u, c.time, c.cl_index, c.reason
            );
        }
        if collisions.len() > 10 {
            let _ = write!(s, "\n  … {} more", collisions.len() - 10);
        }
    }
    s
}

fn cut(a: CutArgs) -> Result<(), String> {
    let text = input::read_text("--request", &a.request, input::REQUEST_CAP)?;
    let machine = match (&a.urdf, &a.limits) {
        (Some(u), Some(l)) => {
            let urdf = input::read_text("--urdf", u, input::ROBOT_CAP)?;
            let limits = input::read_text("--limits", l, input::ROBOT_CAP)?;
            let robot = RobotModel::from_strings(&urdf, Some(&limits))
                .map_err(|e| format!("--urdf {u} with --limits {l}: {e}"))?;
            LaserMachine::from_robot(robot)
        }
        _ => LaserMachine::default_machine(),
    }
    .map_err(|e| describe(&e))?;
    let request = CutRequest::from_yaml(&text)
        .map_err(|e| format!("--request {}: {}", a.request, describe(&e)))?;
    input::check_offline_start(&format!("--request {}", a.request), &request.start)?;
    let limits = *machine.limits();
    let mut planner = Planner::new(machine).map_err(|e| describe(&e))?;
    let plan = planner.plan(&request).map_err(|e| describe(&e))?;
    print!("{}", summary(&plan));
    if let Some(out) = &a.out {
        let json = serde_json::to_string_pretty(&plan)
            .map_err(|e| format!("cannot serialize the plan: {e}"))?;
        std::fs::write(out, json).map_err(|e| format!("cannot write {}: {e}", out.display()))?;
        println!("plan written to {}", out.display());
    }
    if let Some(dir) = &a.plots {
        let qi = match JointSeries::qi_baseline(&request, &plan, &limits) {
            Ok(s) => Some(s),
            Err(e) => {
                eprintln!("kerf: QI baseline not plotted: {e}");
                None
            }
        };
        let files = crate::plots::joints::write_plots(
            dir,
            &JointSeries::of_plan(&plan),
            qi.as_ref(),
            &limits,
        )?;
        println!("{} plots written to {}", files.len(), dir.display());
    }
    Ok(())
}

/// The text summary printed after a successful plan: headline, RTO table, MJTO vs QI metrics
/// per joint, path errors and stage times.
fn summary(plan: &CutPlan) -> String {
    let mut s = String::new();
    let duration = plan.times.last().copied().unwrap_or(0.0);
    let _ = writeln!(
        s,
        "request '{}': SUCCESS (0): {:.4} m of path, {:.3} s of motion, {} samples, {} control \
         points, {} iteration(s), {} collision queries",
        plan.request_id,
        plan.path_length,
        duration,
        plan.times.len(),
        plan.control_points,
        plan.iterations,
        plan.collision_queries
    );
    let f = &plan.feed;
    let _ = writeln!(
        s,
        "feed: {} law, cycle time {:.3} s (constant feed {:.3} s), peak feed {:.4} m/s",
        f.law.as_str(),
        f.cycle_time,
        f.constant_feed_time,
        f.peak_feed
    );
    for l in &f.limits {
        let _ = writeln!(s, "  s {:.4}-{:.4} m: {}", l.s_start, l.s_end, l.limited_by);
    }
    let _ = writeln!(s, "RTOs ({}):", plan.rtos.len());
    let _ = writeln!(
        s,
        "  {:>3} {:>8} {:>8} {:>10} {:>10} {:>9} {:>9}",
        "#", "CL", "u", "q4 (rad)", "q5 (rad)", "q6 (m)", "inserted"
    );
    for (i, r) in plan.rtos.iter().enumerate() {
        let _ = writeln!(
            s,
            "  {:>3} {:>8} {:>8.4} {:>10.5} {:>10.5} {:>9.5} {:>9}",
            i,
            r.cl_index,
            r.u,
            r.q4,
            r.q5,
            r.q6,
            if r.inserted_at_iteration == 0 {
                "initial".to_string()
            } else {
                format!("iter {}", r.inserted_at_iteration)
            }
        );
    }
    s.push_str(&metrics_table(&plan.metrics, &plan.qi_metrics));
    let t = &plan.times_per_stage;
    let _ = writeln!(
        s,
        "stage times (s): setup {:.3}, hessian {:.3}, gfd {:.3}, selection {:.3}, rotary QP {:.3}, \
         M-path QP {:.3}, collision {:.3}, evaluation {:.3}, feed {:.3}, total {:.3}",
        t.setup,
        t.hessian,
        t.gfd,
        t.selection,
        t.rotary_qp,
        t.mpath_qp,
        t.collision,
        t.evaluation,
        t.feed,
        t.total
    );
    s
}

/// Per joint: peak |velocity|, |acceleration|, |jerk| and RMS jerk of MJTO and QI, then the
/// path figures and limit checks of both.
fn metrics_table(m: &Metrics, qi: &Metrics) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "metrics, MJTO / QI (units of the joint: m or rad, per s, s², s³):"
    );
    let _ = writeln!(
        s,
        "  {:<5} {:>23} {:>23} {:>23} {:>23}",
        "joint", "peak |velocity|", "peak |acceleration|", "peak |jerk|", "RMS jerk"
    );
    for (j, name) in JOINT_NAMES.iter().enumerate() {
        let pair = |a: f64, b: f64| format!("{a:.4} / {b:.4}");
        let _ = writeln!(
            s,
            "  {:<5} {:>23} {:>23} {:>23} {:>23}",
            name,
            pair(m.peak_velocity[j], qi.peak_velocity[j]),
            pair(m.peak_acceleration[j], qi.peak_acceleration[j]),
            pair(m.peak_jerk[j], qi.peak_jerk[j]),
            pair(m.rms_jerk[j], qi.rms_jerk[j]),
        );
    }
    for (label, x) in [("MJTO", m), ("QI", qi)] {
        let _ = writeln!(
            s,
            "  {label}: max CL error {:.3e} m, max lead {:.4} rad, max tilt {:.4} rad, {} \
             colliding sample(s), {}",
            x.max_cl_error,
            x.max_lead_angle,
            x.max_tilt_angle,
            x.colliding_samples,
            if x.within_limits {
                "within every joint limit".to_string()
            } else {
                format!("limits exceeded: {}", x.limit_violations.join("; "))
            }
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use kerf_mjto::optimal_feed::{FeedLimit, FeedMode};
    use kerf_mjto::plan::FeedReport;
    use kerf_mjto::{
        error::CollisionReport,
        plan::{RtoRecord, StageTimes},
    };

    fn metrics(k: f64, ok: bool) -> Metrics {
        Metrics {
            peak_velocity: [0.3 * k, 0.0, 0.0, 1.0 * k, 0.5, 0.01],
            peak_acceleration: [1.0 * k; 6],
            peak_jerk: [10.0 * k; 6],
            rms_jerk: [2.0 * k; 6],
            within_limits: ok,
            limit_violations: if ok {
                vec![]
            } else {
                vec!["q4 jerk 250 > 200 at t = 1.2 s".into()]
            },
            max_cl_error: 2e-6,
            max_lead_angle: 0.05,
            max_tilt_angle: 0.04,
            colliding_samples: if ok { 0 } else { 3 },
        }
    }

    #[test]
    fn summary_lists_rtos_and_both_metrics() {
        let plan = CutPlan {
            request_id: "case1".into(),
            joint_names: JOINT_NAMES.iter().map(|s| s.to_string()).collect(),
            times: vec![0.0, 0.01, 0.02],
            path_positions: vec![0.0, 0.75, 1.5],
            positions: vec![[0.0; 6]; 3],
            velocities: vec![[0.0; 6]; 3],
            accelerations: vec![[0.0; 6]; 3],
            rtos: vec![
                RtoRecord {
                    u: 0.0,
                    cl_index: 0,
                    q4: 0.1,
                    q5: -0.2,
                    q6: -0.07,
                    inserted_at_iteration: 0,
                },
                RtoRecord {
                    u: 0.5,
                    cl_index: 12,
                    q4: 0.15,
                    q5: -0.1,
                    q6: -0.06,
                    inserted_at_iteration: 2,
                },
            ],
            metrics: metrics(1.0, true),
            qi_metrics: metrics(3.0, false),
            iterations: 2,
            collision_queries: 99,
            control_points: 25,
            path_length: 1.5,
            feed: FeedReport {
                law: FeedMode::TimeOptimal,
                cycle_time: 0.02,
                constant_feed_time: 0.015,
                peak_feed: 0.33,
                limits: vec![FeedLimit {
                    s_start: 0.25,
                    s_end: 0.5,
                    limited_by: "q5 jerk".into(),
                }],
            },
            times_per_stage: StageTimes {
                total: 4.5,
                ..Default::default()
            },
        };
        let s = summary(&plan);
        assert!(
            s.starts_with("request 'case1': SUCCESS (0): 1.5000 m of path, 0.020 s"),
            "{s}"
        );
        assert!(s.contains("RTOs (2):"), "{s}");
        assert!(
            s.contains("feed: time_optimal law, cycle time 0.020 s (constant feed 0.015 s)"),
            "{s}"
        );
        assert!(s.contains("s 0.2500-0.5000 m: q5 jerk"), "{s}");
        assert!(
            s.contains("   12   0.5000    0.15000   -0.10000  -0.06000    iter 2"),
            "{s}"
        );
        assert!(s.contains("initial"), "{s}");
        // q4: MJTO peak velocity 1, QI 3; peak jerk 10 vs 30.
        let q4 = s
            .lines()
            .find(|l| l.trim_start().starts_with("q4"))
            .unwrap();
        assert!(
            q4.contains("1.0000 / 3.0000") && q4.contains("10.0000 / 30.0000"),
            "{q4}"
        );
        assert!(s.contains("MJTO: max CL error 2.000e-6 m"), "{s}");
        assert!(s.contains("within every joint limit"), "{s}");
        assert!(
            s.contains("QI:") && s.contains("limits exceeded: q4 jerk 250 > 200"),
            "{s}"
        );
        assert!(s.contains("total 4.500"), "{s}");
    }

    #[test]
    fn errors_name_status_and_code() {
        let e = PlanError::invalid("points", "1 CL point(s): at least 2 are required");
        assert_eq!(
            describe(&e),
            "INVALID_REQUEST (1): invalid request: points: 1 CL point(s): at least 2 are required"
        );
        let collisions = (0..12)
            .map(|i| CollisionReport {
                u: i as f64 / 12.0,
                time: i as f64,
                cl_index: i,
                links: vec!["nozzle".into()],
                reason: format!("contact {i}"),
            })
            .collect();
        let d = describe(&PlanError::Collision {
            iterations: 10,
            collisions,
        });
        assert!(d.starts_with("COLLISION (5): "), "{d}");
        assert!(d.contains("CL point 9: contact 9"), "{d}");
        assert!(!d.contains("contact 10"), "{d}");
        assert!(d.ends_with("… 2 more"), "{d}");
    }
}
