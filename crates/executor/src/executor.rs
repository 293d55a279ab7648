//! The executor state machine: one active goal, preemption, cancel, tolerance monitoring.

use std::fmt;

use crate::error::ExecutorError;
use crate::stop::StopProfile;
use crate::tolerance::{self, ResolvedTolerances, Violation};
use crate::trajectory::ValidatedTrajectory;
use crate::types::{check_limits, ExecutorConfig, GoalTolerances, JointLimits, JointSample};
use crate::validate::{prepare, validate, PreparedTrajectory};
use crate::TrajectoryRequest;

/// Identifier of an accepted goal, unique per [`Executor`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct GoalId(pub u64);

impl fmt::Display for GoalId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)
    }
}

/// How a goal ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// Reached the goal tolerances after the trajectory end.
    Succeeded,
    /// Ended by a tolerance violation; the motion was brought to a controlled stop.
    Aborted {
        /// `control_msgs/FollowJointTrajectory` result code.
        error_code: i32,
        /// What was violated: joint, quantity, error, tolerance, time.
        message: String,
    },
    /// Replaced by a newer goal, which continues from the commanded state.
    Preempted,
    /// Canceled; the motion was brought to a controlled stop.
    Canceled,
}

/// The end of a goal, reported by [`Executor::update`].
#[derive(Debug, Clone, PartialEq)]
pub struct GoalEvent {
    /// The goal.
    pub id: GoalId,
    /// How it ended.
    pub outcome: Outcome,
}

/// Feedback for the active goal (`control_msgs/FollowJointTrajectory` feedback: the desired
/// state is [`Cycle::reference`], the error [`Cycle::error`], the actual state the measured
/// sample passed to [`Executor::update`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Feedback {
    /// The active goal.
    pub id: GoalId,
    /// Time since the goal's start time (s), `desired.time_from_start`; negative before it.
    pub time_from_start: f64,
}

/// Result of one control cycle.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Cycle {
    /// Time of the cycle (s).
    pub time: f64,
    /// Commanded positions, velocities and accelerations, model order.
    pub reference: JointSample,
    /// Reference − measured; velocities/accelerations empty where not measured.
    pub error: JointSample,
    /// Feedback for the goal still active after this cycle.
    pub feedback: Option<Feedback>,
    /// Goals that ended since the previous cycle, in order.
    pub events: Vec<GoalEvent>,
}

/// What generates the reference.
#[derive(Debug, Clone)]
enum Motion {
    /// At rest at these positions.
    Hold(Vec<f64>),
    /// A validated trajectory (then holding its end).
    Trajectory(ValidatedTrajectory),
    /// A controlled stop (then holding).
    Stop(StopProfile),
}

impl Motion {
    fn sample_into(&self, t: f64, out: &mut JointSample) {
        match self {
            Motion::Hold(p) => {
                out.resize_full(p.len());
                out.positions.copy_from_slice(p);
                out.velocities.fill(0.0);
                out.accelerations.fill(0.0);
            }
            Motion::Trajectory(traj) => traj.sample_into(t, out),
            Motion::Stop(stop) => stop.sample_into(t, out),
        }
    }
}

#[derive(Debug, Clone)]
struct ActiveGoal {
    id: GoalId,
    tolerances: ResolvedTolerances,
    start_time: f64,
    end_time: f64,
}

/// The trajectory executor, ROS-free: call [`Executor::update`] once per control period.
///
/// Holds one motion (hold, trajectory or controlled stop) and at most one active goal. A
/// newly accepted goal preempts the active one and starts from the current commanded state
/// (JTC with `interpolate_from_desired_state`), so the reference stays continuous.
#[derive(Debug, Clone)]
pub struct Executor {
    limits: Vec<JointLimits>,
    cfg: ExecutorConfig,
    motion: Motion,
    commanded: JointSample,
    last_update: f64,
    active: Option<ActiveGoal>,
    next_id: u64,
    pending: Vec<GoalEvent>,
    /// Replaced trajectories kept for the caller to drop, when drops are deferred.
    retired: Option<Vec<ValidatedTrajectory>>,
}

