//! The core of the executor's streaming mode (issue 29, item 5): reference
//! points that arrive while the robot moves, stepped through at the
//! control rate within every joint limit.
//!
//! # The rules a stream follows
//! * **Start.** The first point of a stream is where the robot is (the
//!   executor checks it against its commanded state, within its start
//!   tolerance). It is reached at once.
//! * **Each further point** has one coordinate per joint, inside the joint's
//!   range, and a precision in (0, 1] (rad or m, Euclidean over the joints).
//!   It is refused, with the reason, when a coordinate is NaN or out of
//!   range, when it lies within twice its precision of the point before it
//!   (repeated), when a joint would move more than
//!   [`StreamSettings::max_jump`] from the point before it (a jump), or
//!   when [`StreamSettings::queue`] points are already waiting (a stream
//!   faster than the robot follows). A refused point changes nothing else.
//! * **Batches.** When the robot rests and points wait, all of them become
//!   one batch: the spline through the last point and them ([`MultiCourse`]),
//!   stepped by the controller at the control period, ending at rest on the
//!   batch's last point. Points that arrive meanwhile wait for the next
//!   batch. A stream that stops therefore ends in a controlled stop on its
//!   last point, never in a step: every batch is a motion from rest to rest
//!   inside the limits.
//! * **Reports.** Each point of a batch is reached at the sample that
//!   passes it, with its distance ([`Batch::passes`]).
//!
//! A batch that cannot be planned (its path leaves a joint's range between
//! two points) reports every point of it as not reached and keeps the robot
//! where it is.

use std::collections::VecDeque;

use crate::{
    error::{check_positive, StepError},
    limits::{check_period, Limits},
    multi::{AxisSample, MultiCourse},
    run::Controller,
    spline::distance,
    Course,
};

/// Settings of a [`Stream`] (builder style).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StreamSettings {
    /// Control period [s]: one stepping decision per period.
    pub period: f64,
    /// Most points waiting for a batch (default 256).
    pub queue: usize,
    /// Largest move of any joint from one point to the next (default 0.5,
    /// rad or m).
    pub max_jump: f64,
    /// Periods a batch may take (default 10⁶).
    pub max_steps: usize,
}

impl StreamSettings {
    /// Defaults at control period `period`.
    pub fn new(period: f64) -> Self {
        Self {
            period,
            queue: 256,
            max_jump: 0.5,
            max_steps: 1_000_000,
        }
    }

    /// Sets [`StreamSettings::queue`].
    pub fn queue(mut self, queue: usize) -> Self {
        self.queue = queue;
        self
    }

    /// Sets [`StreamSettings::max_jump`].
    pub fn max_jump(mut self, max_jump: f64) -> Self {
        self.max_jump = max_jump;
        self
    }

    /// # Errors
    /// [`StepError::InvalidParameter`] for a bad period, an empty queue, or
    /// a jump bound that is not finite and > 0.
    pub fn validate(&self) -> Result<(), StepError> {
        check_period(self.period)?;
        check_positive("stream max_jump", self.max_jump)?;
        if self.queue == 0 || self.max_steps == 0 {
            return Err(StepError::InvalidParameter {
                name: "stream queue / max steps".to_string(),
                value: 0.0,
                reason: "must be at least 1".to_string(),
            });
        }
        Ok(())
    }
}

/// A point of a stream.
#[derive(Debug, Clone, PartialEq)]
pub struct StreamPoint {
    /// The sender's id, echoed in every report.
    pub id: u32,
    /// One coordinate per joint, in the robot's joint order.
    pub positions: Vec<f64>,
    /// Precision (rad or m, Euclidean over the joints).
    pub precision: f64,
}

/// What [`Stream::push`] did with a point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pushed {
    /// It starts the stream: the robot is there.
    Start,
    /// It waits for a batch; `waiting` points now wait.
    Queued {
        /// Points waiting, this one included.
        waiting: usize,
    },
}

/// How one point of a batch was passed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BatchPass {
    /// The point's id.
    pub id: u32,
    /// Sample of the batch that passed it.
    pub step: usize,
    /// Distance of that sample to the point.
    pub error: f64,
    /// The point's own precision.
    pub precision: f64,
}

/// A planned batch: the samples to command, one per control period, from
/// rest at the previous point to rest at the last.
#[derive(Debug, Clone)]
pub struct Batch {
    /// Batch number (1 = the first of the stream).
    pub number: u64,
    /// Joint samples, the start first.
    pub samples: Vec<AxisSample>,
    /// One pass per point, in order.
    pub passes: Vec<BatchPass>,
}

