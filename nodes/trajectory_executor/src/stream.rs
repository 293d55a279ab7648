//! The streaming mode (issue 29, item 5): reference points on `~/reference_points`
//! (`kerf_msgs/msg/ReferencePoint`), stepped through online at the control rate within every
//! joint limit, answered point by point on `~/stream_status` (`kerf_msgs/msg/StreamStatus`).
//!
//! The rules are those of `kerf_stepping::stream` (its module documentation); this module
//! maps the messages onto it and its batches onto the executor:
//! * **Joint order.** `joint_names` empty means the robot's joint order; otherwise it names
//!   every joint once (an unknown, missing or repeated name refuses the point).
//! * **Start.** The first point of a stream is checked against the executor's commanded
//!   state by a dry run (the `ValidateTrajectory` check of a one-point trajectory due now,
//!   within `start_tolerance`): START, or REFUSED with the mismatch (and the points queued
//!   meanwhile NOT_REACHED).
//! * **Each further point** is QUEUED or REFUSED with the reason (NaN, out of a joint's
//!   range, repeated, a jump over `stream.max_jump`, `stream.queue` points already waiting:
//!   a stream faster than the robot is refused point by point, never followed faster than
//!   the limits allow).
//! * **Batches.** While no batch runs or is being planned, the waiting points become one
//!   batch, planned on the `stream` thread (points that arrive meanwhile wait): RPRO
//!   (`kerf_stepping::Rpro`, look-ahead `stream.lookahead`) steps them from rest to rest at
//!   the control period; the samples (positions, velocities, accelerations) become a
//!   `JointTrajectory` started on receipt and run through the executor's own path (validated
//!   against every limit, status `source: stream` on `~/trajectory_status`). A stream that
//!   stops ends at rest on its last point.
//! * **Reports.** When the batch succeeds, each of its points is REACHED with the distance of
//!   the sample that passed it and that sample's time. When it is aborted, canceled,
//!   preempted (by a topic trajectory or an action goal) or refused, its points are
//!   NOT_REACHED with the executor's reason and the stream is reset: the waiting points are
//!   NOT_REACHED too, and the next point must be a new start (the robot's position). A batch
//!   that cannot be planned (its path leaves a joint's range between points) reports its
//!   points NOT_REACHED and the robot stays.
//! * A topic trajectory or an action goal that starts while a stream waits resets it the same
//!   way: the robot is moved by something else.

use kerf_msgs::{
    builtin_interfaces::Duration,
    msg::{ReferencePoint, StreamStatus},
    std_msgs::Header,
    trajectory_msgs::{JointTrajectory, JointTrajectoryPoint},
};
use kerf_stepping::{
    stream::{Batch, BatchJob, BatchPass, Pushed, Stream, StreamPoint, StreamSettings},
    Controller, Course, Limits, Rpro, RproSettings, StepError,
};

use crate::{NodeConfig, NodeError};

/// How [`Streaming::push`] answered a point.
#[derive(Debug, Clone, PartialEq)]
pub enum PushOutcome {
    /// Statuses to publish now (QUEUED, REFUSED).
    Answered(Vec<StreamStatus>),
    /// A start: check this one-point trajectory against the commanded state (a dry run),
    /// then call [`Streaming::start_checked`] with the point's id.
    CheckStart {
        /// The point's id.
        id: u32,
        /// The trajectory to check.
        trajectory: JointTrajectory,
    },
}

/// The batch the executor runs.
#[derive(Debug, Clone)]
struct Running {
    number: u64,
    passes: Vec<BatchPass>,
}

/// The streaming mode's state on the request thread.
pub struct Streaming {
    stream: Stream,
    /// Joint names, model order.
    names: Vec<String>,
    /// Control period (s).
    period: f64,
    lookahead: usize,
    /// The batch handed to the executor, until it ends.
    running: Option<Running>,
    /// The id of a start waiting for its check.
    pending_start: Option<u32>,
    /// Why every point is refused (a joint without a jerk limit), if so.
    unavailable: Option<String>,
    /// The batch being planned (on the planner thread): its number and point ids.
    planning: Option<(u64, Vec<u32>)>,
    /// Counts resets: a plan made before the last reset is dropped.
    generation: u64,
}

/// A batch to plan on the planner thread, tagged with the stream's generation.
pub type PlanJob = (u64, BatchJob);

