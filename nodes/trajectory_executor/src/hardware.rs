//! The hardware the control loop drives: the mock (`hardware: mock`), the simulated cell
//! (`hardware: sim`, `kerf_cell`) or a real robot's driver over topics (`hardware: topic`,
//! [`crate::driver`]). The control loop is the same for all: read the state, write a command
//! for one control period. (`hardware: jtc` has no control loop: trajectories go to an
//! external FollowJointTrajectory server, [`crate::jtc`].)

use kerf_cell::{Cell, CellError, CellSettings, CellState};
use kerf_executor::{JointLimits, JointSample, MockHardware};

use crate::{config::SimConfig, driver::TopicDriver, NodeConfig, NodeError};

/// The hardware behind the control loop.
#[derive(Debug)]
pub enum Hardware {
    /// `kerf_executor::MockHardware`: follows commands, exactly or with a lag.
    Mock(MockHardware),
    /// A simulated cell on rapier, stepped in lock-step with the control loop.
    Sim(Box<SimHardware>),
    /// A real robot's driver: commands out, measured joint states in.
    Topic(Box<TopicDriver>),
}

/// The simulated cell and its state as the executor measures it.
#[derive(Debug)]
pub struct SimHardware {
    cell: Cell,
    measured: JointSample,
}

impl SimHardware {
    /// The cell.
    pub fn cell(&self) -> &Cell {
        &self.cell
    }
}

fn sim_err(name: &str, e: &CellError) -> NodeError {
    NodeError::Config {
        name: name.to_string(),
        reason: e.to_string(),
    }
}

/// Loads the simulated cell of `sim` for the robot of `cfg` and checks it against the
/// executor: cell file (meshes, masses), effort limits of the URDF, joint names, physics rate.
///
/// # Errors
/// [`NodeError::Config`] naming the parameter at fault: `sim_physics_rate` (not an integer
/// multiple of `control_rate`), `urdf_file` (an effort limit ≤ 0, or a URDF the cell cannot
/// use), `sim_cell` (unreadable cell file, a missing or bad mesh, the cell's robot joints not
/// the executor's), `initial_positions` (not valid for the cell).
pub fn load_cell(cfg: &NodeConfig, sim: &SimConfig) -> Result<Cell, NodeError> {
    let settings = CellSettings {
        mode: sim.mode,
        control_rate_hz: cfg.control_rate,
        physics_rate_hz: sim.physics_rate,
        ..CellSettings::default()
    };
    settings
        .substeps()
        .map_err(|e| sim_err("sim_physics_rate", &e))?;
    let mut cell = Cell::from_files(&cfg.urdf_file, &sim.cell_file, settings).map_err(|e| {
        let name = match e {
            CellError::EffortLimit { .. } | CellError::Robot { .. } => "urdf_file",
            CellError::FileRead { ref path, .. } if path == &cfg.urdf_file => "urdf_file",
            _ => "sim_cell",
        };
        sim_err(name, &e)
    })?;
    check_joints(&cell, &cfg.limits)?;
    cell.reset(&cfg.initial_positions)
        .map_err(|e| sim_err("initial_positions", &e))?;
    Ok(cell)
}

/// Checks that the cell's robot has exactly the executor's joints, in model order.
///
/// # Errors
/// [`NodeError::Config`] for `sim_cell`, naming the first difference.
pub fn check_joints(cell: &Cell, limits: &[JointLimits]) -> Result<(), NodeError> {
    let names: Vec<&str> = limits.iter().map(|l| l.name.as_str()).collect();
    cell.check_joint_names(&names)
        .map_err(|e| sim_err("sim_cell", &e))
}

impl Hardware {
    /// The hardware `cfg` asks for, at rest at its initial positions.
    ///
    /// # Errors
    /// See [`load_cell`]; for the mock, an invalid lag time constant; `hardware: topic` and
    /// `jtc` are refused (their endpoints are made by the node: [`TopicDriver`]).
    pub fn build(cfg: &NodeConfig) -> Result<Self, NodeError> {
        if cfg.driver.is_some() {
            return Err(NodeError::Config {
                name: "hardware".into(),
                reason: "a real robot's driver is reached through the node's DDS endpoints; \
                         Hardware::build makes the mock or the simulated cell only"
                    .into(),
            });
        }
        match &cfg.sim {
            None => Ok(Self::Mock(MockHardware::with_lag(
                cfg.initial_positions.clone(),
                cfg.lag_time_constant,
            )?)),
            Some(sim) => Ok(Self::from_cell(load_cell(cfg, sim)?)),
        }
    }

    /// Simulated hardware around a loaded cell (at its current state).
    pub fn from_cell(cell: Cell) -> Self {
        let measured = cell.state().joint_sample();
        Self::Sim(Box::new(SimHardware { cell, measured }))
    }

    /// The measured state (positions, velocities, accelerations), model order. For a topic
    /// driver: the latest good joint state (velocities when it gives them, no accelerations).
    pub fn state(&self) -> &JointSample {
        match self {
            Self::Mock(m) => m.state(),
            Self::Sim(s) => &s.measured,
            Self::Topic(d) => d.monitor().measured(),
        }
    }

    /// Measured efforts (N or N m), model order; empty for the mock (it has none).
    pub fn efforts(&self) -> &[f64] {
        match self {
            Self::Mock(_) | Self::Topic(_) => &[],
            Self::Sim(s) => &s.cell.state().efforts,
        }
    }

    /// The simulated cell's state (contacts, tracking error, time); `None` for the mock.
    pub fn sim_state(&self) -> Option<&CellState> {
        match self {
            Self::Mock(_) | Self::Topic(_) => None,
            Self::Sim(s) => Some(s.cell.state()),
        }
    }

    /// The topic driver, if that is the hardware.
    pub fn topic(&mut self) -> Option<&mut TopicDriver> {
        match self {
            Self::Topic(d) => Some(d),
            _ => None,
        }
    }

    /// Applies `command` for one control period `dt` (s): the mock follows it, the cell runs
    /// its physics sub-steps towards it, a topic driver gets it on its command topic.
    ///
    /// # Returns
    /// The measured state at the end of the period.
    ///
    /// # Errors
    /// A malformed command or `dt` (the state is then unchanged), as text for the log.
    pub fn write(
        &mut self,
        limits: &[JointLimits],
        command: &JointSample,
        dt: f64,
    ) -> Result<&JointSample, String> {
        match self {
            Self::Mock(m) => {
                m.write(limits, command, dt).map_err(|e| e.to_string())?;
                Ok(m.state())
            }
            Self::Topic(d) => match d.send(command) {
                Some(warning) => Err(warning),
                None => Ok(d.monitor().measured()),
            },
            Self::Sim(s) => {
                let state = s.cell.step(command, dt).map_err(|e| e.to_string())?;
                s.measured.positions.clone_from(&state.positions);
                s.measured.velocities.clone_from(&state.velocities);
                s.measured.accelerations.clone_from(&state.accelerations);
                Ok(&s.measured)
            }
        }
    }
}
