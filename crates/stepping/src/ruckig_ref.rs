//! The Ruckig reference: jerk-limited motion through the same reference
//! points as RPRO, sampled at the control period, as the yardstick for
//! steps and accuracy (issue 29).
//!
//! Ruckig (Berscheid & Kröger 2021, "Jerk-limited real-time trajectory
//! generation with arbitrary target states", RSS) computes the
//! time-optimal jerk-limited motion from any state to any target state
//! (position, velocity, acceleration) of several synchronized axes. kerf
//! uses its maintained Rust port `rsruckig` 3.0.1. Time-optimal motion
//! *through* intermediate points is not what Ruckig solves exactly (the
//! port's own waypoint solver is a local refinement, "not guaranteed
//! time-optimal"), so this module offers several ways to chain Ruckig
//! through the points ([`Method`]) and measures them.
//!
//! # What a reference is
//! The axes start at rest on the first point and end at rest on the last;
//! the trajectory is sampled every period ([`Reference`]), and each point
//! is credited with its closest sample (Euclidean distance over the axes,
//! over all samples). Steps are periods, as in [`crate::run::Run::steps`].
//!
//! # Methods
//! * [`Method::Waypoints`]: one rsruckig call with `intermediate_positions`
//!   (continuous time; the port refuses discrete durations with
//!   waypoints). Fewest periods of the Ruckig methods, but the samples fall
//!   where they fall: a point is missed by up to half a period of travel.
//! * [`Method::WaypointStates`]: the pass-through states (velocity and
//!   acceleration per axis) of [`Method::Waypoints`], then one state-to-state
//!   Ruckig section per pair of points with
//!   `DurationDiscretization::Discrete`, so that every point is a sample
//!   (error at Ruckig's numerical precision, ~1e-8 m). Each section is
//!   rounded up to whole periods: at most one period more per point.
//! * [`Method::VelocityPass`]: the same discrete sections, with the
//!   pass-through velocities of a forward/backward pass per axis (zero
//!   acceleration at every point, zero velocity where an axis turns back).
//! * [`Method::RestToRest`]: discrete sections that stop on every point:
//!   slow, but an honest upper bound.
//!
//! [`lower_bound`] is the rest-to-rest time-optimal duration from the first
//! to the last point with the points in between ignored: no motion within
//! the limits can be faster, RPRO's included.
//!
//! # What was measured (`cargo bench -p kerf_stepping --bench stepping`)
//! Held-out single-axis paths of seed 002's database (15 and 50 points,
//! three densities, four limit combinations of Table 1, 10 paths each):
//!
//! | sum of steps (40 processes) | 15 high | 15 medium | 15 low | 50 high | 50 medium | 50 low |
//! |---|---|---|---|---|---|---|
//! | [`lower_bound`] | 4202 | 22343 | 210885 | 9380 | 78662 | 775947 |
//! | RPRO look-ahead 1 | 7537 | 24920 | 211683 | 24085 | 88237 | 778753 |
//! | [`Method::WaypointStates`] | 13833 | 28023 | 211140 | 49784 | 100149 | 776912 |
//! | [`Method::VelocityPass`] | 12539 | 28231 | 211140 | 43669 | 99892 | 776912 |
//! | [`Method::Waypoints`] | 8563 | 24615 | 210885 | 28219 | 86848 | 775947 |
//! | [`Method::RestToRest`] | 23315 | 56921 | 244939 | 86311 | 206949 | 901736 |
//!
//! (high-density rows over the 35 and 36 processes RPRO completed.) The
//! discrete-section methods hit every point to ≤ 0.01 µm; the one-call
//! waypoint trajectory misses points by 8–42 µm on average and up to
//! 133 µm, beyond seed 002's 10 µm precision, and at high density its
//! continuous-time refinement is far from the bound (rsruckig states it
//! is not time-optimal). [`Method::WaypointStates`] is the default: every
//! point within precision, within 0.1–0.4 % of the bound at low density
//! and 12–27 % above it at medium density, one computation in ~3.4 ms
//! (max 13 ms) per 50-point path. Where points are 1–10 periods of
//! travel apart (high density) an exact hit of every point costs whole
//! periods that RPRO's ±10 µm windows do not: there RPRO needs fewer
//! periods, and the bound is the fairer yardstick. [`Method::VelocityPass`]
//! is better than the default at high density (10–12 % fewer periods) and
//! about equal elsewhere; both stay selectable.
//!
//! # Sampling and accuracy
//! Samples are taken from rsruckig's `Trajectory::at_time` at multiples of
//! the period (within a discrete section: `i·Δt` from its start; its last
//! sample is its end state). The accuracy figures in the bench use the
//! same closest-sample rule as RPRO's passes.

