//! `kerf step`: reference-point stepping offline (issue 29, item 4; seed 002).
//!
//! ```sh
//! kerf step POINTS [--controller rpro|ddqn|ruckig] [--limits V,A,J] [--precision M]
//!                  [--period S] [--unit m|mm] [--gcode] [--joints ROBOT] [--lookahead N]
//!                  [--network FILE] --out FILE
//! ```
//!
//! Reads reference points (one per line, 1 to 6 coordinates; or a G-code program's points),
//! steps through them with the chosen controller ([`kerf_stepping`]) at the control period,
//! prints the steps, the time and the accuracy at each point, and writes the per-step
//! trajectory (position, velocity, acceleration and jerk per axis) and the step at which each
//! point was passed as JSON. Everything is parsed and validated here and computed by the
//! library; units are SI (m or rad, s).

use std::{path::PathBuf, time::Instant};

use clap::{Args, ValueEnum};
use kerf_stepping::{
    ddqn::{file::from_bytes, Agent, Shielded},
    multi::{AxisSample, MultiCourse},
    points::parse_points,
    ruckig_ref::{reference, Method},
    Limits, Rpro, RproSettings,
};
use serde::Serialize;

use crate::{
    bounds::{Count, Real, Triple},
    input::{self, InputFile},
    launch::Robot,
    output_paths::check_writable,
};

/// Cap of a points file or G-code program (64 MiB: about a million points).
const POINTS_CAP: u64 = 64 << 20;

/// `--limits`: velocity, acceleration and jerk, each in (0, 1e6].
const LIMITS: Triple = Triple {
    what: "limits",
    names: ["velocity", "acceleration", "jerk"],
    value: Real::above(0.0, 1e6, "SI"),
};

/// Reference points, one `Vec` of coordinates each.
type Points = Vec<Vec<f64>>;

/// Joint ranges `(min, max)`.
type Ranges = Vec<(f64, f64)>;

/// Cap of a DDQN network file (1 MiB; the committed one is 4 kB).
const NETWORK_CAP: u64 = 1 << 20;

/// The committed DDQN network, relative to the data root.
const NETWORK: &str = "crates/stepping/weights/ddqn_high_arch2.safetensors";

/// Periods a run may take before it is refused (10⁷: 5.6 h at 2 ms).
const MAX_STEPS: usize = 10_000_000;

/// Per-period controller.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ControllerArg {
    /// kerf's reading of seed 002's RPRO (greedy jerk decisions with a viability look-ahead).
    Rpro,
    /// The Ruckig reference: time-optimal jerk-limited sections through the points (rsruckig),
    /// each ending on a sample; per-axis limits, no spline.
    Ruckig,
    /// Seed 002's DDQN imitation of RPRO behind RPRO's shield: the agent's action where RPRO
    /// allows it and it keeps the axis moving, RPRO's otherwise (overrides are printed).
    Ddqn,
}

/// Unit of the points' numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum UnitArg {
    /// Metres (or radians for `--joints`).
    M,
    /// Millimetres.
    Mm,
}

/// Arguments of `kerf step`.
#[derive(Args, Debug)]
pub struct StepArgs {
    /// Reference points: one per line, 1 to 6 coordinates separated by blanks or commas (`#`
    /// starts a comment), the start first; or a G-code program with `--gcode` (at most 64
    /// MiB; `-` reads standard input).
    points: InputFile,
    /// The per-period controller.
    #[arg(long, value_enum, default_value_t = ControllerArg::Rpro)]
    controller: ControllerArg,
    /// Velocity, acceleration and jerk limits of every axis, V,A,J in m/s, m/s², m/s³ (default:
    /// seed 002 Table 1's fastest, 8 m/min = 0.1333 m/s, 3 m/s², 30 m/s³; not with --joints);
    /// each in (0, 1000000] SI.
    #[arg(long, value_parser = LIMITS, conflicts_with = "joints")]
    limits: Option<[f64; 3]>,
    /// Precision within which each point is passed (default 1e-5 m = 0.01 mm, Table 1); (0,
    /// 1] m or rad.
    #[arg(long, default_value_t = 1e-5, allow_hyphen_values = true,
          value_parser = Real::above(0.0, 1.0, "m"))]
    precision: f64,
    /// Control period (default 0.002 s, Table 1); (0, 1] s.
    #[arg(long, default_value_t = 0.002, allow_hyphen_values = true,
          value_parser = Real::above(0.0, 1.0, "s"))]
    period: f64,
    /// Unit of the points' numbers (G-code programs state their own, G20/G21).
    #[arg(long, value_enum, default_value_t = UnitArg::M)]
    unit: UnitArg,
    /// The points are a G-code program: its moves' end points, arcs divided so that no chord
    /// leaves the arc by more than half the precision.
    #[arg(long)]
    gcode: bool,
    /// The points are joint positions [rad] of this robot: its joint limits (URDF and
    /// `urdf/<robot>_limits.yaml`) replace --limits, and every point and sample must stay
    /// inside its joint range.
    #[arg(long, value_enum)]
    joints: Option<Robot>,
    /// Points passed at a chosen speed before RPRO's look-ahead ends in a crawl (default 1);
    /// [0, 8] points.
    #[arg(long, default_value_t = 1, value_parser = Count::<usize>::new(0, 8, "points"))]
    lookahead: usize,
    /// The DDQN network of `--controller ddqn` (default: the committed
    /// crates/stepping/weights/ddqn_high_arch2.safetensors; at most 1 MiB).
    #[arg(long)]
    network: Option<InputFile>,
    /// Where the trajectory is written as JSON.
    #[arg(long)]
    out: PathBuf,
}

