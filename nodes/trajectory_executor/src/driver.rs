//! `hardware: topic`: a real robot's driver reached through two topics (issue 27, item 2).
//!
//! Every control period the executor streams its command to `hardware.command_topic`, as
//! `std_msgs/msg/Float64MultiArray` (ros2_control's `forward_command_controller`: one position
//! per joint, in the model's joint order) or `sensor_msgs/msg/JointState` (names and
//! positions), and reads the driver's measured state from `hardware.state_topic`
//! (`sensor_msgs/msg/JointState`, names in any order, other joints left out:
//! [`kerf_executor::measured_state`]). Path and goal tolerances are judged on the latest
//! measured state, as JTC judges them on its state interfaces.
//!
//! [`FeedbackMonitor`] decides whether the feedback can be trusted:
//! * **waiting**: no state yet. Goals are refused ("waiting for the driver"), nothing is
//!   commanded; the first good state becomes the hold (`Executor::hold_at`), so the robot
//!   starts where it is, not at `initial_positions`.
//! * **good**: states keep coming ([`FeedbackWatchdog`]: at most
//!   `hardware.feedback_timeout_periods` control periods apart), their stamps never go back,
//!   and `measured_state` accepts each.
//! * **bad**: stale feedback, a stamp that went back (the state is dropped and the watchdog
//!   re-armed, so a driver whose clock was stepped back recovers with its next state), a
//!   state `measured_state` refuses (NaN, a missing joint, mis-sized arrays), a sample that
//!   cannot be read, or a driver topic with an endpoint of another type
//!   ([`check_topic_types`]). The running goal is aborted with PATH_TOLERANCE_VIOLATED and
//!   the fault's message, the motion is brought to the executor's controlled stop
//!   (`kerf_executor::StopProfile`, within the acceleration limits, commanded to the driver
//!   as ever, then paused until good states come back), and new goals are refused with the
//!   reason. Once good states are back and the stop has ended, goals are accepted again as
//!   soon as the measured state is within the start tolerance of the hold; when it is not (a
//!   driver restarted elsewhere), once it has been still for `control::SETTLE`, and the hold
//!   moves to it ([`FeedbackMonitor::still_for`]).
//!
//! The executor's own `joint_states` republishes each good state as it was received (the
//! driver's names, order, stamp, velocities and efforts), so that planners and tools see the
//! robot; a refused state is not republished.

use kerf_executor::{
    measured_state, ExecutorError, FeedbackWatchdog, JointLimits, JointSample, NamedState,
};
use kerf_msgs::{
    builtin_interfaces::Time,
    sensor_msgs::JointState,
    std_msgs::{Float64MultiArray, Header},
};
use kerf_ros::{Inbox, Streamer};

use crate::{config::CommandType, convert::Clock, NodeError};

/// What a joint state, a read error, a watchdog check or a type check changed.
#[derive(Debug, Clone, PartialEq)]
pub enum FeedbackEvent {
    /// The feedback became good: the first state (`first`), or good states after a fault.
    Good {
        /// Whether this is the first good state since the start.
        first: bool,
    },
    /// The feedback became bad, or bad for another reason: what is wrong.
    Fault(String),
}

/// The kind of a feedback fault: a repeat of the same kind is one fault.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum FaultKind {
    Stale,
    StampBack,
    Refused,
    Unreadable,
}

#[derive(Debug, Clone, PartialEq)]
enum Status {
    Waiting,
    Good,
    Bad { kind: FaultKind, message: String },
}

/// The state of a driver's feedback: the latest good measured state, the watchdog, and
/// whether goals may run. ROS-free apart from the message type, so that it is tested
/// without DDS.
#[derive(Debug, Clone)]
pub struct FeedbackMonitor {
    topic: String,
    limits: Vec<JointLimits>,
    period: f64,
    allowed: u32,
    watchdog: Option<FeedbackWatchdog>,
    last_stamp: Option<Time>,
    status: Status,
    type_fault: Option<String>,
    measured: JointSample,
    /// Stillness band (joint units): the executor's start tolerance.
    band: f64,
    /// The good state the later ones are compared with, and since when they stayed within
    /// `band` of it (s).
    anchor: Vec<f64>,
    still_since: f64,
}

/// `sec.nanosec` of a ROS time, for messages.
fn stamp_text(t: &Time) -> String {
    format!("{}.{:09}", t.sec, t.nanosec)
}