use rsruckig::prelude::{
    DataArrayOrVec, DurationDiscretization, InputParameter, Ruckig, RuckigResult,
    ThrowErrorHandler, Trajectory,
};

use crate::{
    error::StepError,
    limits::{check_period, Limits},
};

/// How the reference is chained through the points (module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Method {
    /// rsruckig's waypoint solver in one call, continuous time, sampled.
    Waypoints,
    /// The waypoint solver's pass-through states, discrete sections.
    #[default]
    WaypointStates,
    /// Forward/backward velocity pass (zero acceleration), discrete
    /// sections.
    VelocityPass,
    /// Rest on every point, discrete sections.
    RestToRest,
}

impl Method {
    /// All methods, default first.
    pub const ALL: [Method; 4] = [
        Method::WaypointStates,
        Method::Waypoints,
        Method::VelocityPass,
        Method::RestToRest,
    ];

    /// Short name as printed in tables.
    pub fn name(self) -> &'static str {
        match self {
            Method::Waypoints => "waypoints",
            Method::WaypointStates => "waypoint states",
            Method::VelocityPass => "velocity pass",
            Method::RestToRest => "rest to rest",
        }
    }
}

/// The sample closest to one reference point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Index of the point (0 = the start).
    pub point: usize,
    /// Sample index (0 = the start; a sample per period).
    pub step: usize,
    /// Euclidean distance [m or rad] of that sample to the point.
    pub distance: f64,
}

/// A sampled reference trajectory.
#[derive(Debug, Clone, PartialEq)]
pub struct Reference {
    /// How it was made.
    pub method: Method,
    /// Sample period (s).
    pub period: f64,
    /// Number of axes.
    pub axes: usize,
    /// Positions, sample-major: sample `i`, axis `j` at `i·axes + j`.
    pub positions: Vec<f64>,
    /// Velocities, same layout.
    pub velocities: Vec<f64>,
    /// Accelerations, same layout.
    pub accelerations: Vec<f64>,
    /// For each point (the start first), its closest sample.
    pub hits: Vec<Hit>,
    /// Duration (s) of the Ruckig trajectory (continuous for
    /// [`Method::Waypoints`], whole periods otherwise).
    pub duration: f64,
    /// Discrete sections whose moving pass-through state was scaled down
    /// (fewer periods, or no solution, at full scale).
    pub degraded: usize,
}

impl Reference {
    /// Number of samples (steps + 1).
    pub fn samples(&self) -> usize {
        self.positions.len() / self.axes.max(1)
    }

    /// Number of periods from the start to rest on the last point.
    pub fn steps(&self) -> usize {
        self.samples().saturating_sub(1)
    }

    /// Position of sample `i` (one entry per axis; empty past the end).
    pub fn position(&self, i: usize) -> &[f64] {
        self.positions
            .get(i * self.axes..(i + 1) * self.axes)
            .unwrap_or(&[])
    }

    /// Velocity of sample `i`.
    pub fn velocity(&self, i: usize) -> &[f64] {
        self.velocities
            .get(i * self.axes..(i + 1) * self.axes)
            .unwrap_or(&[])
    }

    /// Acceleration of sample `i`.
    pub fn acceleration(&self, i: usize) -> &[f64] {
        self.accelerations
            .get(i * self.axes..(i + 1) * self.axes)
            .unwrap_or(&[])
    }

