//! The kerf trajectory executor node.
//!
//! Validates, interpolates and streams joint trajectories for one robot (URDF + limits YAML
//! given as parameters), with ros2_control's `joint_trajectory_controller` as the reference
//! semantics (see `kerf_executor` for the differences).
//!
//! | endpoint | type | |
//! |---|---|---|
//! | `~/joint_trajectory` | `trajectory_msgs/msg/JointTrajectory` | subscription |
//! | `~/follow_joint_trajectory` | `control_msgs/action/FollowJointTrajectory` | action server |
//! | `~/validate_trajectory` | `kerf_msgs/srv/ValidateTrajectory` | service (dry run) |
//! | `joint_states` | `sensor_msgs/msg/JointState` | measured state, every control cycle |
//! | `~/controller_state` | `control_msgs/msg/JointTrajectoryControllerState` | every control cycle |
//! | `~/joint_command` | `sensor_msgs/msg/JointState` | command stream for a hardware driver |
//! | `~/trajectory_status` | `kerf_msgs/msg/TrajectoryStatus` | accepted / rejected / finished |
//! | `~/reference_points` | `kerf_msgs/msg/ReferencePoint` | subscription: the streaming mode's points ([`stream`]) |
//! | `~/stream_status` | `kerf_msgs/msg/StreamStatus` | each point started, queued, refused, reached or not reached ([`stream`]) |
//! | `/clock` | `rosgraph_msgs/msg/Clock` | simulated time, every control cycle (`hardware: sim`) |
//! | `~/contacts` | `kerf_msgs/msg/CellContacts` | the cell's contacts, every control cycle (`hardware: sim`) |
//! | `hardware.command_topic` | `std_msgs/msg/Float64MultiArray` or `sensor_msgs/msg/JointState` | commands to a robot driver, every control cycle (`hardware: topic`) |
//! | `hardware.state_topic` | `sensor_msgs/msg/JointState` | subscription: the driver's measured state (`hardware: topic`; optional with `jtc`) |
//! | `hardware.jtc_action` | `control_msgs/action/FollowJointTrajectory` | action client: an external trajectory controller (`hardware: jtc`) |
//!
//! # Hardware
//! `hardware: mock` (the default) drives `kerf_executor::MockHardware`; `hardware: sim`
//! drives a simulated cell (`kerf_cell`, parameters `sim_cell`, `sim_mode`,
//! `sim_physics_rate`), whose physics steps run in lock-step with the control loop
//! ([`hardware::Hardware`]). In sim mode:
//! * the executor runs on the simulated time, which advances exactly one control period per
//!   cycle from the system time of the node's start; it is published on `/clock` and stamps
//!   every message (so `use_sim_time` nodes and nodes on the system clock both see times
//!   close to their own, unless the loop overruns);
//! * `/joint_states` is the simulated state with the drive efforts; path and goal tolerances
//!   are judged on it (as JTC judges them on the hardware's state);
//! * a contact during motion is a fault ([`control`]): the motion is brought to a controlled
//!   stop within the limits and the goal is aborted (PATH_TOLERANCE_VIOLATED) with a message
//!   naming the links, the objects and the depths. Contacts present when a motion starts are
//!   tolerated while they do not get deeper, so that the robot can be moved out of them.
//!
//!
//! `hardware: topic` drives a real robot's driver ([`driver`], issue 27): the command of every
//! control cycle goes to `hardware.command_topic` (ros2_control's `forward_command_controller`
//! or a topic-based driver), the measured state comes from `hardware.state_topic`, and path
//! and goal tolerances are judged on it. Goals wait for the driver's first state, which
//! becomes the robot's start; a watchdog (`hardware.feedback_timeout_periods`), refused states
//! (NaN, a missing joint), stamps that go back, unreadable samples and driver topics of
//! another type abort the running goal (PATH_TOLERANCE_VIOLATED, the fault named) with a
//! controlled stop and refuse new goals until good states come back. `joint_states`
//! republishes the driver's good states as received.
//!
//! `hardware: jtc` forwards each validated trajectory to an external FollowJointTrajectory
//! server ([`jtc`]) and relays acceptance, feedback, results and cancels; there is no control
//! loop then.
//!
//! # Threads
//! * **control** ([`control::ControlLoop`]): read → update → write every control period. It
//!   does nothing whose cost depends on a trajectory's size: requests arrive prepared, are
//!   finished against the commanded state in O(joints) (shared segments, no copy), and
//!   everything large is freed on the request thread. It owns no DDS endpoint; its state
//!   streams leave through bounded queues ([`kerf_ros::Streamer`]). With
//!   `realtime_priority > 0` it runs `SCHED_FIFO`.
//! * **requests** (the thread calling [`run`]): every DDS endpoint — the trajectory topic's
//!   inbox, the action server (whose goals are deserialized here), the validate service — and
//!   the goal book-keeping; it hands prepared requests to the control thread and publishes
//!   what comes back (statuses, action results, feedback, log lines).
//! * **stream** ([`kerf_ros::Worker`]): plans the streaming mode's batches ([`stream`]; about
//!   0.8 ms per point of a six-joint batch), so that the request thread never waits for one.
//! * **prepare** ([`kerf_ros::Worker`]): validation against the robot model
//!   (`kerf_executor::prepare`, O(points · joints), about 3 ms for 1000 six-joint quintic
//!   points in a release build), one request at a time in arrival order.
//!
//! As in JTC, an empty `JointTrajectory` (no points) on `~/joint_trajectory` stops the current
//! motion (here: a controlled stop within the acceleration limits) and the robot holds.
//!
//! Every cycle follows ros2_control's read → update → write order: the measured state is read
//! from the hardware (mock or simulated cell), the executor computes the reference, the
//! reference is written to the hardware and published on `~/joint_command`.

pub mod action;
pub mod config;
pub mod control;
pub mod convert;
pub mod driver;
mod goals;
pub mod hardware;
pub mod jtc;
pub mod memory;
pub mod stream;
mod validate_service;

use std::{
    collections::HashMap,
    sync::{
        atomic::{AtomicBool, Ordering},
        mpsc::{channel, Receiver, Sender},
        Arc,
    },
    thread::JoinHandle,
    time::Duration as StdDuration,
};