impl FeedbackMonitor {
    /// A monitor of the joint states on `topic` for the robot `limits`, allowing `allowed`
    /// control periods of `period` seconds between two states.
    ///
    /// # Errors
    /// [`NodeError::Config`] naming `hardware.feedback_timeout_periods` or `control_rate` when
    /// the watchdog refuses them.
    pub fn new(
        topic: &str,
        limits: Vec<JointLimits>,
        period: f64,
        allowed: u32,
        band: f64,
    ) -> Result<Self, NodeError> {
        FeedbackWatchdog::new(period, allowed, 0.0).map_err(|e| NodeError::Config {
            name: "hardware.feedback_timeout_periods".into(),
            reason: e.to_string(),
        })?;
        Ok(Self {
            topic: topic.to_string(),
            limits,
            period,
            allowed,
            watchdog: None,
            last_stamp: None,
            status: Status::Waiting,
            type_fault: None,
            measured: JointSample::default(),
            band,
            anchor: Vec::new(),
            still_since: f64::INFINITY,
        })
    }

    /// How long (s, at `now`) every good state has stayed within the start tolerance of one
    /// position: the robot has come to rest when this exceeds a few periods. 0 before the
    /// first state.
    pub fn still_for(&self, now: f64) -> f64 {
        (now - self.still_since).max(0.0)
    }

    /// The driver's joint-state topic.
    pub fn topic(&self) -> &str {
        &self.topic
    }

    /// The latest good measured state (model order; velocities when the driver gives them,
    /// no accelerations); empty before the first.
    pub fn measured(&self) -> &JointSample {
        &self.measured
    }

    /// Whether a good state has come since the start (commands are streamed from then on).
    pub fn has_state(&self) -> bool {
        self.watchdog.is_some()
    }

    /// Whether the latest joint state was taken (good feedback, whatever the topic types).
    pub fn feedback_good(&self) -> bool {
        self.status == Status::Good
    }

    /// Whether goals may run: good feedback and no driver topic of the wrong type.
    pub fn is_good(&self) -> bool {
        self.status == Status::Good && self.type_fault.is_none()
    }

    /// Why goals are refused now, if they are.
    pub fn refusal(&self) -> Option<String> {
        if let Some(t) = &self.type_fault {
            return Some(t.clone());
        }
        match &self.status {
            Status::Good => None,
            Status::Waiting => Some(
                NodeError::WaitingForDriver {
                    topic: self.topic.clone(),
                }
                .to_string(),
            ),
            Status::Bad { message, .. } => Some(format!(
                "{message}; goals are refused until good joint states come back on {}",
                self.topic
            )),
        }
    }

    fn fault(&mut self, kind: FaultKind, message: String) -> Option<FeedbackEvent> {
        if matches!(&self.status, Status::Bad { kind: k, .. } if *k == kind) {
            return None;
        }
        self.status = Status::Bad {
            kind,
            message: message.clone(),
        };
        Some(FeedbackEvent::Fault(message))
    }

