//! The node's parameters, read once at start-up and checked.

use std::path::PathBuf;

use kerf_executor::{ExecutorConfig, JointLimits, JointTolerance};
use kerf_robot::{RobotError, RobotModel};
use kerf_ros::Params;

use crate::NodeError;

/// Parameter names this node reads (`constraints.*` and `hardware.*` are groups).
pub const KNOWN_PARAMS: &[&str] = &[
    "urdf_file",
    "joint_limits_file",
    "control_rate",
    "action_monitor_rate",
    "initial_positions",
    "start_tolerance",
    "realtime_priority",
    "hardware",
    "sim_cell",
    "sim_mode",
    "sim_physics_rate",
    "constraints.*",
    "hardware.*",
    "stream.queue",
    "stream.max_jump",
    "stream.lookahead",
];

/// Default `hardware.command_topic`: the command topic of ros2_control's
/// `forward_command_controller` loaded as `forward_position_controller` (its `~/commands`).
pub const DEFAULT_COMMAND_TOPIC: &str = "/forward_position_controller/commands";

/// Default `hardware.state_topic`: the driver's joint states. Not `/joint_states`, which is the
/// executor's own output; remap ros2_control's `joint_state_broadcaster` there
/// (`-r /joint_states:=/driver/joint_states`) or set this parameter.
pub const DEFAULT_STATE_TOPIC: &str = "/driver/joint_states";

/// Default `hardware.jtc_action`: the action of ros2_control's `joint_trajectory_controller`
/// loaded as `joint_trajectory_controller`.
pub const DEFAULT_JTC_ACTION: &str = "/joint_trajectory_controller/follow_joint_trajectory";

/// Default `hardware.feedback_timeout_periods`: 5 control periods (20 ms at 250 Hz), as
/// ros2_control drivers commonly allow a few missed cycles before they fault.
pub const DEFAULT_FEEDBACK_TIMEOUT_PERIODS: i64 = 5;

/// Longest feedback silence `hardware.feedback_timeout_periods` may allow (s): beyond a second
/// a robot moving at speed travels too far on stale feedback for a watchdog to mean anything.
pub const MAX_FEEDBACK_TIMEOUT_S: f64 = 1.0;

/// Default `hardware.jtc_timeout` (s).
pub const DEFAULT_JTC_TIMEOUT_S: f64 = 1.0;

/// Largest `hardware.jtc_timeout` (s).
pub const MAX_JTC_TIMEOUT_S: f64 = 60.0;

/// The message type of the command stream of `hardware: topic`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CommandType {
    /// `std_msgs/msg/Float64MultiArray`: one position per joint in the model's joint order
    /// (ros2_control's `forward_command_controller` `~/commands`).
    Float64MultiArray,
    /// `sensor_msgs/msg/JointState`: names and positions (topic-based drivers).
    JointState,
}

impl CommandType {
    /// The ROS type name (`std_msgs/msg/Float64MultiArray`).
    pub fn ros_type(self) -> &'static str {
        match self {
            Self::Float64MultiArray => "std_msgs/msg/Float64MultiArray",
            Self::JointState => "sensor_msgs/msg/JointState",
        }
    }
}

/// `hardware: topic`: a driver reached through a command topic and a joint-state topic.
#[derive(Debug, Clone, PartialEq)]
pub struct TopicConfig {
    /// Where the commands go (`hardware.command_topic`).
    pub command_topic: String,
    /// Their type (`hardware.command_type`).
    pub command_type: CommandType,
    /// The driver's measured joint states (`hardware.state_topic`).
    pub state_topic: String,
    /// Control periods without a new joint state before the feedback is stale
    /// (`hardware.feedback_timeout_periods`).
    pub feedback_timeout_periods: u32,
}

/// `hardware: jtc`: an external `control_msgs/action/FollowJointTrajectory` server.
#[derive(Debug, Clone, PartialEq)]
pub struct JtcConfig {
    /// The external action (`hardware.jtc_action`).
    pub action: String,
    /// An optional joint-state topic of the driver (`hardware.state_topic`).
    pub state_topic: Option<String>,
    /// How long to wait for the external server (s, `hardware.jtc_timeout`).
    pub timeout: f64,
}

/// A real robot's driver (`hardware: topic` or `hardware: jtc`).
#[derive(Debug, Clone, PartialEq)]
pub enum DriverConfig {
    /// Command stream and measured joint states.
    Topic(TopicConfig),
    /// Trajectories forwarded to an external FollowJointTrajectory server.
    Jtc(JtcConfig),
}