    /// Mean distance of the points after the start to their closest
    /// samples (as [`crate::run::Run::mean_error`]).
    pub fn mean_error(&self) -> f64 {
        let n = self.hits.len().saturating_sub(1);
        if n == 0 {
            return 0.0;
        }
        self.hits.iter().skip(1).map(|h| h.distance).sum::<f64>() / n as f64
    }

    /// Largest distance of a point to its closest sample.
    pub fn max_error(&self) -> f64 {
        self.hits.iter().map(|h| h.distance).fold(0.0, f64::max)
    }
}

/// Largest number of axes.
pub const MAX_AXES: usize = 6;

/// Points closer than this [m or rad] to their predecessor are refused as
/// repeated (Ruckig's final-position precision is ~1e-8).
pub const MIN_GAP: f64 = 1e-7;

/// Largest number of samples a reference may hold.
pub const MAX_SAMPLES: usize = 4_000_000;

/// Scales `c` of a pass-through state (velocity × c, acceleration × c²,
/// as a time scaling by 1/c would) among which each discrete section picks
/// the fewest periods; 0 (rest) always has a solution.
const SCALES: [f64; 7] = [1.0, 0.85, 0.7, 0.5, 0.3, 0.15, 0.0];

/// One kinematic state of every axis.
#[derive(Debug, Clone, PartialEq)]
struct Kin {
    p: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
}

impl Kin {
    fn rest(p: &[f64]) -> Self {
        Self {
            p: p.to_vec(),
            v: vec![0.0; p.len()],
            a: vec![0.0; p.len()],
        }
    }
}

/// rsruckig with heap-allocated axes, its input and trajectory.
struct Solver {
    otg: Ruckig<0, ThrowErrorHandler>,
    input: InputParameter<0>,
    traj: Trajectory<0>,
    axes: usize,
}

fn ruckig_err(section: usize, reason: impl std::fmt::Display) -> StepError {
    StepError::Ruckig {
        section,
        reason: reason.to_string(),
    }
}

fn daov(x: &[f64]) -> DataArrayOrVec<f64, 0> {
    DataArrayOrVec::Heap(x.to_vec())
}

impl Solver {
    fn new(limits: &[Limits], period: f64) -> Self {
        let axes = limits.len();
        let mut input = InputParameter::new(Some(axes));
        for (j, l) in limits.iter().enumerate() {
            input.max_velocity[j] = l.velocity;
            input.max_acceleration[j] = l.acceleration;
            input.max_jerk[j] = l.jerk;
        }
        Self {
            otg: Ruckig::new(Some(axes), period),
            input,
            traj: Trajectory::new(Some(axes)),
            axes,
        }
    }

    /// Solves `from → to` into `self.traj`; its duration.
    fn solve(
        &mut self,
        section: usize,
        from: &Kin,
        to: &Kin,
        discrete: bool,
    ) -> Result<f64, StepError> {
        let inp = &mut self.input;
        inp.intermediate_positions.clear();
        inp.duration_discretization = if discrete {
            DurationDiscretization::Discrete
        } else {
            DurationDiscretization::Continuous
        };
        for j in 0..self.axes {
            inp.current_position[j] = from.p[j];
            inp.current_velocity[j] = from.v[j];
            inp.current_acceleration[j] = from.a[j];
            inp.target_position[j] = to.p[j];
            inp.target_velocity[j] = to.v[j];
            inp.target_acceleration[j] = to.a[j];
        }
        match self.otg.calculate(&self.input, &mut self.traj) {
            Ok(RuckigResult::Working) => Ok(self.traj.get_duration()),
            Ok(other) => Err(ruckig_err(section, format!("result {other:?}"))),
            Err(e) => Err(ruckig_err(section, e)),
        }
    }

    /// The state of `self.traj` at `t`.
    fn at(&self, t: f64) -> Kin {
        let mut p = DataArrayOrVec::new(Some(self.axes), 0.0);
        let mut v = DataArrayOrVec::new(Some(self.axes), 0.0);
        let mut a = DataArrayOrVec::new(Some(self.axes), 0.0);
        let mut section = None;
        self.traj.at_time(
            t,
            &mut Some(&mut p),
            &mut Some(&mut v),
            &mut Some(&mut a),
            &mut None,
            &mut section,
        );
        Kin {
            p: p.to_vec(),
            v: v.to_vec(),
            a: a.to_vec(),
        }
    }
}

