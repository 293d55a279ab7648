//! [`Stitched`]: approach + process + retract as one time-ordered sample list.

use std::fmt;

use crate::waypoints::sample_count;
use crate::{ApproachError, Sample, WaypointMove};

/// Largest position jump (rad or m) accepted where the approach meets the process and where
/// the process meets the retract.
pub const STITCH_POSITION_TOLERANCE: f64 = 1e-9;

/// Largest velocity (rad/s or m/s) accepted at the first and last process samples: the
/// approach ends and the retract starts at rest.
pub const STITCH_VELOCITY_TOLERANCE: f64 = 1e-6;

/// Largest acceleration (rad/s² or m/s²) accepted at the first and last process samples.
pub const STITCH_ACCELERATION_TOLERANCE: f64 = 1e-6;

/// Where two parts of a stitched motion meet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Boundary {
    /// Approach end → first process sample.
    ProcessStart,
    /// Last process sample → retract start.
    ProcessEnd,
}

impl fmt::Display for Boundary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Boundary::ProcessStart => write!(f, "approach end / process start"),
            Boundary::ProcessEnd => write!(f, "process end / retract start"),
        }
    }
}

/// The three parts of a plan, to be joined in time.
#[derive(Debug, Clone, PartialEq)]
pub struct Stitched {
    /// The approach (ends at rest at the first process point).
    pub approach: WaypointMove,
    /// The process samples `(t, q, q̇, q̈)`, strictly increasing in `t` (any origin),
    /// starting and ending at rest.
    pub process: Vec<Sample>,
    /// The retract (starts at rest at the last process point).
    pub retract: WaypointMove,
}

/// A stitched plan: one time-ordered sample list and the process's time marks.
#[derive(Debug, Clone, PartialEq)]
pub struct Timeline {
    /// Approach samples at the control period (its end left out: the first process sample is
    /// that configuration), the process samples shifted in time, then retract samples at the
    /// control period (its start left out: the last process sample).
    pub samples: Vec<Sample>,
    /// Time of the first process sample (s) = the approach's duration.
    pub process_start: f64,
    /// Time of the last process sample (s).
    pub process_end: f64,
}

impl Stitched {
    /// Joins approach, process and retract into one [`Timeline`] starting at `t = 0`.
    ///
    /// The process samples are copied unchanged except for their time, shifted by
    /// `approach duration − t_first`. The approach and retract are sampled every `period`
    /// ([`WaypointMove::samples`]).
    ///
    /// # Arguments
    /// * `period` – sampling period of approach and retract (s): the control period.
    ///
    /// # Returns
    /// The timeline; [`ApproachError::EmptyProcess`]; [`ApproachError::InvalidProcess`] for a
    /// sample with a non-finite or non-increasing time, a wrong length or a non-finite value;
    /// [`ApproachError::Discontinuity`] when the parts do not meet within
    /// [`STITCH_POSITION_TOLERANCE`] or the process does not start and end at rest within
    /// [`STITCH_VELOCITY_TOLERANCE`] and [`STITCH_ACCELERATION_TOLERANCE`];
    /// [`ApproachError::InvalidPeriod`], [`ApproachError::TooManySamples`].
    ///
    /// # Performance
    /// O(samples × joints), one pass; copies the process.
    pub fn timeline(&self, period: f64) -> Result<Timeline, ApproachError> {
        let n = self.approach.start().len();
        self.check_process(n)?;
        let (first, last) = match (self.process.first(), self.process.last()) {
            (Some(f), Some(l)) => (f, l),
            _ => return Err(ApproachError::EmptyProcess),
        };
        meet(Boundary::ProcessStart, self.approach.end(), first)?;
        meet(Boundary::ProcessEnd, self.retract.start(), last)?;
        let count = sample_count(self.approach.duration(), period)?
            + self.process.len()
            + sample_count(self.retract.duration(), period)?;
        let mut samples = Vec::with_capacity(count);
        let mut approach = self.approach.samples(period)?;
        approach.pop();
        samples.extend(approach);
        let process_start = self.approach.duration();
        samples.extend(self.process.iter().map(|s| Sample {
            t: (s.t - first.t) + process_start,
            ..s.clone()
        }));
        let process_end = (last.t - first.t) + process_start;
        samples.extend(
            self.retract
                .samples(period)?
                .into_iter()
                .skip(1)
                .map(|s| Sample {
                    t: s.t + process_end,
                    ..s
                }),
        );
        Ok(Timeline {
            samples,
            process_start,
            process_end,
        })
    }

    /// Checks the process samples: non-empty, lengths `n`, finite, strictly increasing time.
    fn check_process(&self, n: usize) -> Result<(), ApproachError> {
        if self.process.is_empty() {
            return Err(ApproachError::EmptyProcess);
        }
        let bad = |index, reason: String| Err(ApproachError::InvalidProcess { index, reason });
        let mut previous = f64::NEG_INFINITY;
        for (i, s) in self.process.iter().enumerate() {
            if !s.t.is_finite() || s.t <= previous {
                return bad(
                    i,
                    format!("time {} is not finite and after {previous}", s.t),
                );
            }
            previous = s.t;
            for (what, v) in [("q", &s.q), ("qd", &s.qd), ("qdd", &s.qdd)] {
                if v.len() != n {
                    return bad(i, format!("{what} has {} values for {n} joints", v.len()));
                }
                if let Some(j) = v.iter().position(|x| !x.is_finite()) {
                    return bad(i, format!("{what}[{j}] = {} is not finite", v[j]));
                }
            }
        }
        Ok(())
    }
}

/// Checks that `q` (an end of approach or retract, at rest) meets the process sample `s`.
fn meet(boundary: Boundary, q: &[f64], s: &Sample) -> Result<(), ApproachError> {
    let rest = vec![0.0; q.len()];
    for (quantity, theirs, ours, tolerance) in [
        ("position", &s.q, q, STITCH_POSITION_TOLERANCE),
        (
            "velocity",
            &s.qd,
            rest.as_slice(),
            STITCH_VELOCITY_TOLERANCE,
        ),
        (
            "acceleration",
            &s.qdd,
            rest.as_slice(),
            STITCH_ACCELERATION_TOLERANCE,
        ),
    ] {
        if theirs.len() != ours.len() {
            return Err(ApproachError::JointCount {
                what: format!("{boundary} {quantity}"),
                expected: ours.len(),
                found: theirs.len(),
            });
        }
        for (joint, (a, b)) in theirs.iter().zip(ours).enumerate() {
            let gap = (a - b).abs();
            if gap.is_nan() || gap > tolerance {
                return Err(ApproachError::Discontinuity {
                    boundary,
                    joint,
                    quantity,
                    gap,
                    tolerance,
                });
            }
        }
    }
    Ok(())
}
