//! [`plan_program`]: a G-code program to a joint trajectory for a machine,
//! checked as the executor will run it.
//!
//! 1. Read the program into runs and stops ([`crate::runs`]).
//! 2. Per run: smooth its corners within δ_c with the settings' corner
//!    method ([`kerf_toolpath::smooth_polyline_with`]), sample it, plan the
//!    feed with the settings' feed method ([`kerf_toolpath::FeedMethod`]:
//!    every segment held to its programmed F, capped at the machine's, and
//!    optionally the gantry's axis limits on the laser cutter), and the bang-bang
//!    bound T_lb on the same path ([`kerf_toolpath::bang_bang_under`] under
//!    seed 003 eq. 22's limit curve and the programmed feeds).
//! 3. Per run: the joint points ([`crate::knots::run_knots`]), slowed
//!    uniformly where a joint limit needs it.
//! 4. The runs in order, from rest to rest, with dwells held.
//! 5. **The executor's check**: the trajectory through
//!    `kerf_executor::check_executable` (what the executor accepts), then
//!    its interpolation at every control period, the tool tip by forward
//!    kinematics against the planned point at that time. A piece beyond δ_i
//!    is split and steps 4–5 repeat.

use std::io::BufRead;

use kerf_budget::{bytes_of, Budget};
use kerf_executor::{
    check_executable, ExecutorConfig, JointSample, TrajectoryPoint, TrajectoryRequest,
};
use kerf_toolpath::{
    bang_bang_under_within, check_plan_within, metrics_within, smooth_polyline_within,
    FeedConstraints, FeedLimits, Metrics, PathSample, Piece, SmoothedPath,
};

use crate::error::{path as path_error_at, GcodePlanError};
use crate::knots::{knot_at, run_knots, Peak, RunKnots};
use crate::machine::{Machine, DOF};
use crate::memory::Held;
use crate::network::{committed_network, LearnedCorners};
use crate::runs::{read_into, Run, RunKind, Step};
use crate::settings::PlanSettings;
use crate::timed::TimedRun;

/// Rounds of the executor's check (step 5) before the plan is given up.
pub const MAX_CHECK_ROUNDS: usize = 8;

/// Bytes of one trajectory point as assembled (positions, velocities, accelerations, an empty
/// effort: four vectors of six values) or as the executor validates it, about.
pub const TRAJECTORY_POINT_BYTES: u64 = 4 * 24 + 3 * 6 * 8 + 8;

/// Bytes a placed run holds: its pieces, samples, feed plan phases and joint points.
fn run_bytes(timed: &TimedRun, knots: &RunKnots) -> u64 {
    bytes_of::<Piece>(timed.path.pieces.len() as u64)
        .saturating_add(bytes_of::<[f64; 3]>(timed.path.polyline.len() as u64))
        .saturating_add(bytes_of::<PathSample>(timed.samples.len() as u64))
        .saturating_add(bytes_of::<kerf_toolpath::feed::PlacedPhase>(
            timed.plan.phases.len() as u64,
        ))
        .saturating_add(bytes_of::<crate::knots::JointKnot>(knots.knots.len() as u64))
        .saturating_add((std::mem::size_of::<RunReport>() + std::mem::size_of::<Placed>()) as u64)
}

/// What one run became.
#[derive(Debug, Clone, PartialEq)]
pub struct RunReport {
    /// What it does.
    pub kind: RunKind,
    /// First and last source line.
    pub lines: (usize, usize),
    /// Vertices of its polyline (after merging).
    pub vertices: usize,
    /// Corners smoothed.
    pub corners: usize,
    /// Length of the smoothed path \[m\].
    pub length: f64,
    /// The feed it was planned at \[m/s\].
    pub feed: f64,
    /// The corner tolerance δ_c it was smoothed within \[m\].
    pub corner_tolerance: f64,
    /// The largest corner deviation from its polyline (exact) \[m\].
    pub max_corner_deviation: f64,
    /// Time of its feed plan as run (lowered in corners for the joints) \[s\].
    pub feed_time: f64,
    /// Time of its feed plan under the path's limits alone \[s\] (T_m for T_m / T_lb).
    pub path_time: f64,
    /// T_lb on the same path \[s\].
    pub lower_bound: f64,
    /// Uniform slowdown for the joint limits (1: none).
    pub slowdown: f64,
    /// The binding joint limit before the slowdown.
    pub peak: Peak,
    /// When it starts in the trajectory \[s\].
    pub start_time: f64,
    /// Seeds 000/003 metrics of its feed plan at the interpolation period.
    pub metrics: Metrics,
}