impl Executor {
    /// Creates an executor holding `initial_positions`.
    ///
    /// # Arguments
    /// * `limits` — the robot model, defining the model joint order.
    /// * `cfg` — configuration, checked against the model.
    /// * `initial_positions` — one finite position per joint, within the position limits.
    ///
    /// # Returns
    /// The executor, or the first invalid limit, configuration value or position.
    pub fn new(
        limits: Vec<JointLimits>,
        cfg: ExecutorConfig,
        initial_positions: Vec<f64>,
    ) -> Result<Self, ExecutorError> {
        check_limits(&limits)?;
        cfg.check(&limits)?;
        let initial = JointSample::at_rest(initial_positions);
        initial.check("initial positions", &limits, true)?;
        initial.check_in_limits("initial positions", &limits)?;
        Ok(Self {
            limits,
            cfg,
            motion: Motion::Hold(initial.positions.clone()),
            commanded: initial,
            last_update: f64::NEG_INFINITY,
            active: None,
            next_id: 1,
            pending: Vec::new(),
            retired: None,
        })
    }

    /// From now on, trajectories replaced by a new goal, a cancel or an abort are kept for
    /// [`Executor::take_retired`] instead of being dropped inside the call that replaced them.
    ///
    /// Dropping the last holder of a large trajectory frees its segments (O(points)); a
    /// real-time loop takes them with [`Executor::take_retired`] and drops them on another
    /// thread, so that no call on the control thread costs more than O(joints).
    pub fn defer_drops(&mut self) {
        if self.retired.is_none() {
            self.retired = Some(Vec::with_capacity(4));
        }
    }

    /// The next trajectory replaced since the last call, when drops are deferred
    /// ([`Executor::defer_drops`]); `None` otherwise or when there is none.
    pub fn take_retired(&mut self) -> Option<ValidatedTrajectory> {
        self.retired.as_mut().and_then(Vec::pop)
    }

    /// Makes `motion` current; the replaced trajectory is kept for [`Executor::take_retired`]
    /// when drops are deferred.
    fn replace_motion(&mut self, motion: Motion) {
        let old = std::mem::replace(&mut self.motion, motion);
        if let (Motion::Trajectory(traj), Some(retired)) = (old, self.retired.as_mut()) {
            retired.push(traj);
        }
    }

    /// The robot model.
    pub fn limits(&self) -> &[JointLimits] {
        &self.limits
    }

    /// The configuration.
    pub fn config(&self) -> &ExecutorConfig {
        &self.cfg
    }

    /// The reference of the last cycle (the initial hold before the first).
    pub fn commanded(&self) -> &JointSample {
        &self.commanded
    }

    /// The active goal, if any.
    pub fn active_goal(&self) -> Option<GoalId> {
        self.active.as_ref().map(|g| g.id)
    }

    /// Whether the reference is moving: a trajectory before its end, or a stop in progress.
    pub fn is_moving(&self, t: f64) -> bool {
        match &self.motion {
            Motion::Hold(_) => false,
            Motion::Trajectory(traj) => t < traj.end_time(),
            Motion::Stop(stop) => t < stop.end_time(),
        }
    }

    /// Time used for requests at `now`: never before the last update, so the reference
    /// stays monotone in time.
    fn request_time(&self, what: &'static str, now: f64) -> Result<f64, ExecutorError> {
        if !now.is_finite() {
            return Err(ExecutorError::NonFiniteTime { what, value: now });
        }
        Ok(now.max(self.last_update))
    }

    /// The commanded state at `t`.
    fn commanded_at(&self, t: f64) -> JointSample {
        let mut s = JointSample::default();
        self.motion.sample_into(t, &mut s);
        s
    }

    /// Dry run: validates `req` as [`Executor::submit`] would, without changing anything.
    ///
    /// # Returns
    /// The trajectory that would run, or why it would be rejected.
    pub fn validate(
        &self,
        req: &TrajectoryRequest,
        tolerances: &GoalTolerances,
        now: f64,
    ) -> Result<ValidatedTrajectory, ExecutorError> {
        let t = self.request_time("now", now)?;
        tolerance::resolve(&self.limits, &self.cfg, tolerances)?;
        validate(&self.limits, &self.cfg, req, &self.commanded_at(t), t)
    }

