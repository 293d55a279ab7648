//! The control thread: read → update → write every control period, and nothing else.
//!
//! The thread owns the executor core and the hardware ([`Hardware`]: mock, simulated cell or a
//! robot driver's topics). It never touches DDS except
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
//!
//! # A robot driver (`hardware: topic`)
//! Each cycle first takes the driver's joint states from their inbox ([`crate::driver`]):
//! the feedback monitor's faults abort the active goal with a controlled stop
//! (`Executor::fault`, PATH_TOLERANCE_VIOLATED), good feedback after none or after a fault
//! moves the hold to the measured state once the robot is at rest (`Executor::hold_at`), and
//! starts are refused while the feedback is not good. Nothing is commanded before the first
//! state; after a fault, commands continue until the stop has been commanded to rest, then
//! pause until good states come back (so a restarted driver never receives a stale hold).
//!
//! # Contacts (simulated cell)
//! After each write the cell's contacts are checked ([`ContactWatch`]). While the reference
//! moves or a goal is active, a contact is a fault unless it was already there when the
//! motion started and has not got deeper since (by more than [`DEEPER`]): the executor
//! brings the motion to a controlled stop (`Executor::fault`) and aborts the goal with
//! PATH_TOLERANCE_VIOLATED and a message naming the links, shapes, objects and depths. The
//! robot is not pushed back by the scene, so it travels on during the stop; the depth
//! reached is at most the depth at detection plus the stopping distance (`v² / 2a` of the
//! slowest-stopping joint, mapped to the tool).

use std::{
    sync::{
        atomic::{AtomicBool, Ordering},
        mpsc::{Receiver, Sender, TryRecvError},
        Arc,
    },
    time::{Duration as StdDuration, Instant},
};

use kerf_cell::Contact;
use kerf_executor::{
    Cycle, Executor, GoalId as ExecGoalId, GoalTolerances, JointLimits, JointSample, Outcome,
    PreparedTrajectory, ValidatedTrajectory, INVALID_GOAL, PATH_TOLERANCE_VIOLATED,
};
use kerf_msgs::{
    control_msgs::{FollowJointTrajectoryFeedback, JointTrajectoryControllerState},
    geometry_msgs::Point,
    msg::{CellContact, CellContacts},
    rosgraph_msgs::Clock as ClockMsg,
    sensor_msgs::JointState,
    std_msgs::Header,
};
use kerf_ros::{LogLevel, Streamer};

use crate::convert::{self, Clock, Rejection};
use crate::driver::FeedbackEvent;
use crate::hardware::Hardware;

/// A contact present when a motion started stays tolerated while its signed distance does
/// not fall more than this below the distance it had then (m): 0.1 mm, above the cell's
/// distance noise, well below the depths a fault is meant to catch.
pub const DEEPER: f64 = 1e-4;

/// `hardware: topic`: how long the measured state must stay within the start tolerance before
/// the hold moves to it after a driver fault (s). Ten periods of a 250 Hz driver: longer than
/// the lag of a driver that follows the commands, so that a robot still catching up with the
/// stop is not mistaken for one at rest elsewhere.
pub const SETTLE: f64 = 0.04;

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
    /// `hardware: topic`: the request thread's check of the driver topics' types found an
    /// endpoint of another type (the message), or none any more.
    DriverTypes {
        /// What is wrong, or `None`.
        fault: Option<String>,
    },
}

/// Something the trajectory's size makes expensive to free: freed by the request thread.
// The fields are never read: they exist to be dropped off the control thread. The variants
// differ in size (a trajectory's few hundred bytes of state against a prepared one's shared
// pointer); boxing would allocate on the control thread to save that on a channel message.
#[allow(dead_code, clippy::large_enum_variant)]
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
    /// The simulated cell's streams (`hardware: sim`).
    pub sim: Option<SimStreams>,
}

/// The streams of the simulated cell.
pub struct SimStreams {
    /// `/clock`: the simulated time.
    pub clock: Streamer<ClockMsg>,
    /// `~/contacts`.
    pub contacts: Streamer<CellContacts>,
    /// `frame_id` of the contacts: the robot's base link.
    pub frame_id: String,
}

/// Decides which contacts are faults: those that appear, or get deeper, during a motion.
#[derive(Debug, Default)]
pub struct ContactWatch {
    /// (shape, object, signed distance) of the contacts present when the motion started.
    tolerated: Vec<(String, String, f64)>,
}