/// Runs `kerf step`.
///
/// # Errors
/// A message for every bad input or failed run.
pub fn run(args: StepArgs) -> Result<(), String> {
    check_writable("--out", &args.out)?;
    let text = input::read_text("POINTS", &args.points, POINTS_CAP)?;
    let (points, lines) = if args.gcode {
        gcode_points(&text, args.precision)?
    } else {
        let scale = match args.unit {
            UnitArg::M => 1.0,
            UnitArg::Mm => 1e-3,
        };
        (parse_points(&text, scale).map_err(|e| e.to_string())?, None)
    };
    let name_point = |e: kerf_stepping::StepError| match (&e, &lines) {
        (kerf_stepping::StepError::InvalidPoint { index, .. }, Some(lines)) => {
            match lines.get(*index) {
                Some(l) => format!("{e} (G-code line {l})"),
                None => e.to_string(),
            }
        }
        _ => e.to_string(),
    };
    let (limits, ranges) = match args.joints {
        Some(robot) => joint_limits(robot, &points)?,
        None => {
            let [v, a, j] = args.limits.unwrap_or([8.0 / 60.0, 3.0, 30.0]);
            (vec![Limits::new(v, a, j)], None)
        }
    };
    let agent = match args.controller {
        ControllerArg::Ddqn => Some(load_agent(args.network.as_ref())?),
        _ => {
            if args.network.is_some() {
                return Err("--network is the network of --controller ddqn".to_string());
            }
            None
        }
    };
    let mut overrides = None;
    let started = Instant::now();
    let outcome = match args.controller {
        ControllerArg::Rpro | ControllerArg::Ddqn => {
            let course = MultiCourse::new(points.clone(), &limits, args.precision, args.period)
                .map_err(name_point)?;
            let settings = RproSettings::default().lookahead_points(args.lookahead);
            let result = match &agent {
                None => {
                    let mut rpro =
                        Rpro::new(&course.course, settings).map_err(|e| e.to_string())?;
                    course.run(&mut rpro, MAX_STEPS)
                }
                Some(agent) => {
                    let mut shielded = Shielded::new(agent.clone(), &course.course, settings)
                        .map_err(|e| e.to_string())?;
                    let r = course.run(&mut shielded, MAX_STEPS);
                    overrides = Some((shielded.overrides(), shielded.decisions()));
                    r
                }
            }
            .map_err(|e| format!("{}: {e}", controller_name(args.controller)))?;
            Outcome {
                passes: result
                    .passes
                    .iter()
                    .map(|p| (p.point, p.step, p.error))
                    .collect(),
                samples: result.samples,
                axis_limits: course.axis_limits.clone(),
                path_limits: Some(course.course.lattice.limits),
            }
        }
        ControllerArg::Ruckig => {
            ruckig_outcome(&points, &limits, args.period).map_err(name_point)?
        }
    };
    let seconds = started.elapsed().as_secs_f64();
    if let Some(ranges) = &ranges {
        check_ranges(ranges, &outcome.samples)?;
    }
    let missed: Vec<usize> = outcome
        .passes
        .iter()
        .filter(|(_, _, e)| *e > args.precision)
        .map(|(p, _, _)| *p)
        .collect();
    // Joint positions mix rad and m (the laser cutter has prismatic axes).
    let micro = if args.joints.is_some() {
        "µ joint units"
    } else {
        "µm"
    };
    let steps = outcome.samples.len() - 1;
    let duration = steps as f64 * args.period;
    let count = outcome.passes.len().max(1) as f64;
    let mean = outcome.passes.iter().map(|p| p.2).sum::<f64>() / count;
    let max = outcome.passes.iter().map(|p| p.2).fold(0.0, f64::max);
    println!(
        "{}: {} points on {} axes, {steps} steps of {} s = {duration:.3} s; accuracy mean {:.2} \
         {micro}, max {:.2} {micro} (precision {} {micro}); planned in {:.3} s",
        controller_name(args.controller),
        points.len(),
        points[0].len(),
        args.period,
        mean * 1e6,
        max * 1e6,
        args.precision * 1e6,
        seconds
    );
    if let Some(path) = outcome.path_limits {
        println!(
            "path limits: {:.6} /s, {:.6} /s², {:.6} /s³ along the chord length",
            path.velocity, path.acceleration, path.jerk
        );
    }
    if let Some((n, of)) = overrides {
        println!("shield: RPRO overrode the agent in {n} of {of} decisions");
    }
    if !missed.is_empty() {
        println!("points not passed within the precision: {missed:?}");
    }
    println!(
        "{:>6} {:>8} {:>10} {:>12}",
        "point",
        "step",
        "time [s]",
        format!("error [{micro}]")
    );
    for (point, step, error) in &outcome.passes {
        println!(
            "{point:>6} {step:>8} {:>10.3} {:>12.3}",
            *step as f64 * args.period,
            error * 1e6
        );
    }
    let doc = Document {
        controller: controller_name(args.controller),
        period: args.period,
        precision: args.precision,
        axis_limits: outcome.axis_limits.clone(),
        path_limits: outcome.path_limits,
        steps,
        duration,
        mean_error: mean,
        max_error: max,
        points: outcome
            .passes
            .iter()
            .map(|&(index, step, error)| PointDoc {
                index,
                position: points[index].clone(),
                step,
                time: step as f64 * args.period,
                error,
                within_precision: error <= args.precision,
            })
            .collect(),
        samples: &outcome.samples,
    };
    let json = serde_json::to_string(&doc).map_err(|e| format!("--out: {e}"))?;
    std::fs::write(&args.out, json)
        .map_err(|e| format!("--out {}: cannot write: {e}", args.out.display()))?;
    println!("wrote {}", args.out.display());
    Ok(())
}