/// Default `stream.queue`: reference points that may wait for a batch.
pub const DEFAULT_STREAM_QUEUE: i64 = 256;

/// Largest `stream.queue`: one batch plans every waiting point on the request thread.
pub const MAX_STREAM_QUEUE: i64 = 10_000;

/// Default `stream.max_jump` (rad or m): the largest move of a joint between two points.
pub const DEFAULT_STREAM_MAX_JUMP: f64 = 0.5;

/// Default `stream.lookahead`: points RPRO looks ahead at a velocity level.
pub const DEFAULT_STREAM_LOOKAHEAD: i64 = 1;

/// Largest `stream.lookahead` (`kerf_stepping::RproSettings`' bound).
pub const MAX_STREAM_LOOKAHEAD: i64 = 8;

/// The streaming mode's settings (`stream.*`, [`crate::stream`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StreamConfig {
    /// Most points waiting for a batch (`stream.queue`); more are refused.
    pub queue: usize,
    /// Largest move of any joint from one point to the next (`stream.max_jump`, rad or m).
    pub max_jump: f64,
    /// RPRO's look-ahead in points (`stream.lookahead`).
    pub lookahead: usize,
}

/// The simulated cell's settings (`hardware: sim`).
#[derive(Debug, Clone, PartialEq)]
pub struct SimConfig {
    /// The cell file (`sim_cell`), e.g. `urdf/cells/laser_bpillar.yaml`.
    pub cell_file: PathBuf,
    /// Kinematic or dynamic (`sim_mode`).
    pub mode: kerf_cell::Mode,
    /// Physics rate (Hz, `sim_physics_rate`): an integer multiple of the control rate.
    pub physics_rate: f64,
}

/// Everything the node needs, checked.
#[derive(Debug, Clone)]
pub struct NodeConfig {
    /// The robot.
    pub robot: RobotModel,
    /// The URDF file the robot was loaded from (`urdf_file`).
    pub urdf_file: PathBuf,
    /// Joint limits in model order (from the URDF and the limits YAML).
    pub limits: Vec<JointLimits>,
    /// Executor settings (control period, default tolerances, start tolerance).
    pub executor: ExecutorConfig,
    /// Control rate (Hz).
    pub control_rate: f64,
    /// Rate of action feedback (Hz), like JTC's `action_monitor_rate`.
    pub action_monitor_rate: f64,
    /// Initial positions, model order.
    pub initial_positions: Vec<f64>,
    /// Mock hardware first-order lag (s); 0 follows commands exactly.
    pub lag_time_constant: f64,
    /// `SCHED_FIFO` priority of the control thread (1–99); 0 = normal scheduling.
    pub realtime_priority: i64,
    /// The simulated cell (`hardware: sim`); `None` otherwise.
    pub sim: Option<SimConfig>,
    /// A real robot's driver (`hardware: topic` or `jtc`); `None` otherwise.
    pub driver: Option<DriverConfig>,
    /// The streaming mode (`stream.*`).
    pub stream: StreamConfig,
}

fn param_err(name: &str, reason: String) -> NodeError {
    NodeError::Config {
        name: name.to_string(),
        reason,
    }
}

/// Highest `control_rate` (Hz): a 1 ms period. The control loop's own work per cycle stays
/// under 0.1 ms, 10⁶-point hand-overs included (BENCHMARKS.md, issue 11), so 1 kHz leaves a
/// margin of 10; faster than that, the loop's wake-up latency on a loaded PC (measured up to
/// 6.3 ms late) is several periods, and ros2_control's JTC runs at most about this rate.
pub const MAX_CONTROL_RATE_HZ: f64 = 1_000.0;

fn non_negative(params: &Params, name: &str, default: f64) -> Result<f64, NodeError> {
    let v = params.f64_or(name, default)?;
    if !(v.is_finite() && v >= 0.0) {
        return Err(param_err(name, format!("must be finite and >= 0, got {v}")));
    }
    Ok(v)
}

/// A rate (Hz): finite, > 0 and at most `max`, `why` saying where the bound comes from.
fn rate(params: &Params, name: &str, default: f64, max: f64, why: &str) -> Result<f64, NodeError> {
    let v = params.f64_or(name, default)?;
    if !(v.is_finite() && v > 0.0 && v <= max) {
        return Err(param_err(
            name,
            format!("{v} Hz: must be finite, > 0 and <= {max} Hz ({why})"),
        ));
    }
    Ok(v)
}

