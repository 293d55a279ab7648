//! The trajectory a robot runs for a plan (issue 13, item 1): dense joint
//! samples with positions, velocities and accelerations, so that the
//! executor's own interpolation (quintic Hermite, as JTC's
//! `interpolation_method: splines` with accelerations) keeps the tool tip
//! within a stated tolerance of the path, from rest to rest, within every
//! joint's velocity, acceleration and jerk limit.
//!
//! # Why not one point per segment
//! With one point per segment midpoint, g steps of up to 0.2 rad between
//! points swing the wrist, and joint-space interpolation of the swing
//! leaves the path by millimetres (measured by
//! [`crate::deviation::executed_deviation`]: 4.0 mm for the ddpg plan).
//!
//! # Steps of [`time_scale`]
//! 1. **Smooth states along the path.** g(s) is the cubic spline through
//!    the segments' g at their arc-length midpoints, with zero slope at the
//!    path's ends ([`crate::spline1d::CubicSpline`]; where it would overshoot
//!    the cell's g range, the smootherstep profile through the same values,
//!    which cannot); f(s) joins the
//!    segments' feeds with the smootherstep profile
//!    ([`crate::spline1d::StepProfile`]); both pass exactly through the
//!    planned values at every midpoint, where each segment was evaluated.
//!    The spindle speed follows the same profile as the feed
//!    ([`ExecutedProfiles`]).
//! 2. **Geometry.** Knots in arc length — initially every segment's ends
//!    and midpoint — carry the IK solution at (s, g(s)), each nearest the
//!    previous knot's (one continuous branch). Per joint, the natural cubic
//!    spline Q_j(s) through the knots gives Q_j' and Q_j''.
//! 3. **Time law** s(t) ([`crate::time_law`]): ṡ = f(s) R(t) / c(s), from
//!    rest to rest over the ramp time, slowed by c(s) ≥ 1.
//! 4. **Samples.** At each knot: t = t(s), q̇ = Q' ṡ, q̈ = Q'' ṡ² + Q' s̈ (the
//!    chain rule). Consecutive samples are joined by the executor's quintic
//!    Hermite polynomial ([`kerf_executor::spline::coefficients`]).
//! 5. **Checks on what the executor runs.** For every piece: the exact
//!    largest |velocity|, |acceleration| and |jerk| of each joint's quintic
//!    (extremes at the ends and the real roots of the next derivative), and
//!    the tool tip by forward kinematics at every control period inside the
//!    piece (at least 3 samples): its distance from the path curve (the
//!    closest point by Gauss–Newton, [`crate::deviation`]) and from the
//!    milling plane.
//! 6. **Repair.** A piece whose tip leaves [`SPLIT_FRACTION`] of the
//!    tolerance is split at its middle time (a new knot, step 2). A piece
//!    that needs r = max_j(|v|/v_max, √(|a|/a_max), ∛(|j|/j_max)) > 1 raises c
//!    on its arc-length span by r (at most 4× per round), and the ramp time
//!    by r when it lies in a ramp. After [`LOCAL_ROUNDS`] rounds, c and the
//!    ramp time are multiplied by the largest r: an exact uniform slowdown
//!    (v/r, a/r², j/r³, [`crate::time_law`]). Steps 2–6 repeat until nothing
//!    is split or slowed.
//! 7. **The executor's own check.** The trajectory goes through the
//!    executor's validation and interpolation at every control period
//!    ([`crate::deviation`]); a piece with a sample beyond the tolerance is
//!    split and steps 2–7 repeat, so what is returned has been measured
//!    within the tolerance ([`TimeScaling::deviation`]).
//!
//! # Run-in and run-out ([`Entry::RunIn`], the default; issue 28)
//! The law runs over the path extended by a straight run-in along its start
//! tangent and a run-out along its end tangent (knots there are IK solutions
//! of [`kerf_mill::MillCell::tool_pose_on_extension`] at the first and last
//! segment's g; the feed there is the first and last segment's), so both ramps
//! lie outside the material and the path itself runs at the planned feeds
//! (divided by c). The run lengths start at 0.6 f T_r and are lengthened when
//! the settled law's ramps would end on the path ([`time_scale`] tries again,
//! at most 4 times). With [`Entry::InMaterial`] the ramps lie on the path.
//!
//! The executed feed of a segment is the planned one divided by c at its
//! midpoint ([`TimeScaling::segment_feeds`]; the ramps' passage through
//! every feed from 0 is not counted, as a start from rest must); its time
//! is the time between its ends on the law ([`TimeScaling::segment_times`]).
//! No segment runs faster than planned: c ≥ 1 and f never leaves the range
//! of its two neighbouring planned feeds.

use kerf_budget::Budget;
use kerf_executor::spline::{coefficients, Interpolation, Knot};
use kerf_mill::{condition_number, MillCell};

use crate::deviation::{distance_to_path, measure, PathDeviation};
use crate::error::MillPlanError;
use crate::plan::{Plan, SegmentInput};
use crate::slowdown::SlowdownField;
use crate::spline1d::{CubicSpline, Profile, StepProfile};
use crate::time_law::TimeLaw;
use crate::trajectory::{JointTrajectory, TrajectoryPoint, TrajectoryRequest};