use kerf_executor::{
    prepare, Executor, ExecutorError, GoalId as ExecGoalId, GoalTolerances, Outcome,
    PreparedTrajectory, TrajectoryRequest, INVALID_GOAL, SUCCESSFUL,
};
use kerf_msgs::{
    builtin_interfaces::Time,
    control_msgs::{
        FollowJointTrajectoryFeedback, FollowJointTrajectoryGoal, FollowJointTrajectoryResult,
        JointTrajectoryControllerState,
    },
    msg::{CellContacts, ReferencePoint, StreamStatus, TrajectoryStatus},
    rosgraph_msgs::Clock as ClockMsg,
    sensor_msgs::JointState,
    srv::{ValidateTrajectoryRequest, ValidateTrajectoryResponse},
    std_msgs::{Float64MultiArray, Header},
    trajectory_msgs::JointTrajectory,
    RosType,
};
use kerf_robot::RobotError;
use kerf_ros::{
    qos, Inbox, KerfNode, Logger, NodeSpec, RosArgs, RosEnv, RosError, StopToken, Streamer, Worker,
};
use ros2_client::{
    action::{ActionServer, GoalId, GoalStatusEnum},
    builtin_interfaces::Time as RosTime,
    RmwRequestId, Server,
};

use config::{CommandType, DriverConfig, JtcConfig, TopicConfig};
pub use config::{NodeConfig, KNOWN_PARAMS};
use convert::{Clock, Rejection};
use driver::{CommandStream, FeedbackMonitor, TopicDriver, TopicRole};

/// Default node name.
pub const DEFAULT_NAME: &str = "trajectory_executor";

/// Samples each outgoing stream may queue before new ones are dropped (0.25 s at 250 Hz).
const STREAM_QUEUE: usize = 64;

/// History depth of `~/reference_points` and `~/stream_status` and the status queue: a burst
/// of points (and their answers) is not lost to a keep-last history.
const REFERENCE_DEPTH: usize = 1000;

/// The request thread waits at most this long for a report of the control thread before it
/// polls its DDS endpoints again.
const REQUEST_POLL: StdDuration = StdDuration::from_millis(1);

/// What goes wrong in the node: why it could not start, and the faults of a real robot's
/// driver (`hardware: topic` or `jtc`), which abort goals and refuse new ones but never end
/// the node.
#[derive(Debug, thiserror::Error)]
pub enum NodeError {
    /// Environment, arguments, names or DDS.
    #[error(transparent)]
    Ros(#[from] RosError),
    /// The robot description could not be loaded.
    #[error("robot description: {0}")]
    Robot(#[from] RobotError),
    /// The executor refused the configuration.
    #[error("executor configuration: {0}")]
    Executor(#[from] ExecutorError),
    /// A parameter is inconsistent with the robot.
    #[error("parameter '{name}': {reason}")]
    Config {
        /// Parameter.
        name: String,
        /// What is wrong.
        reason: String,
    },
    /// No joint state has come from the driver yet.
    #[error("waiting for the driver: no joint state on {topic} yet")]
    WaitingForDriver {
        /// The driver's joint-state topic.
        topic: String,
    },
    /// The driver's joint states stopped coming ([`kerf_executor::FeedbackWatchdog`]).
    #[error(
        "feedback stale: no joint state on {topic} for {age_ms:.1} ms ({periods:.1} control \
         periods; hardware.feedback_timeout_periods allows {allowed})"
    )]
    FeedbackStale {
        /// The driver's joint-state topic.
        topic: String,
        /// Time since the last state (ms).
        age_ms: f64,
        /// The same in control periods.
        periods: f64,
        /// The periods allowed.
        allowed: u32,
    },
    /// A joint state's stamp is older than the previous one's.
    #[error(
        "feedback stamp went back on {topic}: stamp {got} after {previous} (the driver's clock \
         stepped back, or a sample came out of order); the state was not used"
    )]
    FeedbackStampBack {
        /// The driver's joint-state topic.
        topic: String,
        /// The previous stamp (`sec.nanosec`).
        previous: String,
        /// The new stamp (`sec.nanosec`).
        got: String,
    },
    /// A joint state that `kerf_executor::measured_state` refuses (NaN, a missing joint, wrong
    /// lengths), or a position outside the robot's limits.
    #[error("bad joint state on {topic}: {reason}")]
    BadFeedback {
        /// The driver's joint-state topic.
        topic: String,
        /// What is wrong, naming the joint.
        reason: String,
    },
    /// A sample on the driver's joint-state topic could not be read.
    #[error("could not read a joint state on {topic} (is it a {expected}?): {reason}")]
    UnreadableFeedback {
        /// The driver's joint-state topic.
        topic: String,
        /// The type the executor reads.
        expected: &'static str,
        /// The reader's error.
        reason: String,
    },
    /// A driver topic has an endpoint of another type on the domain.
    #[error(
        "driver topic {topic} has a {endpoint} of type {found}, but the executor {role} \
         {expected} there; fix the driver's or the executor's configuration \
         (hardware.command_type, hardware.state_topic, hardware.command_topic)"
    )]
    WrongTopicType {
        /// The topic.
        topic: String,
        /// "publisher" or "subscription".
        endpoint: &'static str,
        /// Its type.
        found: String,
        /// "reads" or "publishes".
        role: &'static str,
        /// The executor's type.
        expected: &'static str,
    },
    /// The external FollowJointTrajectory server of `hardware: jtc` refused a goal, did not
    /// answer, or went away.
    #[error("external FollowJointTrajectory server {action}: {reason}")]
    ExternalServer {
        /// The external action.
        action: String,
        /// What happened.
        reason: String,
    },
}

type FjtServer = ActionServer<
    FollowJointTrajectoryGoal,
    FollowJointTrajectoryResult,
    FollowJointTrajectoryFeedback,
>;

/// A request for the preparation worker: converted from its message and checked against the
/// robot there, off the control thread.
enum Incoming {
    /// A topic trajectory or a ValidateTrajectory request's trajectory.
    Trajectory(JointTrajectory),
    /// A FollowJointTrajectory goal.
    Goal(Box<FollowJointTrajectoryGoal>),
    /// An empty topic trajectory: nothing to prepare, kept in order with the others.
    Stop,
}

impl Incoming {
    /// Number of trajectory points the request carries.
    fn point_count(&self) -> usize {
        match self {
            Incoming::Trajectory(msg) => msg.points.len(),
            Incoming::Goal(goal) => goal.trajectory.points.len(),
            Incoming::Stop => 0,
        }
    }
}

/// What the worker returns: `None` for [`Incoming::Stop`].
type Prepared = Result<(PreparedTrajectory, GoalTolerances), Rejection>;

/// What to do with a prepared request.
#[derive(Debug, Clone)]
enum Job {
    /// Start it (topic trajectory or action goal).
    Run(Source),
    /// Answer a ValidateTrajectory request.
    Validate(RmwRequestId),
    /// An empty topic trajectory: stop the current motion.
    Stop(Source),
    /// The dry-run check of a stream's start point (its id).
    StreamStart(u32),
}

