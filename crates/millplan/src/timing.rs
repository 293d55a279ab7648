//! The trajectory a robot can run: the plan's joint trajectory from rest to
//! rest, time-scaled so that its cubic Hermite interpolation (what the
//! trajectory executor runs: positions and velocities at every point) stays
//! within every joint's velocity and acceleration limit.
//!
//! The plan is timed by its feeds ([`crate::planned`]); the
//! environment and the DP bound joint SPEEDS between segment midpoints, not
//! accelerations, and a change of g from one segment to the next can ask a
//! wrist joint for several times its acceleration limit. Such a trajectory
//! would be refused by the executor. [`time_scale`] slows it down where it
//! must (never speeds it up) and says by how much: the feed actually run
//! in each segment follows ([`TimeScaling::segment_feeds`]), and the
//! planner re-evaluates |μ|max at that feed
//! ([`crate::planner::MillPlanOutput::executed`]).
//!
//! # Steps
//! 1. Ramps: the robot starts and ends at rest, so the first and the last
//!    interval (path start → first midpoint, last midpoint → path end) take
//!    twice their planned time (from rest to the planned velocity over the
//!    interval's length at half the mean speed), with zero velocity at the
//!    two end points.
//! 2. Velocities at the interior points: the derivative of the parabola
//!    through each point and its two neighbours at the CURRENT times
//!    ([`three_point_velocity`], Fornberg 1988).
//! 3. Each interval's need r_i = max over its joints of |v|/v_max and
//!    sqrt(|a|/a_max) of its Hermite cubic ([`hermite_extremes`]). Where
//!    r_i > 1 the interval is stretched by r_i (at most 4× per round; the
//!    velocities of step 2 change with the neighbours' times, so this
//!    repeats).
//! 4. After [`LOCAL_ROUNDS`] rounds without success, every interval is
//!    stretched by the largest remaining need: stretching ALL times by s
//!    divides every three-point velocity by s and every Hermite
//!    acceleration by s², so one such round always ends it.
//!
//! No interval is ever shortened: the executed time of every segment is at
//! least its planned time.
//!
//! Jerk is not limited (the executor's cubic Hermite interpolation has
//! piecewise-constant jerk and acceleration steps at the points).

use crate::error::MillPlanError;
use crate::trajectory::{JointTrajectory, TrajectoryPoint, TrajectoryRequest};

/// Local stretching rounds before the uniform round of step 4.
pub const LOCAL_ROUNDS: usize = 200;

/// Largest stretch of one interval in one local round.
const MAX_ROUND_STRETCH: f64 = 4.0;

/// Relative margin the scaled trajectory keeps below each limit (the
/// executor accepts values up to the limit × (1 + 1e-9)).
const MARGIN: f64 = 1e-6;

/// A joint's limits for [`time_scale`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointLimit {
    /// Largest speed \[rad/s\], > 0.
    pub max_velocity: f64,
    /// Largest acceleration \[rad/s²\], > 0; `None`: not limited.
    pub max_acceleration: Option<f64>,
}

/// Extremes of one joint's cubic Hermite segment (see [`hermite_extremes`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HermiteExtremes {
    /// Acceleration at the segment's start and end (it is linear in
    /// between) \[rad/s²\].
    pub accelerations: [(f64, f64); 2],
    /// Time from the segment's start \[s\] and value of the largest |velocity|
    /// \[rad/s\] (at an end or at the parabola's vertex).
    pub peak_velocity: (f64, f64),
}

