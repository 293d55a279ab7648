//! The machines a program can drive: where a program-frame point puts the
//! joints ([`Machine::joints`]) and where the joints put the tool tip
//! ([`Machine::tip`]).
//!
//! | machine | mapping |
//! |---|---|
//! | [`LaserSheet`] | the laser cutter of seed 001 over a flat sheet: q1, q2 trace the path, q3 at the cutting height, q4 = q5 = 0 (vertical beam), q6 fixed |
//! | [`MillingPlane`] | the IRB 6660 of seed 004 on a milling plane: the tool pose at the point with a fixed redundancy angle g, through kerf_mill's closed-form IK |

pub mod irb;
pub mod laser;

pub use irb::MillingPlane;
pub use laser::LaserSheet;

use kerf_executor::JointLimits;
use kerf_robot::RobotModel;

use crate::error::GcodePlanError;

/// Joints of either machine.
pub const DOF: usize = 6;

/// One joint's limits, with the jerk the executor does not check.
#[derive(Debug, Clone, PartialEq)]
pub struct JointBounds {
    /// Joint name.
    pub name: String,
    /// Largest |velocity| (m/s or rad/s).
    pub velocity: f64,
    /// Largest |acceleration| (m/s² or rad/s²).
    pub acceleration: f64,
    /// Largest |jerk| (m/s³ or rad/s³).
    pub jerk: f64,
}

/// A machine a program drives.
pub trait Machine: Sync {
    /// Its name, for messages.
    fn name(&self) -> &str;

    /// The robot model (URDF joint order = every joint vector's order).
    fn robot(&self) -> &RobotModel;

    /// The joints' limits (velocity, acceleration and jerk), model order.
    fn bounds(&self) -> &[JointBounds; DOF];

    /// The joint vector that puts the tool tip at `point`.
    ///
    /// # Arguments
    /// * `point` — program frame \[m\].
    /// * `reference` — the previous joint vector (branch continuity), or
    ///   `None` for the machine's own reference.
    ///
    /// # Errors
    /// A sentence saying why the point is out of reach.
    fn joints(&self, point: [f64; 3], reference: Option<&[f64; DOF]>)
        -> Result<[f64; DOF], String>;

    /// The tool tip of a joint vector, program frame \[m\].
    ///
    /// # Errors
    /// A sentence for a non-finite joint vector.
    fn tip(&self, q: &[f64; DOF]) -> Result<[f64; 3], String>;

    /// Limits of the program frame's Cartesian axes when the machine's joints are those axes
    /// (the laser cutter's gantry), for the feed plan; `None` when the joints are not.
    fn axis_limits(&self) -> Option<kerf_toolpath::AxisLimits> {
        None
    }

    /// The executor's view of the limits (model order).
    ///
    /// # Errors
    /// [`GcodePlanError::InvalidSetting`] when the model lacks a limit.
    fn executor_limits(&self) -> Result<Vec<JointLimits>, GcodePlanError> {
        self.robot()
            .executor_limits()
            .map_err(|e| GcodePlanError::InvalidRequest {
                field: "machine".to_string(),
                reason: e.to_string(),
            })
    }
}

/// The velocity, acceleration and jerk limits of every joint of `robot`.
///
/// # Errors
/// [`GcodePlanError::InvalidSetting`] for a joint without an acceleration
/// or jerk limit, or another count of joints than [`DOF`].
pub(crate) fn bounds_of(robot: &RobotModel) -> Result<[JointBounds; DOF], GcodePlanError> {
    let joints = robot.joints();
    if joints.len() != DOF {
        return Err(GcodePlanError::InvalidSetting {
            name: "machine joints".to_string(),
            value: joints.len() as f64,
            reason: format!(
                "{} has {} joints; G-code drives {DOF}",
                robot.name(),
                joints.len()
            ),
        });
    }
    let missing = |name: &str, what: &str| GcodePlanError::InvalidRequest {
        field: format!("{name} {what} limit"),
        reason: "the limits YAML must give it: the trajectory is checked against it".to_string(),
    };
    let mut out: Vec<JointBounds> = Vec::with_capacity(DOF);
    for j in joints {
        out.push(JointBounds {
            name: j.name.clone(),
            velocity: j.max_velocity,
            acceleration: j
                .max_acceleration
                .ok_or_else(|| missing(&j.name, "acceleration"))?,
            jerk: j.max_jerk.ok_or_else(|| missing(&j.name, "jerk"))?,
        });
    }
    out.try_into().map_err(|_| GcodePlanError::InvalidSetting {
        name: "machine joints".to_string(),
        value: joints.len() as f64,
        reason: "not six".to_string(),
    })
}

/// Checks a program-frame point or origin.
pub(crate) fn check_finite(name: &str, v: &[f64]) -> Result<(), GcodePlanError> {
    match v.iter().find(|x| !x.is_finite()) {
        Some(x) => Err(GcodePlanError::InvalidSetting {
            name: name.to_string(),
            value: *x,
            reason: "must be finite".to_string(),
        }),
        None => Ok(()),
    }
}
