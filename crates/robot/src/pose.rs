//! Conversion of URDF `<origin>` poses to rigid transforms.

use nalgebra::{Isometry3, Translation3, UnitQuaternion};

use crate::RobotError;

/// Converts a URDF `<origin xyz rpy>` of joint `joint` to an isometry.
///
/// The URDF specification (ROS wiki `urdf/XML/joint`, `<origin>`; angle
/// convention of ROS REP 103) defines `rpy` as fixed-axis roll about X,
/// then pitch about Y, then yaw about Z, i.e. `R = Rz(yaw) * Ry(pitch) *
/// Rx(roll)`, which is what [`UnitQuaternion::from_euler_angles`] builds.
///
/// # Arguments
/// * `joint` - joint name, used in the error message.
/// * `pose` - the parsed `<origin>`.
///
/// # Returns
/// The transform from the parent link frame to the joint frame, or
/// [`RobotError::InvalidOrigin`] if any value is not finite.
pub(crate) fn isometry_from_origin(
    joint: &str,
    pose: &urdf_rs::Pose,
) -> Result<Isometry3<f64>, RobotError> {
    let xyz = pose.xyz.0;
    let rpy = pose.rpy.0;
    if xyz.iter().chain(rpy.iter()).any(|v| !v.is_finite()) {
        return Err(RobotError::InvalidOrigin {
            joint: joint.to_owned(),
            xyz,
            rpy,
        });
    }
    Ok(Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    ))
}