/// Where an executor goal came from.
#[derive(Debug, Clone)]
enum Source {
    Topic {
        stamp: Time,
    },
    Action {
        id: GoalId,
        stamp: Time,
    },
    /// A batch of the reference-point stream ([`stream`]).
    Stream {
        batch: u64,
    },
}

impl Source {
    /// "trajectory from topic" or "goal <id>", for log lines.
    fn describe(&self) -> String {
        match self {
            Source::Topic { .. } => "trajectory from topic".to_string(),
            Source::Action { id, .. } => format!("goal {id:?}"),
            Source::Stream { batch } => format!("stream batch {batch}"),
        }
    }
}

/// Runs the node until its stop token (or Ctrl-C) stops it.
///
/// # Returns
/// `Ok` after a clean shutdown; an error if the node could not start (bad parameter,
/// unreadable robot description, DDS failure, real-time priority refused) or if the control
/// thread ended unexpectedly. Request errors never end the node.
pub fn run(args: &RosArgs, env: &RosEnv, stop: StopToken) -> Result<(), NodeError> {
    let node = KerfNode::new(
        NodeSpec {
            default_name: DEFAULT_NAME,
            default_namespace: "/",
            known_params: KNOWN_PARAMS,
        },
        args,
        env,
        stop,
    )?;
    let log = node.logger();
    let cfg = match NodeConfig::from_params(node.params()) {
        Ok(c) => c,
        Err(e) => {
            log.error(&format!("cannot start: {e}"));
            return Err(e);
        }
    };
    let mut n = ExecutorNode::new(node, cfg)?;
    let result = n.spin();
    if let Err(e) = &result {
        log.error(&e.to_string());
    }
    result
}

/// The node's request thread. Fields drop in declaration order: the control thread is
/// stopped and joined in [`ExecutorNode::spin`] (its streams are DDS publishers of `node`),
/// then the DDS endpoints drop, `node` (and its Context) last.
struct ExecutorNode {
    traj_sub: Inbox<JointTrajectory>,
    action: FjtServer,
    validate_srv: Server<ValidateTrajectoryRequest, ValidateTrajectoryResponse>,
    status: Streamer<TrajectoryStatus>,
    /// The streaming mode's points and answers.
    reference_sub: Inbox<ReferencePoint>,
    stream_status: Streamer<StreamStatus>,
    streaming: stream::Streaming,
    /// Batches of the stream are planned here (up to about 0.2 s for a full queue), off the
    /// request thread.
    stream_planner: Worker<stream::PlanJob, stream::PlanDone>,
    goals: action::ActionGoals,
    /// The request behind each running executor goal.
    sources: HashMap<ExecGoalId, Source>,
    /// Validation of incoming trajectories (O(points · joints)) runs here, off the control
    /// thread; one thread, so results come back in arrival order.
    prep: Worker<Incoming, Option<Prepared>>,
    /// Requests being prepared, by ticket.
    jobs: HashMap<u64, Job>,
    /// Requests handed to the control thread and not answered yet, by ticket.
    dispatched: HashMap<u64, Job>,
    commands: Sender<control::Command>,
    reports: Receiver<control::Report>,
    control_running: Arc<AtomicBool>,
    control: Option<JoinHandle<()>>,
    /// `hardware: jtc`: the external server (no control thread then).
    jtc: Option<Box<jtc::Forwarder>>,
    jtc_events: Vec<jtc::JtcEvent>,
    /// `hardware: topic`: the check of the driver topics' types.
    driver_types: Option<TypeWatch>,
    statuses_changed: bool,
    publish_failures: u64,
    clock: Clock,
    log: Logger,
    node: KerfNode,
}

/// What runs the trajectories: the control loop (mock, simulated cell, topic driver), or an
/// external FollowJointTrajectory server.
enum Backend {
    Control {
        hw: hardware::Hardware,
        joint_states: Streamer<JointState>,
    },
    Jtc(Box<jtc::Forwarder>),
}

/// How often the request thread checks the types of a topic driver's endpoints (discovery
/// changes at DDS's pace: a second or so).
const TYPE_CHECK_PERIOD: StdDuration = StdDuration::from_millis(200);

/// The check of a topic driver's topics for endpoints of another type
/// ([`driver::check_topic_types`]), run on the request thread.
struct TypeWatch {
    state_topic: String,
    command_topic: String,
    command_type: &'static str,
    last: Option<String>,
    next: std::time::Instant,
}

/// The executor's own topics, resolved: a driver topic must be none of them.
fn own_topics(node: &KerfNode) -> Result<Vec<String>, NodeError> {
    [
        "joint_states",
        "~/joint_command",
        "~/controller_state",
        "~/trajectory_status",
        "~/joint_trajectory",
        "~/reference_points",
        "~/stream_status",
        "~/contacts",
        "/clock",
    ]
    .iter()
    .map(|t| node.resolve(t).map_err(NodeError::from))
    .collect()
}

/// A driver topic parameter resolved as the node sees it, refused when it is one of the
/// executor's own topics.
fn driver_topic(node: &KerfNode, param: &str, topic: &str) -> Result<String, NodeError> {
    let resolved = node.resolve(topic).map_err(|e| NodeError::Config {
        name: param.into(),
        reason: e.to_string(),
    })?;
    if own_topics(node)?.contains(&resolved) {
        return Err(NodeError::Config {
            name: param.into(),
            reason: format!(
                "'{topic}' resolves to {resolved}, a topic of the executor itself; the driver \
                 needs topics of its own (e.g. /driver/joint_states, with ros2_control's \
                 joint_state_broadcaster remapped there)"
            ),
        });
    }
    Ok(resolved)
}

/// The endpoints of `hardware: topic`: the joint-state inbox, the command stream, the
/// feedback monitor, and the type check of both topics.
fn topic_driver(
    node: &mut KerfNode,
    cfg: &NodeConfig,
    t: &TopicConfig,
    clock: &Clock,
) -> Result<(TopicDriver, TypeWatch), NodeError> {
    let state_topic = driver_topic(node, "hardware.state_topic", &t.state_topic)?;
    let command_topic = driver_topic(node, "hardware.command_topic", &t.command_topic)?;
    if state_topic == command_topic {
        return Err(NodeError::Config {
            name: "hardware.state_topic".into(),
            reason: format!(
                "{state_topic} is also hardware.command_topic; the driver's joint states and \
                 the commands need two topics"
            ),
        });
    }
    let (q, rate) = (STREAM_QUEUE, cfg.control_rate);
    let states = node.inbox(&state_topic, JointState::ROS_TYPE, qos::state())?;
    let command = match t.command_type {
        CommandType::Float64MultiArray => CommandStream::Array(node.streamer(
            &command_topic,
            Float64MultiArray::ROS_TYPE,
            qos::state(),
            q,
            rate,
        )?),
        CommandType::JointState => CommandStream::State(node.streamer(
            &command_topic,
            JointState::ROS_TYPE,
            qos::state(),
            q,
            rate,
        )?),
    };
    let monitor = FeedbackMonitor::new(
        &state_topic,
        cfg.limits.clone(),
        cfg.executor.control_period,
        t.feedback_timeout_periods,
        cfg.executor.start_tolerance,
    )?;
    let names = cfg.limits.iter().map(|l| l.name.clone()).collect();
    let watch = TypeWatch {
        state_topic: state_topic.clone(),
        command_topic,
        command_type: t.command_type.ros_type(),
        last: None,
        next: std::time::Instant::now(),
    };
    Ok((
        TopicDriver::new(monitor, states, command, names, clock.clone()),
        watch,
    ))
}