/// Checks points, limits and period; the number of axes.
fn validate(points: &[Vec<f64>], limits: &[Limits], period: f64) -> Result<usize, StepError> {
    check_period(period)?;
    let axes = limits.len();
    if !(1..=MAX_AXES).contains(&axes) {
        return Err(StepError::InvalidParameter {
            name: "axes".to_string(),
            value: axes as f64,
            reason: format!("one Limits per axis, 1..={MAX_AXES} axes"),
        });
    }
    for l in limits {
        l.validate()?;
    }
    if points.len() < 2 {
        return Err(StepError::InvalidPoint {
            index: points.len(),
            reason: "a reference needs a start and at least one point to pass".to_string(),
        });
    }
    for (i, p) in points.iter().enumerate() {
        if p.len() != axes {
            return Err(StepError::InvalidPoint {
                index: i,
                reason: format!("{} coordinates for {axes} axes", p.len()),
            });
        }
        if let Some(x) = p.iter().find(|x| !x.is_finite()) {
            return Err(StepError::InvalidPoint {
                index: i,
                reason: format!("coordinate {x} is not finite"),
            });
        }
        if i > 0 {
            let d = distance(p, &points[i - 1]);
            if d < MIN_GAP {
                return Err(StepError::InvalidPoint {
                    index: i,
                    reason: format!(
                        "{d} from point {} (a repeated point: at least {MIN_GAP} apart)",
                        i - 1
                    ),
                });
            }
        }
    }
    Ok(axes)
}

fn distance(x: &[f64], y: &[f64]) -> f64 {
    x.iter()
        .zip(y)
        .map(|(a, b)| (a - b) * (a - b))
        .sum::<f64>()
        .sqrt()
}

/// Periods covering `duration`, with slack for Ruckig's rounding.
fn periods(duration: f64, period: f64) -> usize {
    (duration / period - 1e-6).ceil().max(0.0) as usize
}

fn too_long(samples: usize) -> StepError {
    StepError::InvalidParameter {
        name: "reference samples".to_string(),
        value: samples as f64,
        reason: format!("more than {MAX_SAMPLES}: the path is too long for the period"),
    }
}

/// The Ruckig reference through `points` (the start first, one coordinate
/// per axis) under per-axis `limits`, sampled every `period`.
///
/// # Arguments
/// * `points` — at least two, each with `limits.len()` finite coordinates,
///   adjacent points at least [`MIN_GAP`] apart;
/// * `limits` — one per axis, 1..=[`MAX_AXES`] axes (velocity,
///   acceleration and jerk are symmetric bounds, as Ruckig's defaults);
/// * `period` — control period (s);
/// * `method` — how the sections are chained ([`Method`]).
///
/// # Returns
/// The sampled [`Reference`], at rest on the first point at sample 0 and at
/// rest on the last point at its last sample.
///
/// # Errors
/// * [`StepError::InvalidParameter`] for a bad period, limit or axis
///   count, or a trajectory of more than [`MAX_SAMPLES`] samples;
/// * [`StepError::InvalidPoint`] for too few, non-finite, wrongly sized or
///   repeated points;
/// * [`StepError::Ruckig`] when rsruckig fails a section even with its
///   pass-through state brought to rest.
///
/// # Performance
/// One rsruckig state-to-state solve per section (a few µs) plus, for the
/// waypoint methods, the port's refinement (4 sweeps of ~40 solves per
/// point per axis); sampling is one `at_time` per period.
pub fn reference(
    points: &[Vec<f64>],
    limits: &[Limits],
    period: f64,
    method: Method,
) -> Result<Reference, StepError> {
    let axes = validate(points, limits, period)?;
    let mut solver = Solver::new(limits, period);
    let mut out = Reference {
        method,
        period,
        axes,
        positions: Vec::new(),
        velocities: Vec::new(),
        accelerations: Vec::new(),
        hits: Vec::new(),
        duration: 0.0,
        degraded: 0,
    };
    match method {
        Method::Waypoints => {
            waypoints(&mut solver, points)?;
            let duration = solver.traj.get_duration();
            let n = periods(duration, period);
            if n + 1 > MAX_SAMPLES {
                return Err(too_long(n + 1));
            }
            push(&mut out, &Kin::rest(&points[0]));
            for i in 1..=n {
                let s = solver.at((i as f64 * period).min(duration));
                push(&mut out, &s);
            }
            out.duration = duration;
        }
        Method::WaypointStates | Method::VelocityPass | Method::RestToRest => {
            let (states, scales): (Vec<Kin>, &[f64]) = match method {
                Method::WaypointStates => (optimum_states(&mut solver, points)?, &SCALES),
                Method::VelocityPass => (velocity_pass(points, limits), &SCALES),
                _ => (points.iter().map(|p| Kin::rest(p)).collect(), &[0.0]),
            };
            discrete_sections(&mut solver, &states, scales, &mut out)?;
        }
    }
    out.hits = points
        .iter()
        .enumerate()
        .map(|(k, p)| closest(&out, k, p))
        .collect();
    Ok(out)
}