/// Rounds of local slowdown (step 6) before the uniform one.
pub const LOCAL_ROUNDS: usize = 24;

/// Most rounds of steps 2–6 before the trajectory is given up.
pub const MAX_ROUNDS: usize = 80;

/// A piece is split when its sampled tip deviation exceeds this fraction of
/// the tolerance (the rest is the margin for the executor's own sampling).
pub const SPLIT_FRACTION: f64 = 0.8;

/// Tip samples per piece in the rounds (step 5).
const SAMPLES_PER_PIECE: usize = 3;

/// Largest slowdown of one piece in one round.
const MAX_ROUND_FACTOR: f64 = 4.0;

/// Relative margin kept below each limit (the executor accepts values up to
/// the limit × (1 + 1e-9)).
const MARGIN: f64 = 1e-4;

/// Below this fraction of a limit, [`piece_need`] takes the bound Σ |c_i| h^i of a piece's
/// polynomial for its largest value (a margin of 0.1 % over the rounding of the exact
/// extremes, about 1e-15 relative, so that no ratio crosses 1 either way).
const BOUND_FRACTION: f64 = 0.999;

/// Shortest ramp time before the law is given up \[s\].
const MIN_RAMP_TIME: f64 = 1e-3;

/// A joint's limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointLimit {
    /// Largest speed \[rad/s\], > 0.
    pub max_velocity: f64,
    /// Largest acceleration \[rad/s²\], > 0; `None`: not limited.
    pub max_acceleration: Option<f64>,
    /// Largest jerk \[rad/s³\], > 0; `None`: not limited.
    pub max_jerk: Option<f64>,
}

/// The joint limits of the cell's robot in the kinematic chain's order (the
/// order of the trajectory's joints).
///
/// # Errors
/// [`MillPlanError::InvalidConfig`] for a joint of the chain the robot
/// does not have.
pub fn joint_limits(cell: &MillCell) -> Result<Vec<JointLimit>, MillPlanError> {
    let joints = cell.robot().joints();
    cell.kinematics()
        .joints()
        .iter()
        .map(|k| {
            joints
                .iter()
                .find(|j| j.name == k.name)
                .map(|j| JointLimit {
                    max_velocity: j.max_velocity,
                    max_acceleration: j.max_acceleration,
                    max_jerk: j.max_jerk,
                })
                .ok_or_else(|| MillPlanError::InvalidConfig {
                    name: "cell".to_string(),
                    reason: format!("joint '{}' is not a joint of the cell's robot", k.name),
                })
        })
        .collect()
}

/// Settings of [`time_scale`] (builder style: `TrajectorySettings::default().with_…`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrajectorySettings {
    /// Largest distance of the executed tool tip from the path \[m\], > 0
    /// (default 5e-5: 0.05 mm).
    pub path_tolerance: f64,
    /// The executor's control period \[s\], > 0 (default 0.004, the
    /// executor's default): the tip is checked at this period.
    pub control_period: f64,
    /// Initial ramp time T_r from rest and to rest \[s\], > 0 (default 0.5;
    /// lengthened where the joints need it, shortened for short paths).
    pub ramp_time: f64,
    /// Most trajectory points (default 6 000; the planner node's answer
    /// limit is 6 990 six-joint points).
    pub max_points: usize,
    /// Threads of the measurement at every control period (step 7), ≥ 1
    /// (default 1; the planner uses its evaluation threads). The result is
    /// the same for every count.
    pub threads: usize,
    /// Where the tool starts and stops from rest (default [`Entry::RunIn`]).
    pub entry: Entry,
}

/// Where the executed trajectory starts and stops from rest (issue 28, item 1).
///
/// # What a real cell does
/// A milling program enters the stock at cutting feed: the CAM system's lead-in starts
/// outside the material, the machine accelerates in the air and the tool meets the material
/// already at the programmed feed and spindle speed; at the end it leaves the material at
/// feed and stops in the air. A start from rest inside the material passes every feed from 0,
/// and below the lower feed bound of seed 004 Fig. 4/7 the cut chatters (kerf's model with the
/// power-law force of the cell file chatters as f → 0 at every spindle speed: the chip
/// stiffness grows as h^(−0.25)); `kerf lobes` shows the bound per segment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Entry {
    /// The path is the cut in the material, and the tool enters it at feed: the trajectory
    /// starts from rest on a straight run-in along the path's start tangent, outside the
    /// material, long enough for the start ramp to end before the path starts, and stops on
    /// a run-out along the end tangent ([`kerf_mill::MillCell::tool_pose_on_extension`]).
    /// The run-in and run-out carry the first and last segment's Ω, f and g.
    #[default]
    RunIn,
    /// The ramps from and to rest lie on the path (the tool starts and stops in the
    /// material); kerf's behaviour before issue 28, kept to show why a cell does not cut so.
    InMaterial,
}