    /// Dry run of [`Executor::submit_prepared`]: finishes `prepared` against the commanded
    /// state at `now` without changing anything.
    pub fn validate_prepared(
        &self,
        prepared: &PreparedTrajectory,
        tolerances: &GoalTolerances,
        now: f64,
    ) -> Result<ValidatedTrajectory, ExecutorError> {
        let t = self.request_time("now", now)?;
        tolerance::resolve(&self.limits, &self.cfg, tolerances)?;
        prepared.finish(&self.limits, &self.cfg, &self.commanded_at(t), t)
    }

    /// Validates and, if valid, starts a goal, preempting the active one (JTC).
    ///
    /// The trajectory starts from the commanded state at `max(now, last update)`. The
    /// preempted goal's [`Outcome::Preempted`] is reported by the next [`Executor::update`].
    ///
    /// # Returns
    /// The new goal's id, or the rejection; a rejected goal changes nothing.
    ///
    /// # Performance
    /// Dominated by [`prepare`] (O(points · joints)); a control loop that must not stall
    /// prepares on another thread and calls [`Executor::submit_prepared`].
    pub fn submit(
        &mut self,
        req: &TrajectoryRequest,
        tolerances: &GoalTolerances,
        now: f64,
    ) -> Result<GoalId, ExecutorError> {
        let t = self.request_time("now", now)?;
        let resolved = tolerance::resolve(&self.limits, &self.cfg, tolerances)?;
        let prepared = prepare(&self.limits, &self.cfg, req)?;
        self.start(&prepared, resolved, t)
    }

    /// As [`Executor::submit`], for a trajectory already checked by [`prepare`] against this
    /// executor's limits and configuration: only the start (state- and clock-dependent part)
    /// is validated here.
    ///
    /// # Performance
    /// O(joints): the prepared segments are shared, not copied. The replaced trajectory is
    /// dropped here unless drops are deferred ([`Executor::defer_drops`]).
    pub fn submit_prepared(
        &mut self,
        prepared: &PreparedTrajectory,
        tolerances: &GoalTolerances,
        now: f64,
    ) -> Result<GoalId, ExecutorError> {
        let t = self.request_time("now", now)?;
        let resolved = tolerance::resolve(&self.limits, &self.cfg, tolerances)?;
        self.start(prepared, resolved, t)
    }

    /// Finishes `prepared` against the commanded state at `t` and makes it the active goal,
    /// preempting the previous one.
    fn start(
        &mut self,
        prepared: &PreparedTrajectory,
        tolerances: ResolvedTolerances,
        t: f64,
    ) -> Result<GoalId, ExecutorError> {
        let traj = prepared.finish(&self.limits, &self.cfg, &self.commanded_at(t), t)?;
        if let Some(old) = self.active.take() {
            self.pending.push(GoalEvent {
                id: old.id,
                outcome: Outcome::Preempted,
            });
        }
        let id = GoalId(self.next_id);
        self.next_id += 1;
        self.active = Some(ActiveGoal {
            id,
            tolerances,
            start_time: traj.start_time(),
            end_time: traj.end_time(),
        });
        self.replace_motion(Motion::Trajectory(traj));
        Ok(id)
    }

    /// Cancels the active goal `id` with a controlled stop (see [`StopProfile`]).
    ///
    /// [`Outcome::Canceled`] is reported by the next [`Executor::update`].
    ///
    /// # Returns
    /// `Err(UnknownGoal)` when `id` is not the active goal.
    pub fn cancel(&mut self, id: GoalId, now: f64) -> Result<(), ExecutorError> {
        let t = self.request_time("now", now)?;
        match &self.active {
            Some(goal) if goal.id == id => {}
            _ => return Err(ExecutorError::UnknownGoal { id: id.0 }),
        }
        self.active = None;
        self.start_stop(t);
        self.pending.push(GoalEvent {
            id,
            outcome: Outcome::Canceled,
        });
        Ok(())
    }