fn controller_name(c: ControllerArg) -> &'static str {
    match c {
        ControllerArg::Rpro => "rpro",
        ControllerArg::Ruckig => "ruckig",
        ControllerArg::Ddqn => "ddqn",
    }
}

/// The DDQN agent of `--network`, or the committed one.
fn load_agent(network: Option<&InputFile>) -> Result<Agent, String> {
    let bytes = match network {
        Some(f) => input::read_bytes("--network", f, NETWORK_CAP)?,
        None => {
            let path = kerf_robot::data::default_path(NETWORK);
            std::fs::read(&path)
                .map_err(|e| format!("the committed DDQN network {}: {e}", path.display()))?
        }
    };
    let (weights, info) = from_bytes(&bytes).map_err(|e| format!("--network: {e}"))?;
    Agent::new(weights, info).map_err(|e| format!("--network: {e}"))
}

/// The JSON document of `--out`.
#[derive(Serialize)]
struct Document<'a> {
    controller: &'static str,
    period: f64,
    precision: f64,
    axis_limits: Vec<Limits>,
    path_limits: Option<Limits>,
    steps: usize,
    duration: f64,
    mean_error: f64,
    max_error: f64,
    points: Vec<PointDoc>,
    samples: &'a [AxisSample],
}

/// One point of `--out`: where it is, and the step that passed it.
#[derive(Serialize)]
struct PointDoc {
    index: usize,
    position: Vec<f64>,
    step: usize,
    time: f64,
    error: f64,
    within_precision: bool,
}

/// What a controller produced: samples in axis space and each point's closest sample.
struct Outcome {
    samples: Vec<AxisSample>,
    /// (point, step, distance), points 1.. in order.
    passes: Vec<(usize, usize, f64)>,
    axis_limits: Vec<Limits>,
    /// The path-parameter limits (RPRO along the spline).
    path_limits: Option<Limits>,
}

/// The Ruckig reference through `points` as an [`Outcome`]: jerk per period from the
/// accelerations' differences (the mean jerk over the period).
fn ruckig_outcome(
    points: &[Vec<f64>],
    limits: &[Limits],
    period: f64,
) -> Result<Outcome, kerf_stepping::StepError> {
    let dim = points[0].len();
    let axis_limits: Vec<Limits> = if limits.len() == 1 {
        vec![limits[0]; dim]
    } else {
        limits.to_vec()
    };
    let r = reference(points, &axis_limits, period, Method::default())?;
    let n = r.samples();
    let samples = (0..n)
        .map(|k| AxisSample {
            time: k as f64 * period,
            position: r.position(k).to_vec(),
            velocity: r.velocity(k).to_vec(),
            acceleration: r.acceleration(k).to_vec(),
            jerk: if k + 1 < n {
                r.acceleration(k + 1)
                    .iter()
                    .zip(r.acceleration(k))
                    .map(|(b, a)| (b - a) / period)
                    .collect()
            } else {
                vec![0.0; dim]
            },
        })
        .collect();
    Ok(Outcome {
        samples,
        passes: r
            .hits
            .iter()
            .filter(|h| h.point > 0)
            .map(|h| (h.point, h.step, h.distance))
            .collect(),
        axis_limits,
        path_limits: None,
    })
}

