//! `kerf plan gcode`: plans one G-code program offline, without ROS (issue 14, item 6).
//!
//! ```sh
//! kerf plan gcode FILE [--machine laser-cutter|irb6660] [--tolerance M]
//!                      [--method kerf|kerf-curvature|icr|ccr|nurbs|drls-net] [--feed-method near-optimal|constant-intervals]
//!                      [--g RAD] [--origin X,Y,Z] [--plan-memory BYTES] [--plots DIR]
//!                      [--out plan.json] [--normalize L] [--resample N]
//! ```
//!
//! Reads the program as a stream through the CLI's capped reader ([`crate::input::open`]: `-`
//! reads standard input, a FIFO or pipe is streamed, a directory or a regular file over
//! [`kerf_gcodeplan::MAX_PROGRAM_BYTES`] is refused before it is read, and no stream is read
//! past that cap), plans it with [`kerf_gcodeplan::plan_request_reading`] (the shipped machine) under a memory budget of
//! `--plan-memory` bytes (default [`kerf_budget::DEFAULT_PLAN_MEMORY`], 1 GiB, as the node's
//! `plan_memory`: a program whose data would not fit ends with RESOURCE_LIMIT naming what grew)
//! and prints the totals (time, T_lb
//! and T/T_lb, tolerance use, seeds 000/003 metrics), a table of the runs, the tool switches
//! and the warnings. `--out` writes the answer the `gcode_planner` node would publish
//! (`kerf_msgs/msg/GcodePlan`, with its trajectory) as JSON. `--plots DIR` writes, per cutting
//! run k, `run<k>_*.svg`: the path before and after smoothing, the feed along the path with its
//! limit curve, chord error, normal acceleration and jerk, contour error, tangential
//! acceleration and jerk (seed 000 Fig. 5, seed 003 Figs. 12-14).
//!
//! `--normalize L` and `--resample N` (issue 30, item 1) apply seed 000's preprocessing of a
//! contour (section 4.1: "normalized to fit within a [0, 100]² coordinate space", "resampled
//! to generate 200 equally spaced points") to the program's one G01 cut contour before it is
//! planned, each optional and independent: the geometry and what is refused (arcs, several
//! contours, a contour not planar or with a changing feed) are
//! [`kerf_gcodeplan::preprocess`]'s, documented there. `L` is in the program's own unit (mm
//! under G21, in under G20; the seed names none): the larger side of the contour's XY box is
//! scaled to `L` and its lower-left corner moved to the origin. What was done (unit, scale
//! factor, offset, boxes, points and lengths before and after) is printed before the plan, which
//! is then of the preprocessed program (its line numbers are that program's).
//!
//! Exit code 0 on success; 2 on any failure (its status, line and message are printed).

use std::{f64::consts::PI, path::PathBuf};

use clap::{Args, ValueEnum};
use kerf_budget::Budget;
use kerf_gcodeplan::{
    plan_request_reading,
    preprocess::{preprocess_program, Preprocess, PreprocessReport},
    GcodePlan, GcodePlanError, GcodeRequest, MachineBase, MachineKind, RunKind, MAX_PROGRAM_BYTES,
};
use kerf_msgs::msg::GcodePlan as GcodePlanMsg;

use crate::{
    bounds::{Coordinates, Count, Point3, Real},
    input::{self, InputFile},
};

/// `--tolerance`: the `tolerance` rule of `GcodeRequest` (`kerf_msgs::numbers::gcode`).
const TOLERANCE: Real = Real::closed(1e-7, 0.01, "m");

/// `--g`: the `redundancy_angle` rule of `GcodeRequest`.
const ANGLE: Real = Real::closed(-PI, PI, "rad");

/// `--origin`: the `origin.*` rule of `GcodeRequest`, for each coordinate.
const ORIGIN: Coordinates = Coordinates(Real::closed(-100.0, 100.0, "m"));

/// `--plan-memory`: the node's `plan_memory` range.
const PLAN_MEMORY: Count<u64> = Count::new(
    kerf_budget::MIN_PLAN_MEMORY,
    kerf_budget::MAX_PLAN_MEMORY,
    "bytes",
);