impl ContactWatch {
    /// Takes the contacts of one period; `moving` says whether a motion is under way.
    ///
    /// # Returns
    /// The contacts that are faults (empty while at rest: then the contacts present become
    /// the tolerated ones).
    pub fn check<'a>(&mut self, contacts: &'a [Contact], moving: bool) -> Vec<&'a Contact> {
        if !moving {
            self.tolerated.clear();
            self.tolerated.extend(
                contacts
                    .iter()
                    .map(|c| (c.shape.clone(), c.object.clone(), c.distance)),
            );
            return Vec::new();
        }
        // A tolerated pair that cleared is no longer tolerated.
        self.tolerated.retain(|(shape, object, _)| {
            contacts
                .iter()
                .any(|c| &c.shape == shape && &c.object == object)
        });
        contacts
            .iter()
            .filter(|c| {
                !self.tolerated.iter().any(|(shape, object, d)| {
                    &c.shape == shape && &c.object == object && c.distance >= d - DEEPER
                })
            })
            .collect()
    }
}

/// The abort message of a contact fault: every faulting contact with its link, shape,
/// object, depth and distance.
pub fn contact_message(faults: &[&Contact], time: f64) -> String {
    let list: Vec<String> = faults
        .iter()
        .map(|c| {
            format!(
                "link '{}' (shape '{}') with '{}': depth {:.3} mm (signed distance {:.3} mm) \
                 at [{:.4}, {:.4}, {:.4}] m",
                c.link,
                c.shape,
                c.object,
                c.depth * 1e3,
                c.distance * 1e3,
                c.position[0],
                c.position[1],
                c.position[2],
            )
        })
        .collect();
    format!(
        "contact during motion at t = {time:.3} s (simulated cell): {}; the motion was \
         brought to a controlled stop",
        list.join("; ")
    )
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
    hw: Hardware,
    contacts: ContactWatch,
    efforts: Vec<f64>,
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
    /// `hardware: topic`: the hold moves to the measured state once the robot is at rest
    /// (after the first good joint state, and after a driver fault).
    resync: bool,
    /// Why the last attempt to hold at the measured state failed.
    resync_failed: Option<String>,
    /// Reused buffer of the driver's feedback events.
    driver_events: Vec<FeedbackEvent>,
    /// Whether the last command sent to the hardware was at rest.
    rest_sent: bool,
    /// The pending re-synchronization is the first state's.
    resync_first: bool,
}

impl ControlLoop {
    /// A loop around `exec` and `hw`; it runs while `running` is set and the command channel
    /// is open.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        mut exec: Executor,
        hw: Hardware,
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
            contacts: ContactWatch::default(),
            efforts: Vec::new(),
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
            resync: false,
            resync_failed: None,
            driver_events: Vec::with_capacity(4),
            rest_sent: false,
            resync_first: false,
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
            self.poll_driver(now);
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

    /// `hardware: topic`: takes the driver's joint states and checks its watchdog; a fault
    /// aborts the active goal with a controlled stop, good feedback (first, or after a fault)
    /// moves the hold to the measured state once the robot is at rest. Good states are
    /// republished on `joint_states` as received.
    fn poll_driver(&mut self, now: f64) {
        let Some(driver) = self.hw.topic() else {
            return;
        };
        let mut events = std::mem::take(&mut self.driver_events);
        driver.poll(now, &mut events);
        let f = &mut self.publish_failures;
        for js in driver.take_received() {
            Self::publish(
                &self.streams.joint_states,
                js,
                f,
                &self.reports,
                "joint states",
            );
        }
        for event in events.drain(..) {
            self.on_feedback(event, now);
        }
        self.driver_events = events;
        self.resync_at_rest(now);
    }

    fn on_feedback(&mut self, event: FeedbackEvent, now: f64) {
        let topic = match &self.hw {
            Hardware::Topic(d) => d.monitor().topic().to_string(),
            _ => return,
        };
        match event {
            FeedbackEvent::Fault(message) => {
                let moving = self.exec.active_goal().is_some() || self.exec.is_moving(now);
                if moving {
                    let message = format!("{message}; the motion was brought to a controlled stop");
                    self.log(LogLevel::Error, message.clone());
                    if let Err(e) = self.exec.fault(now, PATH_TOLERANCE_VIOLATED, message) {
                        self.log(LogLevel::Error, format!("driver fault: {e}"));
                    }
                } else {
                    self.log(LogLevel::Error, message);
                }
            }
            FeedbackEvent::Good { first } => {
                self.resync = true;
                self.resync_first |= first;
                let message = if first {
                    format!("first joint state from the driver on {topic}; goals are accepted")
                } else {
                    format!(
                        "good joint states on {topic} again; goals are accepted once the robot \
                         is at rest at the hold (or still elsewhere: the hold then moves there)"
                    )
                };
                self.log(LogLevel::Info, message);
            }
        }
    }