impl Entry {
    /// `run_in` or `in_material`.
    pub fn name(self) -> &'static str {
        match self {
            Entry::RunIn => "run_in",
            Entry::InMaterial => "in_material",
        }
    }

    /// The entry of a name ([`Entry::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "run_in" => Some(Entry::RunIn),
            "in_material" => Some(Entry::InMaterial),
            _ => None,
        }
    }
}

impl Default for TrajectorySettings {
    fn default() -> Self {
        Self {
            path_tolerance: 5e-5,
            control_period: 0.004,
            ramp_time: 0.5,
            max_points: 6000,
            threads: 1,
            entry: Entry::RunIn,
        }
    }
}

impl TrajectorySettings {
    /// With the path tolerance \[m\].
    pub fn with_path_tolerance(mut self, tolerance: f64) -> Self {
        self.path_tolerance = tolerance;
        self
    }

    /// With the control period \[s\].
    pub fn with_control_period(mut self, period: f64) -> Self {
        self.control_period = period;
        self
    }

    /// With the initial ramp time \[s\].
    pub fn with_ramp_time(mut self, ramp_time: f64) -> Self {
        self.ramp_time = ramp_time;
        self
    }

    /// With the threads of the measurement (0 is taken as 1).
    pub fn with_threads(mut self, threads: usize) -> Self {
        self.threads = threads.max(1);
        self
    }

    /// With the entry ([`Entry`]).
    pub fn with_entry(mut self, entry: Entry) -> Self {
        self.entry = entry;
        self
    }

    /// With the most trajectory points.
    pub fn with_max_points(mut self, points: usize) -> Self {
        self.max_points = points;
        self
    }

    /// Checks every setting.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidParameter`] naming the first bad one.
    pub fn validate(&self) -> Result<(), MillPlanError> {
        let positive = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(MillPlanError::InvalidParameter {
                    name: name.to_string(),
                    value: v,
                    reason: "must be finite and > 0".to_string(),
                })
            }
        };
        positive("path tolerance [m]", self.path_tolerance)?;
        positive("control period [s]", self.control_period)?;
        positive("ramp time [s]", self.ramp_time)?;
        if self.max_points < 3 {
            return Err(MillPlanError::InvalidParameter {
                name: "most trajectory points".to_string(),
                value: self.max_points as f64,
                reason: "must be >= 3".to_string(),
            });
        }
        Ok(())
    }
}

/// The smooth state profiles of step 1 (what a spindle and feed controller
/// follows between the segment midpoints).
#[derive(Debug, Clone, PartialEq)]
pub struct ExecutedProfiles {
    /// g(s) \[rad\]: the cubic spline, or the smootherstep profile where the
    /// spline would leave the cell's g range.
    pub g: Profile,
    /// f(s) \[m/s\], before the slowdown.
    pub feed: StepProfile,
    /// Ω(s) \[rpm\].
    pub rpm: StepProfile,
}

/// The result of [`time_scale`].
#[derive(Debug, Clone, PartialEq)]
pub struct TimeScaling {
    /// The executable trajectory: dense points with positions, velocities
    /// and accelerations, from rest to rest, with their arc lengths and
    /// plan segments.
    pub trajectory: JointTrajectory,
    /// The profiles of step 1.
    pub profiles: ExecutedProfiles,
    /// Per plan segment: the slowdown c at its midpoint (1: at the planned
    /// feed).
    pub segment_slowdown: Vec<f64>,
    /// Per plan segment: the time it is machined in \[s\], ramps included.
    pub segment_times: Vec<f64>,
    /// Per plan segment: the feed at its midpoint \[m/s\], the planned one
    /// divided by the slowdown there (the ramps not counted).
    pub segment_feeds: Vec<f64>,
    /// Rounds of steps 2–6.
    pub rounds: usize,
    /// Whether a uniform slowdown was needed.
    pub uniform: bool,
    /// The final ramp time \[s\].
    pub ramp_time: f64,
    /// Largest sampled distance of the interpolated tip from the path or the
    /// plane \[m\] (step 5).
    pub sampled_deviation: f64,
    /// Smallest condition indicator 1/K over the trajectory points, and the
    /// arc length where it is \[m\].
    pub min_condition_indicator: (f64, f64),
    /// The tool path as the executor runs the trajectory, at every control
    /// period (step 7): within the path tolerance.
    pub deviation: PathDeviation,
    /// Length of the straight run-in before the path \[m\] (0 for [`Entry::InMaterial`]).
    pub run_in: f64,
    /// Length of the straight run-out after the path \[m\].
    pub run_out: f64,
    /// The time law s(t) the trajectory was built on, in the law's arc length: the path's
    /// arc length plus [`TimeScaling::run_in`] ([`TimeScaling::path_state`]).
    pub law: TimeLaw,
}

impl TimeScaling {
    /// Segments run slower than planned (slowdown > 1 at the midpoint).
    pub fn slowed_segments(&self) -> usize {
        self.segment_slowdown
            .iter()
            .filter(|c| **c > 1.0 + 1e-9)
            .count()
    }

