//! A validated trajectory: segment polynomials on absolute time, sampled with a cursor.

use std::cell::Cell;

use crate::spline::{evaluate, Interpolation};
use crate::types::JointSample;

/// Beyond this many forward steps of the cursor, [`ValidatedTrajectory::sample`] switches to
/// binary search, which bounds the worst case of one call at O(log n).
const MAX_LINEAR_STEPS: usize = 8;

/// One segment of the interpolated motion, on absolute time `[t0, t1)`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Segment {
    /// Absolute start time (s).
    pub t0: f64,
    /// Absolute end time (s); equals the next segment's `t0`.
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

/// A trajectory that passed [`crate::validate()`]: in robot-model joint order, on absolute time,
/// within all limits on the whole interpolated curve.
///
/// Before its first segment it holds the state it started from; after its last point it holds
/// the last positions at zero velocity and acceleration.
#[derive(Debug, Clone)]
pub struct ValidatedTrajectory {
    pub(crate) n: usize,
    pub(crate) segments: Vec<Segment>,
    /// `segments.len() * n` coefficient sets, segment-major.
    pub(crate) coeffs: Vec<[f64; 6]>,
    /// State held before the first segment.
    pub(crate) initial: JointSample,
    /// Positions held after the last point.
    pub(crate) final_positions: Vec<f64>,
    /// Time at which the trajectory was validated (s).
    pub(crate) accepted_time: f64,
    /// Resolved start time (s): the header stamp, or the acceptance time.
    pub(crate) start_time: f64,
    /// Absolute time of the last point (s).
    pub(crate) end_time: f64,
    /// Index of the segment last sampled.
    pub(crate) cursor: Cell<usize>,
}

impl ValidatedTrajectory {
    /// Number of joints (the robot model's).
    pub fn joint_count(&self) -> usize {
        self.n
    }

    /// Number of interpolated segments, including the start segment if there is one.
    pub fn segment_count(&self) -> usize {
        self.segments.len()
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
        &self.final_positions
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
    /// cursor steps, else a binary search, so O(log n) worst case; any `t` is allowed. No allocation once `out` has the capacity.
    pub fn sample_into(&self, t: f64, out: &mut JointSample) {
        out.resize_full(self.n);
        if t.is_nan() || t >= self.end_time {
            // NaN cannot come from the executor (times are checked); hold the end for safety.
            out.positions.copy_from_slice(&self.final_positions);
            out.velocities.fill(0.0);
            out.accelerations.fill(0.0);
            return;
        }
        let Some(first) = self.segments.first() else {
            self.copy_initial(out);
            return;
        };
        if t < first.t0 {
            self.copy_initial(out);
            return;
        }
        let k = self.find_segment(t);
        self.cursor.set(k);
        let seg = &self.segments[k];
        let tau = t - seg.t0;
        let coeffs = &self.coeffs[k * self.n..(k + 1) * self.n];
        for (j, c) in coeffs.iter().enumerate() {
            let (p, v, a) = evaluate(c, tau);
            out.positions[j] = p;
            out.velocities[j] = v;
            out.accelerations[j] = a;
        }
    }

    fn copy_initial(&self, out: &mut JointSample) {
        out.positions.copy_from_slice(&self.initial.positions);
        out.velocities.copy_from_slice(&self.initial.velocities);
        out.accelerations
            .copy_from_slice(&self.initial.accelerations);
    }

    /// Index of the segment with `t0 <= t < t1`, for `segments[0].t0 <= t < end_time`.
    fn find_segment(&self, t: f64) -> usize {
        let last = self.segments.len() - 1;
        let mut k = self.cursor.get().min(last);
        if t < self.segments[k].t0 {
            return self.search(t);
        }
        for _ in 0..MAX_LINEAR_STEPS {
            if k == last || t < self.segments[k].t1 {
                return k;
            }
            k += 1;
        }
        if k == last || t < self.segments[k].t1 {
            k
        } else {
            self.search(t)
        }
    }

    fn search(&self, t: f64) -> usize {
        let idx = self.segments.partition_point(|s| s.t1 <= t);
        idx.min(self.segments.len() - 1)
    }
}