    /// A joint state `msg` stamped `stamp` (s on the executor's clock) arrived at `now` (s).
    ///
    /// # Returns
    /// The change it makes: the first good state, good again after a fault, or a fault (a
    /// state `measured_state` refuses, a stamp that went back). `None` when nothing changed.
    pub fn receive(&mut self, msg: &JointState, stamp: f64, now: f64) -> Option<FeedbackEvent> {
        let named = NamedState {
            names: &msg.name,
            positions: &msg.position,
            velocities: &msg.velocity,
        };
        let state = match measured_state("measured state", named, &self.limits) {
            Ok(s) => s,
            Err(e) => {
                let message = NodeError::BadFeedback {
                    topic: self.topic.clone(),
                    reason: e.to_string(),
                }
                .to_string();
                return self.fault(FaultKind::Refused, message);
            }
        };
        let first = self.watchdog.is_none();
        let watchdog = match self.watchdog.as_mut() {
            Some(w) => w,
            // In range: checked by `new`.
            None => match FeedbackWatchdog::new(self.period, self.allowed, now) {
                Ok(w) => self.watchdog.insert(w),
                Err(e) => {
                    let message = NodeError::BadFeedback {
                        topic: self.topic.clone(),
                        reason: e.to_string(),
                    }
                    .to_string();
                    return self.fault(FaultKind::Refused, message);
                }
            },
        };
        match watchdog.receive(stamp, now) {
            Ok(()) => {}
            Err(ExecutorError::FeedbackStampBack { .. }) => {
                let message = NodeError::FeedbackStampBack {
                    topic: self.topic.clone(),
                    previous: self
                        .last_stamp
                        .as_ref()
                        .map_or_else(String::new, stamp_text),
                    got: stamp_text(&msg.header.stamp),
                }
                .to_string();
                // Re-armed: the next state is judged on its own, so that a driver whose clock
                // was stepped back recovers.
                if let Ok(w) = FeedbackWatchdog::new(self.period, self.allowed, now) {
                    *watchdog = w;
                }
                self.last_stamp = None;
                return self.fault(FaultKind::StampBack, message);
            }
            Err(e) => {
                let message = NodeError::BadFeedback {
                    topic: self.topic.clone(),
                    reason: e.to_string(),
                }
                .to_string();
                return self.fault(FaultKind::Refused, message);
            }
        }
        self.last_stamp = Some(msg.header.stamp);
        let moved = self.anchor.len() != state.positions.len()
            || self
                .anchor
                .iter()
                .zip(&state.positions)
                .any(|(a, p)| (a - p).abs() > self.band);
        if moved {
            self.anchor.clone_from(&state.positions);
            self.still_since = now;
        }
        self.measured.positions = state.positions;
        self.measured.velocities = state.velocities.unwrap_or_default();
        self.measured.accelerations.clear();
        match self.status {
            Status::Good => None,
            Status::Waiting | Status::Bad { .. } => {
                self.status = Status::Good;
                Some(FeedbackEvent::Good { first })
            }
        }
    }

    /// A sample on the state topic could not be read (`reason`: the reader's error).
    pub fn receive_error(&mut self, reason: String) -> Option<FeedbackEvent> {
        let message = NodeError::UnreadableFeedback {
            topic: self.topic.clone(),
            expected: "sensor_msgs/msg/JointState",
            reason,
        }
        .to_string();
        self.fault(FaultKind::Unreadable, message)
    }

    /// Checks the watchdog at `now` (s).
    ///
    /// # Returns
    /// The stale-feedback fault when good feedback has stopped for longer than the allowed
    /// periods (or `now` is not finite); `None` otherwise, also before the first state and
    /// while the feedback is already bad for another reason.
    pub fn check(&mut self, now: f64) -> Option<FeedbackEvent> {
        if self.status != Status::Good {
            return None;
        }
        let Some(w) = &self.watchdog else {
            return None;
        };
        match w.check(now) {
            Ok(()) => None,
            Err(e) => {
                let age = match e {
                    ExecutorError::FeedbackStale { age, .. } => age,
                    _ => f64::NAN,
                };
                let message = NodeError::FeedbackStale {
                    topic: self.topic.clone(),
                    age_ms: age * 1e3,
                    periods: age / self.period,
                    allowed: self.allowed,
                }
                .to_string();
                self.fault(FaultKind::Stale, message)
            }
        }
    }

    /// Sets or clears the wrong-type fault of the driver's topics ([`check_topic_types`]).
    ///
    /// # Returns
    /// The fault when it is new; good feedback when it clears while the states are good.
    pub fn set_type_fault(&mut self, fault: Option<String>) -> Option<FeedbackEvent> {
        if fault == self.type_fault {
            return None;
        }
        self.type_fault.clone_from(&fault);
        match fault {
            Some(m) => Some(FeedbackEvent::Fault(m)),
            None => (self.status == Status::Good).then_some(FeedbackEvent::Good { first: false }),
        }
    }
}

/// Where a topic driver's commands go.
pub enum CommandStream {
    /// `std_msgs/msg/Float64MultiArray`, positions in model order.
    Array(Streamer<Float64MultiArray>),
    /// `sensor_msgs/msg/JointState`, names and positions.
    State(Streamer<JointState>),
}

impl CommandStream {
    /// The message type.
    pub fn command_type(&self) -> CommandType {
        match self {
            Self::Array(_) => CommandType::Float64MultiArray,
            Self::State(_) => CommandType::JointState,
        }
    }
}

/// The hardware of `hardware: topic`: the joint-state inbox, the command stream and the
/// feedback monitor. Owned by the control thread, which only moves samples in and out of
/// queues (the inbox deserializes on its own thread, the stream publishes on its own).
pub struct TopicDriver {
    monitor: FeedbackMonitor,
    states: Inbox<JointState>,
    command: CommandStream,
    names: Vec<String>,
    clock: Clock,
    /// The time of the latest poll: the stamp of the commands of that cycle.
    now: f64,
    /// Good states received since the last [`TopicDriver::take_received`].
    received: Vec<JointState>,
    dropped_commands: u64,
}