    /// The executable trajectory's duration, from rest to rest \[s\].
    pub fn duration(&self) -> f64 {
        self.trajectory.duration()
    }

    /// Σ of [`TimeScaling::segment_times`]: the machining time as run \[s\].
    pub fn machining_time(&self) -> f64 {
        self.segment_times.iter().sum()
    }

    /// The tool's state on the law at time `t` (clamped to the trajectory), its arc length
    /// on the path: negative on the run-in, beyond the path's length on the run-out.
    pub fn path_state(&self, t: f64) -> crate::time_law::PathState {
        let mut p = self.law.at_time(t);
        p.s -= self.run_in;
        p
    }

    /// The times the tool enters and leaves the material (the path's start and end) \[s\].
    pub fn material_times(&self) -> (f64, f64) {
        let length = self.law.length() - self.run_in - self.run_out;
        (
            self.law.at_arc_length(self.run_in).time,
            self.law.at_arc_length(self.run_in + length).time,
        )
    }
}

/// One geometry knot: arc length and joints.
#[derive(Debug, Clone, Copy)]
struct GeoKnot {
    s: f64,
    /// The path's spline parameter at s.
    u: f64,
    q: [f64; 6],
}

/// The samples of step 4 and the per-piece outcome of step 5.
struct Evaluation {
    times: Vec<f64>,
    velocities: Vec<[f64; 6]>,
    accelerations: Vec<[f64; 6]>,
    need: Vec<f64>,
    deviation: Vec<f64>,
}

/// Builds the executed trajectory of `plan` (module documentation).
///
/// # Arguments
/// * `cell` — the request's cell (path, kinematics, g range).
/// * `plan` — the plan: one entry per path segment, in order, feeds > 0.
/// * `limits` — one per joint of the cell's robot, in its order.
/// * `settings` — tolerance, control period, ramp time, point limit.
/// * `budget` — checked every round.
///
/// # Returns
/// The trajectory and its segment times and feeds.
///
/// # Errors
/// [`MillPlanError::InvalidParameter`] for bad settings;
/// [`MillPlanError::InvalidConfig`] for a plan without segments, out of
/// order, a non-positive feed, bad limits; [`MillPlanError::NotExecutable`]
/// when the
/// tolerance would need more than `max_points` points or pieces shorter
/// than a quarter control period (a branch change of the IK), or when the
/// rounds run out; IK errors along the path; [`MillPlanError::Interrupted`].
///
/// # Performance
/// O(points × joints) per round plus one IK per new knot and one forward
/// kinematics per control period; a few rounds for the default plans.
pub fn time_scale(
    cell: &MillCell,
    plan: &Plan,
    limits: &[JointLimit],
    settings: &TrajectorySettings,
    budget: &Budget,
) -> Result<TimeScaling, MillPlanError> {
    let inputs: Vec<SegmentInput> = plan.segments.iter().map(|s| s.input()).collect();
    time_scale_inputs(cell, &inputs, limits, settings, budget)
}

/// [`time_scale`] of the plan's segments as [`SegmentInput`]s (Ω, f, g,
/// joints; the trajectory reads no |μ|max, so it can be built while they are
/// evaluated: [`crate::evaluation::evaluate_direct_alongside`]).
pub(crate) fn time_scale_inputs(
    cell: &MillCell,
    segments: &[SegmentInput],
    limits: &[JointLimit],
    settings: &TrajectorySettings,
    budget: &Budget,
) -> Result<TimeScaling, MillPlanError> {
    settings.validate()?;
    let (Some(first), Some(last)) = (segments.first(), segments.last()) else {
        return Err(MillPlanError::InvalidConfig {
            name: "executed trajectory".to_string(),
            reason: "a plan without segments".to_string(),
        });
    };
    if settings.entry == Entry::InMaterial {
        return scale_on(cell, segments, limits, settings, budget, (0.0, 0.0));
    }
    // The ramps' distance at the planned end feeds (f T_r / 2 for the smootherstep ramp),
    // with a margin; lengthened when the settled law's ramps end on the path.
    let distance = |feed: f64| 0.6 * feed.abs() * settings.ramp_time;
    let mut run = (distance(first.feed), distance(last.feed));
    for _ in 0..RUN_IN_TRIES {
        let scaling = scale_on(cell, segments, limits, settings, budget, run)?;
        let (enter, leave) = scaling.material_times();
        let ramp = scaling.law.ramp_time();
        let end = scaling.law.duration();
        if enter >= ramp && leave <= end - ramp {
            return Ok(scaling);
        }
        // Where the ramps end, on the path's arc length: the run lengthened by that much
        // and a half again.
        let length = cell.path().total_length();
        let ramp_end = scaling.path_state(ramp).s;
        let ramp_start = scaling.path_state(end - ramp).s;
        if enter < ramp {
            run.0 += 1.5 * ramp_end.max(0.0) + 1e-3;
        }
        if leave > end - ramp {
            run.1 += 1.5 * (length - ramp_start).max(0.0) + 1e-3;
        }
    }
    Err(MillPlanError::NotExecutable {
        reason: format!(
            "the start and stop ramps do not fit on a run-in and run-out of {:.1} and {:.1} mm \
             after {RUN_IN_TRIES} tries",
            run.0 * 1e3,
            run.1 * 1e3
        ),
    })
}