/// rsruckig's waypoint solver from rest on the first point to rest on the
/// last, through the others, into `solver.traj`.
fn waypoints(solver: &mut Solver, points: &[Vec<f64>]) -> Result<(), StepError> {
    let last = points.len() - 1;
    let inp = &mut solver.input;
    inp.duration_discretization = DurationDiscretization::Continuous;
    inp.intermediate_positions = points[1..last].iter().map(|p| daov(p)).collect();
    for (j, (first, end)) in points[0].iter().zip(&points[last]).enumerate() {
        inp.current_position[j] = *first;
        inp.current_velocity[j] = 0.0;
        inp.current_acceleration[j] = 0.0;
        inp.target_position[j] = *end;
        inp.target_velocity[j] = 0.0;
        inp.target_acceleration[j] = 0.0;
    }
    let r = solver.otg.calculate(&solver.input, &mut solver.traj);
    solver.input.intermediate_positions.clear();
    match r {
        Ok(RuckigResult::Working) => Ok(()),
        Ok(other) => Err(ruckig_err(0, format!("waypoints: result {other:?}"))),
        Err(e) => Err(ruckig_err(0, format!("waypoints: {e}"))),
    }
}

/// The pass-through states of the continuous time-optimal motion: for one
/// axis moving one way, the rest-to-rest profile from the first to the last
/// point (it passes every point in between, so it is the optimum through
/// them); otherwise rsruckig's waypoint solver.
fn optimum_states(solver: &mut Solver, points: &[Vec<f64>]) -> Result<Vec<Kin>, StepError> {
    let last = points.len() - 1;
    let mut states: Vec<Kin> = points.iter().map(|p| Kin::rest(p)).collect();
    let rising = points.windows(2).all(|w| w[1][0] > w[0][0]);
    let falling = points.windows(2).all(|w| w[1][0] < w[0][0]);
    if solver.axes == 1 && (rising || falling) {
        solver.solve(0, &states[0], &states[last], false)?;
        for (k, state) in states.iter_mut().enumerate().take(last).skip(1) {
            let t = solver
                .traj
                .get_first_time_at_position(0, points[k][0])
                .ok_or_else(|| ruckig_err(k, "the rest-to-rest profile misses the point"))?;
            let mut s = solver.at(t);
            s.p.clone_from(&points[k]);
            *state = s;
        }
        return Ok(states);
    }
    waypoints(solver, points)?;
    let times = solver.traj.get_intermediate_durations().to_vec();
    for (k, t) in times.iter().enumerate().take(last - 1) {
        let mut s = solver.at(*t);
        s.p.clone_from(&points[k + 1]);
        states[k + 1] = s;
    }
    Ok(states)
}

/// `s` with its velocity scaled by `c` and its acceleration by `c²`.
fn scaled(s: &Kin, c: f64) -> Kin {
    Kin {
        p: s.p.clone(),
        v: s.v.iter().map(|v| v * c).collect(),
        a: s.a.iter().map(|a| a * c * c).collect(),
    }
}

