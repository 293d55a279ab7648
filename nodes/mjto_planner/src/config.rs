//! The node's parameters, read once at start-up and checked.

use std::path::PathBuf;

use kerf_mjto::LaserMachine;
use kerf_robot::roots::AllowedRoots;
use kerf_ros::{planner::HarnessSettings, Params};

use crate::NodeError;

/// Parameter names this node reads; others are refused at start-up.
pub const KNOWN_PARAMS: &[&str] = &[
    "urdf_file",
    "joint_limits_file",
    "queue_depth",
    "plan_timeout",
    "allowed_file_roots",
];

pub use kerf_ros::planner::DEFAULT_QUEUE_DEPTH;

/// Everything the node needs, checked.
#[derive(Debug, Clone)]
pub struct NodeConfig {
    /// The machine the planner plans for.
    pub machine: LaserMachine,
    /// Where the machine came from (for the start-up log).
    pub machine_source: String,
    /// The harness's `queue_depth` and `plan_timeout`.
    pub harness: HarnessSettings,
    /// Where a request's mesh may be (`allowed_file_roots`).
    pub allowed_roots: AllowedRoots,
}

impl NodeConfig {
    /// Reads and checks every parameter, and loads the machine.
    ///
    /// # Parameters
    /// * `urdf_file`, `joint_limits_file` (strings, the same names as the trajectory
    ///   executor's): the machine's URDF (joints q1..q6) and its MoveIt-style limits YAML with
    ///   acceleration and jerk limits (seed 001 Table 2). Both unset: the shipped
    ///   `urdf/laser_cutter.urdf` and `urdf/laser_cutter_limits.yaml`. `joint_limits_file`
    ///   without `urdf_file` is refused.
    /// * `queue_depth` (integer ≥ 1, default 10): requests waiting or being planned; a request
    ///   arriving when the queue is full is answered at once with status QUEUE_FULL.
    /// * `plan_timeout` (seconds, default 60): the time budget of every plan; a request may ask
    ///   for less with its `time_budget`. A plan that runs out of it is answered TIMEOUT.
    /// * `allowed_file_roots` (string array, default: any): directories a request's mesh must
    ///   resolve under (links resolved; the shipped data is always allowed); a mesh outside is
    ///   MESH_ERROR.
    ///
    /// # Errors
    /// [`NodeError::Config`] naming the parameter, [`NodeError::Ros`] for a wrong type,
    /// [`NodeError::Setup`] ([`crate::SetupError::Machine`]) when the machine does not load.
    pub fn from_params(params: &Params) -> Result<Self, NodeError> {
        let urdf = params.string("urdf_file")?;
        let limits = params.string("joint_limits_file")?;
        let (machine, machine_source) =
            match (urdf, limits) {
                (Some(urdf), limits) => {
                    let limits = limits.map(PathBuf::from);
                    let m = LaserMachine::from_files(&PathBuf::from(&urdf), limits.as_deref())
                        .map_err(NodeError::setup)?;
                    let source = match &limits {
                        Some(l) => format!("{urdf} with {}", l.display()),
                        None => urdf,
                    };
                    (m, source)
                }
                (None, Some(_)) => return Err(NodeError::config(
                    "joint_limits_file",
                    "given without urdf_file; set both, or neither for the shipped laser cutter",
                )),
                (None, None) => (
                    LaserMachine::default_machine().map_err(NodeError::setup)?,
                    "the shipped laser_cutter.urdf".to_string(),
                ),
            };
        let harness = HarnessSettings::from_params(params)?;
        let allowed_roots = kerf_ros::planner::allowed_roots(params)?;
        Ok(Self {
            machine,
            machine_source,
            harness,
            allowed_roots,
        })
    }
}