/// Tries of [`time_scale_inputs`] at a longer run-in or run-out.
const RUN_IN_TRIES: usize = 4;

/// [`time_scale_inputs`] with a run-in of `run.0` and a run-out of `run.1` \[m\] (0: the
/// ramps on the path).
fn scale_on(
    cell: &MillCell,
    segments: &[SegmentInput],
    limits: &[JointLimit],
    settings: &TrajectorySettings,
    budget: &Budget,
    run: (f64, f64),
) -> Result<TimeScaling, MillPlanError> {
    let (run_in, run_out) = run;
    let bad = |reason: String| MillPlanError::InvalidConfig {
        name: "executed trajectory".to_string(),
        reason,
    };
    let path = cell.path();
    let n = segments.len();
    if n == 0 || n != path.segments().len() {
        return Err(bad(format!(
            "{n} plan segments for a path of {} segments",
            path.segments().len()
        )));
    }
    if limits.len() != 6 {
        return Err(bad(format!("{} joint limits for 6 joints", limits.len())));
    }
    for (j, l) in limits.iter().enumerate() {
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if !positive(l.max_velocity)
            || !l.max_acceleration.is_none_or(positive)
            || !l.max_jerk.is_none_or(positive)
        {
            return Err(bad(format!(
                "joint {j}: limits {l:?} are not positive and finite"
            )));
        }
    }
    // Step 1: knots at 0, the midpoints, L.
    let length = path.total_length();
    let mut boundaries = vec![0.0];
    let mut x = vec![0.0];
    for (i, seg) in segments.iter().enumerate() {
        if seg.segment != i {
            return Err(bad(format!("plan entry {i} is segment {}", seg.segment)));
        }
        if !(seg.feed.is_finite() && seg.feed > 0.0) {
            return Err(bad(format!(
                "segment {i} has feed {} m/s (> 0 needed)",
                seg.feed
            )));
        }
        let start = *boundaries.last().unwrap_or(&0.0);
        let l = path.segment(i)?.length;
        x.push(start + 0.5 * l);
        boundaries.push(start + l);
    }
    x.push(length);
    let ends = |v: &dyn Fn(usize) -> f64| -> Vec<f64> {
        let mut out = vec![v(0)];
        out.extend((0..n).map(v));
        out.push(v(n - 1));
        out
    };
    let g_values = ends(&|i| segments[i].g);
    let cubic = CubicSpline::new("g(s)", &x, &g_values, Some((0.0, 0.0)))?;
    let [g_lo, g_hi] = cell.state_limits().redundancy_angle;
    let (lo, hi) = cubic.range();
    // The spline overshoots between two values at the edge of the range: there the
    // smootherstep profile, which stays between its values, is used instead.
    let g_profile = if lo < g_lo - 1e-12 || hi > g_hi + 1e-12 {
        Profile::Step(StepProfile::new("g(s)", &x, &g_values)?)
    } else {
        Profile::Cubic(cubic)
    };
    let profiles = ExecutedProfiles {
        g: g_profile,
        feed: StepProfile::new("f(s)", &x, &ends(&|i| segments[i].feed))?,
        rpm: StepProfile::new("spindle speed(s)", &x, &ends(&|i| segments[i].rpm))?,
    };
    let g = &profiles.g;
    // The law runs over the run-in, the path and the run-out: its arc length is the path's
    // plus `run_in`, and the feed is the first and last segment's on the run-in and run-out
    // (the profile is constant outside its knots).
    let law_length = run_in + length + run_out;
    let shifted: Vec<f64> = x.iter().map(|v| v + run_in).collect();
    let law_feed = StepProfile::new("f(s)", &shifted, &ends(&|i| segments[i].feed))?;
    let feed = &law_feed;
    // The knot at path arc length s (negative on the run-in, beyond the length on the
    // run-out), its IK solution nearest `reference`.
    let knot_at = |s: f64, reference: &[f64; 6]| -> Result<GeoKnot, MillPlanError> {
        let g_s = g.eval(s.clamp(0.0, length)).value;
        if (0.0..=length).contains(&s) {
            let u = path.parameter_at(s)?;
            let q = cell.joints_at_parameter(u, g_s, Some(reference))?;
            Ok(GeoKnot { s, u, q })
        } else {
            let u = if s < 0.0 { 0.0 } else { 1.0 };
            let q = cell
                .joints_on_extension(s, g_s, Some(reference))
                .map_err(|e| MillPlanError::NotExecutable {
                    reason: format!(
                        "the {} ({:.1} mm along the path's {} tangent) is out of the robot's \
                         reach or limits: {e}; entry in_material starts and stops on the path",
                        if s < 0.0 { "run-in" } else { "run-out" },
                        if s < 0.0 { -s } else { s - length } * 1e3,
                        if s < 0.0 { "start" } else { "end" }
                    ),
                })?;
            Ok(GeoKnot { s, u, q })
        }
    };
    // Step 2: initial knots at every segment's ends and midpoint, and at the middle and far
    // end of the run-in and run-out.
    let mut places = Vec::with_capacity(2 * n + 5);
    if run_in > 0.0 {
        places.extend([-run_in, -0.5 * run_in]);
    }
    for k in 0..=2 * n {
        places.push(if k % 2 == 0 {
            boundaries[k / 2]
        } else {
            x[k / 2 + 1]
        });
    }
    if run_out > 0.0 {
        places.extend([length + 0.5 * run_out, length + run_out]);
    }
    let mut knots: Vec<GeoKnot> = Vec::with_capacity(places.len());
    let mut reference = segments[0].joints;
    for s in places {
        let knot = knot_at(s, &reference)?;
        reference = knot.q;
        knots.push(knot);
    }
    let cells = ((law_length / (length / n as f64)).round() as usize).max(n);
    let mut slowdown = SlowdownField::new(law_length, cells)
        .ok_or_else(|| bad(format!("path length {length} m")))?;
    let mut ramp_time = settings.ramp_time;
    let mut uniform = false;
    let mut rounds = 0;
    let scaling = loop {
        budget.check("the executed trajectory")?;
        rounds += 1;
        if rounds > MAX_ROUNDS {
            return Err(MillPlanError::NotExecutable {
                reason: format!(
                    "the trajectory did not settle within the limits and the path tolerance in \
                     {MAX_ROUNDS} rounds"
                ),
            });
        }
        let step = settings.control_period.min(ramp_time / 64.0);
        let Some(law) = TimeLaw::new(feed, &slowdown, law_length, ramp_time, step) else {
            ramp_time *= 0.5;
            if ramp_time < MIN_RAMP_TIME {
                return Err(MillPlanError::NotExecutable {
                    reason: format!(
                        "no time law from rest to rest on this {length} m path (ramp time \
                         below {MIN_RAMP_TIME} s, or feeds too low)"
                    ),
                });
            }
            continue;
        };
        let eval = evaluate(cell, &knots, &law, run_in, limits)?;
        let mut split: Vec<usize> = (0..knots.len() - 1)
            .filter(|&k| eval.deviation[k] > SPLIT_FRACTION * settings.path_tolerance)
            .collect();
        let worst = eval.need.iter().copied().fold(0.0, f64::max);
        if split.is_empty() && worst <= 1.0 {
            // Step 7: the executor's own interpolation at every control period.
            let mut scaling = finish(
                cell,
                segments,
                &knots,
                (&boundaries, &x),
                (run_in, run_out),
                &law,
                &eval,
                &profiles,
                &slowdown,
                rounds,
                uniform,
            )?;
            let params: Vec<f64> = knots.iter().map(|k| k.u).collect();
            let (deviation, over) = measure(
                cell,
                &scaling.trajectory,
                settings.control_period,
                settings.path_tolerance,
                Some(&params),
                settings.threads,
            )?;
            if over.is_empty() {
                scaling.deviation = deviation;
                break scaling;
            }
            // Split the pieces the samples found outside.
            for t in over {
                let k = eval
                    .times
                    .partition_point(|x| *x <= t)
                    .clamp(1, knots.len() - 1)
                    - 1;
                if split.last() != Some(&k) {
                    split.push(k);
                }
            }
        }
        // Step 6: split.
        if knots.len() + split.len() > settings.max_points {
            return Err(MillPlanError::NotExecutable {
                reason: format!(
                    "keeping the tool tip within {} mm of the path needs more than {} trajectory \
                     points",
                    settings.path_tolerance * 1e3,
                    settings.max_points
                ),
            });
        }
        for &k in split.iter().rev() {
            let (ta, tb) = (eval.times[k], eval.times[k + 1]);
            if tb - ta < 0.25 * settings.control_period {
                return Err(MillPlanError::NotExecutable {
                    reason: format!(
                        "the tool tip leaves the path by {:.4} mm between arc lengths {:.5} and \
                         {:.5} m even with points {:.2e} s apart (an IK branch change?)",
                        eval.deviation[k] * 1e3,
                        knots[k].s,
                        knots[k + 1].s,
                        tb - ta
                    ),
                });
            }
            let s = law.at_time(0.5 * (ta + tb)).s - run_in;
            if !(s > knots[k].s && s < knots[k + 1].s) {
                continue;
            }
            let knot = knot_at(s, &knots[k].q)?;
            knots.insert(k + 1, knot);
        }
        // Step 6: slow down.
        if worst > 1.0 {
            if rounds <= LOCAL_ROUNDS {
                let mut ramp_need: f64 = 1.0;
                let mut spans = Vec::new();
                for (k, r) in eval.need.iter().enumerate() {
                    if *r > 1.0 {
                        let factor = (r * (1.0 + MARGIN)).min(MAX_ROUND_FACTOR);
                        spans.push((knots[k].s + run_in, knots[k + 1].s + run_in, factor));
                        let (ta, tb) = (eval.times[k], eval.times[k + 1]);
                        if ta < law.ramp_time() || tb > law.duration() - law.ramp_time() {
                            ramp_need = ramp_need.max(factor);
                        }
                    }
                }
                slowdown.raise(&spans);
                ramp_time *= ramp_need;
            } else {
                let factor = worst * (1.0 + MARGIN);
                slowdown.scale(factor);
                ramp_time *= factor;
                uniform = true;
            }
        }
    };
    Ok(scaling)
}