/// `--normalize`: the side L of the square the contour is fitted into, in the program's unit.
const NORMALIZE: Real = Real::above(0.0, 1e6, "program units (mm under G21, in under G20)");

/// `--resample`: the contour's points after resampling (the program's line limit is 10⁶).
const RESAMPLE: Count<usize> = Count::new(2, 1_000_000, "points");

/// The machines, as named in requests.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum MachineArg {
    /// The laser cutter of seed 001 over a flat sheet.
    #[value(name = "laser-cutter", alias = "laser_cutter")]
    LaserCutter,
    /// The IRB 6660 milling cell of seed 004.
    Irb6660,
}

/// Arguments of `kerf plan gcode`.
#[derive(Args, Debug)]
pub struct GcodeArgs {
    /// The program (G-code); `-` reads standard input. Read up to 268435456 bytes (256 MiB).
    file: InputFile,
    /// The machine.
    #[arg(long, value_enum, default_value = "laser-cutter")]
    machine: MachineArg,
    /// Largest distance of the executed tool tip from the programmed path: [0.0000001, 0.01] m.
    #[arg(long, value_parser = TOLERANCE)]
    tolerance: Option<f64>,
    /// Corner smoothing method: kerf, kerf-curvature, icr, ccr, nurbs, drls-net (seed 003's
    /// learned NURBS corner, the committed network, falling back to the nurbs swarm; the
    /// corners predicted and the fallbacks are printed).
    #[arg(long)]
    method: Option<String>,
    /// Feed planner: near-optimal, constant-intervals.
    #[arg(long)]
    feed_method: Option<String>,
    /// IRB 6660: the redundancy angle g about the tool axis: [-3.141592653589793,
    /// 3.141592653589793] rad.
    #[arg(long, allow_hyphen_values = true, value_parser = ANGLE)]
    g: Option<f64>,
    /// The program's zero in the machine's base frame, `x,y,z`: each in [-100, 100] m.
    #[arg(long, allow_hyphen_values = true, value_parser = ORIGIN)]
    origin: Option<Point3>,
    /// The plan's memory budget, as the node's plan_memory: [16777216, 1099511627776] bytes.
    #[arg(long, default_value_t = kerf_budget::DEFAULT_PLAN_MEMORY, value_parser = PLAN_MEMORY)]
    plan_memory: u64,
    /// Write the plots here.
    #[arg(long)]
    plots: Option<PathBuf>,
    /// Write the answer (kerf_msgs/msg/GcodePlan) as JSON here.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Seed 000's preprocessing: fit the G01 cut contour's XY bounding box into [0, L]², the
    /// larger side scaled to L, the lower-left corner to the origin, rapids mapped alike: (0,
    /// 1000000] program units (mm under G21, in under G20).
    #[arg(long, value_name = "L", value_parser = NORMALIZE)]
    normalize: Option<f64>,
    /// Seed 000's preprocessing: replace the G01 cut contour by N points equally spaced in arc
    /// length along it, first and last kept (after --normalize): [2, 1000000] points.
    #[arg(long, value_name = "N", value_parser = RESAMPLE)]
    resample: Option<usize>,
}