/// The external server's client and the optional joint-state inbox of `hardware: jtc`.
fn jtc_forwarder(
    node: &mut KerfNode,
    cfg: &NodeConfig,
    j: &JtcConfig,
    joint_states: Streamer<JointState>,
) -> Result<jtc::Forwarder, NodeError> {
    let action = node.resolve(&j.action).map_err(|e| NodeError::Config {
        name: "hardware.jtc_action".into(),
        reason: e.to_string(),
    })?;
    if action == node.resolve("~/follow_joint_trajectory")? {
        return Err(NodeError::Config {
            name: "hardware.jtc_action".into(),
            reason: format!(
                "'{}' resolves to {action}, the executor's own action: goals would be forwarded \
                 to itself",
                j.action
            ),
        });
    }
    let states = match &j.state_topic {
        None => None,
        Some(t) => {
            let topic = driver_topic(node, "hardware.state_topic", t)?;
            Some((
                node.inbox(&topic, JointState::ROS_TYPE, qos::state())?,
                topic,
            ))
        }
    };
    let client = node.action_client(&action, "control_msgs/action/FollowJointTrajectory")?;
    Ok(jtc::Forwarder::new(
        client,
        action,
        j.timeout,
        cfg.limits.clone(),
        cfg.executor.clone(),
        states,
        joint_states,
        cfg.initial_positions.clone(),
    ))
}

impl ExecutorNode {
    fn new(mut node: KerfNode, cfg: NodeConfig) -> Result<Self, NodeError> {
        let exec = Executor::new(
            cfg.limits.clone(),
            cfg.executor.clone(),
            cfg.initial_positions.clone(),
        )?;
        // Read on its own thread: deserializing a large trajectory takes milliseconds.
        let traj_sub = node.inbox(
            "~/joint_trajectory",
            JointTrajectory::ROS_TYPE,
            qos::commands(),
        )?;
        let action = node.action_server(
            "~/follow_joint_trajectory",
            "control_msgs/action/FollowJointTrajectory",
        )?;
        let validate_srv =
            node.service_server("~/validate_trajectory", "kerf_msgs/srv/ValidateTrajectory")?;
        let clock = if cfg.sim.is_some() {
            Clock::simulated()
        } else {
            Clock::start()
        };
        let (q, rate) = (STREAM_QUEUE, cfg.control_rate);
        let joint_states =
            node.streamer("joint_states", JointState::ROS_TYPE, qos::state(), q, rate)?;
        let mut driver_types = None;
        let backend = match &cfg.driver {
            None => Backend::Control {
                hw: hardware::Hardware::build(&cfg)?,
                joint_states,
            },
            Some(DriverConfig::Topic(t)) => {
                let (driver, watch) = topic_driver(&mut node, &cfg, t, &clock)?;
                driver_types = Some(watch);
                Backend::Control {
                    hw: hardware::Hardware::Topic(Box::new(driver)),
                    joint_states,
                }
            }
            Some(DriverConfig::Jtc(j)) => {
                Backend::Jtc(Box::new(jtc_forwarder(&mut node, &cfg, j, joint_states)?))
            }
        };
        let status = node.streamer(
            "~/trajectory_status",
            TrajectoryStatus::ROS_TYPE,
            qos::latched(),
            q,
            rate,
        )?;
        let reference_sub = node.inbox(
            "~/reference_points",
            ReferencePoint::ROS_TYPE,
            qos::reliable(REFERENCE_DEPTH),
        )?;
        let stream_status = node.streamer(
            "~/stream_status",
            StreamStatus::ROS_TYPE,
            qos::reliable(REFERENCE_DEPTH),
            REFERENCE_DEPTH,
            rate,
        )?;
        let streaming = stream::Streaming::new(&cfg)?;
        let stream_planner =
            Worker::spawn("stream", 1, streaming.planner()).map_err(|e| RosError::Dds {
                what: "stream planning thread".into(),
                reason: e.to_string(),
            })?;
        let log = node.logger();
        let (limits, exec_cfg) = (cfg.limits.clone(), cfg.executor.clone());
        let prep_clock = clock.clone();
        let prep = Worker::spawn("prepare", 1, move |incoming: Incoming| {
            let prepared = |req: TrajectoryRequest, tol: GoalTolerances| -> Prepared {
                Ok((prepare(&limits, &exec_cfg, &req)?, tol))
            };
            let points = incoming.point_count();
            let result = match incoming {
                Incoming::Stop => None,
                Incoming::Trajectory(msg) => Some(
                    convert::trajectory_request(&msg, &prep_clock)
                        .and_then(|req| prepared(req, GoalTolerances::default())),
                ),
                Incoming::Goal(goal) => Some(
                    convert::goal_request(&goal, &prep_clock)
                        .and_then(|(req, tol)| prepared(req, tol)),
                ),
            };
            // The message and the request are freed by now; the prepared trajectory keeps
            // only its compact arrays.
            if points >= memory::TRIM_AFTER_POINTS {
                memory::give_back_freed_memory();
            }
            result
        })
        .map_err(|e| RosError::Dds {
            what: "trajectory preparation thread".into(),
            reason: e.to_string(),
        })?;

        let (commands, command_rx) = channel();
        let (report_tx, reports) = channel();
        let control_running = Arc::new(AtomicBool::new(true));
        let (control, jtc) = match backend {
            // No control loop: the external server commands the robot.
            Backend::Jtc(forwarder) => (None, Some(forwarder)),
            Backend::Control { hw, joint_states } => {
                // Outgoing streams leave the control thread through bounded queues: a stalled
                // subscriber can cost samples but never blocks the control loop. Each is published
                // once per control period at most, and its writer's send window outlasts the lease of
                // a reader that stops acknowledging (`kerf_ros::qos::send_window`): a dead reader
                // never stalls the others.
                let streams = control::Streams {
                    joint_states,
                    controller_state: node.streamer(
                        "~/controller_state",
                        JointTrajectoryControllerState::ROS_TYPE,
                        qos::state(),
                        q,
                        rate,
                    )?,
                    command: node.streamer(
                        "~/joint_command",
                        JointState::ROS_TYPE,
                        qos::state(),
                        q,
                        rate,
                    )?,
                    sim: match &cfg.sim {
                        None => None,
                        Some(_) => Some(control::SimStreams {
                            clock: node.streamer(
                                "/clock",
                                ClockMsg::ROS_TYPE,
                                qos::state(),
                                q,
                                rate,
                            )?,
                            contacts: node.streamer(
                                "~/contacts",
                                CellContacts::ROS_TYPE,
                                qos::state(),
                                q,
                                rate,
                            )?,
                            frame_id: cfg.robot.root_link().to_string(),
                        }),
                    },
                };
                let loop_cfg = control::LoopConfig {
                    limits: cfg.limits.clone(),
                    control_rate: cfg.control_rate,
                    action_monitor_rate: cfg.action_monitor_rate,
                    control_period: cfg.executor.control_period,
                };
                let control_loop = control::ControlLoop::new(
                    exec,
                    hw,
                    loop_cfg,
                    streams,
                    command_rx,
                    report_tx,
                    Arc::clone(&control_running),
                    clock.clone(),
                );
                let control = spawn_control(control_loop, cfg.realtime_priority, &log)?;
                (Some(control), None)
            }
        };
        let names: Vec<&str> = cfg.limits.iter().map(|l| l.name.as_str()).collect();
        let hardware = match (&cfg.sim, &cfg.driver) {
            (_, Some(DriverConfig::Topic(t))) => format!(
                "robot driver: commands ({}) on {}, joint states on {}, stale after {} control \
                 periods",
                t.command_type.ros_type(),
                node.resolve(&t.command_topic)?,
                node.resolve(&t.state_topic)?,
                t.feedback_timeout_periods
            ),
            (_, Some(DriverConfig::Jtc(j))) => format!(
                "external FollowJointTrajectory server {} (timeout {} s){}",
                node.resolve(&j.action)?,
                j.timeout,
                match &j.state_topic {
                    Some(t) => format!(", joint states on {}", node.resolve(t)?),
                    None => String::new(),
                }
            ),
            (None, None) => "mock hardware".to_string(),
            (Some(sim), None) => format!(
                "simulated cell {} ({}, physics {} Hz)",
                sim.cell_file.display(),
                match sim.mode {
                    kerf_cell::Mode::Kinematic => "kinematic",
                    kerf_cell::Mode::Dynamic => "dynamic",
                },
                sim.physics_rate
            ),
        };
        log.info(&format!(
            "ready: robot '{}', joints [{}], {} Hz, {hardware}; trajectories on {}, action {}",
            cfg.robot.name(),
            names.join(", "),
            cfg.control_rate,
            node.resolve("~/joint_trajectory")?,
            node.resolve("~/follow_joint_trajectory")?,
        ));
        if matches!(cfg.driver, Some(DriverConfig::Topic(_)))
            && node.params().get("initial_positions").is_some()
        {
            log.info(
                "initial_positions is not used with hardware: topic: the robot starts where the \
                 driver's first joint state says",
            );
        }
        Ok(Self {
            traj_sub,
            action,
            validate_srv,
            status,
            reference_sub,
            stream_status,
            streaming,
            stream_planner,
            goals: action::ActionGoals::default(),
            sources: HashMap::new(),
            prep,
            jobs: HashMap::new(),
            dispatched: HashMap::new(),
            commands,
            reports,
            control_running,
            control,
            jtc,
            jtc_events: Vec::new(),
            driver_types,
            statuses_changed: false,
            publish_failures: 0,
            clock,
            log,
            node,
        })
    }