impl std::fmt::Debug for TopicDriver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TopicDriver")
            .field("monitor", &self.monitor)
            .field("command_type", &self.command.command_type())
            .finish_non_exhaustive()
    }
}

impl TopicDriver {
    /// A driver around its endpoints.
    pub fn new(
        monitor: FeedbackMonitor,
        states: Inbox<JointState>,
        command: CommandStream,
        names: Vec<String>,
        clock: Clock,
    ) -> Self {
        Self {
            monitor,
            states,
            command,
            names,
            clock,
            now: 0.0,
            received: Vec::with_capacity(8),
            dropped_commands: 0,
        }
    }

    /// The feedback monitor.
    pub fn monitor(&self) -> &FeedbackMonitor {
        &self.monitor
    }

    /// The feedback monitor, mutable.
    pub fn monitor_mut(&mut self) -> &mut FeedbackMonitor {
        &mut self.monitor
    }

    /// Takes every joint state received by now into the monitor, then checks the watchdog;
    /// the changes go to `events`.
    pub fn poll(&mut self, now: f64, events: &mut Vec<FeedbackEvent>) {
        self.now = now;
        while let Some(received) = self.states.try_recv() {
            let event = match received {
                Ok(msg) => {
                    let stamp = self.clock.from_stamp(&msg.header.stamp);
                    let event = self.monitor.receive(&msg, stamp, now);
                    // A state the monitor took is republished as received.
                    if self.monitor.feedback_good() {
                        self.received.push(msg);
                    }
                    event
                }
                Err(e) => self.monitor.receive_error(e),
            };
            events.extend(event);
        }
        events.extend(self.monitor.check(now));
    }

    /// The good states received since the last call, to republish on `joint_states`.
    pub fn take_received(&mut self) -> std::vec::Drain<'_, JointState> {
        self.received.drain(..)
    }

    /// Streams `command` (model order) to the driver, stamped at the latest poll.
    ///
    /// # Returns
    /// A warning when the command was dropped (the stream's queue full), at powers of two
    /// of the count.
    pub fn send(&mut self, command: &JointSample) -> Option<String> {
        let sent = match &self.command {
            CommandStream::Array(s) => s.publish(Float64MultiArray {
                layout: Default::default(),
                data: command.positions.clone(),
            }),
            CommandStream::State(s) => s.publish(JointState {
                header: Header {
                    stamp: self.clock.stamp(self.now),
                    frame_id: String::new(),
                },
                name: self.names.clone(),
                position: command.positions.clone(),
                velocity: Vec::new(),
                effort: Vec::new(),
            }),
        };
        if sent {
            return None;
        }
        self.dropped_commands += 1;
        self.dropped_commands.is_power_of_two().then(|| {
            format!(
                "command to the driver dropped: its stream's queue is full ({} drops so far)",
                self.dropped_commands
            )
        })
    }
}

/// The ROS form of a DDS type name: `sensor_msgs::msg::dds_::JointState_` →
/// `sensor_msgs/msg/JointState`; other names unchanged.
pub fn ros_type_name(dds: &str) -> String {
    let parts: Vec<&str> = dds.split("::").collect();
    match parts.as_slice() {
        [pkg, kind, "dds_", name] => {
            format!("{pkg}/{kind}/{}", name.strip_suffix('_').unwrap_or(name))
        }
        _ => dds.to_string(),
    }
}

/// The DDS form of a ROS type name: `sensor_msgs/msg/JointState` →
/// `sensor_msgs::msg::dds_::JointState_`.
pub fn dds_type_name(ros: &str) -> String {
    let parts: Vec<&str> = ros.split('/').collect();
    match parts.as_slice() {
        [pkg, kind, name] => format!("{pkg}::{kind}::dds_::{name}_"),
        _ => ros.to_string(),
    }
}

/// One side of a driver's topics to check for endpoints of another type.
#[derive(Debug, Clone, Copy)]
pub struct TopicRole<'a> {
    /// The fully qualified topic.
    pub topic: &'a str,
    /// The type the executor uses there (ROS form).
    pub expected: &'static str,
    /// True when the executor reads the topic (the others' publishers are checked), false
    /// when it publishes there (their subscriptions are checked).
    pub executor_reads: bool,
}