/// Runs `kerf plan gcode`.
///
/// # Errors
/// The message to print; the caller exits with [`crate::EXIT_FAILURE`].
pub fn run(a: GcodeArgs) -> Result<(), String> {
    if let Some(out) = &a.out {
        crate::output_paths::check_writable("--out", out)?;
    }
    if let Some(dir) = &a.plots {
        crate::output_paths::check_dir_writable("--plots", dir)?;
    }
    let kind = match a.machine {
        MachineArg::LaserCutter => MachineKind::LaserCutter,
        MachineArg::Irb6660 => MachineKind::Irb6660,
    };
    let memory = a.plan_memory;
    let request = GcodeRequest {
        request_id: a.file.path().display().to_string(),
        machine: kind.name().to_string(),
        program: None,
        program_file: None,
        tolerance: a.tolerance,
        method: a.method.clone(),
        feed_method: a.feed_method.clone(),
        origin: a.origin.map(|o| o.0),
        redundancy_angle: a.g,
        ..GcodeRequest::default()
    };
    let base = MachineBase::load(kind).map_err(|e| e.to_string())?;
    let started = std::time::Instant::now();
    let budget = Budget::unlimited().with_memory(Some(memory));
    // Streamed and capped like every input of kerf; the program is named in every failure.
    let label = format!("FILE {}", a.file);
    let input = input::open("FILE", &a.file, MAX_PROGRAM_BYTES)?;
    let failed = |label: &str, e: GcodePlanError| {
        let status = kerf_gcode_planner::convert::status_of(&e);
        let name = GcodePlanMsg::status_name(status).unwrap_or("?");
        format!("{name} ({status}): {label}: {e}")
    };
    let options = Preprocess {
        normalize: a.normalize,
        resample: a.resample,
    };
    let planned = if options == Preprocess::default() {
        plan_request_reading(
            &request,
            &base,
            &budget,
            None,
            std::io::BufReader::new(input),
        )
        .map_err(|e| failed(&label, e))
    } else {
        let settings = request.settings().map_err(|e| failed(&label, e))?;
        let pre = preprocess_program(std::io::BufReader::new(input), &settings, &options, &budget)
            .map_err(|e| failed(&label, e))?;
        print!("{}", preprocess_summary(&pre.report));
        // The program written out is held while it is planned.
        let bytes = pre.program.len() as u64;
        budget
            .account(bytes, "the preprocessed program")
            .map_err(|e| failed(&label, e.into()))?;
        let planned = plan_request_reading(&request, &base, &budget, None, pre.program.as_bytes());
        budget.release(bytes);
        planned.map_err(|e| {
            failed(
                &format!("{label} preprocessed (lines of the preprocessed program)"),
                e,
            )
        })
    };
    let plan = planned?;
    let took = started.elapsed().as_secs_f64();
    print!("{}", summary(&plan, took));
    if request.method.as_deref() == Some(kerf_gcodeplan::DRLS_NET) {
        println!(
            "drls-net: {} corners predicted, {} fell back to the NURBS swarm",
            plan.corner_predictions, plan.corner_fallbacks
        );
    }
    if let Some(out) = &a.out {
        let m = kerf_gcode_planner::convert::plan_to_msg(&request, &plan)?;
        let json = serde_json::to_string_pretty(&m)
            .map_err(|e| format!("cannot serialize the plan: {e}"))?;
        std::fs::write(out, json).map_err(|e| format!("cannot write {}: {e}", out.display()))?;
        println!("plan written to {}", out.display());
    }
    if let Some(dir) = &a.plots {
        let settings = request.settings().map_err(|e| e.to_string())?;
        let mut files = 0;
        for (k, (report, timed)) in plan.runs.iter().zip(&plan.timed).enumerate() {
            if report.kind != RunKind::Cut {
                continue;
            }
            let mut limits = settings.limits;
            limits.curvature.feed = report.feed;
            let period = limits.curvature.interpolation_period;
            let feed = timed.plan.sample(period);
            let plots =
                kerf_toolpath::pipeline_plots(&timed.path, &timed.samples, &feed, &limits, period)
                    .map_err(|e| format!("run {k}: plots: {e}"))?;
            for (name, svg) in plots {
                let path = dir.join(format!("run{k}_{name}"));
                std::fs::write(&path, svg)
                    .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
                files += 1;
            }
        }
        println!("{files} plots written to {}", dir.display());
    }
    Ok(())
}

