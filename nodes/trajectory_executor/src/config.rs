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
];

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
    /// The simulated cell (`hardware: sim`); `None` for the mock hardware.
    pub sim: Option<SimConfig>,
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
    /// * `hardware` (`mock` or `sim`, default `mock`): the hardware the control loop drives.
    /// * `hardware.lag_time_constant` (s, default 0: the mock follows commands exactly; must
    ///   be 0 with `hardware: sim`).
    /// * `sim_cell` (string, required with `hardware: sim`): the cell file (`kerf_cell`);
    ///   `sim_mode` (`kinematic` or `dynamic`, default `kinematic`); `sim_physics_rate` (Hz,
    ///   default 1000, an integer multiple of `control_rate`, at most
    ///   `kerf_cell::settings::MAX_PHYSICS_RATE_HZ`). Refused with `hardware: mock`.
    ///   With `hardware: sim` and no `initial_positions`, the robot starts at the cell file's
    ///   `robot.initial_positions`.
    /// * `realtime_priority` (0 = normal scheduling, 1–99 = `SCHED_FIFO` for the control
    ///   thread; refused at start-up if the OS does not allow it).
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
            if name.starts_with("hardware.") && name != "hardware.lag_time_constant" {
                return Err(param_err(
                    name,
                    "unknown; hardware.lag_time_constant is the only hardware parameter".into(),
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
        let initial_positions = match (params.f64_array("initial_positions")?, &sim) {
            (Some(v), _) => v,
            (None, Some(sim)) => {
                kerf_cell::CellFile::from_file(&sim.cell_file)
                    .map_err(|e| param_err("sim_cell", e.to_string()))?
                    .robot
                    .initial_positions
            }
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
        })
    }
}

/// Reads `hardware` and the `sim_*` parameters.
fn sim_config(params: &Params) -> Result<Option<SimConfig>, NodeError> {
    let hardware = params.string("hardware")?;
    match hardware.as_deref().unwrap_or("mock") {
        "mock" => {
            for name in ["sim_cell", "sim_mode", "sim_physics_rate"] {
                if params.get(name).is_some() {
                    return Err(param_err(
                        name,
                        "applies to hardware: sim only (hardware is mock)".into(),
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
            format!("must be mock or sim, got '{other}'"),
        )),
    }
}