/// The acceleration at both ends and the largest speed of the cubic Hermite
/// segment of duration `h` from (`p0`, `v0`) to (`p1`, `v1`).
///
/// With Δ = p1 − p0, the cubic is p0 + v0 τ + c2 τ² + c3 τ³ with
/// c2 = (3Δ/h − 2 v0 − v1)/h and c3 = (−2Δ/h + v0 + v1)/h²: its
/// acceleration 2 c2 + 6 c3 τ is linear and its velocity a parabola,
/// whose extreme is at an end or at the vertex τ = −c2/(3 c3).
///
/// # Returns
/// `(τ, value)` pairs: τ = 0 and τ = h for the accelerations.
pub fn hermite_extremes(h: f64, p0: f64, p1: f64, v0: f64, v1: f64) -> HermiteExtremes {
    let d = p1 - p0;
    let c2 = (3.0 * d / h - 2.0 * v0 - v1) / h;
    let c3 = (-2.0 * d / h + v0 + v1) / (h * h);
    let velocity = |tau: f64| v0 + 2.0 * c2 * tau + 3.0 * c3 * tau * tau;
    let mut peak = if v1.abs() > v0.abs() {
        (h, v1)
    } else {
        (0.0, v0)
    };
    if c3 != 0.0 {
        let vertex = -c2 / (3.0 * c3);
        if vertex > 0.0 && vertex < h {
            let v = velocity(vertex);
            if v.abs() > peak.1.abs() {
                peak = (vertex, v);
            }
        }
    }
    HermiteExtremes {
        accelerations: [(0.0, 2.0 * c2), (h, 2.0 * c2 + 6.0 * c3 * h)],
        peak_velocity: peak,
    }
}

/// The derivative at the middle point of the parabola through
/// (t − h1, qm), (t, q), (t + h2, qp): the non-uniform three-point
/// difference −h2/(h1(h1+h2)) qm + (h2−h1)/(h1 h2) q + h1/(h2(h1+h2)) qp
/// (Fornberg 1988, "Generation of finite difference formulas on
/// arbitrarily spaced grids").
pub fn three_point_velocity(h1: f64, h2: f64, qm: f64, q: f64, qp: f64) -> f64 {
    -h2 / (h1 * (h1 + h2)) * qm + (h2 - h1) / (h1 * h2) * q + h1 / (h2 * (h1 + h2)) * qp
}

/// The result of [`time_scale`].
#[derive(Debug, Clone, PartialEq)]
pub struct TimeScaling {
    /// The executable trajectory: the planned points, from rest to rest,
    /// at the scaled times, with the three-point velocities at those times
    /// (the arc lengths and segments of the planned one).
    pub trajectory: JointTrajectory,
    /// Per interval between consecutive points: the factor on its planned
    /// duration (≥ 1), the ramps' factor 2 not included.
    pub interval_stretch: Vec<f64>,
    /// Per plan segment: the time it is machined in \[s\], ramps included.
    pub segment_times: Vec<f64>,
    /// Per plan segment: the feed it is machined at \[m/s\], length over
    /// its time WITHOUT the ramps' factor 2 (a start or stop from rest
    /// passes through every feed from 0; only the stretch of step 3–4
    /// changes the feed): equal to the planned feed where nothing was
    /// stretched.
    pub segment_feeds: Vec<f64>,
    /// Local rounds used (step 3).
    pub rounds: usize,
    /// Whether the uniform round of step 4 was needed.
    pub uniform: bool,
}

impl TimeScaling {
    /// Intervals whose duration was stretched (factor > 1).
    pub fn stretched_intervals(&self) -> usize {
        self.interval_stretch.iter().filter(|c| **c > 1.0).count()
    }

    /// The executable trajectory's duration, from rest to rest \[s\].
    pub fn duration(&self) -> f64 {
        self.trajectory.duration()
    }

    /// Σ of [`TimeScaling::segment_times`]: the machining time as run \[s\].
    pub fn machining_time(&self) -> f64 {
        self.segment_times.iter().sum()
    }
}