/// A factory of per-period controllers for one batch's course.
pub type ControllerFactory<'a> = dyn Fn(&Course) -> Result<Box<dyn Controller>, StepError> + 'a;

/// A stream of reference points for one robot.
#[derive(Debug, Clone)]
pub struct Stream {
    limits: Vec<Limits>,
    ranges: Vec<(f64, f64)>,
    settings: StreamSettings,
    /// Where the robot rests: the stream's start, then each batch's last sample.
    anchor: Option<Vec<f64>>,
    /// The last point accepted (queued or the anchor).
    last: Option<Vec<f64>>,
    queue: VecDeque<StreamPoint>,
    batches: u64,
}

impl Stream {
    /// A stream for joints with `limits` and position `ranges`.
    ///
    /// # Errors
    /// [`StreamSettings::validate`]; limits or ranges of another count, or
    /// invalid.
    pub fn new(
        limits: Vec<Limits>,
        ranges: Vec<(f64, f64)>,
        settings: StreamSettings,
    ) -> Result<Self, StepError> {
        settings.validate()?;
        if limits.is_empty() || limits.len() != ranges.len() {
            return Err(StepError::InvalidParameter {
                name: "joint count".to_string(),
                value: limits.len() as f64,
                reason: format!("{} limits for {} ranges", limits.len(), ranges.len()),
            });
        }
        for l in &limits {
            l.validate()?;
        }
        Ok(Self {
            limits,
            ranges,
            settings,
            anchor: None,
            last: None,
            queue: VecDeque::new(),
            batches: 0,
        })
    }

    /// Whether the stream has a start.
    pub fn started(&self) -> bool {
        self.anchor.is_some()
    }

    /// Points waiting for a batch.
    pub fn waiting(&self) -> usize {
        self.queue.len()
    }

    /// Takes `point` into the stream (module documentation's rules).
    ///
    /// # Errors
    /// [`StepError::InvalidPoint`] (index = the point's id) with the reason
    /// it is refused.
    pub fn push(&mut self, point: StreamPoint) -> Result<Pushed, StepError> {
        let refuse = |reason: String| StepError::InvalidPoint {
            index: point.id as usize,
            reason,
        };
        if point.positions.len() != self.limits.len() {
            return Err(refuse(format!(
                "{} coordinates for {} joints",
                point.positions.len(),
                self.limits.len()
            )));
        }
        // As kerf_msgs's declared rule of ReferencePoint.precision: (0, 1], not denormal (the
        // lattice's windows divide by it).
        if !(point.precision.is_finite()
            && point.precision >= f64::MIN_POSITIVE
            && point.precision <= 1.0)
        {
            return Err(refuse(format!(
                "precision {} must be in (0, 1] and not denormal",
                point.precision
            )));
        }
        for (j, (q, (lo, hi))) in point.positions.iter().zip(&self.ranges).enumerate() {
            if !q.is_finite() {
                return Err(refuse(format!("joint {} is {q}", j + 1)));
            }
            if q < lo || q > hi {
                return Err(refuse(format!(
                    "joint {} at {q} is out of reach (range [{lo}, {hi}])",
                    j + 1
                )));
            }
        }
        let Some(last) = &self.last else {
            self.anchor = Some(point.positions.clone());
            self.last = Some(point.positions);
            return Ok(Pushed::Start);
        };
        let d = distance(last, &point.positions);
        if d <= 2.0 * point.precision {
            return Err(refuse(format!(
                "{d} from the point before it: within twice its precision {} (repeated)",
                point.precision
            )));
        }
        let (joint, jump) = last
            .iter()
            .zip(&point.positions)
            .map(|(a, b)| (b - a).abs())
            .enumerate()
            .fold((0, 0.0f64), |m, (j, x)| if x > m.1 { (j, x) } else { m });
        if jump > self.settings.max_jump {
            return Err(refuse(format!(
                "joint {} jumps {jump} from the point before it (max_jump {})",
                joint + 1,
                self.settings.max_jump
            )));
        }
        if self.queue.len() >= self.settings.queue {
            return Err(refuse(format!(
                "{} points already wait (queue {}): the stream is faster than the robot; \
                 send more after points are reached",
                self.queue.len(),
                self.settings.queue
            )));
        }
        self.last = Some(point.positions.clone());
        self.queue.push_back(point);
        Ok(Pushed::Queued {
            waiting: self.queue.len(),
        })
    }