impl NodeConfig {
    /// Reads and checks every parameter, and loads the robot.
    ///
    /// # Parameters
    /// * `urdf_file` (string, required), `joint_limits_file` (string, required: acceleration
    ///   limits are needed to validate trajectories).
    /// * `control_rate` (Hz, default 250: the 4 ms of seed 001; at most
    ///   [`MAX_CONTROL_RATE_HZ`]), `action_monitor_rate` (Hz, 20; at most the control rate).
    /// * `initial_positions` (one per joint, model order; default all 0, which must be in range).
    /// * `start_tolerance` (default 1e-3): see `kerf_executor::ExecutorConfig`.
    /// * `constraints.stopped_velocity_tolerance` (0.01), `constraints.goal_time` (s, 0 = wait
    ///   forever), `constraints.<joint>.trajectory` and `constraints.<joint>.goal` (position
    ///   tolerances, 0 = unchecked): JTC's names and defaults.
    /// * `hardware` (`mock`, `sim`, `topic` or `jtc`, default `mock`): the hardware the control
    ///   loop drives.
    /// * `hardware.lag_time_constant` (s, default 0: the mock follows commands exactly; must
    ///   be 0 with any other hardware).
    /// * `hardware: topic` (a real robot's driver, e.g. ros2_control with a
    ///   `forward_command_controller` and a `joint_state_broadcaster`; [`crate::driver`]):
    ///   `hardware.command_topic` (default [`DEFAULT_COMMAND_TOPIC`]), `hardware.command_type`
    ///   (`std_msgs/msg/Float64MultiArray`, the default: one position per joint in model order;
    ///   or `sensor_msgs/msg/JointState`: names and positions), `hardware.state_topic`
    ///   (`sensor_msgs/msg/JointState`, default [`DEFAULT_STATE_TOPIC`]; never the executor's own
    ///   topics), `hardware.feedback_timeout_periods` (integer >= 1, default
    ///   [`DEFAULT_FEEDBACK_TIMEOUT_PERIODS`], at most [`MAX_FEEDBACK_TIMEOUT_S`] of control
    ///   periods). The robot starts where the driver's first joint state says;
    ///   `initial_positions` is not used.
    /// * `hardware: jtc` (an external FollowJointTrajectory server; [`crate::jtc`]):
    ///   `hardware.jtc_action` (default [`DEFAULT_JTC_ACTION`]; not the executor's own),
    ///   `hardware.state_topic` (optional: the driver's joint states, the start state of
    ///   validation), `hardware.jtc_timeout` (s, default [`DEFAULT_JTC_TIMEOUT_S`], at most
    ///   [`MAX_JTC_TIMEOUT_S`]). Each `hardware.*` parameter is refused with a hardware it
    ///   does not apply to.
    /// * `sim_cell` (string, required with `hardware: sim`): the cell file (`kerf_cell`);
    ///   `sim_mode` (`kinematic` or `dynamic`, default `kinematic`); `sim_physics_rate` (Hz,
    ///   default 1000, an integer multiple of `control_rate`, at most
    ///   `kerf_cell::settings::MAX_PHYSICS_RATE_HZ`). Refused with `hardware: mock`.
    ///   With `hardware: sim` and no `initial_positions`, the robot starts at the cell file's
    ///   `robot.initial_positions`.
    /// * `realtime_priority` (0 = normal scheduling, 1–99 = `SCHED_FIFO` for the control
    ///   thread; refused at start-up if the OS does not allow it).
    /// * Streaming mode ([`crate::stream`]): `stream.queue` (integer from 1 to
    ///   [`MAX_STREAM_QUEUE`], default [`DEFAULT_STREAM_QUEUE`]: reference points that may wait
    ///   for a batch; more are refused), `stream.max_jump` (rad or m, finite and > 0, default
    ///   [`DEFAULT_STREAM_MAX_JUMP`]: the largest move of a joint from one point to the next),
    ///   `stream.lookahead` (integer from 0 to [`MAX_STREAM_LOOKAHEAD`], default
    ///   [`DEFAULT_STREAM_LOOKAHEAD`]: points RPRO looks ahead at a velocity level).
    pub fn from_params(params: &Params) -> Result<Self, NodeError> {
        let urdf = PathBuf::from(params.required_string("urdf_file")?);
        let limits_file = PathBuf::from(params.required_string("joint_limits_file")?);
        let robot = RobotModel::from_files(&urdf, Some(&limits_file))?;

        let limits = robot.executor_limits().map_err(|e| match e {
            RobotError::NoAccelerationLimit { joint } => param_err(
                "joint_limits_file",
                format!(
                    "{} gives no max_acceleration for joint '{joint}'; the executor needs it to \
                     check trajectories",
                    limits_file.display(),
                ),
            ),
            other => NodeError::from(other),
        })?;

        let control_rate = rate(
            params,
            "control_rate",
            250.0,
            MAX_CONTROL_RATE_HZ,
            "MAX_CONTROL_RATE_HZ: what one control period runs with a margin",
        )?;
        let action_monitor_rate = rate(
            params,
            "action_monitor_rate",
            20.0,
            control_rate,
            "feedback is sent from the control loop, at most once per period: the control_rate",
        )?;
        let mut executor = ExecutorConfig {
            control_period: 1.0 / control_rate,
            stopped_velocity_tolerance: non_negative(
                params,
                "constraints.stopped_velocity_tolerance",
                0.01,
            )?,
            goal_time_tolerance: non_negative(params, "constraints.goal_time", 0.0)?,
            start_tolerance: non_negative(params, "start_tolerance", 1e-3)?,
            ..ExecutorConfig::default()
        };
        for (name, _) in params.iter() {
            let Some(rest) = name.strip_prefix("constraints.") else {
                continue;
            };
            if rest == "stopped_velocity_tolerance" || rest == "goal_time" {
                continue;
            }
            let known = rest
                .rsplit_once('.')
                .filter(|(joint, kind)| {
                    robot.joint_index(joint).is_some() && (*kind == "trajectory" || *kind == "goal")
                })
                .ok_or_else(|| {
                    param_err(
                        name,
                        format!(
                            "expected constraints.<joint>.trajectory or constraints.<joint>.goal \
                             with a joint of {}",
                            robot.joint_names().join(", ")
                        ),
                    )
                })?;
            let tol = JointTolerance {
                name: known.0.to_string(),
                position: non_negative(params, name, 0.0)?,
                velocity: 0.0,
                acceleration: 0.0,
            };
            if known.1 == "trajectory" {
                executor.path_tolerances.push(tol);
            } else {
                executor.goal_tolerances.push(tol);
            }
        }
        for (name, _) in params.iter() {
            if name.starts_with("hardware.") && !HARDWARE_PARAMS.iter().any(|(p, _)| p == name) {
                let known: Vec<&str> = HARDWARE_PARAMS.iter().map(|(p, _)| *p).collect();
                return Err(param_err(
                    name,
                    format!("unknown; the hardware parameters are {}", known.join(", ")),
                ));
            }
        }
        let lag_time_constant = non_negative(params, "hardware.lag_time_constant", 0.0)?;
        let realtime_priority = params.i64_or("realtime_priority", 0)?;
        if !(0..=99).contains(&realtime_priority) {
            return Err(param_err(
                "realtime_priority",
                format!("must be 0 (off) or 1..=99, got {realtime_priority}"),
            ));
        }

        let sim = sim_config(params)?;
        if sim.is_some() && lag_time_constant != 0.0 {
            return Err(param_err(
                "hardware.lag_time_constant",
                format!(
                    "{lag_time_constant}: a lag applies to hardware: mock only (0 or unset with \
                     hardware: sim); the simulated cell has its own dynamics (sim_mode)"
                ),
            ));
        }
        let driver = driver_config(params, control_rate)?;
        if driver.is_some() && lag_time_constant != 0.0 {
            return Err(param_err(
                "hardware.lag_time_constant",
                format!(
                    "{lag_time_constant}: a lag applies to hardware: mock only (0 or unset with \
                     a real robot's driver, which has its own dynamics)"
                ),
            ));
        }
        let initial_positions = match (params.f64_array("initial_positions")?, &sim) {
            (Some(v), _) => v,
            (None, Some(sim)) => {
                kerf_cell::CellFile::from_file(&sim.cell_file)
                    .map_err(|e| param_err("sim_cell", e.to_string()))?
                    .robot
                    .initial_positions
            }
            // With a topic driver the robot starts at the driver's first joint state; until
            // then the executor holds a placeholder it never commands (the middle of each
            // joint's range, so that it is valid).
            (None, None) if matches!(driver, Some(DriverConfig::Topic(_))) => limits
                .iter()
                .map(|l| {
                    if l.min_position.is_finite() && l.max_position.is_finite() {
                        0.5 * (l.min_position + l.max_position)
                    } else {
                        0.0_f64.clamp(l.min_position, l.max_position)
                    }
                })
                .collect(),
            (None, None) => vec![0.0; robot.dof()],
        };
        if initial_positions.len() != robot.dof() {
            return Err(param_err(
                "initial_positions",
                format!(
                    "needs {} values (joints {}), got {}",
                    robot.dof(),
                    robot.joint_names().join(", "),
                    initial_positions.len()
                ),
            ));
        }
        robot
            .check_positions(&initial_positions)
            .map_err(|e| param_err("initial_positions", e.to_string()))?;

        let stream = stream_config(params)?;

        Ok(Self {
            robot,
            urdf_file: urdf,
            limits,
            executor,
            control_rate,
            action_monitor_rate,
            initial_positions,
            lag_time_constant,
            realtime_priority,
            sim,
            driver,
            stream,
        })
    }
}