/// A beam or spindle switch, at rest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToolEvent {
    /// Time in the trajectory \[s\].
    pub time: f64,
    /// On after it.
    pub on: bool,
    /// Source line.
    pub line: usize,
}

/// A planned program.
#[derive(Debug, Clone, PartialEq)]
pub struct GcodePlan {
    /// The machine's name.
    pub machine: String,
    /// The joint trajectory, from rest at the program's start to rest at
    /// its end.
    pub trajectory: TrajectoryRequest,
    /// Every run.
    pub runs: Vec<RunReport>,
    /// Every tool switch.
    pub events: Vec<ToolEvent>,
    /// The trajectory's duration \[s\].
    pub duration: f64,
    /// Σ feed-plan times of the runs as run (lowered in corners for the joints), before any
    /// uniform slowdown \[s\].
    pub feed_time: f64,
    /// Σ feed-plan times under the path's limits alone: T_m of T_m / T_lb \[s\].
    pub path_time: f64,
    /// Σ T_lb \[s\].
    pub lower_bound: f64,
    /// Σ dwell times \[s\].
    pub dwell_time: f64,
    /// The largest distance of the executed tip (the executor's
    /// interpolation at each control period, by forward kinematics) from
    /// the planned point at the same time: ≤ δ_i \[m\].
    pub max_interpolation_deviation: f64,
    /// The largest exact corner deviation: ≤ δ_c \[m\].
    pub max_corner_deviation: f64,
    /// δ \[m\].
    pub tolerance: f64,
    /// The largest peak ratio of each joint over the trajectory after the
    /// slowdowns: (velocity, acceleration, jerk) / limit.
    pub peak_ratios: [[f64; 3]; DOF],
    /// Lines read.
    pub lines: usize,
    /// Arcs read.
    pub arcs: usize,
    /// Motions of zero length.
    pub zero_length_moves: usize,
    /// Blocks skipped by block delete.
    pub skipped_blocks: usize,
    /// What the user should know (a feed capped, a run slowed).
    pub warnings: Vec<String>,
    /// `drls-net` ([`PlanSettings::learned_corners`]): corners the network predicted and its
    /// check accepted (0 for the other methods).
    pub corner_predictions: usize,
    /// `drls-net`: corners that fell back to the NURBS swarm (outside the trained
    /// distribution, or a prediction that broke δ or its check; the first one's reason is in
    /// [`GcodePlan::warnings`]); 0 for the other methods.
    pub corner_fallbacks: usize,
    /// Each run's smoothed path and feed plan (aligned with `runs`), for plots and checks.
    pub timed: Vec<TimedRun>,
}

impl GcodePlan {
    /// T_m / T_lb: the feed plans under the path's limits against the bound on the same
    /// paths and limits.
    pub fn lower_bound_ratio(&self) -> f64 {
        self.path_time / self.lower_bound
    }

    /// Metrics over every cutting run: times summed, maxima of the maxima,
    /// RMS values weighted by their point counts.
    pub fn cut_metrics(&self) -> Metrics {
        let mut out = Metrics {
            time: 0.0,
            max_curvature: 0.0,
            max_turning_angle: 0.0,
            rms_acceleration: 0.0,
            rms_jerk: 0.0,
            max_chord_error: 0.0,
            max_contour_error: 0.0,
            points: 0,
        };
        let (mut sa, mut sj) = (0.0, 0.0);
        for r in self.runs.iter().filter(|r| r.kind == RunKind::Cut) {
            let m = &r.metrics;
            out.time += m.time;
            out.max_curvature = out.max_curvature.max(m.max_curvature);
            out.max_turning_angle = out.max_turning_angle.max(m.max_turning_angle);
            out.max_chord_error = out.max_chord_error.max(m.max_chord_error);
            out.max_contour_error = out.max_contour_error.max(m.max_contour_error);
            sa += m.rms_acceleration.powi(2) * m.points as f64;
            sj += m.rms_jerk.powi(2) * m.points as f64;
            out.points += m.points;
        }
        if out.points > 0 {
            out.rms_acceleration = (sa / out.points as f64).sqrt();
            out.rms_jerk = (sj / out.points as f64).sqrt();
        }
        out
    }
}

/// One run in the trajectory.
struct Placed {
    timed: TimedRun,
    knots: RunKnots,
    start: f64,
    line: usize,
}

/// Plans `source` for `machine` (module documentation).
///
/// # Errors
/// Every [`GcodePlanError`]: the reader's (line, column), a setting, a
/// path (line), a point out of reach (line, point), too many points, an
/// empty program, the budget.
pub fn plan_program<R: BufRead>(
    source: R,
    machine: &dyn Machine,
    settings: &PlanSettings,
    budget: &Budget,
) -> Result<GcodePlan, GcodePlanError> {
    plan_program_inner(source, machine, settings, None, budget)
}