/// Periods of the discrete section `from → to`, `None` without a solution.
fn section_periods(
    solver: &mut Solver,
    k: usize,
    from: &Kin,
    to: &Kin,
    period: f64,
) -> Option<usize> {
    solver
        .solve(k, from, to, true)
        .ok()
        .map(|d| periods(d, period).max(1))
}

/// Chains discrete sections through `states` (pass-through states, the
/// start and the end at rest). Each section's end state is the
/// pass-through state scaled by the entry of `scales` with the fewest
/// periods over this section and the next (the next with its own best
/// scale): a pass-through state that cannot be met in whole periods
/// without a detour is slowed instead.
fn discrete_sections(
    solver: &mut Solver,
    states: &[Kin],
    scales: &[f64],
    out: &mut Reference,
) -> Result<(), StepError> {
    let period = out.period;
    let last = states.len() - 1;
    let mut from = states[0].clone();
    push(out, &from);
    for k in 0..last {
        let mut best: Option<(usize, usize)> = None;
        let candidates = if k + 1 == last { &[0.0][..] } else { scales };
        for (i, c) in candidates.iter().enumerate() {
            let to = scaled(&states[k + 1], *c);
            let Some(n1) = section_periods(solver, k, &from, &to, period) else {
                continue;
            };
            let n2 = if k + 2 <= last {
                let next: &[f64] = if k + 2 == last { &[0.0] } else { scales };
                next.iter()
                    .filter_map(|c2| {
                        section_periods(solver, k + 1, &to, &scaled(&states[k + 2], *c2), period)
                    })
                    .min()
                    .unwrap_or(usize::MAX / 4)
            } else {
                0
            };
            if best.is_none_or(|(_, n)| n1 + n2 < n) {
                best = Some((i, n1 + n2));
            }
        }
        let Some((i, _)) = best else {
            return Err(ruckig_err(
                k,
                "no discrete section into any scaled pass-through state",
            ));
        };
        let c = candidates[i];
        out.degraded +=
            usize::from(c < 1.0 && k + 1 < last && states[k + 1].v.iter().any(|v| *v != 0.0));
        let to = scaled(&states[k + 1], c);
        let duration = solver.solve(k, &from, &to, true)?;
        let n = periods(duration, period).max(1);
        if out.samples() + n > MAX_SAMPLES {
            return Err(too_long(out.samples() + n));
        }
        for i in 1..n {
            push(out, &solver.at(i as f64 * period));
        }
        // The section's end is the state the profile reaches (within ~1e-9
        // of `to`), and the next section starts from it: starting from `to`
        // instead put a ~1e-9 m step between samples, which a third finite
        // difference reads as several % of the jerk limit.
        let end = if k + 1 == last {
            to
        } else {
            solver.at(duration)
        };
        push(out, &end);
        out.duration += n as f64 * period;
        from = end;
    }
    Ok(())
}

fn push(out: &mut Reference, s: &Kin) {
    out.positions.extend_from_slice(&s.p);
    out.velocities.extend_from_slice(&s.v);
    out.accelerations.extend_from_slice(&s.a);
}

fn closest(out: &Reference, point: usize, p: &[f64]) -> Hit {
    let mut best = Hit {
        point,
        step: 0,
        distance: f64::INFINITY,
    };
    for i in 0..out.samples() {
        let d = distance(out.position(i), p);
        if d < best.distance {
            best = Hit {
                point,
                step: i,
                distance: d,
            };
        }
    }
    best
}

/// Shortest distance over which one axis changes its speed from `v0` to
/// `v1` (both ≥ 0) with zero acceleration at both ends: the jerk-limited
/// velocity change is symmetric, so the distance is the mean speed times
/// its duration.
fn change_distance(v0: f64, v1: f64, l: &Limits) -> f64 {
    let dv = (v1 - v0).abs();
    let t = if dv * l.jerk <= l.acceleration * l.acceleration {
        2.0 * (dv / l.jerk).sqrt()
    } else {
        dv / l.acceleration + l.acceleration / l.jerk
    };
    0.5 * (v0 + v1) * t
}

