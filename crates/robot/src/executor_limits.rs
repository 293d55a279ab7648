//! [`RobotModel::executor_limits`]: the robot as the trajectory executor models it.

use kerf_executor::JointLimits;

use crate::{RobotError, RobotModel};

impl RobotModel {
    /// Every joint's position, velocity and acceleration limits in the executor's form, in
    /// the robot's joint order: the model `kerf_executor` validates trajectories against (the
    /// executor node's, and every planner's executability check).
    ///
    /// # Errors
    /// [`RobotError::NoAccelerationLimit`] naming the first joint without one.
    pub fn executor_limits(&self) -> Result<Vec<JointLimits>, RobotError> {
        self.joints()
            .iter()
            .map(|j| {
                Ok(JointLimits {
                    name: j.name.clone(),
                    min_position: j.min_position,
                    max_position: j.max_position,
                    max_velocity: j.max_velocity,
                    max_acceleration: j.max_acceleration.ok_or_else(|| {
                        RobotError::NoAccelerationLimit {
                            joint: j.name.clone(),
                        }
                    })?,
                })
            })
            .collect()
    }
}