/// [`plan_program`] with `network` as the DRLS network of the `drls-net` corners
/// ([`PlanSettings::learned_corners`]) instead of the committed one; other methods ignore it.
///
/// # Errors
/// As [`plan_program`].
pub fn plan_program_with<R: BufRead>(
    source: R,
    machine: &dyn Machine,
    settings: &PlanSettings,
    network: &kerf_cornernet::Model,
    budget: &Budget,
) -> Result<GcodePlan, GcodePlanError> {
    plan_program_inner(source, machine, settings, Some(network), budget)
}

/// [`plan_program`] with the network given or, for the `drls-net` corners, the committed one.
fn plan_program_inner<R: BufRead>(
    source: R,
    machine: &dyn Machine,
    settings: &PlanSettings,
    network: Option<&kerf_cornernet::Model>,
    budget: &Budget,
) -> Result<GcodePlan, GcodePlanError> {
    settings.validate()?;
    let mut learned = match (settings.learned_corners, network) {
        (false, _) => None,
        (true, Some(model)) => Some(LearnedCorners::new(model)),
        (true, None) => Some(LearnedCorners::new(committed_network()?)),
    };
    // What the plan holds (the runs read, each placed run's path, samples, plan and points),
    // accounted on the budget until the plan returns.
    let mut held = Held::new(budget);
    let reading = read_into(source, settings, &mut held)?;
    budget.check("reading")?;
    let mut warnings = Vec::new();
    let mut placed: Vec<Placed> = Vec::new();
    let mut reports: Vec<RunReport> = Vec::new();
    let mut events = Vec::new();
    let mut time = 0.0;
    let mut dwell_time = 0.0;
    let mut holds: Vec<(f64, f64)> = Vec::new();
    let mut reference: Option<[f64; DOF]> = None;
    let mut points = 0usize;
    for step in &reading.steps {
        budget.check("planning runs")?;
        match step {
            Step::Dwell { seconds, .. } => {
                if *seconds > 0.0 {
                    holds.push((time, *seconds));
                    time += seconds;
                    dwell_time += seconds;
                }
            }
            Step::Tool { on, line } => events.push(crate::plan::ToolEvent {
                time,
                on: *on,
                line: *line,
            }),
            Step::Run(run) => {
                reachable(machine, run, reference.as_ref(), budget)?;
                let mut prepared = prepare_run(
                    run,
                    machine,
                    settings,
                    learned.as_mut(),
                    &mut warnings,
                    budget,
                )?;
                let line = run.lines[0];
                let knots = run_joints(
                    machine,
                    &mut prepared,
                    line,
                    reference.as_ref(),
                    settings,
                    settings.max_points.saturating_sub(points),
                    budget,
                )?;
                let Prepared {
                    timed,
                    limits,
                    feed,
                    lines,
                    path_time,
                    lower_bound,
                    ..
                } = prepared;
                points += knots.knots.len();
                if knots.slowdown > 1.0 {
                    warnings.push(format!(
                        "lines {}-{}: {} run slowed {:.3}x for the {} limit of {}",
                        lines.0,
                        lines.1,
                        run.kind.name(),
                        knots.slowdown,
                        knots.peak.what,
                        knots.peak.joint
                    ));
                }
                reference = knots.knots.last().map(|k| k.q);
                // Figures of the plan the joints follow (lowered in corners where they
                // needed it).
                let report = RunReport {
                    kind: run.kind,
                    lines,
                    vertices: run.points.len(),
                    corners: timed.path.corners().count(),
                    length: timed.plan.length,
                    feed,
                    corner_tolerance: run.corner_tolerance,
                    max_corner_deviation: timed.path.max_deviation(),
                    feed_time: timed.plan.time,
                    path_time,
                    lower_bound,
                    slowdown: knots.slowdown,
                    peak: knots.peak.clone(),
                    start_time: time,
                    metrics: metrics_within(
                        &timed.plan,
                        &timed.path,
                        &timed.samples,
                        limits.curvature.interpolation_period,
                        limits.curvature.servo.as_ref(),
                        budget,
                    )?,
                };
                held.add(run_bytes(&timed, &knots), || {
                    format!(
                        "planned runs: {} runs up to line {}, {} pieces, {} samples and {} \
                         joint points in the last",
                        placed.len() + 1,
                        lines.1,
                        timed.path.pieces.len(),
                        timed.samples.len(),
                        knots.knots.len()
                    )
                })?;
                let start = time;
                time += timed.duration() * knots.slowdown;
                reports.push(report);
                placed.push(Placed {
                    timed,
                    knots,
                    start,
                    line,
                });
            }
        }
    }
    if placed.is_empty() {
        return Err(GcodePlanError::Empty {
            reason: format!(
                "{} lines read, no move of nonzero length (zero-length moves: {})",
                reading.lines, reading.zero_length_moves
            ),
        });
    }
    let limits = machine.executor_limits()?;
    let config = ExecutorConfig {
        control_period: settings.control_period,
        ..ExecutorConfig::default()
    };
    let mut round = 0;
    let (trajectory, max_interpolation_deviation) = loop {
        budget.check("executor check")?;
        let count: usize = placed.iter().map(|p| p.knots.knots.len()).sum::<usize>() + holds.len();
        if count > settings.max_points {
            return Err(GcodePlanError::TooManyPoints {
                max: settings.max_points,
            });
        }
        held.check(
            bytes_of::<u8>(count as u64).saturating_mul(2 * TRAJECTORY_POINT_BYTES),
            || format!("joint trajectory: {count} points, assembled and validated"),
        )?;
        let request = assemble(machine, &placed, &holds);
        if request.points.len() > settings.max_points {
            return Err(GcodePlanError::TooManyPoints {
                max: settings.max_points,
            });
        }
        let prepared = check_executable(&limits, &config, &request).map_err(|e| {
            GcodePlanError::NotExecutable {
                line: 0,
                reason: e.to_string(),
            }
        })?;
        let (worst, bad) = executed_deviation(machine, &placed, &prepared, settings, budget)?;
        if bad.is_empty() {
            break (request, worst);
        }
        round += 1;
        if round > MAX_CHECK_ROUNDS {
            // Named by the first run still beyond the tolerance.
            let line = bad
                .first()
                .and_then(|(run, _)| placed.get(*run))
                .map_or(0, |p| p.line);
            return Err(GcodePlanError::NotExecutable {
                line,
                reason: format!(
                    "the executed tool tip leaves the interpolation tolerance {:.3e} m by {worst:.3e} m \
                     after {MAX_CHECK_ROUNDS} rounds of refinement (first in the run from line \
                     {line})",
                    settings.interpolation_tolerance()
                ),
            });
        }
        refine(machine, &mut placed, &bad, budget)?;
    };
    let peak_ratios = joint_peaks(machine, &placed, budget)?;
    let timed: Vec<TimedRun> = placed.into_iter().map(|p| p.timed).collect();
    let duration = trajectory.points.last().map_or(0.0, |p| p.time_from_start);
    let counts = learned
        .as_ref()
        .map(LearnedCorners::counts)
        .unwrap_or_default();
    warnings.extend(learned.as_ref().and_then(LearnedCorners::warning));
    Ok(GcodePlan {
        machine: machine.name().to_string(),
        trajectory,
        feed_time: reports.iter().map(|r| r.feed_time).sum(),
        path_time: reports.iter().map(|r| r.path_time).sum(),
        lower_bound: reports.iter().map(|r| r.lower_bound).sum(),
        max_corner_deviation: reports
            .iter()
            .map(|r| r.max_corner_deviation)
            .fold(0.0, f64::max),
        runs: reports,
        events,
        duration,
        dwell_time,
        max_interpolation_deviation,
        tolerance: settings.tolerance,
        peak_ratios,
        lines: reading.lines,
        arcs: reading.arcs,
        zero_length_moves: reading.zero_length_moves,
        skipped_blocks: reading.skipped_blocks,
        warnings,
        corner_predictions: counts.network,
        corner_fallbacks: counts.fallback,
        timed,
    })
}