/// Reads the `stream.*` parameters.
fn stream_config(params: &Params) -> Result<StreamConfig, NodeError> {
    let queue = params.i64_or("stream.queue", DEFAULT_STREAM_QUEUE)?;
    if !(1..=MAX_STREAM_QUEUE).contains(&queue) {
        return Err(param_err(
            "stream.queue",
            format!("{queue}: must be an integer from 1 to {MAX_STREAM_QUEUE} (points)"),
        ));
    }
    let max_jump = params.f64_or("stream.max_jump", DEFAULT_STREAM_MAX_JUMP)?;
    if !(max_jump.is_finite() && max_jump > 0.0) {
        return Err(param_err(
            "stream.max_jump",
            format!("{max_jump}: must be finite and > 0 (rad or m)"),
        ));
    }
    let lookahead = params.i64_or("stream.lookahead", DEFAULT_STREAM_LOOKAHEAD)?;
    if !(0..=MAX_STREAM_LOOKAHEAD).contains(&lookahead) {
        return Err(param_err(
            "stream.lookahead",
            format!("{lookahead}: must be an integer from 0 to {MAX_STREAM_LOOKAHEAD} (points)"),
        ));
    }
    // In range: checked above.
    Ok(StreamConfig {
        queue: queue as usize,
        max_jump,
        lookahead: lookahead as usize,
    })
}