    /// Serves requests until the node is stopped, then stops and joins the control thread.
    fn spin(&mut self) -> Result<(), NodeError> {
        let mut result = Ok(());
        while !self.node.should_stop() {
            if self.jtc.is_none() && self.control.as_ref().is_none_or(|h| h.is_finished()) {
                result = Err(NodeError::Config {
                    name: "control thread".into(),
                    reason: "the control loop ended unexpectedly; the node stops".into(),
                });
                break;
            }
            self.poll_trajectories();
            self.poll_goals();
            self.poll_cancels();
            self.poll_result_requests();
            self.poll_validate();
            self.poll_reference_points();
            self.poll_prepared();
            self.check_driver_types();
            if self.jtc.is_some() {
                self.poll_jtc();
                std::thread::sleep(REQUEST_POLL);
            } else if let Ok(r) = self.reports.recv_timeout(REQUEST_POLL) {
                self.on_report(r);
            }
            while let Ok(r) = self.reports.try_recv() {
                self.on_report(r);
            }
            self.next_stream_batch();
            self.answer_results();
            if self.statuses_changed {
                self.statuses_changed = false;
                if let Err(e) = self.action.send_goal_statuses(self.goals.status_array()) {
                    self.log.warn(&format!("goal status not published: {e:?}"));
                }
            }
        }
        self.log.info("shutting down");
        self.control_running.store(false, Ordering::Relaxed);
        if let Some(h) = self.control.take() {
            if h.join().is_err() && result.is_ok() {
                result = Err(NodeError::Config {
                    name: "control thread".into(),
                    reason: "the control loop panicked".into(),
                });
            }
        }
        result
    }

    /// Hands a command to the control thread; if it has ended (`spin` then stops the node),
    /// the request is answered with a rejection instead.
    fn dispatch(&mut self, tag: u64, job: Job, command: control::Command) {
        if self.commands.send(command).is_ok() {
            self.dispatched.insert(tag, job);
            return;
        }
        let rej = Rejection {
            code: INVALID_GOAL,
            message: "the control loop has ended; the executor is stopping".into(),
        };
        match job {
            Job::Run(source) => self.rejected(&source, rej),
            Job::Validate(req_id) => self.answer_validate(req_id, Err(rej)),
            Job::Stop(source) => {
                self.log.error(&rej.message);
                let status = TrajectoryStatus::REJECTED;
                self.trajectory_status(&source, status, rej.code, &rej.message);
            }
            job @ Job::StreamStart(_) => self.answer_check(job, Err(rej)),
        }
    }