    /// The next batch to plan: every waiting point, from rest at the anchor;
    /// `None` when nothing waits. Planning ([`BatchJob::plan`]) may run on
    /// another thread; [`Stream::job_done`] then takes its result. Call it
    /// again only after that.
    pub fn take_job(&mut self) -> Option<BatchJob> {
        let anchor = self.anchor.clone()?;
        if self.queue.is_empty() {
            return None;
        }
        self.batches += 1;
        Some(BatchJob {
            number: self.batches,
            anchor,
            points: self.queue.drain(..).collect(),
            limits: self.limits.clone(),
            ranges: self.ranges.clone(),
            period: self.settings.period,
            max_steps: self.settings.max_steps,
        })
    }

    /// Takes the result of planning `job`: the robot will rest where the
    /// batch's last sample is (within the precision of its last point), and
    /// the next batch starts there, not on the point; a batch that could not
    /// be planned leaves the robot where it is.
    pub fn job_done(&mut self, job: &BatchJob, result: &Result<Batch, StepError>) {
        match result {
            Ok(batch) => self.anchor = batch.samples.last().map(|s| s.position.clone()),
            Err(_) => {
                // The points after the dropped ones are compared with where the robot is.
                if self.queue.is_empty() {
                    self.last = Some(job.anchor.clone());
                }
            }
        }
    }

    /// [`Stream::take_job`], [`BatchJob::plan`] and [`Stream::job_done`] in
    /// one call.
    ///
    /// # Returns
    /// `Some(Ok(batch))`, or `Some(Err((ids, error)))` naming the points that
    /// cannot be reached (they are dropped; the robot stays); `None` when
    /// nothing waits.
    pub fn take_batch(
        &mut self,
        make: &ControllerFactory,
    ) -> Option<Result<Batch, (Vec<u32>, StepError)>> {
        let job = self.take_job()?;
        let result = job.plan(make);
        self.job_done(&job, &result);
        Some(result.map_err(|e| (job.ids(), e)))
    }

    /// Forgets the stream (after the robot was moved by something else, or
    /// a batch did not end where planned): the next point is a new start.
    ///
    /// # Returns
    /// The ids of the points that were waiting.
    pub fn reset(&mut self) -> Vec<u32> {
        self.anchor = None;
        self.last = None;
        self.queue.drain(..).map(|p| p.id).collect()
    }
}

/// A batch to plan, with everything planning needs (so that it can run on
/// another thread than the stream's).
#[derive(Debug, Clone)]
pub struct BatchJob {
    /// Batch number (1 = the first of the stream).
    pub number: u64,
    anchor: Vec<f64>,
    points: Vec<StreamPoint>,
    limits: Vec<Limits>,
    ranges: Vec<(f64, f64)>,
    period: f64,
    max_steps: usize,
}

impl BatchJob {
    /// The ids of its points, in order.
    pub fn ids(&self) -> Vec<u32> {
        self.points.iter().map(|p| p.id).collect()
    }