    /// A fault found outside the executor (e.g. a contact reported by a simulated cell):
    /// brings a moving reference to a controlled stop (see [`StopProfile`]; a stop already in
    /// progress continues) and aborts the active goal, if any, with `error_code` and
    /// `message`.
    ///
    /// [`Outcome::Aborted`] is reported by the next [`Executor::update`], as for a path
    /// tolerance violation.
    ///
    /// # Returns
    /// The aborted goal, if one was active.
    pub fn fault(
        &mut self,
        now: f64,
        error_code: i32,
        message: String,
    ) -> Result<Option<GoalId>, ExecutorError> {
        let t = self.request_time("now", now)?;
        if matches!(self.motion, Motion::Trajectory(_)) && self.is_moving(t) {
            self.start_stop(t);
        }
        let Some(goal) = self.active.take() else {
            return Ok(None);
        };
        self.pending.push(GoalEvent {
            id: goal.id,
            outcome: Outcome::Aborted {
                error_code,
                message,
            },
        });
        Ok(Some(goal.id))
    }

    /// Makes the robot's measured state the hold: at rest at `positions` from `now` on.
    ///
    /// A real robot's driver reports where the robot is (issue 27): before its first state
    /// the executor holds a placeholder, and after a driver fault (stale or bad feedback, a
    /// restarted driver) the commanded and the measured positions may differ. Starting the
    /// next goal from the commanded state would then command a jump; re-synchronizing while
    /// the robot is at rest starts it from where it is (JTC likewise sets its hold position
    /// from the measured state on activation).
    ///
    /// # Errors
    /// [`ExecutorError::HoldWhileMoving`] while a goal is active or the reference moves (a
    /// stop in progress); [`ExecutorError::NonFiniteTime`] for a non-finite `now`;
    /// [`ExecutorError::StateLength`], [`ExecutorError::NonFiniteState`] or
    /// [`ExecutorError::StateOutOfLimits`] for positions that are not one finite value per
    /// joint within its limits. Nothing changes on an error.
    pub fn hold_at(&mut self, now: f64, positions: &[f64]) -> Result<(), ExecutorError> {
        let t = self.request_time("now", now)?;
        if self.active.is_some() || self.is_moving(t) {
            return Err(ExecutorError::HoldWhileMoving { time: t });
        }
        let state = JointSample::at_rest(positions.to_vec());
        state.check("measured state", &self.limits, true)?;
        state.check_in_limits("measured state", &self.limits)?;
        self.replace_motion(Motion::Hold(state.positions.clone()));
        self.commanded = state;
        Ok(())
    }

    fn start_stop(&mut self, t: f64) {
        let state = self.commanded_at(t);
        self.replace_motion(Motion::Stop(StopProfile::new(&self.limits, &state, t)));
    }

    /// One control cycle: see [`Executor::update_into`].
    ///
    /// # Performance
    /// Allocates the [`Cycle`]; use [`Executor::update_into`] with a reused `Cycle` in a
    /// real-time loop.
    pub fn update(&mut self, now: f64, measured: &JointSample) -> Result<Cycle, ExecutorError> {
        let mut cycle = Cycle::default();
        self.update_into(now, measured, &mut cycle)?;
        Ok(cycle)
    }