/// Steps 2 (the Q splines), 4 and 5 for the current knots and law.
fn evaluate(
    cell: &MillCell,
    knots: &[GeoKnot],
    law: &TimeLaw,
    run_in: f64,
    limits: &[JointLimit],
) -> Result<Evaluation, MillPlanError> {
    let m = knots.len();
    let s: Vec<f64> = knots.iter().map(|k| k.s).collect();
    let mut splines = Vec::with_capacity(6);
    for j in 0..6 {
        let q: Vec<f64> = knots.iter().map(|k| k.q[j]).collect();
        splines.push(CubicSpline::new("joint path Q(s)", &s, &q, None)?);
    }
    let mut times = Vec::with_capacity(m);
    let mut velocities = Vec::with_capacity(m);
    let mut accelerations = Vec::with_capacity(m);
    let mut states = Vec::with_capacity(m);
    for (k, knot) in knots.iter().enumerate() {
        let p = if k == 0 {
            law.at_time(0.0)
        } else if k + 1 == m {
            law.at_time(law.duration())
        } else {
            law.at_arc_length(knot.s + run_in)
        };
        let mut v = [0.0; 6];
        let mut a = [0.0; 6];
        for j in 0..6 {
            let d = splines[j].eval(knot.s);
            v[j] = d.d1 * p.speed;
            a[j] = d.d2 * p.speed * p.speed + d.d1 * p.acceleration;
        }
        if v.iter().chain(&a).any(|x| !x.is_finite()) {
            return Err(MillPlanError::NotExecutable {
                reason: format!(
                    "non-finite joint velocity or acceleration at arc length {} m",
                    knot.s
                ),
            });
        }
        times.push(p.time);
        velocities.push(v);
        accelerations.push(a);
        states.push(p);
    }
    if let Some(k) = times.windows(2).position(|w| w[1] <= w[0]) {
        return Err(MillPlanError::NotExecutable {
            reason: format!(
                "trajectory times not increasing at arc length {} m ({} then {} s)",
                knots[k].s,
                times[k],
                times[k + 1]
            ),
        });
    }
    let path = cell.path();
    let origin = path.point(0.0)?;
    let normal = path.normal();
    let mut need = Vec::with_capacity(m - 1);
    let mut deviation = Vec::with_capacity(m - 1);
    for k in 0..m - 1 {
        let h = times[k + 1] - times[k];
        let mut c = [[0.0; 6]; 6];
        let mut r: f64 = 0.0;
        for j in 0..6 {
            let k0 = Knot {
                p: knots[k].q[j],
                v: velocities[k][j],
                a: accelerations[k][j],
            };
            let k1 = Knot {
                p: knots[k + 1].q[j],
                v: velocities[k + 1][j],
                a: accelerations[k + 1][j],
            };
            c[j] = coefficients(Interpolation::Quintic, k0, k1, h);
            r = r.max(piece_need(&c[j], h, &limits[j]));
        }
        need.push(r);
        // The tip at 3 interior times of the piece: its distance from the path curve and
        // from the plane (the interpolation error is a smooth bump over the piece; the
        // executor's own sampling at every control period is measured after, step 7).
        let samples = SAMPLES_PER_PIECE;
        let mut worst: f64 = 0.0;
        for i in 1..=samples {
            let x = i as f64 / (samples + 1) as f64;
            let mut q = [0.0; 6];
            for j in 0..6 {
                q[j] = kerf_executor::spline::evaluate(&c[j], h * x).0;
            }
            let tip = cell.kinematics().tcp_pose(&q)?.translation.vector;
            let guess = knots[k].u + x * (knots[k + 1].u - knots[k].u);
            let (off_path, _) = distance_to_path(cell, &tip, guess)?;
            let off_plane = (tip - origin).dot(&normal).abs();
            worst = worst.max(off_path).max(off_plane);
        }
        deviation.push(worst);
    }
    Ok(Evaluation {
        times,
        velocities,
        accelerations,
        need,
        deviation,
    })
}