/// Time-scales a planned trajectory (module documentation).
///
/// # Arguments
/// * `planned` — the plan's trajectory: path start, the N segment
///   midpoints, path end (N + 2 points, times strictly increasing from 0);
/// * `segment_times_planned`, `segment_feeds_planned` — the N segments'
///   planned times \[s\] and feeds \[m/s\] (the trajectory's intervals are
///   the times' halves: T_0/2, (T_0 + T_1)/2, …, T_{N−1}/2, checked to
///   1e-9 relative);
/// * `limits` — one per joint of `planned`.
///
/// # Returns
/// The executable trajectory and the segment times and feeds it runs.
///
/// # Errors
/// [`MillPlanError::InvalidConfig`] for a trajectory whose side tables or
/// points do not match its joints ([`JointTrajectory::check`]), fewer than
/// 3 points, a point count other than N + 2, intervals that are not the
/// segments' halves, a limit count other than the joint count, a
/// non-positive or NaN limit, times not strictly increasing, or a
/// non-finite value on the way.
///
/// # Performance
/// One round is O(points × joints); the default plans need tens of rounds
/// (well under a millisecond).
pub fn time_scale(
    planned: &JointTrajectory,
    segment_times_planned: &[f64],
    segment_feeds_planned: &[f64],
    limits: &[JointLimit],
) -> Result<TimeScaling, MillPlanError> {
    let bad = |reason: String| MillPlanError::InvalidConfig {
        name: "trajectory time scaling".to_string(),
        reason,
    };
    planned.check()?;
    let points = planned.points();
    let m = points.len();
    let n = segment_times_planned.len();
    if m < 3 || m != n + 2 || segment_feeds_planned.len() != n {
        return Err(bad(format!(
            "{m} trajectory points, {n} segment times and {} segment feeds (expected N + 2 \
             points with N >= 1)",
            segment_feeds_planned.len()
        )));
    }
    if limits.len() != planned.joint_names().len() {
        return Err(bad(format!(
            "{} joint limits for {} joints",
            limits.len(),
            planned.joint_names().len()
        )));
    }
    for (j, l) in limits.iter().enumerate() {
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if !positive(l.max_velocity) || !l.max_acceleration.is_none_or(positive) {
            return Err(bad(format!(
                "joint {j}: limits {:?} are not positive and finite",
                l
            )));
        }
    }
    for (k, p) in points.iter().enumerate() {
        if let Some(j) = p.positions.iter().position(|q| !q.is_finite()) {
            return Err(bad(format!(
                "non-finite position of joint {j} at point {k}"
            )));
        }
    }
    let planned_h: Vec<f64> = points
        .windows(2)
        .map(|w| w[1].time_from_start - w[0].time_from_start)
        .collect();
    if let Some(k) = planned_h.iter().position(|h| !(h.is_finite() && *h > 0.0)) {
        return Err(bad(format!(
            "times not strictly increasing between points {k} and {}",
            k + 1
        )));
    }
    for (i, h) in planned_h.iter().enumerate() {
        let half = |k: usize| segment_times_planned.get(k).map_or(0.0, |t| 0.5 * t);
        let expected = if i == 0 {
            half(0)
        } else {
            half(i - 1) + half(i)
        };
        if (h - expected).abs() > 1e-9 * expected {
            return Err(bad(format!(
                "interval {i} lasts {h} s, the segment times give {expected} s"
            )));
        }
    }
    // Step 1: the ramps.
    let mut base = planned_h.clone();
    base[0] *= 2.0;
    base[m - 2] *= 2.0;
    let mut stretch = vec![1.0; m - 1];
    let mut rounds = 0;
    let mut uniform = false;
    let (times, velocities) = loop {
        let h: Vec<f64> = base.iter().zip(&stretch).map(|(b, c)| b * c).collect();
        let (times, velocities) = timed(points, &h, limits.len());
        let need = needs(points, &h, &velocities, limits);
        if let Some(i) = need.iter().position(|r| !r.is_finite()) {
            return Err(bad(format!(
                "non-finite velocity or acceleration in interval {i}"
            )));
        }
        let worst = need.iter().copied().fold(0.0, f64::max);
        if worst <= 1.0 {
            break (times, velocities);
        }
        if rounds < LOCAL_ROUNDS {
            // Step 3.
            for (c, r) in stretch.iter_mut().zip(&need) {
                if *r > 1.0 {
                    *c *= (r * (1.0 + MARGIN)).min(MAX_ROUND_STRETCH);
                }
            }
            rounds += 1;
        } else if !uniform {
            // Step 4: exact for a uniform stretch (v ∝ 1/s, a ∝ 1/s²).
            for c in &mut stretch {
                *c *= worst * (1.0 + MARGIN);
            }
            uniform = true;
        } else {
            return Err(bad(format!(
                "the uniform stretch left a need of {worst} (numerical failure)"
            )));
        }
    };
    // Segment k's first half lies in interval k, its second half in k + 1.
    let mut segment_times = Vec::with_capacity(n);
    let mut segment_feeds = Vec::with_capacity(n);
    for (k, (&planned_time, &feed)) in segment_times_planned
        .iter()
        .zip(segment_feeds_planned)
        .enumerate()
    {
        let ramp_first = if k == 0 { 2.0 } else { 1.0 };
        let ramp_second = if k + 1 == m - 2 { 2.0 } else { 1.0 };
        segment_times
            .push(0.5 * planned_time * (stretch[k] * ramp_first + stretch[k + 1] * ramp_second));
        // l / (T (c_k + c_{k+1}) / 2): exactly the planned feed when unstretched.
        segment_feeds.push(feed * (2.0 / (stretch[k] + stretch[k + 1])));
    }
    let out_points = points
        .iter()
        .zip(times.iter().zip(&velocities))
        .map(|(p, (&t, v))| TrajectoryPoint {
            positions: p.positions.clone(),
            velocities: v.clone(),
            time_from_start: t,
            ..TrajectoryPoint::default()
        })
        .collect();
    Ok(TimeScaling {
        trajectory: JointTrajectory {
            request: TrajectoryRequest {
                joint_names: planned.joint_names().to_vec(),
                points: out_points,
                start_time: planned.request.start_time,
            },
            arc_length: planned.arc_length.clone(),
            segment: planned.segment.clone(),
        },
        interval_stretch: stretch,
        segment_times,
        segment_feeds,
        rounds,
        uniform,
    })
}