    /// One control cycle at time `now` with the `measured` state (model order).
    ///
    /// Samples the reference, computes the error, checks the active goal's path tolerances
    /// while `now` is before the trajectory end (violation: abort with
    /// PATH_TOLERANCE_VIOLATED and a controlled stop) and its goal tolerances from the end on
    /// (success, or abort with GOAL_TOLERANCE_VIOLATED once `goal_time` has elapsed, if it is
    /// not 0).
    ///
    /// # Returns
    /// `Err` without any change when `now` is not finite or earlier than the previous update,
    /// or `measured` has wrong lengths or non-finite values (the caller should treat that as a
    /// hardware fault).
    ///
    /// # Performance
    /// O(joints) plus amortized O(1) segment lookup; no allocation once `out` has capacity,
    /// except for messages of ending goals.
    pub fn update_into(
        &mut self,
        now: f64,
        measured: &JointSample,
        out: &mut Cycle,
    ) -> Result<(), ExecutorError> {
        if !now.is_finite() {
            return Err(ExecutorError::NonFiniteTime {
                what: "update time",
                value: now,
            });
        }
        if now < self.last_update {
            return Err(ExecutorError::TimeWentBackwards {
                now,
                last: self.last_update,
            });
        }
        measured.check("measured state", &self.limits, false)?;

        out.time = now;
        out.events.clear();
        out.events.append(&mut self.pending);
        out.feedback = None;
        self.motion.sample_into(now, &mut out.reference);
        compute_error(&out.reference, measured, &mut out.error);

        if let Some(goal) = &self.active {
            let id = goal.id;
            if now < goal.end_time {
                let violation = tolerance::check(
                    &goal.tolerances.path,
                    &out.error.positions,
                    &out.error.velocities,
                    &out.error.accelerations,
                );
                if let Some(v) = violation {
                    let err = self.path_error(v, now);
                    self.finish(out, id, err);
                    self.start_stop(now);
                    self.motion.sample_into(now, &mut out.reference);
                    compute_error(&out.reference, measured, &mut out.error);
                } else {
                    out.feedback = Some(Feedback {
                        id,
                        time_from_start: now - goal.start_time,
                    });
                }
            } else {
                let violation = tolerance::check(
                    &goal.tolerances.goal,
                    &out.error.positions,
                    &out.error.velocities,
                    &out.error.accelerations,
                );
                match violation {
                    None => {
                        self.active = None;
                        out.events.push(GoalEvent {
                            id,
                            outcome: Outcome::Succeeded,
                        });
                    }
                    Some(v)
                        if goal.tolerances.goal_time > 0.0
                            && now > goal.end_time + goal.tolerances.goal_time =>
                    {
                        let err = ExecutorError::GoalToleranceViolated {
                            joint: self.limits[v.joint].name.clone(),
                            quantity: v.quantity,
                            error: v.error,
                            tolerance: v.tolerance,
                            time: now,
                            end_time: goal.end_time,
                            goal_time: goal.tolerances.goal_time,
                        };
                        // The reference already holds the end at rest (JTC: hold position).
                        self.finish(out, id, err);
                    }
                    Some(_) => {
                        out.feedback = Some(Feedback {
                            id,
                            time_from_start: now - goal.start_time,
                        });
                    }
                }
            }
        }
        self.commanded.clone_from(&out.reference);
        self.last_update = now;
        if let Motion::Stop(stop) = &self.motion {
            if now >= stop.end_time() {
                self.motion = Motion::Hold(stop.final_positions());
            }
        }
        Ok(())
    }

    fn path_error(&self, v: Violation, now: f64) -> ExecutorError {
        ExecutorError::PathToleranceViolated {
            joint: self.limits[v.joint].name.clone(),
            quantity: v.quantity,
            error: v.error,
            tolerance: v.tolerance,
            time: now,
        }
    }

    fn finish(&mut self, out: &mut Cycle, id: GoalId, err: ExecutorError) {
        self.active = None;
        out.events.push(GoalEvent {
            id,
            outcome: Outcome::Aborted {
                error_code: err.error_code(),
                message: err.to_string(),
            },
        });
    }
}

/// `error = reference − measured`, velocity/acceleration only where measured.
fn compute_error(reference: &JointSample, measured: &JointSample, error: &mut JointSample) {
    let diff = |r: &[f64], m: &[f64], e: &mut Vec<f64>| {
        e.clear();
        if !m.is_empty() {
            e.extend(r.iter().zip(m).map(|(r, m)| r - m));
        }
    };
    diff(
        &reference.positions,
        &measured.positions,
        &mut error.positions,
    );
    diff(
        &reference.velocities,
        &measured.velocities,
        &mut error.velocities,
    );
    diff(
        &reference.accelerations,
        &measured.accelerations,
        &mut error.accelerations,
    );
}