/// r of step 6 for one joint's quintic `c` over [0, h].
///
/// A polynomial's largest |value| on [0, h] is bounded by Σ |c_i| h^i; where that bound is
/// already below [`BOUND_FRACTION`] of the limit, the exact extremes (roots of the next
/// derivative) are not needed: the contribution is reported as that bound's ratio (< 1, so it
/// never triggers a slowdown and never hides one: the exact value is below it too). The ratios
/// are only compared with 1 and, above 1, used as slowdown factors (step 6), and a ratio above
/// 1 is always the exact one: the trajectory is the same as with every extreme computed.
fn piece_need(c: &[f64; 6], h: f64, limit: &JointLimit) -> f64 {
    use kerf_executor::roots::extrema;
    let v = [c[1], 2.0 * c[2], 3.0 * c[3], 4.0 * c[4], 5.0 * c[5]];
    let a = [2.0 * c[2], 6.0 * c[3], 12.0 * c[4], 20.0 * c[5]];
    let jerk = [6.0 * c[3], 24.0 * c[4], 60.0 * c[5]];
    let ratio = |p: &[f64], max: f64| {
        let scale = max * (1.0 - MARGIN);
        let mut bound = 0.0;
        let mut power = 1.0;
        for x in p {
            bound += x.abs() * power;
            power *= h;
        }
        if bound <= BOUND_FRACTION * scale {
            return bound / scale;
        }
        let ((_, lo), (_, hi)) = extrema(p, 0.0, h);
        lo.abs().max(hi.abs()) / scale
    };
    let mut r = ratio(&v, limit.max_velocity);
    if let Some(amax) = limit.max_acceleration {
        r = r.max(ratio(&a, amax).sqrt());
    }
    if let Some(jmax) = limit.max_jerk {
        r = r.max(ratio(&jerk, jmax).cbrt());
    }
    if r.is_finite() {
        r
    } else {
        f64::INFINITY
    }
}

