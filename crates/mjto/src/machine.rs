//! The laser cutting machine as the planner sees it: joint limits of
//! Table 2 (seed 001) and the URDF it came from.

use std::path::{Path, PathBuf};

use kerf_robot::RobotModel;

use crate::PlanError;

/// Names of the six joints, in the order of every joint vector in this crate.
pub const JOINT_NAMES: [&str; 6] = ["q1", "q2", "q3", "q4", "q5", "q6"];

/// Position, velocity, acceleration and jerk limits of one axis (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisLimits {
    /// Lower position limit (m or rad).
    pub min: f64,
    /// Upper position limit (m or rad).
    pub max: f64,
    /// Maximum |velocity| (m/s or rad/s).
    pub vel: f64,
    /// Maximum |acceleration| (m/s² or rad/s²).
    pub acc: f64,
    /// Maximum |jerk| (m/s³ or rad/s³).
    pub jerk: f64,
}

/// The machine model: the URDF chain plus the limits of each joint.
#[derive(Debug, Clone)]
pub struct LaserMachine {
    robot: RobotModel,
    limits: [AxisLimits; 6],
}

impl LaserMachine {
    /// The shipped `urdf/` directory, found by the data search of [`kerf_robot::data`]
    /// (`KERF_DATA_DIR`, the share directory beside the binary, the source tree).
    ///
    /// # Returns
    /// `urdf/` below the data root; when the search fails, below the place it failed at
    /// ([`kerf_robot::data::default_path`]), and [`LaserMachine::default_machine`] reports why.
    pub fn urdf_dir() -> PathBuf {
        kerf_robot::data::default_path("urdf")
    }

    /// Loads `urdf/laser_cutter.urdf` with `urdf/laser_cutter_limits.yaml` from the kerf data
    /// root ([`kerf_robot::data::root`]).
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] (field `machine`) when no data root is found (the message
    /// names every place searched) or as [`LaserMachine::from_files`].
    pub fn default_machine() -> Result<Self, PlanError> {
        let dir = kerf_robot::data::path("urdf")
            .map_err(|e| PlanError::invalid("machine", e.to_string()))?;
        Self::from_files(
            &dir.join("laser_cutter.urdf"),
            Some(&dir.join("laser_cutter_limits.yaml")),
        )
    }

    /// Loads a machine from a URDF and a MoveIt limits YAML.
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] (field `machine`) if the files do not
    /// load, the joints are not q1..q6 in this order, or a joint lacks an
    /// acceleration or jerk limit.
    pub fn from_files(urdf: &Path, limits_yaml: Option<&Path>) -> Result<Self, PlanError> {
        let robot = RobotModel::from_files(urdf, limits_yaml)
            .map_err(|e| PlanError::invalid("machine", e.to_string()))?;
        Self::from_robot(robot)
    }

    /// Wraps a loaded [`RobotModel`]; see [`LaserMachine::from_files`].
    pub fn from_robot(robot: RobotModel) -> Result<Self, PlanError> {
        let names = robot.joint_names();
        if names != JOINT_NAMES {
            return Err(PlanError::invalid(
                "machine",
                format!("expected joints {JOINT_NAMES:?}, the URDF has {names:?}"),
            ));
        }
        let mut limits = [AxisLimits {
            min: 0.0,
            max: 0.0,
            vel: 0.0,
            acc: 0.0,
            jerk: 0.0,
        }; 6];
        for (l, j) in limits.iter_mut().zip(robot.joints()) {
            let acc = j.max_acceleration.ok_or_else(|| {
                PlanError::invalid(
                    "machine",
                    format!("joint {} has no acceleration limit", j.name),
                )
            })?;
            let jerk = j.max_jerk.ok_or_else(|| {
                PlanError::invalid("machine", format!("joint {} has no jerk limit", j.name))
            })?;
            *l = AxisLimits {
                min: j.min_position,
                max: j.max_position,
                vel: j.max_velocity,
                acc,
                jerk,
            };
        }
        Ok(Self { robot, limits })
    }

    /// The limits of the six joints, q1..q6.
    pub fn limits(&self) -> &[AxisLimits; 6] {
        &self.limits
    }

    /// The underlying robot model (URDF chain, link geometry).
    pub fn robot(&self) -> &RobotModel {
        &self.robot
    }
}
