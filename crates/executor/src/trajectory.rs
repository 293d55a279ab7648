//! A validated trajectory: segment polynomials, sampled with a cursor.
//!
//! The waypoints ([`Body`]) are stored once by [`crate::prepare`], compactly (about the
//! message's wire size: `8 · (1 + 3 · joints) + 1` bytes per point, no allocation per point),
//! on time relative to the trajectory's start time, and shared (`Arc`) by every trajectory
//! finished from them, so that finishing a prepared trajectory against the current state
//! costs O(joints), never a copy. A segment's coefficients are computed from its two
//! waypoints when it is first sampled and kept until the cursor leaves it.
//!
//! Measured with `cargo run --release -p kerf_executor --example trajectory_memory`
//! (10⁶ quintic points of 6 joints, wire size 145 MB): the prepared trajectory holds 146 MB;
//! a table of per-segment coefficients and times held 504 MB (issue 33).

use std::cell::{Cell, RefCell};
use std::sync::Arc;

use crate::spline::{coefficients, evaluate, Interpolation, Knot};
use crate::types::JointSample;

/// Beyond this many forward steps of the cursor, [`ValidatedTrajectory::sample`] switches to
/// binary search, which bounds the worst case of one call at O(log n).
const MAX_LINEAR_STEPS: usize = 8;

/// One segment of the interpolated motion on `[t0, t1)`: absolute time for the start
/// segment, time from the trajectory's start time for the waypoint segments.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Segment {
    /// Start time (s).
    pub t0: f64,
    /// End time (s); equals the next segment's `t0`.
    pub t1: f64,
    /// Duration used for the coefficients (s); `t1 − t0` up to rounding.
    pub duration: f64,
    /// The polynomial kind.
    pub kind: Interpolation,
    /// Index of the start point, `None` for the current state (start segment).
    pub from: Option<usize>,
}

impl Segment {
    /// "between point 2 and point 3 (cubic)" or "start segment, current state → point 0 (linear)".
    pub fn location(&self) -> String {
        match self.from {
            None => format!(
                "start segment, current state → point 0 ({})",
                self.kind.name()
            ),
            Some(k) => format!(
                "between point {k} and point {} ({})",
                k + 1,
                self.kind.name()
            ),
        }
    }
}

/// Bit of [`Body::given`]: the waypoint has velocities.
pub(crate) const HAS_VELOCITIES: u8 = 1;
/// Bit of [`Body::given`]: the waypoint has accelerations.
pub(crate) const HAS_ACCELERATIONS: u8 = 2;

/// The request-only part of a trajectory: its waypoints in model joint order, on time from the
/// start time.
///
/// Stored compactly, close to the message's wire size: per waypoint its time and `3 · n`
/// values (positions, velocities, accelerations; missing ones as 0) in two flat vectors and
/// one flag byte, 8 · (1 + 3n) + 1 bytes (145 for 6 joints), with no allocation per point.
/// A segment's polynomial coefficients are computed from its two waypoints when it is
/// sampled or checked (O(joints), a few dozen flops per joint), bit for bit the values a
/// table of coefficients would hold, instead of being stored (48 bytes per joint and
/// segment, plus the segment's times).
#[derive(Debug)]
pub(crate) struct Body {
    /// Number of joints.
    pub n: usize,
    /// `time_from_start` of every waypoint (s), strictly increasing.
    pub times: Vec<f64>,
    /// Waypoint-major: positions, velocities, accelerations of each waypoint, `3 · n` values.
    pub knots: Vec<f64>,
    /// Per waypoint: [`HAS_VELOCITIES`] | [`HAS_ACCELERATIONS`].
    pub given: Vec<u8>,
}

impl Body {
    /// Number of waypoints (at least 1).
    pub fn point_count(&self) -> usize {
        self.times.len()
    }

    /// Number of segments between waypoints.
    pub fn segment_count(&self) -> usize {
        self.times.len().saturating_sub(1)
    }

    /// `time_from_start` of the last waypoint (s).
    pub fn duration(&self) -> f64 {
        self.times.last().copied().unwrap_or(0.0)
    }

    /// Positions of waypoint `k`, model order.
    pub fn positions(&self, k: usize) -> &[f64] {
        let at = 3 * self.n * k;
        &self.knots[at..at + self.n]
    }

    /// Positions of the last waypoint, held after the end.
    pub fn final_positions(&self) -> &[f64] {
        self.positions(self.point_count() - 1)
    }