/// Every vertex of a run within reach, each IK nearest the previous: an
/// unreachable program point is reported with its own source line.
fn reachable(
    machine: &dyn Machine,
    run: &Run,
    reference: Option<&[f64; DOF]>,
    budget: &Budget,
) -> Result<(), GcodePlanError> {
    let mut previous = reference.copied();
    for (k, (p, line)) in run.points.iter().zip(&run.lines).enumerate() {
        if k % 256 == 255 {
            budget.check("reach of the program's points")?;
        }
        let q = machine.joints(*p, previous.as_ref()).map_err(|reason| {
            GcodePlanError::Unreachable {
                line: *line,
                x: p[0],
                y: p[1],
                z: p[2],
                reason,
            }
        })?;
        previous = Some(q);
    }
    Ok(())
}

/// A run smoothed, sampled and timed under the path limits, with what its report needs.
struct Prepared {
    timed: TimedRun,
    /// The programmed feed of every sample (capped at the machine's).
    caps: Vec<f64>,
    /// The path limits, `curvature.feed` the run's highest feed.
    limits: FeedLimits,
    /// The run's highest feed \[m/s\].
    feed: f64,
    /// First and last source line.
    lines: (usize, usize),
    /// T_m: the plan's time under the path limits alone \[s\].
    path_time: f64,
    /// T_lb \[s\].
    lower_bound: f64,
}