    /// Plans the batch: the spline through the anchor and the points,
    /// stepped by `make`'s controller, every sample inside the joint ranges.
    ///
    /// # Errors
    /// [`MultiCourse::new`]'s and the run's errors; [`StepError::Violation`]
    /// when the path leaves a joint's range between two points.
    ///
    /// # Performance
    /// About 0.8 ms per point of a six-joint batch (BENCHMARKS
    /// "Streaming mode of the executor").
    pub fn plan(&self, make: &ControllerFactory) -> Result<Batch, StepError> {
        let (anchor, points) = (&self.anchor, &self.points);
        let precision = points
            .iter()
            .map(|p| p.precision)
            .fold(f64::INFINITY, f64::min);
        let mut path = Vec::with_capacity(points.len() + 1);
        path.push(anchor.to_vec());
        path.extend(points.iter().map(|p| p.positions.clone()));
        let course = MultiCourse::new(path, &self.limits, precision, self.period)?;
        let mut controller = make(&course.course)?;
        let run = course.run(controller.as_mut(), self.max_steps)?;
        for (k, s) in run.samples.iter().enumerate() {
            for (j, (q, (lo, hi))) in s.position.iter().zip(&self.ranges).enumerate() {
                if q < lo || q > hi {
                    return Err(StepError::Violation {
                        step: k,
                        reason: format!(
                            "the path between the points leaves joint {}'s range ({q}, range \
                             [{lo}, {hi}]); add points where it bulges",
                            j + 1
                        ),
                    });
                }
            }
        }
        let passes = run
            .passes
            .iter()
            .zip(points)
            .map(|(p, sp)| BatchPass {
                id: sp.id,
                step: p.step,
                error: p.error,
                precision: sp.precision,
            })
            .collect();
        Ok(Batch {
            number: self.number,
            samples: run.samples,
            passes,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Rpro, RproSettings};

    fn rpro(course: &Course) -> Result<Box<dyn Controller>, StepError> {
        Ok(Box::new(Rpro::new(course, RproSettings::default())?))
    }

    fn stream() -> Stream {
        Stream::new(
            vec![Limits::new(1.0, 5.0, 50.0); 2],
            vec![(-1.0, 1.0); 2],
            StreamSettings::new(0.004).queue(3),
        )
        .unwrap()
    }

    fn point(id: u32, q: [f64; 2]) -> StreamPoint {
        StreamPoint {
            id,
            positions: q.to_vec(),
            precision: 1e-4,
        }
    }

    #[test]
    fn batches_run_from_rest_to_rest_through_every_point() {
        let mut s = stream();
        assert_eq!(s.push(point(0, [0.0, 0.0])).unwrap(), Pushed::Start);
        assert!(s.take_batch(&rpro).is_none());
        s.push(point(1, [0.05, 0.01])).unwrap();
        s.push(point(2, [0.1, 0.03])).unwrap();
        let b = s.take_batch(&rpro).unwrap().unwrap();
        assert_eq!(
            b.passes.iter().map(|p| p.id).collect::<Vec<_>>(),
            vec![1, 2]
        );
        assert!(b.passes.iter().all(|p| p.error <= p.precision));
        let last = b.samples.last().unwrap();
        assert!(distance(&last.position, &[0.1, 0.03]) <= 1e-4);
        assert!(last.velocity.iter().all(|v| v.abs() < 1e-12));
        // The next batch starts where this one rests.
        s.push(point(3, [0.12, 0.05])).unwrap();
        let b2 = s.take_batch(&rpro).unwrap().unwrap();
        assert_eq!(b2.number, 2);
        assert!(distance(&b2.samples[0].position, &last.position) < 1e-12);
    }

    #[test]
    fn bad_points_are_refused_and_change_nothing() {
        let mut s = stream();
        s.push(point(0, [0.0, 0.0])).unwrap();
        let cases = [
            (point(1, [f64::NAN, 0.0]), "NaN"),
            (point(2, [2.0, 0.0]), "out of reach"),
            (point(3, [0.00005, 0.0]), "repeated"),
            (point(4, [0.8, 0.0]), "jumps"),
            (
                StreamPoint {
                    id: 5,
                    positions: vec![0.1, 0.0],
                    precision: 0.0,
                },
                "precision",
            ),
            (
                StreamPoint {
                    id: 7,
                    positions: vec![0.1, 0.0],
                    precision: 5e-324,
                },
                "not denormal",
            ),
            (
                StreamPoint {
                    id: 6,
                    positions: vec![0.1],
                    precision: 1e-4,
                },
                "coordinates",
            ),
        ];
        for (p, want) in cases {
            let e = s.push(p).unwrap_err().to_string();
            assert!(e.contains(want), "{e}");
        }
        for k in 0..3 {
            s.push(point(10 + k, [0.1 * (k + 1) as f64, 0.0])).unwrap();
        }
        let e = s.push(point(20, [0.4, 0.0])).unwrap_err().to_string();
        assert!(e.contains("queue 3"), "{e}");
        assert_eq!(s.waiting(), 3);
        let b = s.take_batch(&rpro).unwrap().unwrap();
        assert_eq!(b.passes.len(), 3);
    }

    #[test]
    fn reset_forgets_the_start_and_the_queue() {
        let mut s = stream();
        s.push(point(0, [0.0, 0.0])).unwrap();
        s.push(point(1, [0.1, 0.0])).unwrap();
        assert_eq!(s.reset(), vec![1]);
        assert!(!s.started());
        assert_eq!(s.push(point(2, [0.5, 0.0])).unwrap(), Pushed::Start);
    }
}
