//! The node's parameters, read once at start-up and checked.

use kerf_gcodeplan::{MachineBase, MachineKind};
use kerf_robot::roots::AllowedRoots;
use kerf_ros::{planner::HarnessSettings, Params};

use crate::surroundings::MachineSurroundings;
use crate::NodeError;

/// Parameter names this node reads; others are refused at start-up.
pub const KNOWN_PARAMS: &[&str] = &[
    "machine",
    "queue_depth",
    "plan_timeout",
    "allowed_file_roots",
    "collision_cell_file",
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
    /// What the approach and retract of every plan with a start keep clear of
    /// (`collision_cell_file` for the IRB 6660).
    pub surroundings: MachineSurroundings,
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
    /// * `collision_cell_file` (string, `irb6660` only): the kerf_cell cell file (the one the
    ///   executor's `sim_cell` reads) whose objects every approach and retract keeps its
    ///   clearance from; unset = the shipped `urdf/cells/irb6660_plate.yaml`. Refused for the
    ///   laser cutter, whose approach keeps clear of the sheet under each program
    ///   ([`crate::sheet`]). Relative paths are relative to the working directory.
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
        let cell_file = match params.string("collision_cell_file")? {
            None => None,
            Some(s) if s.trim().is_empty() => {
                return Err(NodeError::config(
                    "collision_cell_file",
                    "is empty; leave it unset for the default, or give a file path",
                ))
            }
            Some(s) => Some(std::path::PathBuf::from(s)),
        };
        let surroundings = MachineSurroundings::load(&machine, cell_file.as_deref())
            .map_err(|reason| NodeError::config("collision_cell_file", reason))?;
        Ok(Self {
            machine,
            surroundings,
            harness: HarnessSettings::from_params(params)?,
            allowed_roots: kerf_ros::planner::allowed_roots(params)?,
        })
    }
}
