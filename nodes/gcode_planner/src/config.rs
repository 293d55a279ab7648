//! The node's parameters, read once at start-up and checked.

use kerf_gcodeplan::{MachineBase, MachineKind};
use kerf_robot::roots::AllowedRoots;
use kerf_ros::{planner::HarnessSettings, Params};

use crate::NodeError;

/// Parameter names this node reads; others are refused at start-up.
pub const KNOWN_PARAMS: &[&str] = &[
    "machine",
    "queue_depth",
    "plan_timeout",
    "allowed_file_roots",
];

/// Everything the node needs, checked.
#[derive(Debug)]
pub struct NodeConfig {
    /// The machine it plans for, loaded.
    pub machine: MachineBase,
    /// The harness's `queue_depth` and `plan_timeout`.
    pub harness: HarnessSettings,
    /// Where a request's program file may be (`allowed_file_roots`).
    pub allowed_roots: AllowedRoots,
}

impl NodeConfig {
    /// Reads and checks every parameter and loads the machine.
    ///
    /// # Parameters
    /// * `machine` (string, `laser-cutter` (default) or `irb6660`): the machine every request
    ///   is planned for (the shipped `urdf/laser_cutter.urdf` or `urdf/irb6660_milling.yaml`);
    ///   a request naming the other is INVALID_REQUEST.
    /// * `queue_depth` (integer ≥ 1, default 10) and `plan_timeout` (seconds, default 60): the
    ///   harness's ([`HarnessSettings::from_params`]).
    /// * `allowed_file_roots` (string array, default: any): directories a request's
    ///   `program_uri` must resolve under (links resolved; the shipped data is always
    ///   allowed); a file outside is INVALID_REQUEST.
    ///
    /// # Errors
    /// [`NodeError::Config`] naming the parameter, [`NodeError::Ros`] for a wrong type,
    /// [`NodeError::Setup`] when the machine does not load.
    pub fn from_params(params: &Params) -> Result<Self, NodeError> {
        let kind = match params.string("machine")?.as_deref() {
            None => MachineKind::LaserCutter,
            Some(name) if name.trim().is_empty() => {
                return Err(NodeError::config(
                    "machine",
                    "is empty; leave it unset for laser-cutter, or give irb6660",
                ))
            }
            Some(name) => MachineKind::parse(name).map_err(|_| {
                NodeError::config(
                    "machine",
                    format!("must be laser-cutter or irb6660, got {name:?}"),
                )
            })?,
        };
        let machine =
            MachineBase::load(kind).map_err(|e| NodeError::setup(crate::SetupError::Machine(e)))?;
        Ok(Self {
            machine,
            harness: HarnessSettings::from_params(params)?,
            allowed_roots: kerf_ros::planner::allowed_roots(params)?,
        })
    }
}