/// The first endpoint of another type on a driver's topics, among the discovered publishers
/// `writers` and subscriptions `readers` ((ROS topic, DDS type) pairs, e.g. from
/// `KerfNode::discovered_topics`).
///
/// RustDDS matches endpoints by topic name alone, so a driver configured for another type is
/// otherwise only seen as samples that do not deserialize (or none at all).
///
/// # Returns
/// The [`NodeError::WrongTopicType`] message naming the topic and both types, or `None`.
pub fn check_topic_types(
    roles: &[TopicRole<'_>],
    writers: &[(String, String)],
    readers: &[(String, String)],
) -> Option<String> {
    for role in roles {
        let (others, endpoint) = if role.executor_reads {
            (writers, "publisher")
        } else {
            (readers, "subscription")
        };
        let expected = dds_type_name(role.expected);
        if let Some((_, found)) = others
            .iter()
            .find(|(t, ty)| t == role.topic && *ty != expected)
        {
            return Some(
                NodeError::WrongTopicType {
                    topic: role.topic.to_string(),
                    endpoint,
                    found: ros_type_name(found),
                    role: if role.executor_reads {
                        "reads"
                    } else {
                        "publishes"
                    },
                    expected: role.expected,
                }
                .to_string(),
            );
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits() -> Vec<JointLimits> {
        ["a", "b"]
            .iter()
            .map(|n| JointLimits {
                name: (*n).into(),
                min_position: -1.0,
                max_position: 1.0,
                max_velocity: 1.0,
                max_acceleration: 1.0,
            })
            .collect()
    }

    fn state(names: &[&str], positions: &[f64], sec: i32, nanosec: u32) -> JointState {
        JointState {
            header: Header {
                stamp: Time { sec, nanosec },
                frame_id: String::new(),
            },
            name: names.iter().map(|s| (*s).to_string()).collect(),
            position: positions.to_vec(),
            velocity: Vec::new(),
            effort: Vec::new(),
        }
    }

    const P: f64 = 0.004;

    fn monitor() -> FeedbackMonitor {
        FeedbackMonitor::new("/driver/joint_states", limits(), P, 5, 1e-3).unwrap()
    }

    #[test]
    fn goals_wait_for_the_first_state_which_is_read_in_model_order() {
        let mut m = monitor();
        assert!(!m.is_good() && !m.has_state());
        let r = m.refusal().unwrap();
        assert!(
            r.contains("waiting for the driver") && r.contains("/driver/joint_states"),
            "{r}"
        );
        // No staleness before the first state.
        assert_eq!(m.check(10.0), None);
        let s = state(&["b", "gripper", "a"], &[0.2, 9.0, 0.1], 1, 0);
        assert_eq!(
            m.receive(&s, 1.0, 10.0),
            Some(FeedbackEvent::Good { first: true })
        );
        assert_eq!(m.measured().positions, [0.1, 0.2]);
        assert!(m.measured().velocities.is_empty());
        assert!(m.is_good() && m.refusal().is_none());
        assert_eq!(m.receive(&s, 1.004, 10.004), None);
        // Still since the first state; a move beyond the band restarts the clock.
        assert!((m.still_for(10.05) - 0.05).abs() < 1e-12);
        let moved = state(&["a", "b"], &[0.1, 0.2 + 2e-3], 1, 8_000_000);
        assert_eq!(m.receive(&moved, 1.008, 10.06), None);
        assert!((m.still_for(10.07) - 0.01).abs() < 1e-12);
        let jitter = state(&["a", "b"], &[0.1 + 5e-4, 0.202], 1, 12_000_000);
        m.receive(&jitter, 1.012, 10.08);
        assert!((m.still_for(10.09) - 0.03).abs() < 1e-12);
    }

    #[test]
    fn stale_nan_fewer_joints_and_stamps_back_are_faults_until_good_states_return() {
        let mut m = monitor();
        let good = |t: f64| state(&["a", "b"], &[0.1, 0.2], 1, (t * 1e9).round() as u32);
        m.receive(&good(0.1), 0.1, 0.0).unwrap();
        assert_eq!(m.check(0.02), None);
        // Stale after 5 periods: named with the topic, the age and the periods.
        let Some(FeedbackEvent::Fault(e)) = m.check(0.024) else {
            panic!("not stale")
        };
        assert!(
            e.contains("feedback stale: no joint state on /driver/joint_states for 24.0 ms")
                && e.contains("6.0 control periods")
                && e.contains("allows 5"),
            "{e}"
        );
        // Reported once; goals refused with the reason.
        assert_eq!(m.check(0.03), None);
        assert!(m.refusal().unwrap().contains("feedback stale"));
        assert_eq!(
            m.receive(&good(0.2), 0.2, 0.03),
            Some(FeedbackEvent::Good { first: false })
        );
        // NaN and a missing joint, each named; the bad state is not used.
        let nan = state(&["a", "b"], &[f64::NAN, 0.5], 1, 0);
        let Some(FeedbackEvent::Fault(e)) = m.receive(&nan, 0.21, 0.034) else {
            panic!("NaN accepted")
        };
        assert!(e.contains("position of joint 'a' is NaN"), "{e}");
        assert_eq!(m.measured().positions, [0.1, 0.2]);
        assert_eq!(
            m.receive(&good(0.22), 0.22, 0.036),
            Some(FeedbackEvent::Good { first: false })
        );
        let fewer = state(&["a"], &[0.3], 1, 0);
        let Some(FeedbackEvent::Fault(_)) = m.receive(&fewer, 0.23, 0.038) else {
            panic!("fewer joints accepted")
        };
        assert!(m.refusal().unwrap().contains("no value for joint(s) [b]"));
        // A stamp that goes back: a fault, the state not used, the watchdog re-armed.
        m.receive(&good(0.3), 0.3, 0.04).unwrap();
        let back = state(&["a", "b"], &[0.9, 0.9], 1, 100_000_000);
        let Some(FeedbackEvent::Fault(e)) = m.receive(&back, 0.25, 0.044) else {
            panic!("stamp back accepted")
        };
        assert!(
            e.contains("feedback stamp went back on /driver/joint_states: stamp 1.100000000 after 1.300000000"),
            "{e}"
        );
        assert_eq!(m.measured().positions, [0.1, 0.2]);
        assert_eq!(
            m.receive(&good(0.26), 0.26, 0.048),
            Some(FeedbackEvent::Good { first: false })
        );
        // A sample that cannot be read.
        let Some(FeedbackEvent::Fault(e)) = m.receive_error("bad CDR".into()) else {
            panic!("read error ignored")
        };
        assert!(
            e.contains("could not read a joint state on /driver/joint_states")
                && e.contains("bad CDR"),
            "{e}"
        );
    }

    #[test]
    fn a_topic_of_the_wrong_type_refuses_goals_naming_both_types() {
        let roles = [
            TopicRole {
                topic: "/driver/joint_states",
                expected: "sensor_msgs/msg/JointState",
                executor_reads: true,
            },
            TopicRole {
                topic: "/driver/commands",
                expected: "std_msgs/msg/Float64MultiArray",
                executor_reads: false,
            },
        ];
        let js = (
            "/driver/joint_states".to_string(),
            dds_type_name("sensor_msgs/msg/JointState"),
        );
        assert_eq!(js.1, "sensor_msgs::msg::dds_::JointState_");
        assert_eq!(
            check_topic_types(&roles, std::slice::from_ref(&js), &[]),
            None
        );
        // Our own command writer is a writer, not a reader: not a fault.
        let cmd_writer = (
            "/driver/commands".to_string(),
            "std_msgs::msg::dds_::String_".to_string(),
        );
        assert_eq!(
            check_topic_types(&roles, &[js.clone(), cmd_writer], &[]),
            None
        );
        let reader = (
            "/driver/commands".to_string(),
            "sensor_msgs::msg::dds_::JointState_".to_string(),
        );
        let e = check_topic_types(&roles, &[js], &[reader]).unwrap();
        assert!(
            e.contains("driver topic /driver/commands has a subscription of type sensor_msgs/msg/JointState")
                && e.contains("publishes std_msgs/msg/Float64MultiArray"),
            "{e}"
        );
        let mut m = monitor();
        assert_eq!(
            m.set_type_fault(Some(e.clone())),
            Some(FeedbackEvent::Fault(e.clone()))
        );
        assert_eq!(m.set_type_fault(Some(e.clone())), None);
        assert_eq!(m.refusal(), Some(e));
        assert_eq!(m.set_type_fault(None), None, "states never came");
        assert_eq!(ros_type_name("odd"), "odd");
    }
}