/// Step 2 for one run: smoothing, samples, programmed feeds, T_lb, and the feed plan under
/// the programmed feeds.
fn prepare_run(
    run: &Run,
    machine: &dyn Machine,
    settings: &PlanSettings,
    learned: Option<&mut LearnedCorners>,
    warnings: &mut Vec<String>,
    budget: &Budget,
) -> Result<Prepared, GcodePlanError> {
    let line = run.lines[0];
    let last_line = run.lines.last().copied().unwrap_or(line);
    let path_error = |error| path_error_at(line, error);
    let machine_max = match run.kind {
        RunKind::Rapid => f64::INFINITY,
        _ => settings.limits.curvature.feed,
    };
    let programmed = run.feeds.iter().copied().fold(0.0, f64::max);
    if programmed > machine_max {
        warnings.push(format!(
            "lines {line}-{last_line}: F up to {programmed:.4} m/s is above the machine's \
             {machine_max:.4} m/s and is planned at {machine_max:.4} m/s"
        ));
    }
    let feeds: Vec<f64> = run.feeds.iter().map(|f| f.min(machine_max)).collect();
    let feed = feeds.iter().copied().fold(0.0, f64::max);
    let mut limits: FeedLimits = settings.limits;
    limits.curvature.feed = feed;
    let path = match learned {
        Some(corners) => corners.smooth(&run.points, run.corner_tolerance, line, budget),
        None => smooth_polyline_within(
            &run.points,
            run.corner_tolerance,
            &settings.corner_method,
            budget,
        ),
    }
    .map_err(path_error)?;
    // The feed plan, checked on its output at the interpolation period against every limit
    // (kerf_toolpath::check_plan); where it breaks one between its samples, the path is
    // sampled 4x finer (every bound of its sampling) and planned again, at most
    // SAMPLE_REFINEMENTS times.
    let mut sampling = settings.sampling;
    let mut attempt = 0;
    let (samples, caps, plan) = loop {
        budget.check("path sampling")?;
        let samples = sampling.sample_within(&path, budget).map_err(path_error)?;
        // The caps, the limit curve of T_lb and the pieces' caps: three numbers per sample.
        budget.check_memory(
            bytes_of::<f64>(3 * samples.len() as u64),
            &format!("programmed feeds of {} path samples", samples.len()),
        )?;
        let caps = sample_caps(&path, &samples, &run.points, &feeds);
        let plan = feed_plan(&samples, &caps, feed, &limits, machine, settings, budget)
            .map_err(path_error)?;
        match plan_violation(
            &path, &samples, &caps, feed, &limits, &plan, machine, settings, budget,
        )
        .map_err(path_error)?
        {
            None => break (samples, caps, plan),
            Some((what, ratio, time)) if attempt == SAMPLE_REFINEMENTS => {
                return Err(GcodePlanError::NotExecutable {
                    line,
                    reason: format!(
                        "lines {line}-{last_line}: the feed plan breaks the {what} limit \
                         ({ratio:.4} of it at {time:.3} s into the run) even with the \
                         samples {sampling:?}"
                    ),
                });
            }
            Some(_) => {
                sampling = sampling.finer(4.0);
                attempt += 1;
            }
        }
    };
    let curve: Vec<f64> = samples
        .iter()
        .zip(&caps)
        .map(|(p, cap)| limits.curvature.speed(p.curvature).min(*cap))
        .collect();
    let lower = bang_bang_under_within(&samples, curve, limits.tangential_acceleration, budget)
        .map_err(path_error)?;
    let path_time = plan.time;
    Ok(Prepared {
        timed: TimedRun {
            path,
            samples,
            plan,
        },
        caps,
        limits,
        feed,
        lines: (line, last_line),
        path_time,
        lower_bound: lower.time,
    })
}

/// The feed plan under per-sample caps (`feed` when they are all equal to it).
fn feed_plan(
    samples: &[PathSample],
    caps: &[f64],
    feed: f64,
    limits: &FeedLimits,
    machine: &dyn Machine,
    settings: &PlanSettings,
    budget: &Budget,
) -> Result<kerf_toolpath::FeedPlan, kerf_toolpath::ToolpathError> {
    settings.feed_method.plan_within(
        samples,
        &constraints(caps, feed, limits, machine, settings),
        budget,
    )
}

