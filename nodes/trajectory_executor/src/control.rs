//! The control thread: read → update → write every control period, and nothing else.
//!
//! The thread owns the executor core and the (mock) hardware. It never touches DDS except
//! through [`Streamer`] queues, never deserializes, validates, copies or frees anything whose
//! size depends on a trajectory, and never blocks:
//! * requests arrive as [`Command`]s already prepared by the preparation worker
//!   (`kerf_executor::prepare`, O(points · joints)); a command is moved in and finished against
//!   the commanded state in O(joints) (the prepared segments are shared, not copied);
//! * the time of a cycle is taken after the hand-over, so the start of a new trajectory and
//!   the cycle that first samples it use the same clock reading;
//! * prepared trajectories after use, and trajectories the executor replaced, go back to the
//!   node's request thread as [`Report::Trash`] and are freed there
//!   ([`Executor::defer_drops`]);
//! * answers, goal ends, feedback and log lines go back as [`Report`]s on an unbounded
//!   channel (a send never blocks).

use std::{
    sync::{
        atomic::{AtomicBool, Ordering},
        mpsc::{Receiver, Sender, TryRecvError},
        Arc,
    },
    time::{Duration as StdDuration, Instant},
};

use kerf_executor::{
    Cycle, Executor, GoalId as ExecGoalId, GoalTolerances, JointLimits, JointSample, MockHardware,
    Outcome, PreparedTrajectory, ValidatedTrajectory,
};
use kerf_msgs::{
    control_msgs::{FollowJointTrajectoryFeedback, JointTrajectoryControllerState},
    sensor_msgs::JointState,
    std_msgs::Header,
};
use kerf_ros::{LogLevel, Streamer};

use crate::convert::{self, Clock, Rejection};

/// Commands the control thread takes in one cycle at most; the rest wait for the next cycle,
/// so a burst of requests costs at most this many O(joints) hand-overs per cycle.
pub const MAX_COMMANDS_PER_CYCLE: usize = 8;

/// A request for the control thread, already prepared off it.
pub enum Command {
    /// Start a trajectory (topic trajectory or action goal), preempting the active one.
    Start {
        /// The request's ticket.
        tag: u64,
        /// The prepared trajectory.
        prepared: PreparedTrajectory,
        /// The goal's tolerances.
        tolerances: GoalTolerances,
    },
    /// Dry run of a start (ValidateTrajectory).
    Validate {
        /// The request's ticket.
        tag: u64,
        /// The prepared trajectory.
        prepared: PreparedTrajectory,
        /// The tolerances to check.
        tolerances: GoalTolerances,
    },
    /// Cancel the goal started by the request `tag`, if it is still active.
    Cancel {
        /// Ticket of the goal's request.
        tag: u64,
    },
    /// An empty topic trajectory: stop the active motion.
    Stop {
        /// The request's ticket.
        tag: u64,
    },
}

/// Something the trajectory's size makes expensive to free: freed by the request thread.
// The fields are never read: they exist to be dropped off the control thread.
#[allow(dead_code)]
pub enum Trash {
    /// A prepared trajectory after its start or dry run.
    Prepared(PreparedTrajectory),
    /// A trajectory the executor replaced.
    Trajectory(ValidatedTrajectory),
}

/// What the control thread tells the request thread.
pub enum Report {
    /// The request `tag` started as executor goal `exec_id`.
    Started {
        /// The request's ticket.
        tag: u64,
        /// The executor goal.
        exec_id: ExecGoalId,
        /// Waypoints.
        points: usize,
        /// `time_from_start` of the last point (s).
        duration: f64,
    },
    /// The request `tag` could not start from the current state.
    Refused {
        /// The request's ticket.
        tag: u64,
        /// Why.
        rejection: Rejection,
    },
    /// The dry run of request `tag`: the duration of the trajectory, or why it would be
    /// refused.
    Validated {
        /// The request's ticket.
        tag: u64,
        /// Duration (s) or rejection.
        result: Result<f64, Rejection>,
    },
    /// The empty trajectory `tag` was handled: what it did.
    Stopping {
        /// The request's ticket.
        tag: u64,
        /// What happened.
        message: String,
    },
    /// An executor goal ended.
    Finished {
        /// The goal.
        exec_id: ExecGoalId,
        /// How.
        outcome: Outcome,
    },
    /// Action feedback for the active goal (sent at the action monitor rate).
    Feedback {
        /// The goal.
        exec_id: ExecGoalId,
        /// The feedback message.
        feedback: Box<FollowJointTrajectoryFeedback>,
    },
    /// A line for the node's log.
    Log {
        /// Level.
        level: LogLevel,
        /// Text.
        message: String,
    },
    /// Free this off the control thread.
    Trash(Trash),
}