    fn on_report(&mut self, report: control::Report) {
        use control::Report;
        match report {
            Report::Started {
                tag,
                exec_id,
                points,
                duration,
            } => {
                let Some(Job::Run(source)) = self.dispatched.remove(&tag) else {
                    return;
                };
                let what = source.describe();
                self.log.info(&format!(
                    "accepted {what}: {points} points over {duration:.3} s"
                ));
                self.trajectory_status(&source, TrajectoryStatus::ACCEPTED, SUCCESSFUL, "accepted");
                if let Source::Action { id, .. } = &source {
                    if let Some(g) = self.goals.get_mut(id) {
                        g.exec_id = Some(exec_id);
                    }
                }
                if !matches!(source, Source::Stream { .. }) {
                    let out = self.streaming.robot_moved_by_other(&what);
                    self.publish_stream(out);
                }
                self.sources.insert(exec_id, source);
            }
            Report::Refused { tag, rejection } => {
                if let Some(Job::Run(source)) = self.dispatched.remove(&tag) {
                    self.rejected(&source, rejection);
                }
            }
            Report::Validated { tag, result } => {
                if let Some(job @ (Job::Validate(_) | Job::StreamStart(_))) =
                    self.dispatched.remove(&tag)
                {
                    self.answer_check(job, result);
                }
            }
            Report::Stopping { tag, message } => {
                if let Some(Job::Stop(source)) = self.dispatched.remove(&tag) {
                    self.log.info(&message);
                    self.trajectory_status(
                        &source,
                        TrajectoryStatus::ACCEPTED,
                        SUCCESSFUL,
                        &message,
                    );
                }
            }
            Report::Finished { exec_id, outcome } => self.finish(exec_id, outcome),
            Report::Feedback { exec_id, feedback } => {
                if let Some(Source::Action { id, .. }) = self.sources.get(&exec_id) {
                    if let Err(e) = self.action.send_feedback(*id, *feedback) {
                        self.log.debug(&format!("feedback not sent: {e:?}"));
                    }
                }
            }
            Report::Log { level, message } => self.log.log(level, &message),
            // Freed here, off the control thread.
            Report::Trash(trash) => drop(trash),
        }
    }

    fn trajectory_status(&mut self, source: &Source, status: u8, code: i32, message: &str) {
        let (src, goal_id, stamp) = match source {
            Source::Topic { stamp } => (TrajectoryStatus::SOURCE_TOPIC, String::new(), *stamp),
            Source::Action { id, stamp } => (
                TrajectoryStatus::SOURCE_ACTION,
                action::goal_id_hex(id),
                *stamp,
            ),
            Source::Stream { .. } => (TrajectoryStatus::SOURCE_STREAM, String::new(), Time::ZERO),
        };
        let msg = TrajectoryStatus {
            header: Header {
                stamp: self.clock.stamp(self.clock.now()),
                frame_id: String::new(),
            },
            trajectory_stamp: stamp,
            source: src.to_string(),
            goal_id,
            status,
            error_code: code,
            message: message.to_string(),
        };
        let f = &mut self.publish_failures;
        if let Some(warning) = control::publish_counted(&self.status, msg, f, "trajectory status") {
            self.log.warn(&warning);
        }
    }

    fn ros_now(&self) -> RosTime {
        RosTime::from_nanos(self.clock.stamp(self.clock.now()).as_nanos())
    }

    fn poll_trajectories(&mut self) {
        while let Some(received) = self.traj_sub.try_recv() {
            match received {
                Ok(msg) => self.on_trajectory(msg),
                Err(e) => {
                    let msg = format!("could not read a JointTrajectory sample: {e}");
                    self.log.error(&msg);
                    let source = Source::Topic { stamp: Time::ZERO };
                    self.trajectory_status(&source, TrajectoryStatus::REJECTED, INVALID_GOAL, &msg);
                }
            }
        }
    }

    /// The streaming mode's points: each answered START (after its check), QUEUED or
    /// REFUSED.
    fn poll_reference_points(&mut self) {
        while let Some(received) = self.reference_sub.try_recv() {
            let msg = match received {
                Ok(msg) => msg,
                Err(e) => {
                    self.log
                        .error(&format!("could not read a ReferencePoint sample: {e}"));
                    continue;
                }
            };
            match self.streaming.push(&msg) {
                stream::PushOutcome::Answered(out) => self.publish_stream(out),
                stream::PushOutcome::CheckStart { id, trajectory } => {
                    self.enqueue(Job::StreamStart(id), Incoming::Trajectory(trajectory));
                }
            }
        }
    }

    /// Hands the stream's planned batches to the executor, and the next batch to the planner
    /// thread when none runs or is being planned and points wait.
    fn next_stream_batch(&mut self) {
        while let Some((_, done)) = self.stream_planner.try_recv() {
            let (batch, out) = match done {
                Ok(done) => self.streaming.planned(done),
                Err(e) => (None, self.streaming.planner_failed(&format!("{e:?}"))),
            };
            self.publish_stream(out);
            if let Some((batch, trajectory)) = batch {
                self.enqueue(
                    Job::Run(Source::Stream { batch }),
                    Incoming::Trajectory(trajectory),
                );
            }
        }
        if let Some(job) = self.streaming.next_job() {
            self.stream_planner.submit(job);
        }
    }

    /// Answers a dry run: the `ValidateTrajectory` service or a stream's start check.
    fn answer_check(&mut self, job: Job, result: Result<f64, Rejection>) {
        match job {
            Job::Validate(req_id) => self.answer_validate(req_id, result),
            Job::StreamStart(id) => {
                let out = self
                    .streaming
                    .start_checked(id, result.map(|_| ()).map_err(|r| r.message));
                self.publish_stream(out);
            }
            Job::Run(_) | Job::Stop(_) => {}
        }
    }

    /// Stamps and publishes stream statuses; refusals and points not reached are logged.
    fn publish_stream(&mut self, statuses: Vec<StreamStatus>) {
        for mut msg in statuses {
            let name = StreamStatus::status_name(msg.status).unwrap_or("?");
            let line = format!("reference point {}: {name} {}", msg.id, msg.message);
            match msg.status {
                StreamStatus::REFUSED | StreamStatus::NOT_REACHED => self.log.warn(&line),
                _ => self.log.debug(&line),
            }
            msg.header.stamp = self.clock.stamp(self.clock.now());
            let f = &mut self.publish_failures;
            let warning = control::publish_counted(&self.stream_status, msg, f, "stream status");
            if let Some(warning) = warning {
                self.log.warn(&warning);
            }
        }
    }

    fn on_trajectory(&mut self, msg: JointTrajectory) {
        let source = Source::Topic {
            stamp: msg.header.stamp,
        };
        if msg.points.is_empty() {
            // Queued behind the trajectories still being prepared, so it stops whatever was
            // sent before it.
            self.enqueue(Job::Stop(source), Incoming::Stop);
        } else {
            self.enqueue(Job::Run(source), Incoming::Trajectory(msg));
        }
    }