/// The result from the settled knots and law.
#[allow(clippy::too_many_arguments)]
fn finish(
    cell: &MillCell,
    segments: &[SegmentInput],
    knots: &[GeoKnot],
    (boundaries, midpoints): (&[f64], &[f64]),
    (run_in, run_out): (f64, f64),
    law: &TimeLaw,
    eval: &Evaluation,
    profiles: &ExecutedProfiles,
    slowdown: &SlowdownField,
    rounds: usize,
    uniform: bool,
) -> Result<TimeScaling, MillPlanError> {
    let n = segments.len();
    let names: Vec<String> = cell
        .kinematics()
        .joints()
        .iter()
        .map(|j| j.name.clone())
        .collect();
    let mut points = Vec::with_capacity(knots.len());
    let mut arc_length = Vec::with_capacity(knots.len());
    let mut segment = Vec::with_capacity(knots.len());
    let mut min_ci = (f64::INFINITY, 0.0);
    for (k, knot) in knots.iter().enumerate() {
        points.push(TrajectoryPoint {
            positions: knot.q.to_vec(),
            velocities: eval.velocities[k].to_vec(),
            accelerations: eval.accelerations[k].to_vec(),
            time_from_start: eval.times[k],
            ..TrajectoryPoint::default()
        });
        arc_length.push(knot.s);
        let seg = boundaries[1..].partition_point(|b| *b <= knot.s).min(n - 1);
        segment.push(seg);
        let j = cell.kinematics().jacobian(&knot.q)?;
        let ci = 1.0 / condition_number(&j, cell.characteristic_length())?;
        if ci < min_ci.0 {
            min_ci = (ci, knot.s);
        }
    }
    // The time at each segment boundary, once (each inner one ends a segment and starts the next).
    let at: Vec<f64> = boundaries
        .iter()
        .map(|b| law.at_arc_length(*b + run_in).time)
        .collect();
    let segment_times = at.windows(2).map(|w| w[1] - w[0]).collect();
    let segment_slowdown: Vec<f64> = (0..n)
        .map(|i| slowdown.eval(midpoints[i + 1] + run_in).0)
        .collect();
    let segment_feeds = segments
        .iter()
        .zip(&segment_slowdown)
        .map(|(s, c)| s.feed / c)
        .collect();
    let sampled_deviation = eval.deviation.iter().copied().fold(0.0, f64::max);
    Ok(TimeScaling {
        trajectory: JointTrajectory {
            request: TrajectoryRequest {
                joint_names: names,
                points,
                start_time: None,
            },
            arc_length,
            segment,
        },
        profiles: profiles.clone(),
        segment_slowdown,
        segment_times,
        segment_feeds,
        rounds,
        uniform,
        ramp_time: law.ramp_time(),
        sampled_deviation,
        min_condition_indicator: min_ci,
        deviation: PathDeviation::default(),
        run_in,
        run_out,
        law: law.clone(),
    })
}

/// The derivative at the middle point of the parabola through
/// (t − h1, qm), (t, q), (t + h2, qp): the non-uniform three-point
/// difference −h2/(h1(h1+h2)) qm + (h2−h1)/(h1 h2) q + h1/(h2(h1+h2)) qp
/// (Fornberg 1988, "Generation of finite difference formulas on
/// arbitrarily spaced grids").
pub fn three_point_velocity(h1: f64, h2: f64, qm: f64, q: f64, qp: f64) -> f64 {
    -h2 / (h1 * (h1 + h2)) * qm + (h2 - h1) / (h1 * h2) * q + h1 / (h2 * (h1 + h2)) * qp
}