/// What the planner thread returns: the job and its result.
pub type PlanDone = (u64, BatchJob, Result<Batch, StepError>);

/// A status without stamp (the node stamps it when it publishes).
fn status(id: u32, status: u8, batch: u64, message: impl Into<String>) -> StreamStatus {
    StreamStatus {
        header: Header::default(),
        id,
        status,
        batch,
        error: 0.0,
        time_from_batch_start: 0.0,
        message: message.into(),
    }
}

impl Streaming {
    /// The streaming mode for the robot and settings of `cfg`.
    ///
    /// # Errors
    /// [`NodeError::Config`] (`stream.*`) when the stepping core refuses the limits or the
    /// settings.
    pub fn new(cfg: &NodeConfig) -> Result<Self, NodeError> {
        let joints = cfg.robot.joints();
        let mut limits = Vec::with_capacity(cfg.limits.len());
        let mut ranges = Vec::with_capacity(cfg.limits.len());
        let mut unavailable: Option<String> = None;
        for l in &cfg.limits {
            let jerk = match joints
                .iter()
                .find(|j| j.name == l.name)
                .and_then(|j| j.max_jerk)
            {
                Some(j) => j,
                None => {
                    // Never guessed: every point is refused naming the joint. The stream
                    // below is built with a stand-in that no point reaches.
                    unavailable.get_or_insert_with(|| {
                        format!(
                            "streaming needs a jerk limit for every joint; joint {} has none \
                             (max_jerk in the limits file)",
                            l.name
                        )
                    });
                    l.max_acceleration
                }
            };
            limits.push(Limits::new(l.max_velocity, l.max_acceleration, jerk));
            ranges.push((l.min_position, l.max_position));
        }
        let settings = StreamSettings::new(cfg.executor.control_period)
            .queue(cfg.stream.queue)
            .max_jump(cfg.stream.max_jump);
        let stream = Stream::new(limits, ranges, settings).map_err(|e| NodeError::Config {
            name: "stream.*".into(),
            reason: e.to_string(),
        })?;
        Ok(Self {
            stream,
            names: cfg.limits.iter().map(|l| l.name.clone()).collect(),
            period: cfg.executor.control_period,
            lookahead: cfg.stream.lookahead,
            running: None,
            pending_start: None,
            unavailable,
            planning: None,
            generation: 0,
        })
    }

    /// `msg`'s positions in the model's joint order.
    ///
    /// # Errors
    /// Why the joint names cannot be mapped (unknown, missing, repeated, count).
    fn model_order(&self, msg: &ReferencePoint) -> Result<Vec<f64>, String> {
        if msg.joint_names.is_empty() {
            return Ok(msg.positions.clone());
        }
        if msg.joint_names.len() != msg.positions.len() {
            return Err(format!(
                "{} joint names for {} positions",
                msg.joint_names.len(),
                msg.positions.len()
            ));
        }
        let mut q = vec![None; self.names.len()];
        for (name, &p) in msg.joint_names.iter().zip(&msg.positions) {
            let Some(j) = self.names.iter().position(|n| n == name) else {
                return Err(format!(
                    "unknown joint '{name}'; the robot's joints are {}",
                    self.names.join(", ")
                ));
            };
            if q[j].replace(p).is_some() {
                return Err(format!("joint '{name}' is named twice"));
            }
        }
        let missing: Vec<&str> = self
            .names
            .iter()
            .zip(&q)
            .filter(|(_, v)| v.is_none())
            .map(|(n, _)| n.as_str())
            .collect();
        if !missing.is_empty() {
            return Err(format!("joint(s) {} missing", missing.join(", ")));
        }
        Ok(q.into_iter().map(|v| v.unwrap_or(f64::NAN)).collect())
    }

    /// The reason of a refusal, joints named by name instead of number.
    fn refusal(&self, e: &StepError) -> String {
        let mut text = match e {
            StepError::InvalidPoint { reason, .. } => reason.clone(),
            other => other.to_string(),
        };
        // The core numbers joints from 1 in the model order.
        for (j, name) in self.names.iter().enumerate().rev() {
            text = text.replace(&format!("joint {} ", j + 1), &format!("{name} "));
        }
        text
    }