/// Queues `msg` on `stream` without blocking; a dropped sample (full queue: a subscriber is
/// not keeping up) is counted in `failures`, shared by the streams of a thread.
///
/// # Returns
/// The warning to log when the count reaches a power of two, so that a persistent slow
/// subscriber does not flood the log.
pub fn publish_counted<M: serde::Serialize + Send + 'static>(
    stream: &Streamer<M>,
    msg: M,
    failures: &mut u64,
    what: &str,
) -> Option<String> {
    if stream.publish(msg) {
        return None;
    }
    *failures += 1;
    failures.is_power_of_two().then(|| {
        format!("{what}: sample dropped, a subscriber is not keeping up ({failures} drops so far)")
    })
}

/// The published state streams of the control thread.
pub struct Streams {
    /// `joint_states`.
    pub joint_states: Streamer<JointState>,
    /// `~/controller_state`.
    pub controller_state: Streamer<JointTrajectoryControllerState>,
    /// `~/joint_command`.
    pub command: Streamer<JointState>,
}

/// Settings of the control loop.
pub struct LoopConfig {
    /// The robot model.
    pub limits: Vec<JointLimits>,
    /// Control rate (Hz).
    pub control_rate: f64,
    /// Action feedback rate (Hz).
    pub action_monitor_rate: f64,
    /// Control period (s), as the executor's configuration.
    pub control_period: f64,
}

/// The control loop's state; [`ControlLoop::run`] runs it on the calling thread.
pub struct ControlLoop {
    exec: Executor,
    hw: MockHardware,
    cfg: LoopConfig,
    names: Vec<String>,
    streams: Streams,
    commands: Receiver<Command>,
    reports: Sender<Report>,
    running: Arc<AtomicBool>,
    clock: Clock,
    cycle: Cycle,
    batch: Vec<Command>,
    /// The request ticket of the active goal and its executor id.
    active: Option<(u64, ExecGoalId)>,
    next_feedback: f64,
    publish_failures: u64,
    cycle_failures: u64,
}