/// The constraints of a run's feed plan: its limits, the per-sample feeds when they vary, and
/// the machine's axis limits when the settings ask for them.
fn constraints<'a>(
    caps: &'a [f64],
    feed: f64,
    limits: &FeedLimits,
    machine: &dyn Machine,
    settings: &PlanSettings,
) -> FeedConstraints<'a> {
    let varies = caps.iter().any(|c| *c != feed);
    FeedConstraints {
        limits: *limits,
        axes: if settings.feed_axis_limits {
            machine.axis_limits()
        } else {
            None
        },
        caps: varies.then_some(caps),
        whole_normal_jerk: settings.feed_whole_normal_jerk,
    }
}

/// Times the samples of a run are made 4x finer when its feed plan breaks a limit between
/// them (step 2) before the run is refused.
pub const SAMPLE_REFINEMENTS: usize = 3;

/// Rounding margin of the plan check: a ratio up to 1 + this holds.
pub const CHECK_MARGIN: f64 = 1e-6;

/// The worst limit a feed plan breaks on its output at the interpolation period
/// ([`kerf_toolpath::check_plan`]): its name, ratio and time; `None` when every limit holds
/// (within [`CHECK_MARGIN`]).
#[allow(clippy::too_many_arguments)]
fn plan_violation(
    path: &SmoothedPath,
    samples: &[PathSample],
    caps: &[f64],
    feed: f64,
    limits: &FeedLimits,
    plan: &kerf_toolpath::FeedPlan,
    machine: &dyn Machine,
    settings: &PlanSettings,
    budget: &Budget,
) -> Result<Option<(&'static str, f64, f64)>, kerf_toolpath::ToolpathError> {
    let constraints = constraints(caps, feed, limits, machine, settings);
    let check = check_plan_within(
        path,
        samples,
        plan,
        &constraints,
        limits.curvature.interpolation_period,
        budget,
    )?;
    if check.holds(CHECK_MARGIN) {
        return Ok(None);
    }
    let (what, worst) = check.worst();
    Ok(Some((what, worst.ratio, worst.time)))
}

/// Rounds of local slowdown in corners (step 3) before what remains is a uniform slowdown.
pub const LOCAL_ROUNDS: usize = 4;

/// Step 3 for one run: its joint points. Where a piece needs r > 1 for a joint limit, the
/// corner samples of its arc-length span are capped at the piece's highest planned speed /
/// (1.02 r) and the feed is replanned (the v³ dκ/ds term that binds in corners scales as the
/// cube of the speed: r is already its cube root), at most [`LOCAL_ROUNDS`] times; what
/// remains is the uniform slowdown of [`crate::knots`]. Only corner samples are capped: a line
/// is sampled at its ends, and a cap at a line's end would hold the whole line. The round
/// with the least executed time (plan time × its uniform slowdown) is kept: capping can also
/// cost time (more S-curves), so the uniform slowdown of round 0 stays when it is better.
fn run_joints(
    machine: &dyn Machine,
    prepared: &mut Prepared,
    line: usize,
    reference: Option<&[f64; DOF]>,
    settings: &PlanSettings,
    max_points: usize,
    budget: &Budget,
) -> Result<RunKnots, GcodePlanError> {
    let knots_of = |timed: &TimedRun| {
        run_knots(
            machine,
            timed,
            line,
            reference,
            settings.knot_spacing,
            settings.control_period,
            settings.interpolation_tolerance(),
            max_points,
            budget,
        )
    };
    let feed = prepared.feed;
    let mut caps = prepared.caps.clone();
    let first = knots_of(&prepared.timed)?;
    let mut over = first.over.clone();
    // The round whose executed time (plan time × its uniform slowdown) is the least.
    let mut best = (
        prepared.timed.duration() * first.slowdown,
        prepared.timed.plan.clone(),
        first,
    );
    // Seed 003's constant-interval planner takes no per-sample caps: uniform slowdown only.
    let rounds = match settings.feed_method {
        kerf_toolpath::FeedMethod::NearOptimal => LOCAL_ROUNDS,
        kerf_toolpath::FeedMethod::ConstantIntervals => 0,
    };
    for _ in 0..rounds {
        if over.is_empty() || !lower_corner_caps(&prepared.timed, &over, &mut caps) {
            break;
        }
        budget.check("local slowdown")?;
        let plan = feed_plan(
            &prepared.timed.samples,
            &caps,
            feed,
            &prepared.limits,
            machine,
            settings,
            budget,
        )
        .map_err(|error| path_error_at(line, error))?;
        // A replanned feed that breaks a path limit is not used (the last checked one stays).
        let timed = &prepared.timed;
        if plan_violation(
            &timed.path,
            &timed.samples,
            &caps,
            feed,
            &prepared.limits,
            &plan,
            machine,
            settings,
            budget,
        )
        .map_err(|error| path_error_at(line, error))?
        .is_some()
        {
            break;
        }
        prepared.timed.plan = plan;
        let knots = knots_of(&prepared.timed)?;
        over = knots.over.clone();
        let executed = prepared.timed.duration() * knots.slowdown;
        if executed < best.0 {
            best = (executed, prepared.timed.plan.clone(), knots);
        }
    }
    let (_, plan, knots) = best;
    prepared.timed.plan = plan;
    Ok(knots)
}