    /// `hardware: topic`: checks the driver's topics for endpoints of another type (at most
    /// every [`TYPE_CHECK_PERIOD`]) and tells the control thread when the answer changes.
    fn check_driver_types(&mut self) {
        let Some(w) = self.driver_types.as_mut() else {
            return;
        };
        let now = std::time::Instant::now();
        if now < w.next {
            return;
        }
        w.next = now + TYPE_CHECK_PERIOD;
        let roles = [
            TopicRole {
                topic: &w.state_topic,
                expected: JointState::ROS_TYPE,
                executor_reads: true,
            },
            TopicRole {
                topic: &w.command_topic,
                expected: w.command_type,
                executor_reads: false,
            },
        ];
        let found = driver::check_topic_types(
            &roles,
            &self.node.discovered_topics(),
            &self.node.discovered_subscriptions(),
        );
        if found == w.last {
            return;
        }
        if found.is_none() {
            self.log.info("the driver topics' types are right again");
        }
        w.last.clone_from(&found);
        let _ = self
            .commands
            .send(control::Command::DriverTypes { fault: found });
    }

    /// `hardware: jtc`: the external server's answers, feedback and results, relayed.
    fn poll_jtc(&mut self) {
        let Some(f) = self.jtc.as_mut() else {
            return;
        };
        let mut events = std::mem::take(&mut self.jtc_events);
        f.poll(self.clock.now(), &mut events);
        for event in events.drain(..) {
            match event {
                jtc::JtcEvent::Accepted { exec_id } => {
                    if let Some(source) = self.sources.get(&exec_id).cloned() {
                        let action = self.jtc.as_ref().map_or("", |f| f.action()).to_string();
                        self.log.info(&format!(
                            "{} accepted by the external server {action}",
                            source.describe()
                        ));
                        self.trajectory_status(
                            &source,
                            TrajectoryStatus::ACCEPTED,
                            SUCCESSFUL,
                            "accepted",
                        );
                    }
                }
                jtc::JtcEvent::Finished { exec_id, outcome } => self.finish(exec_id, outcome),
                jtc::JtcEvent::Feedback { exec_id, feedback } => {
                    if let Some(Source::Action { id, .. }) = self.sources.get(&exec_id) {
                        if let Err(e) = self.action.send_feedback(*id, *feedback) {
                            self.log.debug(&format!("feedback not sent: {e:?}"));
                        }
                    }
                }
                jtc::JtcEvent::Log { level, message } => self.log.log(level, &message),
            }
        }
        self.jtc_events = events;
    }

    /// `hardware: jtc`: validates a prepared trajectory from the robot's state and forwards
    /// its goal to the external server.
    fn forward(&mut self, ticket: u64, source: Source, prepared: Prepared) {
        let Some(f) = self.jtc.as_mut() else {
            return;
        };
        let started = prepared.and_then(|(prepared, tolerances)| {
            f.start(ticket, &prepared, &tolerances, self.clock.now())
        });
        f.forget(ticket);
        match started {
            Ok(exec_id) => {
                if let Source::Action { id, .. } = &source {
                    if let Some(g) = self.goals.get_mut(id) {
                        g.exec_id = Some(exec_id);
                    }
                }
                self.log.info(&format!(
                    "{}: valid, forwarded to the external server",
                    source.describe()
                ));
                self.sources.insert(exec_id, source);
            }
            Err(rej) => self.rejected(&source, rej),
        }
    }

    /// Hands a request to the preparation worker; results come back in order.
    fn enqueue(&mut self, job: Job, incoming: Incoming) {
        // `hardware: jtc`: the message is forwarded once it is valid.
        let forwarded = match (&job, &incoming, self.jtc.is_some()) {
            (Job::Run(_), Incoming::Goal(goal), true) => Some((**goal).clone()),
            (Job::Run(_), Incoming::Trajectory(msg), true) => Some(FollowJointTrajectoryGoal {
                trajectory: msg.clone(),
                ..Default::default()
            }),
            _ => None,
        };
        let ticket = self.prep.submit(incoming);
        if let (Some(goal), Some(f)) = (forwarded, self.jtc.as_mut()) {
            f.keep(ticket, goal);
        }
        if let Job::Run(Source::Action { id, .. }) = &job {
            if let Some(g) = self.goals.get_mut(id) {
                g.ticket = Some(ticket);
            }
        }
        self.jobs.insert(ticket, job);
    }

    fn rejected(&mut self, source: &Source, rej: Rejection) {
        self.log
            .warn(&format!("rejected {}: {}", source.describe(), rej.message));
        self.trajectory_status(source, TrajectoryStatus::REJECTED, rej.code, &rej.message);
        if let Source::Stream { batch } = source {
            let reason = format!("REJECTED by the executor: {}", rej.message);
            let out = self.streaming.batch_ended(*batch, false, &reason);
            self.publish_stream(out);
        }
        if let Source::Action { id, .. } = source {
            self.goals.finish(
                id,
                GoalStatusEnum::Aborted,
                FollowJointTrajectoryResult {
                    error_code: rej.code,
                    error_string: rej.message,
                },
            );
            self.statuses_changed = true;
        }
    }

    /// Hands the requests the worker has prepared to the control thread, in the order they
    /// arrived; answers those that failed preparation.
    fn poll_prepared(&mut self) {
        while let Some((ticket, result)) = self.prep.try_recv() {
            let Some(job) = self.jobs.remove(&ticket) else {
                continue;
            };
            let missing = || Rejection {
                code: INVALID_GOAL,
                message: "no trajectory in the request".into(),
            };
            let prepared = match result {
                Ok(p) => p,
                Err(e) => Some(Err(Rejection {
                    code: INVALID_GOAL,
                    message: format!("internal error while validating: {e}"),
                })),
            };
            match job {
                Job::Stop(source) if self.jtc.is_some() => {
                    let n = self.jtc.as_mut().map_or(0, |f| f.cancel_all());
                    let message = if n == 0 {
                        "empty trajectory: no active motion to stop".to_string()
                    } else {
                        format!("empty trajectory: canceling {n} goal(s) of the external server")
                    };
                    self.log.info(&message);
                    self.trajectory_status(
                        &source,
                        TrajectoryStatus::ACCEPTED,
                        SUCCESSFUL,
                        &message,
                    );
                }
                Job::Stop(source) => {
                    let command = control::Command::Stop { tag: ticket };
                    self.dispatch(ticket, Job::Stop(source), command);
                }
                job @ (Job::Validate(_) | Job::StreamStart(_)) if self.jtc.is_some() => {
                    let now = self.clock.now();
                    let answer = match (prepared.unwrap_or_else(|| Err(missing())), &self.jtc) {
                        (Ok((prepared, tolerances)), Some(f)) => {
                            f.validate(&prepared, &tolerances, now)
                        }
                        (Ok(_), None) => Err(missing()),
                        (Err(rej), _) => Err(rej),
                    };
                    self.answer_check(job, answer);
                }
                job @ (Job::Validate(_) | Job::StreamStart(_)) => {
                    match prepared.unwrap_or_else(|| Err(missing())) {
                        Ok((prepared, tolerances)) => {
                            let command = control::Command::Validate {
                                tag: ticket,
                                prepared,
                                tolerances,
                            };
                            self.dispatch(ticket, job, command);
                        }
                        Err(rej) => self.answer_check(job, Err(rej)),
                    }
                }
                Job::Run(source) => {
                    self.start(ticket, source, prepared.unwrap_or_else(|| Err(missing())));
                }
            }
        }
    }