    /// Whether waypoint `k` has velocities.
    pub fn has_velocities(&self, k: usize) -> bool {
        self.given[k] & HAS_VELOCITIES != 0
    }

    /// Whether waypoint `k` has accelerations.
    pub fn has_accelerations(&self, k: usize) -> bool {
        self.given[k] & HAS_ACCELERATIONS != 0
    }

    /// Joint `j`'s state at waypoint `k`; missing velocities or accelerations count as 0.
    pub fn knot(&self, k: usize, j: usize) -> Knot {
        let at = 3 * self.n * k + j;
        Knot {
            p: self.knots[at],
            v: self.knots[at + self.n],
            a: self.knots[at + 2 * self.n],
        }
    }

    /// Segment `k`, from waypoint `k` to waypoint `k + 1`.
    pub fn segment(&self, k: usize) -> Segment {
        let (t0, t1) = (self.times[k], self.times[k + 1]);
        Segment {
            t0,
            t1,
            duration: t1 - t0,
            kind: Interpolation::between(
                self.has_velocities(k),
                self.has_accelerations(k),
                self.has_velocities(k + 1),
                self.has_accelerations(k + 1),
            ),
            from: Some(k),
        }
    }

    /// Writes the coefficients of segment `k` (one set per joint) into `out`.
    ///
    /// # Performance
    /// O(joints), no allocation once `out` has the capacity.
    pub fn coefficients_into(&self, k: usize, out: &mut Vec<[f64; 6]>) {
        let seg = self.segment(k);
        out.clear();
        out.extend(
            (0..self.n).map(|j| {
                coefficients(seg.kind, self.knot(k, j), self.knot(k + 1, j), seg.duration)
            }),
        );
    }
}

/// The start segment, from the state a trajectory started from to its first point, on
/// absolute time, with its coefficients (one set per joint).
#[derive(Debug, Clone)]
pub(crate) struct Lead {
    pub segment: Segment,
    pub coeffs: Vec<[f64; 6]>,
}

/// A trajectory that passed [`crate::validate()`]: in robot-model joint order, on absolute time,
/// within all limits on the whole interpolated curve.
///
/// Before its first segment it holds the state it started from; after its last point it holds
/// the last positions at zero velocity and acceleration.
///
/// Cloning and dropping cost O(joints) unless this is the last trajectory holding its
/// waypoint segments; a real-time loop hands replaced trajectories to another thread to drop
/// (see [`crate::Executor::defer_drops`]).
#[derive(Debug, Clone)]
pub struct ValidatedTrajectory {
    pub(crate) n: usize,
    /// The start segment, if the first point is not due at the start.
    pub(crate) lead: Option<Lead>,
    /// The waypoint segments, on time from `start_time`.
    pub(crate) body: Arc<Body>,
    /// State held before the first segment.
    pub(crate) initial: JointSample,
    /// Time at which the trajectory was validated (s).
    pub(crate) accepted_time: f64,
    /// Resolved start time (s): the header stamp, or the acceptance time.
    pub(crate) start_time: f64,
    /// Absolute time of the last point (s).
    pub(crate) end_time: f64,
    /// Index of the waypoint segment last sampled.
    pub(crate) cursor: Cell<usize>,
    /// The coefficients of one waypoint segment (one set per joint) and its index
    /// (`usize::MAX`: none yet): successive samples within a segment reuse them.
    pub(crate) cached: RefCell<(usize, Vec<[f64; 6]>)>,
}

impl ValidatedTrajectory {
    /// Number of joints (the robot model's).
    pub fn joint_count(&self) -> usize {
        self.n
    }

    /// Number of interpolated segments, including the start segment if there is one.
    pub fn segment_count(&self) -> usize {
        usize::from(self.lead.is_some()) + self.body.segment_count()
    }

    /// Number of waypoints.
    pub fn point_count(&self) -> usize {
        self.body.point_count()
    }

    /// Absolute time the trajectory was validated at (s).
    pub fn accepted_time(&self) -> f64 {
        self.accepted_time
    }

    /// Resolved absolute start time (s): the request's `start_time`, or the acceptance time.
    pub fn start_time(&self) -> f64 {
        self.start_time
    }

    /// Absolute time of the last point (s); after it the last positions are held.
    pub fn end_time(&self) -> f64 {
        self.end_time
    }

    /// `time_from_start` of the last point (s): `end_time() − start_time()`.
    pub fn duration(&self) -> f64 {
        self.end_time - self.start_time
    }