    /// Ends a pending re-synchronization once the feedback is good and the commanded motion
    /// has ended: at once for the first state (nothing was commanded yet); otherwise when the
    /// measured state is within the start tolerance of the hold (the robot followed the
    /// stop: the hold stays, no jump), or, when it is not, once it has been still for
    /// [`SETTLE`] (the robot is elsewhere, e.g. a restarted driver: the hold moves there).
    fn resync_at_rest(&mut self, now: f64) {
        if !self.resync || self.exec.active_goal().is_some() || self.exec.is_moving(now) {
            return;
        }
        let Hardware::Topic(d) = &self.hw else {
            return;
        };
        let m = d.monitor();
        if !m.is_good() {
            return;
        }
        let positions = m.measured().positions.clone();
        if !self.resync_first {
            let off = positions
                .iter()
                .zip(&self.exec.commanded().positions)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            if off <= self.exec.config().start_tolerance {
                self.resync = false;
                self.resync_failed = None;
                self.log(
                    LogLevel::Info,
                    format!("the robot is at the hold (within {off:.2e}); goals are accepted"),
                );
                return;
            }
            if m.still_for(now) < SETTLE {
                return;
            }
        }
        match self.exec.hold_at(now, &positions) {
            Ok(()) => {
                self.resync = false;
                self.resync_first = false;
                self.resync_failed = None;
                self.log(
                    LogLevel::Info,
                    format!("holding at the measured state {positions:?}"),
                );
            }
            Err(e) => {
                let message = format!(
                    "cannot hold at the driver's measured state: {e}; goals are refused until \
                     the robot reports a valid state"
                );
                if self.resync_failed.as_ref() != Some(&message) {
                    self.log(LogLevel::Error, message.clone());
                    self.resync_failed = Some(message);
                }
            }
        }
    }

    /// Whether a topic driver's feedback is good and the hold is where the robot is.
    fn driver_ready(&self) -> bool {
        match &self.hw {
            Hardware::Topic(d) => d.monitor().is_good() && !self.resync,
            _ => true,
        }
    }

    /// Why a goal cannot start now because of the driver (`hardware: topic`), if it cannot.
    fn driver_refusal(&self) -> Option<Rejection> {
        let Hardware::Topic(d) = &self.hw else {
            return None;
        };
        let message = d.monitor().refusal().or_else(|| {
            self.resync.then(|| {
                self.resync_failed.clone().unwrap_or_else(|| {
                    "the robot is coming to rest after a driver fault; goals are accepted once \
                     the measured state is at the hold, or still elsewhere"
                        .to_string()
                })
            })
        })?;
        Some(Rejection {
            code: INVALID_GOAL,
            message,
        })
    }