    fn start(&mut self, ticket: u64, source: Source, prepared: Prepared) {
        if let Source::Action { id, .. } = &source {
            if self
                .goals
                .get(id)
                .is_some_and(|g| g.status == GoalStatusEnum::Canceling)
            {
                if let Some(f) = self.jtc.as_mut() {
                    f.forget(ticket);
                }
                let message = "canceled before it started".to_string();
                self.log.info(&format!("goal {id:?} {message}"));
                self.trajectory_status(&source, TrajectoryStatus::CANCELED, SUCCESSFUL, &message);
                self.goals.finish(
                    id,
                    GoalStatusEnum::Canceled,
                    FollowJointTrajectoryResult {
                        error_code: SUCCESSFUL,
                        error_string: message,
                    },
                );
                self.statuses_changed = true;
                return;
            }
        }
        if self.jtc.is_some() {
            self.forward(ticket, source, prepared);
            return;
        }
        match prepared {
            Ok((prepared, tolerances)) => {
                let command = control::Command::Start {
                    tag: ticket,
                    prepared,
                    tolerances,
                };
                self.dispatch(ticket, Job::Run(source), command);
            }
            Err(rej) => self.rejected(&source, rej),
        }
    }

    fn finish(&mut self, id: ExecGoalId, outcome: Outcome) {
        let Some(source) = self.sources.remove(&id) else {
            return;
        };
        let (status, action_status, code, message) = match outcome {
            Outcome::Succeeded => (
                TrajectoryStatus::SUCCEEDED,
                GoalStatusEnum::Succeeded,
                SUCCESSFUL,
                String::new(),
            ),
            Outcome::Aborted {
                error_code,
                message,
            } => (
                TrajectoryStatus::ABORTED,
                GoalStatusEnum::Aborted,
                error_code,
                message,
            ),
            // JTC ends a preempted goal as CANCELED with INVALID_GOAL and this kind of message.
            Outcome::Preempted => (
                TrajectoryStatus::PREEMPTED,
                GoalStatusEnum::Canceled,
                INVALID_GOAL,
                "preempted by a newer trajectory, which continues from the current commanded state"
                    .to_string(),
            ),
            Outcome::Canceled => (
                TrajectoryStatus::CANCELED,
                GoalStatusEnum::Canceled,
                SUCCESSFUL,
                "canceled; the motion was brought to a controlled stop".to_string(),
            ),
        };
        let name = TrajectoryStatus::status_name(status).unwrap_or("?");
        if message.is_empty() {
            self.log.info(&format!("trajectory {name}"));
        } else if code == SUCCESSFUL {
            self.log.info(&format!("trajectory {name}: {message}"));
        } else {
            self.log.warn(&format!("trajectory {name}: {message}"));
        }
        self.trajectory_status(&source, status, code, &message);
        if let Source::Stream { batch } = source {
            let reason = format!("{name}: {message}");
            let succeeded = status == TrajectoryStatus::SUCCEEDED;
            let out = self.streaming.batch_ended(batch, succeeded, &reason);
            self.publish_stream(out);
        }
        if let Source::Action { id: goal_id, .. } = source {
            self.goals.finish(
                &goal_id,
                action_status,
                FollowJointTrajectoryResult {
                    error_code: code,
                    error_string: message,
                },
            );
            self.statuses_changed = true;
        }
    }
}

/// Starts the control thread running `control_loop`, with `SCHED_FIFO` at `priority` when it
/// is > 0.
///
/// # Errors
/// [`NodeError::Config`] naming `realtime_priority` when the priority is refused, or the
/// thread could not start.
fn spawn_control(
    mut control_loop: control::ControlLoop,
    priority: i64,
    log: &Logger,
) -> Result<JoinHandle<()>, NodeError> {
    // Ok(a warning) once the loop runs, Err(why) if it cannot.
    let (started_tx, started_rx) = channel::<Result<Option<String>, String>>();
    let control = std::thread::Builder::new()
        .name("control".into())
        .spawn(move || {
            let mut warning = None;
            if priority > 0 {
                if let Err(reason) = kerf_ros::set_realtime_priority(priority) {
                    let _ = started_tx.send(Err(reason));
                    return;
                }
                // As ros2_control's `lock_memory`: no major page fault in the loop.
                warning = kerf_ros::lock_memory().err();
            }
            let _ = started_tx.send(Ok(warning));
            control_loop.run();
        })
        .map_err(|e| RosError::Dds {
            what: "control thread".into(),
            reason: e.to_string(),
        })?;
    let refused = |reason: String| {
        log.error(&format!("cannot start: {reason}"));
        NodeError::Config {
            name: "realtime_priority".into(),
            reason,
        }
    };
    match started_rx.recv() {
        Ok(Ok(None)) => {}
        Ok(Ok(Some(warning))) => log.warn(&format!(
            "control thread: {warning}; it may take page faults"
        )),
        Ok(Err(reason)) => {
            let _ = control.join();
            return Err(refused(reason));
        }
        Err(_) => {
            let _ = control.join();
            return Err(refused("the control thread ended at start-up".into()));
        }
    }
    if priority > 0 {
        log.info(&format!(
            "control thread runs SCHED_FIFO at priority {priority}, process memory locked"
        ));
    }
    Ok(control)
}

/// Takes every sample or request available now, in arrival order.
///
/// # Returns
/// The items, and the read error that ended the drain early, if any (e.g. a sample that does
/// not deserialize); items read before it are kept.
fn drain<T, E: std::fmt::Debug>(
    mut read: impl FnMut() -> Result<Option<T>, E>,
) -> (Vec<T>, Option<String>) {
    let mut items = Vec::new();
    loop {
        match read() {
            Ok(Some(x)) => items.push(x),
            Ok(None) => return (items, None),
            Err(e) => return (items, Some(format!("{e:?}"))),
        }
    }
}