    /// Positions held after the end, in model order.
    pub fn final_positions(&self) -> &[f64] {
        self.body.final_positions()
    }

    /// The commanded state at absolute time `t`.
    ///
    /// # Returns
    /// Positions, velocities and accelerations in model order. Before the first segment: the
    /// state the trajectory started from; from `end_time()` on: the last positions at rest.
    ///
    /// # Performance
    /// Allocates the result; see [`Self::sample_into`] for the allocation-free form.
    pub fn sample(&self, t: f64) -> JointSample {
        let mut out = JointSample::default();
        self.sample_into(t, &mut out);
        out
    }

    /// As [`Self::sample`], writing into `out` (resized to the joint count).
    ///
    /// # Performance
    /// O(1) amortized for non-decreasing `t` (a segment cursor moves forward); at most 8
    /// cursor steps, else a binary search, so O(log n) worst case; any `t` is allowed. No
    /// allocation once `out` has the capacity.
    pub fn sample_into(&self, t: f64, out: &mut JointSample) {
        out.resize_full(self.n);
        if t.is_nan() || t >= self.end_time {
            // NaN cannot come from the executor (times are checked); hold the end for safety.
            out.positions.copy_from_slice(self.body.final_positions());
            out.velocities.fill(0.0);
            out.accelerations.fill(0.0);
            return;
        }
        let body_begins = (self.body.segment_count() > 0).then(|| self.body.times[0]);
        match (&self.lead, body_begins) {
            (Some(lead), _) if t < lead.segment.t0 => self.copy_initial(out),
            (Some(lead), first) if t < lead.segment.t1 || first.is_none() => {
                write_segment(&lead.coeffs, t - lead.segment.t0, out)
            }
            (Some(_), _) => self.sample_body(t, out),
            (None, Some(t0)) if t >= self.start_time + t0 => self.sample_body(t, out),
            (None, _) => self.copy_initial(out),
        }
    }

    /// Samples the waypoint segments at absolute `t` (at or after the first one's start).
    fn sample_body(&self, t: f64, out: &mut JointSample) {
        let rel = t - self.start_time;
        let k = self.find_segment(rel);
        self.cursor.set(k);
        let tau = rel - self.body.times[k];
        match self.cached.try_borrow_mut() {
            Ok(mut cached) => {
                if cached.0 != k {
                    self.body.coefficients_into(k, &mut cached.1);
                    cached.0 = k;
                }
                write_segment(&cached.1, tau, out);
            }
            // Unreachable (no sampling calls back into sampling); computed in place then.
            Err(_) => {
                let body = &self.body;
                let seg = body.segment(k);
                for j in 0..self.n {
                    let c =
                        coefficients(seg.kind, body.knot(k, j), body.knot(k + 1, j), seg.duration);
                    let (p, v, a) = evaluate(&c, tau);
                    out.positions[j] = p;
                    out.velocities[j] = v;
                    out.accelerations[j] = a;
                }
            }
        }
    }

    fn copy_initial(&self, out: &mut JointSample) {
        out.positions.copy_from_slice(&self.initial.positions);
        out.velocities.copy_from_slice(&self.initial.velocities);
        out.accelerations
            .copy_from_slice(&self.initial.accelerations);
    }

    /// Index of the waypoint segment with `t0 <= rel < t1` (time from the start time):
    /// segment `k` runs from `times[k]` to `times[k + 1]`.
    fn find_segment(&self, rel: f64) -> usize {
        let times = &self.body.times;
        let last = self.body.segment_count() - 1;
        let mut k = self.cursor.get().min(last);
        if rel < times[k] {
            return self.search(rel);
        }
        for _ in 0..MAX_LINEAR_STEPS {
            if k == last || rel < times[k + 1] {
                return k;
            }
            k += 1;
        }
        if k == last || rel < times[k + 1] {
            k
        } else {
            self.search(rel)
        }
    }

    fn search(&self, rel: f64) -> usize {
        // The segments whose end `times[k + 1]` is at or before `rel`.
        let idx = self.body.times[1..].partition_point(|&t1| t1 <= rel);
        idx.min(self.body.segment_count() - 1)
    }
}

/// Evaluates one segment's per-joint coefficients at local time `tau` into `out`.
fn write_segment(coeffs: &[[f64; 6]], tau: f64, out: &mut JointSample) {
    for (j, c) in coeffs.iter().enumerate() {
        let (p, v, a) = evaluate(c, tau);
        out.positions[j] = p;
        out.velocities[j] = v;
        out.accelerations[j] = a;
    }
}