    /// Applies one command at the cycle time `now`, in O(joints).
    fn apply(&mut self, command: Command, now: f64) {
        match command {
            Command::Start {
                tag,
                prepared,
                tolerances,
            } if self.driver_refusal().is_some() => {
                drop(tolerances);
                self.report(Report::Trash(Trash::Prepared(prepared)));
                if let Some(rejection) = self.driver_refusal() {
                    self.report(Report::Refused { tag, rejection });
                }
            }
            Command::Validate {
                tag,
                prepared,
                tolerances,
            } if self.driver_refusal().is_some() => {
                drop(tolerances);
                self.report(Report::Trash(Trash::Prepared(prepared)));
                if let Some(rejection) = self.driver_refusal() {
                    self.report(Report::Validated {
                        tag,
                        result: Err(rejection),
                    });
                }
            }
            Command::DriverTypes { fault } => {
                if let Some(d) = self.hw.topic() {
                    if let Some(event) = d.monitor_mut().set_type_fault(fault) {
                        self.on_feedback(event, now);
                    }
                }
            }
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

    /// Simulated cell only, after the write at `now`: advances the clock to the cell's time,
    /// publishes `/clock` and `~/contacts`, and turns a contact during motion into a fault.
    fn after_write(&mut self, now: f64) {
        let Some(state) = self.hw.sim_state() else {
            return;
        };
        let Some(sim) = &self.streams.sim else {
            return;
        };
        let time = state.time;
        self.clock.set(time);
        let stamp = self.clock.stamp(time);
        let f = &mut self.publish_failures;
        let clock = ClockMsg { clock: stamp };
        Self::publish(&sim.clock, clock, f, &self.reports, "clock");
        let msg = CellContacts {
            header: Header {
                stamp,
                frame_id: sim.frame_id.clone(),
            },
            contacts: state
                .contacts
                .iter()
                .map(|c| CellContact {
                    robot_link: c.link.clone(),
                    robot_shape: c.shape.clone(),
                    scene_object: c.object.clone(),
                    distance: c.distance,
                    depth: c.depth,
                    position: Point {
                        x: c.position[0],
                        y: c.position[1],
                        z: c.position[2],
                    },
                })
                .collect(),
        };
        Self::publish(&sim.contacts, msg, f, &self.reports, "contacts");
        let moving = self.exec.is_moving(now) || self.exec.active_goal().is_some();
        let faults = self.contacts.check(&state.contacts, moving);
        if faults.is_empty() {
            return;
        }
        let message = contact_message(&faults, time);
        // With no active goal the only motion is a stop already in progress (a cancel or an
        // earlier fault): `fault` lets it run on, and the fault was already reported.
        if let Err(e) = self.exec.fault(now, PATH_TOLERANCE_VIOLATED, message) {
            self.log(LogLevel::Error, format!("contact fault: {e}"));
        }
    }

    /// Read → update → write at `now`, then the state streams, goal ends and feedback.
    ///
    /// A topic driver's robot is not commanded before its first joint state: until then the
    /// cycle does nothing.
    fn control_cycle(&mut self, now: f64) {
        let topic = match &self.hw {
            Hardware::Topic(d) if !d.monitor().has_state() => return,
            Hardware::Topic(_) => true,
            _ => false,
        };
        let measured = self.hw.state().clone();
        self.efforts.clear();
        self.efforts.extend_from_slice(self.hw.efforts());
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
        // A topic driver is commanded while its feedback is good, and after a fault until
        // the controlled stop has been commanded to rest: a driver that comes back (a restart,
        // elsewhere) must not get a stale hold before the hold has moved to where it is.
        let send = !topic || self.driver_ready() || self.exec.is_moving(now) || !self.rest_sent;
        if send {
            if let Err(e) =
                self.hw
                    .write(&self.cfg.limits, &cycle.reference, self.cfg.control_period)
            {
                self.log(
                    LogLevel::Error,
                    format!("hardware refused the command: {e}"),
                );
            }
            let at_rest = cycle.reference.velocities.iter().all(|v| *v == 0.0);
            if topic && at_rest && !self.rest_sent && !self.driver_ready() {
                self.log(
                    LogLevel::Warn,
                    "the robot is commanded to rest; commands to the driver pause until good \
                     joint states come back"
                        .into(),
                );
            }
            self.rest_sent = at_rest;
        }
        self.after_write(now);
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
        let mut js = joint_state(&measured);
        js.effort.clone_from(&self.efforts);
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
        // A topic driver's states are republished as they come (`poll_driver`).
        if !topic {
            Self::publish(
                &self.streams.joint_states,
                js,
                f,
                &self.reports,
                "joint states",
            );
        }
        if send {
            Self::publish(
                &self.streams.command,
                cmd,
                f,
                &self.reports,
                "joint command",
            );
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    fn contact(shape: &str, distance: f64) -> Contact {
        Contact {
            link: "nozzle".into(),
            shape: shape.into(),
            object: "bpillar".into(),
            distance,
            depth: (-distance).max(0.0),
            position: [0.1, 0.2, 0.3],
            object_point: [0.1, 0.2, 0.3],
            time: 1.0,
        }
    }

    #[test]
    fn contacts_are_faults_when_new_or_deeper_during_motion() {
        let mut w = ContactWatch::default();
        // At rest: never a fault; the contact present is tolerated for the next motion.
        assert!(w.check(&[contact("nozzle/1", 0.001)], false).is_empty());
        // Moving: the tolerated one is no fault while it does not get deeper.
        assert!(w.check(&[contact("nozzle/1", 0.0015)], true).is_empty());
        assert!(w
            .check(&[contact("nozzle/1", 0.001 - DEEPER / 2.0)], true)
            .is_empty());
        let deeper = [contact("nozzle/1", 0.001 - 2.0 * DEEPER)];
        assert_eq!(w.check(&deeper, true).len(), 1);
        // A new pair during motion is a fault.
        let both = [contact("nozzle/1", 0.001), contact("nozzle/0", -0.0003)];
        let faults = w.check(&both, true);
        assert_eq!(faults.len(), 1);
        assert_eq!(faults[0].shape, "nozzle/0");
        // Once a tolerated pair clears, its return is a fault.
        assert!(w.check(&[], true).is_empty());
        assert_eq!(w.check(&[contact("nozzle/1", 0.0015)], true).len(), 1);
        // The message names link, shape, object and depth.
        let c = contact("nozzle/0", -0.0003);
        let m = contact_message(&[&c], 2.5);
        for needle in [
            "'nozzle'",
            "'nozzle/0'",
            "'bpillar'",
            "depth 0.300 mm",
            "t = 2.500 s",
        ] {
            assert!(m.contains(needle), "{needle}: {m}");
        }
    }
}