/// Times from the interval durations `h` and the velocities of step 1–2
/// (zero at the ends, three-point in between) of `joints` joints.
fn timed(points: &[TrajectoryPoint], h: &[f64], joints: usize) -> (Vec<f64>, Vec<Vec<f64>>) {
    let m = points.len();
    let mut times = Vec::with_capacity(m);
    let mut t = 0.0;
    times.push(t);
    for d in h {
        t += d;
        times.push(t);
    }
    let mut velocities = vec![vec![0.0; joints]; m];
    for k in 1..m - 1 {
        for (j, v) in velocities[k].iter_mut().enumerate() {
            *v = three_point_velocity(
                h[k - 1],
                h[k],
                points[k - 1].positions[j],
                points[k].positions[j],
                points[k + 1].positions[j],
            );
        }
    }
    (times, velocities)
}

/// Per interval, r_i of step 3 (≤ 1: within every limit).
fn needs(
    points: &[TrajectoryPoint],
    h: &[f64],
    velocities: &[Vec<f64>],
    limits: &[JointLimit],
) -> Vec<f64> {
    (0..h.len())
        .map(|i| {
            let mut r: f64 = 0.0;
            for (j, l) in limits.iter().enumerate() {
                let e = hermite_extremes(
                    h[i],
                    points[i].positions[j],
                    points[i + 1].positions[j],
                    velocities[i][j],
                    velocities[i + 1][j],
                );
                let mut ratios = vec![e.peak_velocity.1.abs() / (l.max_velocity * (1.0 - MARGIN))];
                if let Some(amax) = l.max_acceleration {
                    for (_, a) in e.accelerations {
                        ratios.push((a.abs() / (amax * (1.0 - MARGIN))).sqrt());
                    }
                }
                for x in ratios {
                    // f64::max would drop a NaN.
                    if !x.is_finite() {
                        return f64::NAN;
                    }
                    r = r.max(x);
                }
            }
            r
        })
        .collect()
}