/// Caps the corner samples of each over-limit piece's arc-length span at the piece's highest
/// planned speed / (1.02 r) ([`run_joints`]); whether any cap was lowered.
fn lower_corner_caps(timed: &TimedRun, over: &[(f64, f64, f64)], caps: &mut [f64]) -> bool {
    let samples = &timed.samples;
    let in_corner = |k: usize| {
        matches!(
            timed.path.pieces.get(samples[k].piece),
            Some(Piece::Corner(_))
        ) && samples
            .get(k + 1)
            .is_none_or(|n| n.piece == samples[k].piece)
    };
    let mut lowered = false;
    for &(t0, t1, r) in over {
        let (s0, _, _) = timed.state(t0);
        let (s1, _, _) = timed.state(t1);
        let vmax = (0..=8)
            .map(|i| timed.state(t0 + (t1 - t0) * f64::from(i) / 8.0).1)
            .fold(0.0, f64::max);
        let cap = vmax / (1.02 * r);
        if cap <= 0.0 {
            continue;
        }
        let lo = samples.partition_point(|p| p.s < s0).saturating_sub(1);
        let hi = samples.partition_point(|p| p.s <= s1).min(caps.len() - 1);
        for (k, c) in caps.iter_mut().enumerate().take(hi + 1).skip(lo) {
            if in_corner(k) && *c > cap {
                *c = cap;
                lowered = true;
            }
        }
    }
    lowered
}

/// The programmed feed of every sample: a line piece's is the lowest feed of the polyline
/// segments it lies on, a corner's the lower of its two segments'.
fn sample_caps(
    path: &SmoothedPath,
    samples: &[PathSample],
    points: &[[f64; 3]],
    feeds: &[f64],
) -> Vec<f64> {
    let n = points.len();
    let lowest = |a: usize, b: usize| {
        feeds[a.min(feeds.len() - 1)..b.clamp(a + 1, feeds.len())]
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min)
    };
    // The vertex index of every corner, in order.
    let mut vertex = 0usize;
    let mut corner_vertex: Vec<Option<usize>> = Vec::with_capacity(path.pieces.len());
    for piece in &path.pieces {
        match piece {
            Piece::Corner(c) => {
                let mut k = vertex + 1;
                while k < n - 1 && points[k] != c.vertex {
                    k += 1;
                }
                vertex = k;
                corner_vertex.push(Some(k));
            }
            Piece::Line { .. } => corner_vertex.push(None),
        }
    }
    let mut piece_caps = Vec::with_capacity(path.pieces.len());
    let mut previous = 0usize;
    for (i, v) in corner_vertex.iter().enumerate() {
        piece_caps.push(match v {
            Some(k) => {
                previous = *k;
                lowest(k - 1, k + 1)
            }
            None => {
                let next = corner_vertex[i + 1..]
                    .iter()
                    .find_map(|v| *v)
                    .unwrap_or(n - 1);
                lowest(previous, next)
            }
        });
    }
    samples.iter().map(|s| piece_caps[s.piece]).collect()
}

/// Step 4: every run's points in scaled global time, dwells as a second
/// point at rest; the first point of a run is the previous run's last
/// (both at rest at the same place) and is kept once.
fn assemble(machine: &dyn Machine, placed: &[Placed], holds: &[(f64, f64)]) -> TrajectoryRequest {
    let names: Vec<String> = machine.bounds().iter().map(|b| b.name.clone()).collect();
    let mut points: Vec<TrajectoryPoint> = Vec::new();
    // A dwell is the last point again, at rest, at the dwell's end (before the first run the
    // first point's own time holds the robot where it stands).
    let hold = |points: &mut Vec<TrajectoryPoint>, &(at, seconds): &(f64, f64)| {
        if let Some(last) = points.last().cloned() {
            points.push(TrajectoryPoint {
                time_from_start: at + seconds,
                velocities: vec![0.0; DOF],
                accelerations: vec![0.0; DOF],
                ..last
            });
        }
    };
    let mut dwells = holds.iter().peekable();
    for p in placed {
        while let Some(dwell) = dwells.next_if(|(at, _)| *at <= p.start) {
            hold(&mut points, dwell);
        }
        let skip = usize::from(!points.is_empty());
        for k in p.knots.scaled(p.start).skip(skip) {
            points.push(TrajectoryPoint {
                positions: k.q.to_vec(),
                velocities: k.qd.to_vec(),
                accelerations: k.qdd.to_vec(),
                effort: Vec::new(),
                time_from_start: k.t,
            });
        }
    }
    for dwell in dwells {
        hold(&mut points, dwell);
    }
    TrajectoryRequest {
        joint_names: names,
        points,
        start_time: None,
    }
}