/// Reads `hardware` and the `sim_*` parameters.
fn sim_config(params: &Params) -> Result<Option<SimConfig>, NodeError> {
    let hardware = params.string("hardware")?;
    match hardware.as_deref().unwrap_or("mock") {
        kind @ ("mock" | "topic" | "jtc") => {
            for name in ["sim_cell", "sim_mode", "sim_physics_rate"] {
                if params.get(name).is_some() {
                    return Err(param_err(
                        name,
                        format!("applies to hardware: sim only (hardware is {kind})"),
                    ));
                }
            }
            Ok(None)
        }
        "sim" => {
            let cell_file = PathBuf::from(params.string("sim_cell")?.ok_or_else(|| {
                param_err(
                    "sim_cell",
                    "required with hardware: sim (a kerf_cell cell file, e.g. \
                     urdf/cells/laser_bpillar.yaml)"
                        .into(),
                )
            })?);
            let mode = match params.string("sim_mode")?.as_deref().unwrap_or("kinematic") {
                "kinematic" => kerf_cell::Mode::Kinematic,
                "dynamic" => kerf_cell::Mode::Dynamic,
                other => {
                    return Err(param_err(
                        "sim_mode",
                        format!("must be kinematic or dynamic, got '{other}'"),
                    ))
                }
            };
            let physics_rate = rate(
                params,
                "sim_physics_rate",
                1000.0,
                kerf_cell::settings::MAX_PHYSICS_RATE_HZ,
                "kerf_cell::settings::MAX_PHYSICS_RATE_HZ: one physics sub-step costs up to \
                 about 80 us, so the sub-steps of a control period cannot run in real time with \
                 a margin above it",
            )?;
            Ok(Some(SimConfig {
                cell_file,
                mode,
                physics_rate,
            }))
        }
        other => Err(param_err(
            "hardware",
            format!("must be mock, sim, topic or jtc, got '{other}'"),
        )),
    }
}