/// Largest speed in `[v, V]` reachable from `v` over `d` (bisection).
fn reach(v: f64, d: f64, l: &Limits) -> f64 {
    if change_distance(v, l.velocity, l) <= d {
        return l.velocity;
    }
    let (mut lo, mut hi) = (v, l.velocity);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if change_distance(v, mid, l) <= d {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Pass-through states of a forward/backward velocity pass per axis: zero
/// acceleration at every point, zero velocity where an axis turns back or
/// stands still, otherwise the largest speed from which the axis can both
/// have come from its previous point and still reach the next one.
fn velocity_pass(points: &[Vec<f64>], limits: &[Limits]) -> Vec<Kin> {
    let m = points.len() - 1;
    let mut states: Vec<Kin> = points.iter().map(|p| Kin::rest(p)).collect();
    for (j, l) in limits.iter().enumerate() {
        let d: Vec<f64> = (0..m).map(|k| points[k + 1][j] - points[k][j]).collect();
        let mut w = vec![0.0; m + 1];
        let mut sign = vec![0.0; m + 1];
        for k in 1..m {
            if d[k - 1] * d[k] > 0.0 {
                sign[k] = d[k].signum();
                w[k] = l.velocity;
            }
        }
        for k in (1..m).rev() {
            w[k] = w[k].min(reach(w[k + 1], d[k].abs(), l));
        }
        for k in 1..m {
            w[k] = w[k].min(reach(w[k - 1], d[k - 1].abs(), l));
        }
        for k in 1..m {
            states[k].v[j] = sign[k] * w[k];
        }
    }
    states
}

/// Fewest periods any motion within `limits` needs from rest on the first
/// point to rest on the last, sampled every `period`: the time-optimal
/// rest-to-rest Ruckig duration of the slowest axis, rounded up to whole
/// periods (points in between ignored; for a single axis moving one way
/// the time-optimal motion passes them anyway).
///
/// # Errors
/// As [`reference()`].
///
/// # Performance
/// One rsruckig solve.
pub fn lower_bound(
    points: &[Vec<f64>],
    limits: &[Limits],
    period: f64,
) -> Result<usize, StepError> {
    validate(points, limits, period)?;
    let mut solver = Solver::new(limits, period);
    let last = points.len() - 1;
    solver.solve(0, &Kin::rest(&points[0]), &Kin::rest(&points[last]), false)?;
    let t = solver
        .traj
        .get_independent_min_durations()
        .iter()
        .fold(0.0f64, |m, t| m.max(*t));
    Ok(periods(t, period))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bad_input_is_an_error_not_a_panic() {
        let l = [Limits::new(0.1, 2.0, 20.0)];
        let ok = vec![vec![0.0], vec![0.01]];
        assert!(reference(&ok, &l, 0.002, Method::default()).is_ok());
        for bad in [
            vec![vec![0.0]],
            vec![vec![0.0], vec![f64::NAN]],
            vec![vec![0.0], vec![0.0]],
            vec![vec![0.0], vec![0.01, 0.0]],
        ] {
            for m in Method::ALL {
                assert!(reference(&bad, &l, 0.002, m).is_err(), "{bad:?} {m:?}");
            }
        }
        assert!(reference(&ok, &l, f64::NAN, Method::default()).is_err());
        assert!(reference(&ok, &[], 0.002, Method::default()).is_err());
        assert!(reference(
            &ok,
            &[Limits::new(0.1, -2.0, 20.0)],
            0.002,
            Method::default()
        )
        .is_err());
    }

    #[test]
    fn change_distance_matches_a_stepped_profile() {
        let l = Limits::new(1.0, 2.0, 20.0);
        // Δv = 0.5 > A²/J = 0.2: acceleration-limited, T = 0.25 + 0.1.
        let d = change_distance(0.1, 0.6, &l);
        assert!((d - 0.35 * 0.35).abs() < 1e-12, "{d}");
        assert!((reach(0.1, d, &l) - 0.6).abs() < 1e-9);
    }
}
