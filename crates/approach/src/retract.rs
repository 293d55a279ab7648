//! The retract from the last process point: [`ApproachPlanner::retract`] to safe poses, and
//! [`tool_axis_target`], the configuration a distance along the tool axis.

use nalgebra::{Isometry3, Translation3};

use crate::limits::check_configuration;
use crate::{ApproachError, ApproachPlanner, CheckedMove, Role, Route};

/// Largest position error (m) of `FK(IK(pose))` against `pose` that [`tool_axis_target`]
/// accepts.
pub const IK_POSITION_TOLERANCE: f64 = 1e-6;

/// Largest rotation error (rad) of `FK(IK(pose))` against `pose` that [`tool_axis_target`]
/// accepts.
pub const IK_ROTATION_TOLERANCE: f64 = 1e-6;

impl ApproachPlanner<'_> {
    /// The retract from `last` (the last process configuration, at rest) through `targets`
    /// (e.g. `[tool_axis_target(..)?, safe_pose]`, or just a safe pose), each leg a
    /// rest-to-rest [`crate::JointMove`] timed in whole control periods and checked like an
    /// approach ([`crate::ClearanceCheck`]). There is no fallback route: the caller chose the
    /// targets.
    ///
    /// # Arguments
    /// * `last` – inside the position limits and at least the clearance from every obstacle
    ///   (the clearance function must leave out the tool's allowed contact with the
    ///   workpiece).
    /// * `targets` – at least one configuration, each inside the position limits.
    ///
    /// # Returns
    /// The [`CheckedMove`] ([`Route::Retract`]); configuration errors naming
    /// [`Role::RetractStart`] or [`Role::RetractTarget`]; [`ApproachError::InCollision`];
    /// [`ApproachError::RetractBlocked`] with the obstacle, time, configuration and
    /// distance; [`ApproachError::MoveTooLong`]; [`ApproachError::InvalidClearance`].
    ///
    /// # Performance
    /// As [`ApproachPlanner::approach`] for one route.
    pub fn retract<W: AsRef<[f64]>>(
        &self,
        last: &[f64],
        targets: &[W],
    ) -> Result<CheckedMove, ApproachError> {
        check_configuration(Role::RetractStart, last, self.limits())?;
        if targets.is_empty() {
            return Err(ApproachError::TooFewWaypoints { found: 1 });
        }
        for (i, target) in targets.iter().enumerate() {
            check_configuration(Role::RetractTarget(i), target.as_ref(), self.limits())?;
        }
        self.clear_endpoint(Role::RetractStart, last)?;
        let waypoints: Vec<&[f64]> = std::iter::once(last)
            .chain(targets.iter().map(AsRef::as_ref))
            .collect();
        self.checked(&waypoints, Route::Retract)?
            .map_err(|v| ApproachError::RetractBlocked {
                violation: Box::new(v),
            })
    }
}

/// The configuration that puts the tool `distance` metres along its own z axis from where it
/// is at `last`: `FK(q) = FK(last) · Trans(0, 0, distance)`, same orientation.
///
/// The sign follows the tool frame: with kerf_mill's convention (tool z from the tip towards
/// the spindle) a positive distance backs the tool out of the work; with a tool frame whose z
/// points into the work (the beam direction), pass a negative distance. The motion from
/// `last` to the answer is a joint move, not a straight line: [`ApproachPlanner::retract`]
/// checks it like any other.
///
/// # Arguments
/// * `last` – the last process configuration (finite).
/// * `distance` – signed distance along the tool z axis (m), finite and non-zero.
/// * `fk` – forward kinematics: configuration → tool pose in the base frame.
/// * `ik` – inverse kinematics: tool pose → a configuration, `None` when unreachable. It
///   should return the solution nearest `last` (same branch), or the joint move becomes a
///   large reconfiguration.
///
/// # Returns
/// The configuration; [`ApproachError::InvalidRetractDistance`],
/// [`ApproachError::NonFinitePose`] (FK of `last`), [`ApproachError::IkFailed`],
/// [`ApproachError::JointCount`] or [`ApproachError::NonFinitePosition`] for a malformed IK
/// answer, [`ApproachError::IkMismatch`] when `FK(answer)` misses the pose by more than
/// [`IK_POSITION_TOLERANCE`] or [`IK_ROTATION_TOLERANCE`]. Position limits are checked by
/// [`ApproachPlanner::retract`].
///
/// # Performance
/// Two FK calls and one IK call.
pub fn tool_axis_target<F, I>(
    last: &[f64],
    distance: f64,
    fk: F,
    ik: I,
) -> Result<Vec<f64>, ApproachError>
where
    F: Fn(&[f64]) -> Isometry3<f64>,
    I: Fn(&Isometry3<f64>) -> Option<Vec<f64>>,
{
    if !(distance.is_finite() && distance != 0.0) {
        return Err(ApproachError::InvalidRetractDistance { distance });
    }
    if let Some((j, &value)) = last.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(ApproachError::NonFinitePosition {
            role: Role::RetractStart,
            joint: format!("#{j}"),
            value,
        });
    }
    let pose = fk(last);
    if !finite_pose(&pose) {
        return Err(ApproachError::NonFinitePose {
            configuration: last.to_vec(),
        });
    }
    let target = pose * Translation3::new(0.0, 0.0, distance);
    let q = ik(&target).ok_or(ApproachError::IkFailed { distance })?;
    if q.len() != last.len() {
        return Err(ApproachError::JointCount {
            what: "inverse kinematics answer".into(),
            expected: last.len(),
            found: q.len(),
        });
    }
    if let Some((j, &value)) = q.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(ApproachError::NonFinitePosition {
            role: Role::RetractTarget(0),
            joint: format!("#{j}"),
            value,
        });
    }
    let reached = fk(&q);
    let position_error = (reached.translation.vector - target.translation.vector).norm();
    let rotation_error = reached.rotation.angle_to(&target.rotation);
    // `!(e <= tol)` also refuses NaN errors of a non-finite FK answer.
    if !(position_error <= IK_POSITION_TOLERANCE && rotation_error <= IK_ROTATION_TOLERANCE) {
        return Err(ApproachError::IkMismatch {
            position_error,
            rotation_error,
            position_tolerance: IK_POSITION_TOLERANCE,
            rotation_tolerance: IK_ROTATION_TOLERANCE,
        });
    }
    Ok(q)
}

/// Whether every number of `pose` is finite.
fn finite_pose(pose: &Isometry3<f64>) -> bool {
    pose.translation.vector.iter().all(|v| v.is_finite())
        && pose.rotation.coords.iter().all(|v| v.is_finite())
}