/// What the preprocessing did, in the program's unit.
fn preprocess_summary(r: &PreprocessReport) -> String {
    use std::fmt::Write;
    let u = r.unit.metres();
    let sym = r.unit.symbol();
    let bx = |b: &kerf_gcodeplan::preprocess::Box2| {
        format!(
            "[{:.4}, {:.4}] x [{:.4}, {:.4}] {sym}",
            b.min[0] / u,
            b.max[0] / u,
            b.min[1] / u,
            b.max[1] / u
        )
    };
    let mut s = String::new();
    let _ = writeln!(
        s,
        "preprocessing (seed 000 section 4.1): contour of lines {}-{} ({}, {sym}): {} points, \
         length {:.4} {sym}",
        r.contour_lines.0,
        r.contour_lines.1,
        r.unit.gcode(),
        r.points_before,
        r.length_before / u
    );
    if let Some(n) = &r.normalization {
        let [tx, ty] = n.map.offset();
        let _ = writeln!(
            s,
            "normalize to [0, {}]^2 {sym}: scale factor {:.6}, offset ({:.4}, {:.4}) {sym}; box {} \
             -> {}",
            n.side,
            n.map.scale,
            tx / u,
            ty / u,
            bx(&n.before),
            bx(&n.after)
        );
    }
    if let Some(h) = r.spacing {
        let _ = writeln!(
            s,
            "resample: {} points -> {} points, {:.4} {sym} apart along the contour; length \
             {:.4} -> {:.4} {sym} (chords cut the corners)",
            r.points_before,
            r.points_after,
            h / u,
            h * r.points_after.saturating_sub(1) as f64 / u,
            r.length_after / u
        );
    }
    let _ = writeln!(
        s,
        "carried through: {} rapids, {} feed moves with the tool off{}{}",
        r.rapids,
        r.travel_moves,
        if r.normalization.is_some() {
            " (XY mapped by the same scale and offset, Z unchanged)"
        } else {
            ""
        },
        if r.start_rapid {
            "; a rapid added first to the start position's image"
        } else {
            ""
        }
    );
    let _ = writeln!(
        s,
        "the plan below is of the preprocessed program (its line numbers are its own)"
    );
    s
}

/// The printed summary.
fn summary(plan: &GcodePlan, took: f64) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let m = plan.cut_metrics();
    let _ = writeln!(
        s,
        "{}: {} lines, {} arcs, {} runs, {} trajectory points, planned in {:.3} s",
        plan.machine,
        plan.lines,
        plan.arcs,
        plan.runs.len(),
        plan.trajectory.points.len(),
        took
    );
    let _ = writeln!(
        s,
        "time {:.3} s: feed plan as run {:.3} s; under the path limits T_m {:.3} s, T_lb {:.3} s, \
         T_m/T_lb {:.3}; dwell {:.3} s",
        plan.duration,
        plan.feed_time,
        plan.path_time,
        plan.lower_bound,
        plan.lower_bound_ratio(),
        plan.dwell_time
    );
    let _ = writeln!(
        s,
        "tolerance {:.1} um: corners within {:.2} um, executed tip within {:.3} um of the plan",
        plan.tolerance * 1e6,
        plan.max_corner_deviation * 1e6,
        plan.max_interpolation_deviation * 1e6
    );
    let _ = writeln!(
        s,
        "cutting: kappa_max {:.1} 1/m, theta_max {:.4} rad, a_rms {:.4} m/s^2, j_rms {:.2} m/s^3, \
         chord error {:.3} um, contour error {:.3} um",
        m.max_curvature,
        m.max_turning_angle,
        m.rms_acceleration,
        m.rms_jerk,
        m.max_chord_error * 1e6,
        m.max_contour_error * 1e6
    );
    let _ = writeln!(
        s,
        "{:>4} {:>7} {:>13} {:>8} {:>10} {:>9} {:>9} {:>9} {:>8}  binding",
        "run",
        "kind",
        "lines",
        "corners",
        "length [m]",
        "F [m/s]",
        "T_run [s]",
        "T_lb [s]",
        "slowed"
    );
    for (k, r) in plan.runs.iter().enumerate() {
        let _ = writeln!(
            s,
            "{k:>4} {:>7} {:>13} {:>8} {:>10.4} {:>9.4} {:>9.3} {:>9.3} {:>8.3}  {} {} at {:.2}",
            r.kind.name(),
            format!("{}-{}", r.lines.0, r.lines.1),
            r.corners,
            r.length,
            r.feed,
            r.feed_time,
            r.lower_bound,
            r.slowdown,
            r.peak.joint,
            r.peak.what,
            r.peak.ratio
        );
    }
    for e in &plan.events {
        let _ = writeln!(
            s,
            "line {}: tool {} at {:.3} s",
            e.line,
            if e.on { "on" } else { "off" },
            e.time
        );
    }
    for w in &plan.warnings {
        let _ = writeln!(s, "warning: {w}");
    }
    s
}