    /// Takes a point into the stream.
    pub fn push(&mut self, msg: &ReferencePoint) -> PushOutcome {
        let refused = |reason: String| {
            PushOutcome::Answered(vec![status(msg.id, StreamStatus::REFUSED, 0, reason)])
        };
        if let Some(reason) = &self.unavailable {
            return refused(reason.clone());
        }
        let positions = match self.model_order(msg) {
            Ok(q) => q,
            Err(reason) => return refused(reason),
        };
        let point = StreamPoint {
            id: msg.id,
            positions: positions.clone(),
            precision: msg.precision,
        };
        match self.stream.push(point) {
            Err(e) => refused(self.refusal(&e)),
            Ok(Pushed::Start) => {
                self.pending_start = Some(msg.id);
                let zeros = vec![0.0; positions.len()];
                PushOutcome::CheckStart {
                    id: msg.id,
                    trajectory: JointTrajectory {
                        header: Header::default(),
                        joint_names: self.names.clone(),
                        points: vec![JointTrajectoryPoint {
                            positions,
                            velocities: zeros.clone(),
                            accelerations: zeros,
                            effort: Vec::new(),
                            time_from_start: Duration::ZERO,
                        }],
                    },
                }
            }
            Ok(Pushed::Queued { waiting }) => PushOutcome::Answered(vec![status(
                msg.id,
                StreamStatus::QUEUED,
                0,
                format!("{waiting} point(s) waiting"),
            )]),
        }
    }

    /// The answer of the start check of point `id`: START, or REFUSED (the stream reset).
    pub fn start_checked(&mut self, id: u32, result: Result<(), String>) -> Vec<StreamStatus> {
        if self.pending_start != Some(id) {
            return Vec::new();
        }
        self.pending_start = None;
        match result {
            Ok(()) => vec![status(id, StreamStatus::START, 0, "the robot is there")],
            Err(reason) => {
                let mut out = vec![status(
                    id,
                    StreamStatus::REFUSED,
                    0,
                    format!("not where the robot is: {reason}"),
                )];
                out.extend(self.reset_waiting("the start was refused"));
                out
            }
        }
    }

    /// Whether a batch runs.
    pub fn running(&self) -> bool {
        self.running.is_some()
    }