/// Every `hardware.*` parameter and the hardware kinds it applies to.
pub const HARDWARE_PARAMS: &[(&str, &[&str])] = &[
    (
        "hardware.lag_time_constant",
        &["mock", "sim", "topic", "jtc"],
    ),
    ("hardware.command_topic", &["topic"]),
    ("hardware.command_type", &["topic"]),
    ("hardware.state_topic", &["topic", "jtc"]),
    ("hardware.feedback_timeout_periods", &["topic"]),
    ("hardware.jtc_action", &["jtc"]),
    ("hardware.jtc_timeout", &["jtc"]),
];

/// A topic or action name parameter: a valid ROS name (checked by expansion in the root
/// namespace; the node checks it again against its own namespace and remappings).
fn name_param(
    params: &Params,
    name: &str,
    default: Option<&str>,
) -> Result<Option<String>, NodeError> {
    let Some(v) = params.string(name)?.or_else(|| default.map(str::to_string)) else {
        return Ok(None);
    };
    kerf_ros::names::expand(&v, "/", crate::DEFAULT_NAME)
        .map_err(|e| param_err(name, format!("'{v}' is not a valid ROS name: {e}")))?;
    Ok(Some(v))
}

/// Reads `hardware: topic|jtc` and their parameters; refuses a `hardware.*` parameter that
/// does not apply to the hardware chosen.
fn driver_config(params: &Params, control_rate: f64) -> Result<Option<DriverConfig>, NodeError> {
    let kind = params.string("hardware")?.unwrap_or_else(|| "mock".into());
    for (name, applies) in HARDWARE_PARAMS {
        if params.get(name).is_some() && !applies.contains(&kind.as_str()) {
            return Err(param_err(
                name,
                format!(
                    "applies to hardware: {} only (hardware is {kind})",
                    applies.join(" or ")
                ),
            ));
        }
    }
    match kind.as_str() {
        "topic" => {
            let command_type = match params.string("hardware.command_type")?.as_deref() {
                None | Some("std_msgs/msg/Float64MultiArray") => CommandType::Float64MultiArray,
                Some("sensor_msgs/msg/JointState") => CommandType::JointState,
                Some(other) => {
                    return Err(param_err(
                        "hardware.command_type",
                        format!(
                            "must be std_msgs/msg/Float64MultiArray or sensor_msgs/msg/JointState, \
                             got '{other}'"
                        ),
                    ))
                }
            };
            let periods = params.i64_or(
                "hardware.feedback_timeout_periods",
                DEFAULT_FEEDBACK_TIMEOUT_PERIODS,
            )?;
            let max_periods = (MAX_FEEDBACK_TIMEOUT_S * control_rate).floor() as i64;
            if !(1..=max_periods).contains(&periods) {
                return Err(param_err(
                    "hardware.feedback_timeout_periods",
                    format!(
                        "{periods}: must be an integer from 1 to {max_periods} (at most \
                         {MAX_FEEDBACK_TIMEOUT_S} s of control periods at {control_rate} Hz)"
                    ),
                ));
            }
            let command_topic = name_param(
                params,
                "hardware.command_topic",
                Some(DEFAULT_COMMAND_TOPIC),
            )?
            .unwrap_or_default();
            let state_topic =
                name_param(params, "hardware.state_topic", Some(DEFAULT_STATE_TOPIC))?
                    .unwrap_or_default();
            Ok(Some(DriverConfig::Topic(TopicConfig {
                command_topic,
                command_type,
                state_topic,
                // In range: checked above (1 ..= 1000 at the highest control rate).
                feedback_timeout_periods: periods as u32,
            })))
        }
        "jtc" => {
            let timeout = params.f64_or("hardware.jtc_timeout", DEFAULT_JTC_TIMEOUT_S)?;
            if !(timeout > 0.0 && timeout <= MAX_JTC_TIMEOUT_S) {
                return Err(param_err(
                    "hardware.jtc_timeout",
                    format!("{timeout} s: must be > 0 and <= {MAX_JTC_TIMEOUT_S} s"),
                ));
            }
            Ok(Some(DriverConfig::Jtc(JtcConfig {
                action: name_param(params, "hardware.jtc_action", Some(DEFAULT_JTC_ACTION))?
                    .unwrap_or_default(),
                state_topic: name_param(params, "hardware.state_topic", None)?,
                timeout,
            })))
        }
        _ => Ok(None),
    }
}
