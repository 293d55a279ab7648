//! A validated trajectory: segment polynomials, sampled with a cursor.
//!
//! The waypoint segments ([`Body`]) are built once by [`crate::prepare`] on time relative to
//! the trajectory's start time and shared (`Arc`) by every trajectory finished from them, so
//! that finishing a prepared trajectory against the current state costs O(joints), never a
//! copy of its segments.

use std::cell::Cell;
use std::sync::Arc;

use crate::spline::{evaluate, Interpolation, Knot};
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

/// One waypoint in model joint order.
#[derive(Debug, Clone)]
pub(crate) struct ModelPoint {
    pub positions: Vec<f64>,
    pub velocities: Option<Vec<f64>>,
    pub accelerations: Option<Vec<f64>>,
    pub time_from_start: f64,
}

impl ModelPoint {
    /// Joint `j`'s state at this point; missing velocities or accelerations count as 0.
    pub fn knot(&self, j: usize) -> Knot {
        Knot {
            p: self.positions[j],
            v: self.velocities.as_ref().map_or(0.0, |v| v[j]),
            a: self.accelerations.as_ref().map_or(0.0, |a| a[j]),
        }
    }
}

/// The request-only part of a trajectory: its waypoint segments on time from the start time.
#[derive(Debug)]
pub(crate) struct Body {
    /// Number of joints.
    pub n: usize,
    /// Segments between consecutive waypoints, on time from the start time.
    pub segments: Vec<Segment>,
    /// `segments.len() * n` coefficient sets, segment-major.
    pub coeffs: Vec<[f64; 6]>,
    /// The first waypoint (the start segment runs to it).
    pub first: ModelPoint,
    /// Positions of the last waypoint, held after the end.
    pub final_positions: Vec<f64>,
    /// Number of waypoints.
    pub point_count: usize,
    /// `time_from_start` of the last waypoint (s).
    pub duration: f64,
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
}

impl ValidatedTrajectory {
    /// Number of joints (the robot model's).
    pub fn joint_count(&self) -> usize {
        self.n
    }

    /// Number of interpolated segments, including the start segment if there is one.
    pub fn segment_count(&self) -> usize {
        usize::from(self.lead.is_some()) + self.body.segments.len()
    }

    /// Number of waypoints.
    pub fn point_count(&self) -> usize {
        self.body.point_count
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
        &self.body.final_positions
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
            out.positions.copy_from_slice(&self.body.final_positions);
            out.velocities.fill(0.0);
            out.accelerations.fill(0.0);
            return;
        }
        match (&self.lead, self.body.segments.first()) {
            (Some(lead), _) if t < lead.segment.t0 => self.copy_initial(out),
            (Some(lead), first) if t < lead.segment.t1 || first.is_none() => {
                write_segment(&lead.coeffs, t - lead.segment.t0, out)
            }
            (Some(_), _) => self.sample_body(t, out),
            (None, Some(first)) if t >= self.start_time + first.t0 => self.sample_body(t, out),
            (None, _) => self.copy_initial(out),
        }
    }

    /// Samples the waypoint segments at absolute `t` (at or after the first one's start).
    fn sample_body(&self, t: f64, out: &mut JointSample) {
        let rel = t - self.start_time;
        let k = self.find_segment(rel);
        self.cursor.set(k);
        let seg = &self.body.segments[k];
        let n = self.n;
        write_segment(&self.body.coeffs[k * n..(k + 1) * n], rel - seg.t0, out);
    }

    fn copy_initial(&self, out: &mut JointSample) {
        out.positions.copy_from_slice(&self.initial.positions);
        out.velocities.copy_from_slice(&self.initial.velocities);
        out.accelerations
            .copy_from_slice(&self.initial.accelerations);
    }

    /// Index of the waypoint segment with `t0 <= rel < t1` (time from the start time).
    fn find_segment(&self, rel: f64) -> usize {
        let segments = &self.body.segments;
        let last = segments.len() - 1;
        let mut k = self.cursor.get().min(last);
        if rel < segments[k].t0 {
            return self.search(rel);
        }
        for _ in 0..MAX_LINEAR_STEPS {
            if k == last || rel < segments[k].t1 {
                return k;
            }
            k += 1;
        }
        if k == last || rel < segments[k].t1 {
            k
        } else {
            self.search(rel)
        }
    }

    fn search(&self, rel: f64) -> usize {
        let segments = &self.body.segments;
        let idx = segments.partition_point(|s| s.t1 <= rel);
        idx.min(segments.len() - 1)
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