impl ControlLoop {
    /// A loop around `exec` and `hw`; it runs while `running` is set and the command channel
    /// is open.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        mut exec: Executor,
        hw: MockHardware,
        cfg: LoopConfig,
        streams: Streams,
        commands: Receiver<Command>,
        reports: Sender<Report>,
        running: Arc<AtomicBool>,
        clock: Clock,
    ) -> Self {
        exec.defer_drops();
        let names = cfg.limits.iter().map(|l| l.name.clone()).collect();
        Self {
            exec,
            hw,
            cfg,
            names,
            streams,
            commands,
            reports,
            running,
            clock,
            cycle: Cycle::default(),
            batch: Vec::with_capacity(MAX_COMMANDS_PER_CYCLE),
            active: None,
            next_feedback: 0.0,
            publish_failures: 0,
            cycle_failures: 0,
        }
    }

    fn report(&self, r: Report) {
        // The request thread outlives this loop; if it is gone there is nobody to tell.
        let _ = self.reports.send(r);
    }

    fn log(&self, level: LogLevel, message: String) {
        self.report(Report::Log { level, message });
    }

    /// Runs until `running` is cleared or the command channel closes.
    pub fn run(&mut self) {
        let period = StdDuration::from_secs_f64(1.0 / self.cfg.control_rate);
        let mut next = Instant::now();
        let mut overruns = 0u64;
        while self.running.load(Ordering::Relaxed) {
            // Hand-over: moves only.
            let mut open = true;
            while self.batch.len() < MAX_COMMANDS_PER_CYCLE {
                match self.commands.try_recv() {
                    Ok(c) => self.batch.push(c),
                    Err(TryRecvError::Empty) => break,
                    Err(TryRecvError::Disconnected) => {
                        open = false;
                        break;
                    }
                }
            }
            // The cycle's time, after the hand-over.
            let now = self.clock.now();
            let mut batch = std::mem::take(&mut self.batch);
            for c in batch.drain(..) {
                self.apply(c, now);
            }
            self.batch = batch;
            self.control_cycle(now);
            while let Some(t) = self.exec.take_retired() {
                self.report(Report::Trash(Trash::Trajectory(t)));
            }
            if !open {
                break;
            }
            next += period;
            let after = Instant::now();
            if next > after {
                std::thread::sleep(next - after);
            } else if after - next > period * 10 {
                overruns += 1;
                if overruns.is_power_of_two() {
                    self.log(
                        LogLevel::Warn,
                        format!(
                            "control loop fell {:.1} ms behind; skipping ahead ({overruns} times so far)",
                            (after - next).as_secs_f64() * 1e3
                        ),
                    );
                }
                next = after;
            }
        }
    }

    /// Applies one command at the cycle time `now`, in O(joints).
    fn apply(&mut self, command: Command, now: f64) {
        match command {
            Command::Start {
                tag,
                prepared,
                tolerances,
            } => {
                let (points, duration) = (prepared.point_count(), prepared.duration());
                let started = self.exec.submit_prepared(&prepared, &tolerances, now);
                self.report(Report::Trash(Trash::Prepared(prepared)));
                match started {
                    Ok(exec_id) => {
                        self.active = Some((tag, exec_id));
                        self.report(Report::Started {
                            tag,
                            exec_id,
                            points,
                            duration,
                        });
                    }
                    Err(e) => self.report(Report::Refused {
                        tag,
                        rejection: e.into(),
                    }),
                }
            }
            Command::Validate {
                tag,
                prepared,
                tolerances,
            } => {
                let checked = self.exec.validate_prepared(&prepared, &tolerances, now);
                // The dry-run trajectory shares the prepared segments: drop it before them.
                let result = checked.map(|t| t.duration()).map_err(Rejection::from);
                self.report(Report::Trash(Trash::Prepared(prepared)));
                self.report(Report::Validated { tag, result });
            }
            Command::Cancel { tag } => match self.active {
                Some((t, id)) if t == tag && self.exec.active_goal() == Some(id) => {
                    if let Err(e) = self.exec.cancel(id, now) {
                        self.log(LogLevel::Warn, format!("cancel of goal {id}: {e}"));
                    }
                }
                // Ended already (its end is reported), or refused at its start.
                _ => {}
            },
            Command::Stop { tag } => {
                let message = match self.exec.active_goal() {
                    Some(id) => match self.exec.cancel(id, now) {
                        Ok(()) => "empty trajectory: stopping the current motion".to_string(),
                        Err(e) => format!("empty trajectory: {e}"),
                    },
                    None => "empty trajectory: no active motion to stop".to_string(),
                };
                self.report(Report::Stopping { tag, message });
            }
        }
    }

    /// Queues `msg` on `stream`; a dropped sample is counted and logged (through a report) at
    /// powers of two.
    fn publish<M: serde::Serialize + Send + 'static>(
        stream: &Streamer<M>,
        msg: M,
        failures: &mut u64,
        reports: &Sender<Report>,
        what: &str,
    ) {
        if let Some(message) = publish_counted(stream, msg, failures, what) {
            let _ = reports.send(Report::Log {
                level: LogLevel::Warn,
                message,
            });
        }
    }

    /// Read → update → write at `now`, then the state streams, goal ends and feedback.
    fn control_cycle(&mut self, now: f64) {
        let measured = self.hw.state().clone();
        let mut cycle = std::mem::take(&mut self.cycle);
        if let Err(e) = self.exec.update_into(now, &measured, &mut cycle) {
            self.cycle_failures += 1;
            if self.cycle_failures.is_power_of_two() {
                self.log(
                    LogLevel::Error,
                    format!(
                        "control cycle failed: {e} ({} times so far)",
                        self.cycle_failures
                    ),
                );
            }
            self.cycle = cycle;
            return;
        }
        if let Err(e) = self
            .hw
            .write(&self.cfg.limits, &cycle.reference, self.cfg.control_period)
        {
            self.log(
                LogLevel::Error,
                format!("hardware refused the command: {e}"),
            );
        }
        let header = Header {
            stamp: self.clock.stamp(now),
            frame_id: String::new(),
        };
        let joint_state = |s: &JointSample| JointState {
            header: header.clone(),
            name: self.names.clone(),
            position: s.positions.clone(),
            velocity: s.velocities.clone(),
            effort: Vec::new(),
        };
        let js = joint_state(&measured);
        let cmd = joint_state(&cycle.reference);
        let tfs = cycle.feedback.map_or(0.0, |f| f.time_from_start.max(0.0));
        let state = JointTrajectoryControllerState {
            header: header.clone(),
            joint_names: self.names.clone(),
            reference: convert::point(&cycle.reference, tfs),
            feedback: convert::point(&measured, tfs),
            error: convert::point(&cycle.error, tfs),
            output: convert::point(&cycle.reference, tfs),
            ..Default::default()
        };
        let f = &mut self.publish_failures;
        Self::publish(
            &self.streams.joint_states,
            js,
            f,
            &self.reports,
            "joint states",
        );
        Self::publish(
            &self.streams.command,
            cmd,
            f,
            &self.reports,
            "joint command",
        );
        let cs = &self.streams.controller_state;
        Self::publish(cs, state, f, &self.reports, "controller state");

        for ev in cycle.events.drain(..) {
            if self.active.is_some_and(|(_, id)| id == ev.id) {
                self.active = None;
            }
            let _ = self.reports.send(Report::Finished {
                exec_id: ev.id,
                outcome: ev.outcome,
            });
        }
        if let Some(fb) = cycle.feedback {
            if now >= self.next_feedback {
                self.next_feedback = now + 1.0 / self.cfg.action_monitor_rate;
                let feedback = FollowJointTrajectoryFeedback {
                    header,
                    joint_names: self.names.clone(),
                    desired: convert::point(&cycle.reference, tfs),
                    actual: convert::point(&measured, tfs),
                    error: convert::point(&cycle.error, tfs),
                    ..Default::default()
                };
                self.report(Report::Feedback {
                    exec_id: fb.id,
                    feedback: Box::new(feedback),
                });
            }
        }
        self.cycle = cycle;
    }
}