    /// The controller factory of this stream's batches (RPRO with the configured
    /// look-ahead), for the planner thread.
    pub fn planner(&self) -> impl Fn(PlanJob) -> PlanDone + Send + Sync + 'static {
        let lookahead = self.lookahead;
        move |(generation, job): PlanJob| {
            let make = move |course: &Course| -> Result<Box<dyn Controller>, StepError> {
                Ok(Box::new(Rpro::new(
                    course,
                    RproSettings::default().lookahead_points(lookahead),
                )?))
            };
            let result = job.plan(&make);
            (generation, job, result)
        }
    }

    /// The next batch to plan, when none runs or is being planned and points wait.
    pub fn next_job(&mut self) -> Option<PlanJob> {
        if self.running.is_some() || self.pending_start.is_some() || self.planning.is_some() {
            return None;
        }
        let job = self.stream.take_job()?;
        self.planning = Some((job.number, job.ids()));
        Some((self.generation, job))
    }

    /// The planner thread's answer for a job: the batch's number and trajectory to run, and
    /// the statuses to publish (NOT_REACHED for a batch that cannot be planned, or that was
    /// planned for a stream reset meanwhile).
    pub fn planned(
        &mut self,
        done: PlanDone,
    ) -> (Option<(u64, JointTrajectory)>, Vec<StreamStatus>) {
        let (generation, job, result) = done;
        if self
            .planning
            .as_ref()
            .is_some_and(|(n, _)| *n == job.number)
        {
            self.planning = None;
        }
        let not_reached = |message: String| -> Vec<StreamStatus> {
            job.ids()
                .into_iter()
                .map(|id| status(id, StreamStatus::NOT_REACHED, job.number, message.clone()))
                .collect()
        };
        if generation != self.generation {
            return (
                None,
                not_reached("the stream was reset while its batch was planned".to_string()),
            );
        }
        self.stream.job_done(&job, &result);
        match result {
            Err(e) => (
                None,
                not_reached(format!("the batch cannot be planned: {}", self.refusal(&e))),
            ),
            Ok(batch) => {
                let trajectory = self.trajectory(&batch);
                self.running = Some(Running {
                    number: batch.number,
                    passes: batch.passes,
                });
                (Some((batch.number, trajectory)), Vec::new())
            }
        }
    }

    /// The planner thread failed on the batch being planned (it stopped): its points are
    /// NOT_REACHED and the stream is reset.
    pub fn planner_failed(&mut self, reason: &str) -> Vec<StreamStatus> {
        let Some((number, ids)) = self.planning.take() else {
            return Vec::new();
        };
        let message = format!("the batch planner failed: {reason}");
        let mut out: Vec<StreamStatus> = ids
            .into_iter()
            .map(|id| status(id, StreamStatus::NOT_REACHED, number, message.clone()))
            .collect();
        out.extend(self.reset_waiting(&message));
        out
    }

    /// [`Streaming::next_job`] planned on this thread and [`Streaming::planned`] (tests).
    pub fn next_batch(&mut self) -> (Option<(u64, JointTrajectory)>, Vec<StreamStatus>) {
        match self.next_job() {
            None => (None, Vec::new()),
            Some(job) => {
                let plan = self.planner();
                self.planned(plan(job))
            }
        }
    }

    /// The samples of `batch` as a trajectory started on receipt, one point per control
    /// period.
    fn trajectory(&self, batch: &Batch) -> JointTrajectory {
        let points = batch
            .samples
            .iter()
            .enumerate()
            .map(|(k, s)| JointTrajectoryPoint {
                positions: s.position.clone(),
                velocities: s.velocity.clone(),
                accelerations: s.acceleration.clone(),
                effort: Vec::new(),
                time_from_start: Duration::from_secs_f64(k as f64 * self.period)
                    .unwrap_or(Duration::ZERO),
            })
            .collect();
        JointTrajectory {
            header: Header::default(),
            joint_names: self.names.clone(),
            points,
        }
    }

    /// Batch `number` ended: REACHED for each of its points when it `succeeded`, else
    /// NOT_REACHED with `reason` and the stream reset.
    pub fn batch_ended(&mut self, number: u64, succeeded: bool, reason: &str) -> Vec<StreamStatus> {
        let Some(running) = self.running.take_if(|r| r.number == number) else {
            return Vec::new();
        };
        if succeeded {
            return running
                .passes
                .iter()
                .map(|p| StreamStatus {
                    error: p.error,
                    time_from_batch_start: p.step as f64 * self.period,
                    ..status(p.id, StreamStatus::REACHED, number, "")
                })
                .collect();
        }
        let message = format!("batch {number} ended: {reason}");
        let mut out: Vec<StreamStatus> = running
            .passes
            .iter()
            .map(|p| status(p.id, StreamStatus::NOT_REACHED, number, message.clone()))
            .collect();
        out.extend(self.reset_waiting(&message));
        out
    }

    /// Something else moves the robot (a topic trajectory or an action goal starts): the
    /// stream is reset unless it has no start.
    pub fn robot_moved_by_other(&mut self, what: &str) -> Vec<StreamStatus> {
        if !self.stream.started() || self.running.is_some() {
            return Vec::new();
        }
        self.pending_start = None;
        self.reset_waiting(&format!("{what} moves the robot"))
    }

    /// Resets the stream: NOT_REACHED for the points that were waiting (a batch being
    /// planned is dropped when its plan arrives).
    fn reset_waiting(&mut self, why: &str) -> Vec<StreamStatus> {
        self.generation += 1;
        let message =
            format!("stream reset: {why}; send the robot's position to start a new stream");
        self.stream
            .reset()
            .into_iter()
            .map(|id| status(id, StreamStatus::NOT_REACHED, 0, message.clone()))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kerf_ros::Params;

    fn config(extra: &[(&str, &str)]) -> NodeConfig {
        let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../urdf");
        let mut words = vec![
            format!("urdf_file:={root}/irb6660.urdf"),
            format!("joint_limits_file:={root}/irb6660_limits.yaml"),
        ];
        words.extend(extra.iter().map(|(k, v)| format!("{k}:={v}")));
        let words: Vec<&str> = words.iter().map(String::as_str).collect();
        let params =
            Params::from_assignments(crate::DEFAULT_NAME, crate::KNOWN_PARAMS, &words).unwrap();
        NodeConfig::from_params(&params).unwrap()
    }

    fn point(id: u32, q: [f64; 6]) -> ReferencePoint {
        ReferencePoint {
            id,
            positions: q.to_vec(),
            precision: 1e-4,
            ..Default::default()
        }
    }

    fn answered(o: PushOutcome) -> Vec<StreamStatus> {
        match o {
            PushOutcome::Answered(v) => v,
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn a_stream_starts_queues_batches_and_reports() {
        let mut s = Streaming::new(&config(&[])).unwrap();
        let PushOutcome::CheckStart { id, trajectory } = s.push(&point(0, [0.0; 6])) else {
            panic!("a start");
        };
        assert_eq!(trajectory.points.len(), 1);
        let q = answered(s.push(&point(1, [0.05, 0.0, 0.0, 0.0, 0.0, 0.0])));
        assert_eq!(q[0].status, StreamStatus::QUEUED);
        // No batch before the start is checked.
        assert!(s.next_batch().0.is_none());
        let st = s.start_checked(id, Ok(()));
        assert_eq!(st[0].status, StreamStatus::START);
        let (batch, out) = s.next_batch();
        assert!(out.is_empty());
        let (number, traj) = batch.unwrap();
        assert_eq!(number, 1);
        assert!(traj.points.len() > 2);
        assert_eq!(traj.points[0].positions, vec![0.0; 6]);
        assert!(s.running());
        let reached = s.batch_ended(1, true, "");
        assert_eq!(reached.len(), 1);
        assert_eq!(reached[0].status, StreamStatus::REACHED);
        assert!(reached[0].error <= 1e-4, "{:?}", reached[0]);
        assert!(reached[0].time_from_batch_start > 0.0);
        // A failed batch resets the stream.
        answered(s.push(&point(2, [0.1, 0.0, 0.0, 0.0, 0.0, 0.0])));
        let (batch, _) = s.next_batch();
        let (number, _) = batch.unwrap();
        answered(s.push(&point(3, [0.15, 0.0, 0.0, 0.0, 0.0, 0.0])));
        let out = s.batch_ended(number, false, "ABORTED: test");
        assert_eq!(out.len(), 2);
        assert!(out.iter().all(|o| o.status == StreamStatus::NOT_REACHED));
        assert!(
            out[1].message.contains("stream reset"),
            "{}",
            out[1].message
        );
        assert!(matches!(
            s.push(&point(4, [0.0; 6])),
            PushOutcome::CheckStart { .. }
        ));
    }

    #[test]
    fn joint_names_map_to_the_model_order_or_refuse() {
        let mut s = Streaming::new(&config(&[])).unwrap();
        let mut p = point(0, [0.0, 0.1, 0.2, 0.3, 0.4, 0.5]);
        p.joint_names = [
            "joint_6", "joint_5", "joint_4", "joint_3", "joint_2", "joint_1",
        ]
        .map(String::from)
        .to_vec();
        assert_eq!(
            s.model_order(&p).unwrap(),
            vec![0.5, 0.4, 0.3, 0.2, 0.1, 0.0]
        );
        for (names, want) in [
            (vec!["joint_1"; 6], "named twice"),
            (
                vec!["x", "joint_2", "joint_3", "joint_4", "joint_5", "joint_6"],
                "unknown joint 'x'",
            ),
            (vec!["joint_1"], "1 joint names for 6 positions"),
        ] {
            p.joint_names = names.into_iter().map(String::from).collect();
            let out = answered(s.push(&p));
            assert_eq!(out[0].status, StreamStatus::REFUSED);
            assert!(out[0].message.contains(want), "{}", out[0].message);
        }
        // Refusals name the joint.
        let PushOutcome::CheckStart { id, .. } = s.push(&point(1, [0.0; 6])) else {
            panic!("a start");
        };
        s.start_checked(id, Ok(()));
        let out = answered(s.push(&point(2, [0.0, 0.0, 0.9, 0.0, 0.0, 0.0])));
        assert!(
            out[0].message.contains("joint_3 jumps"),
            "{}",
            out[0].message
        );
        // A refused start resets.
        let mut s = Streaming::new(&config(&[("stream.queue", "2")])).unwrap();
        s.push(&point(5, [0.0; 6]));
        answered(s.push(&point(6, [0.1, 0.0, 0.0, 0.0, 0.0, 0.0])));
        let out = s.start_checked(5, Err("start mismatch".into()));
        assert_eq!(out.len(), 2);
        assert_eq!(out[0].status, StreamStatus::REFUSED);
        assert_eq!(out[1].status, StreamStatus::NOT_REACHED);
    }
}