/// A G-code program's points: the start, then every move's end point (arcs divided so that
/// no chord leaves the arc by more than `precision / 2`), and each point's source line.
fn gcode_points(text: &str, precision: f64) -> Result<(Points, Option<Vec<usize>>), String> {
    use kerf_gcode::{read_program, Motion, ReaderSettings};
    let motions = read_program(text, ReaderSettings::default()).map_err(|e| e.to_string())?;
    let mut points: Vec<Vec<f64>> = Vec::new();
    let mut lines = Vec::new();
    let mut zero_length = 0usize;
    let mut push = |p: [f64; 3], line: usize, points: &mut Vec<Vec<f64>>| {
        // A move to where the machine already is has no point of its own to pass.
        if points
            .last()
            .is_some_and(|last: &Vec<f64>| last.as_slice() == p.as_slice())
        {
            zero_length += 1;
            return;
        }
        points.push(p.to_vec());
        lines.push(line);
    };
    for m in &motions {
        match m {
            Motion::Rapid { start, end, line }
            | Motion::Line {
                start, end, line, ..
            } => {
                if points.is_empty() {
                    push(*start, *line, &mut points);
                }
                push(*end, *line, &mut points);
            }
            Motion::Arc { arc, line, .. } => {
                if points.is_empty() {
                    push(arc.start, *line, &mut points);
                }
                // Sagitta r(1 − cos(θ/2)) ≤ precision/2 per piece.
                let half = (1.0 - precision / 2.0 / arc.radius.max(precision)).clamp(-1.0, 1.0);
                let piece = 2.0 * half.acos();
                let n = if piece > 0.0 {
                    (arc.sweep.abs() / piece).ceil().max(1.0) as usize
                } else {
                    1
                };
                for k in 1..=n {
                    push(arc.point_at(k as f64 / n as f64), *line, &mut points);
                }
            }
            Motion::Dwell { .. } | Motion::Tool { .. } | Motion::End { .. } => {}
        }
    }
    if zero_length > 0 {
        println!("{zero_length} move(s) of zero length: no point of their own to pass");
    }
    if points.len() < 2 {
        return Err("the G-code program has no move: no points to step through".to_string());
    }
    Ok((points, Some(lines)))
}

/// The joint limits of `robot` (velocity from the URDF, acceleration and jerk from its limits
/// YAML) and its joint ranges; refuses points of another count or outside a range.
fn joint_limits(
    robot: Robot,
    points: &[Vec<f64>],
) -> Result<(Vec<Limits>, Option<Ranges>), String> {
    let model = robot.model()?;
    let joints = model.joints();
    let mut limits = Vec::with_capacity(joints.len());
    let mut ranges = Vec::with_capacity(joints.len());
    for j in joints {
        let a = j.max_acceleration.ok_or_else(|| {
            format!(
                "--joints: joint {} has no acceleration limit in its limits file",
                j.name
            )
        })?;
        let jerk = j.max_jerk.ok_or_else(|| {
            format!(
                "--joints: joint {} has no jerk limit in its limits file",
                j.name
            )
        })?;
        limits.push(Limits::new(j.max_velocity, a, jerk));
        ranges.push((j.min_position, j.max_position));
    }
    for (i, p) in points.iter().enumerate() {
        if p.len() != joints.len() {
            return Err(format!(
                "reference point {i}: {} coordinates, but {} has {} joints",
                p.len(),
                model.name(),
                joints.len()
            ));
        }
        for (k, (q, (lo, hi))) in p.iter().zip(&ranges).enumerate() {
            if q < lo || q > hi {
                return Err(format!(
                    "reference point {i}: joint {} at {q} rad is out of reach (range [{lo}, {hi}])",
                    joints[k].name
                ));
            }
        }
    }
    Ok((limits, Some(ranges)))
}

/// Refuses a trajectory whose samples leave a joint range (the path between two points may
/// bulge beyond them).
fn check_ranges(ranges: &[(f64, f64)], samples: &[AxisSample]) -> Result<(), String> {
    for (k, s) in samples.iter().enumerate() {
        for (j, (q, (lo, hi))) in s.position.iter().zip(ranges).enumerate() {
            if q < lo || q > hi {
                return Err(format!(
                    "the path between the points leaves joint {} 's range at step {k} ({q} rad, \
                     range [{lo}, {hi}]): add points where it bulges",
                    j + 1
                ));
            }
        }
    }
    Ok(())
}