/// Step 5: the executor's interpolation at every control period against
/// the planned point; returns the worst distance and, per run, the local
/// (unscaled) times where it exceeds δ_i.
fn executed_deviation(
    machine: &dyn Machine,
    placed: &[Placed],
    prepared: &kerf_executor::ValidatedTrajectory,
    settings: &PlanSettings,
    budget: &Budget,
) -> Result<(f64, Vec<(usize, f64)>), GcodePlanError> {
    let period = settings.control_period;
    let tolerance = settings.interpolation_tolerance();
    let t0 = prepared.start_time();
    let mut sample = JointSample::default();
    let mut worst: f64 = 0.0;
    let mut bad = Vec::new();
    let mut count = 0usize;
    // Each run's time window on the executor's clock (every control period in it, and its
    // end); between runs the robot stands still (a dwell, or the shared rest point), exactly.
    for (run, p) in placed.iter().enumerate() {
        let end = p.start + p.timed.duration() * p.knots.slowdown;
        let first = (p.start / period).ceil() as u64;
        let last = (end / period).floor() as u64;
        let times = (first..=last)
            .map(|k| k as f64 * period)
            .chain(std::iter::once(end));
        for t in times {
            count += 1;
            if count.is_multiple_of(4096) {
                budget.check("executor check")?;
            }
            prepared.sample_into(t0 + t, &mut sample);
            let local = ((t - p.start) / p.knots.slowdown).clamp(0.0, p.timed.duration());
            let planned = p.timed.motion(local).point;
            let q: [f64; DOF] =
                std::array::from_fn(|j| sample.positions.get(j).copied().unwrap_or(f64::NAN));
            let tip = machine
                .tip(&q)
                .map_err(|reason| GcodePlanError::NotExecutable {
                    line: p.line,
                    reason: format!("line {}: at {t:.4} s: {reason}", p.line),
                })?;
            let d = (0..3)
                .map(|i| (tip[i] - planned[i]).powi(2))
                .sum::<f64>()
                .sqrt();
            worst = worst.max(d);
            if d > tolerance {
                bad.push((run, local));
            }
        }
    }
    Ok((worst, bad))
}

/// Splits the pieces holding the bad times (step 5's repeat).
fn refine(
    machine: &dyn Machine,
    placed: &mut [Placed],
    bad: &[(usize, f64)],
    budget: &Budget,
) -> Result<(), GcodePlanError> {
    for (k, (run, t)) in bad.iter().enumerate() {
        if k % 64 == 63 {
            budget.check("executor check (refinement)")?;
        }
        let p = &mut placed[*run];
        let knots = &mut p.knots.knots;
        let k = knots
            .partition_point(|x| x.t <= *t)
            .clamp(1, knots.len() - 1);
        let (a, b) = (knots[k - 1], knots[k]);
        let mid = 0.5 * (a.t + b.t);
        if mid <= a.t || mid >= b.t {
            continue;
        }
        let knot = knot_at(machine, &p.timed, mid, Some(&a.q)).map_err(|reason| {
            let x = p.timed.motion(mid).point;
            GcodePlanError::Unreachable {
                line: p.line,
                x: x[0],
                y: x[1],
                z: x[2],
                reason,
            }
        })?;
        knots.insert(k, knot);
    }
    Ok(())
}

/// The largest peak ratios of every joint over every piece, after the
/// slowdowns (v/r, a/r², j/r³).
fn joint_peaks(
    machine: &dyn Machine,
    placed: &[Placed],
    budget: &Budget,
) -> Result<[[f64; 3]; DOF], GcodePlanError> {
    let mut out = [[0.0f64; 3]; DOF];
    for p in placed {
        let r = p.knots.slowdown;
        for (k, w) in p.knots.knots.windows(2).enumerate() {
            if k % 256 == 255 {
                budget.check("joint peaks")?;
            }
            let peaks = crate::knots::piece_peaks(machine, &w[0], &w[1]);
            for j in 0..DOF {
                out[j][0] = out[j][0].max(peaks[j][0] / r);
                out[j][1] = out[j][1].max(peaks[j][1] / (r * r));
                out[j][2] = out[j][2].max(peaks[j][2] / (r * r * r));
            }
        }
    }
    Ok(out)
}
