//! The IRB 6660's milling tool axis ([`ToolAxis`] of `kerf_mill`'s kinematics) and the
//! IRB 6660 milling cell's surroundings ([`milling_surroundings`]) that both the milling
//! planner and the G-code planner use (issue 27).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use kerf_approach::{ApproachError, Role};
use kerf_mill::{Kinematics, MillCell, MillError};
use nalgebra::Translation3;

use crate::surroundings::{CellSurroundings, ToolAxis};
use crate::CellError;

/// The shipped cell file of the IRB 6660 milling on its fixture plate, below the kerf data
/// root (`kerf_robot::data`).
pub const IRB6660_CELL: &str = "urdf/cells/irb6660_plate.yaml";

/// The largest joint step (rad) of a back-off: a larger one is a change of IK branch, not a
/// motion along the tool axis. The branch-jump threshold of `urdf/irb6660_milling.yaml`
/// (`robot.branch_jump_threshold`); a back-off of a few centimetres moves a joint by
/// hundredths of a radian away from singularities.
pub const MAX_BACK_OFF_STEP: f64 = 0.5;

/// `kerf_mill`'s tool frame: its z axis is the approach direction, out of the spindle into
/// the workpiece (`urdf/irb6660_milling.yaml`, `tcp`). Backing off by `d` puts the tool tip at
/// `T_tcp(q) · Trans(0, 0, −d)`, same orientation, reached by the closed-form IK nearest to
/// `q` ([`Kinematics::ik_nearest`], checked by forward kinematics to 1e-8).
impl ToolAxis for Kinematics {
    /// # Errors
    /// [`ApproachError::InvalidRetractDistance`] for a distance not finite and > 0;
    /// [`ApproachError::JointCount`], [`ApproachError::NonFinitePosition`] for a bad `q`;
    /// [`ApproachError::OutOfLimits`] naming the joint when every IK solution breaks a
    /// limit; [`ApproachError::IkFailed`] when the pose is out of reach or only reached on
    /// another IK branch (a joint step over [`MAX_BACK_OFF_STEP`]).
    fn back_off(&self, q: &[f64], distance: f64) -> Result<Vec<f64>, ApproachError> {
        if !(distance.is_finite() && distance > 0.0) {
            return Err(ApproachError::InvalidRetractDistance { distance });
        }
        let q6 = <[f64; 6]>::try_from(q).map_err(|_| ApproachError::JointCount {
            what: "tool-axis back-off".into(),
            expected: 6,
            found: q.len(),
        })?;
        if let Some((j, &value)) = q6.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(ApproachError::NonFinitePosition {
                role: Role::Waypoint(0),
                joint: self.joints()[j].name.clone(),
                value,
            });
        }
        let failed = ApproachError::IkFailed { distance };
        let tip = self.tcp_pose(&q6).map_err(|_| failed.clone())?;
        let target = tip * Translation3::new(0.0, 0.0, -distance);
        let back = self.ik_nearest(&target, &q6).map_err(|e| match e {
            MillError::JointLimit {
                joint,
                value,
                lower,
                upper,
                ..
            } => ApproachError::OutOfLimits {
                role: Role::Waypoint(0),
                joint,
                value,
                min: lower,
                max: upper,
            },
            _ => failed.clone(),
        })?;
        let step = back
            .iter()
            .zip(&q6)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        if step.is_nan() || step > MAX_BACK_OFF_STEP {
            return Err(failed);
        }
        Ok(back.to_vec())
    }
}

/// The shipped [`IRB6660_CELL`] below the kerf data root.
///
/// # Errors
/// [`CellError::Robot`] when no kerf data root is found (the message names every place
/// searched).
pub fn irb6660_cell_path() -> Result<PathBuf, CellError> {
    kerf_robot::data::path(IRB6660_CELL).map_err(|e| CellError::Robot {
        reason: e.to_string(),
    })
}

/// The surroundings of `mill`'s robot in the kerf_cell cell file `cell_file` (`None`: the
/// shipped [`IRB6660_CELL`]), its tool axis `mill`'s kinematics.
///
/// # Errors
/// As [`irb6660_cell_path`] and [`CellSurroundings::from_file`];
/// [`CellError::JointMismatch`] when `mill`'s robot does not have the 6 joints of its
/// kinematics.
pub fn milling_surroundings(
    mill: &MillCell,
    cell_file: Option<&Path>,
) -> Result<CellSurroundings, CellError> {
    let joints = mill.robot().dof();
    if joints != 6 {
        return Err(CellError::JointMismatch {
            what: "milling robot",
            reason: format!("{joints} joints; the IRB 6660's kinematics has 6"),
            expected: mill.robot().joint_names().join(", "),
        });
    }
    let path = match cell_file {
        Some(p) => p.to_path_buf(),
        None => irb6660_cell_path()?,
    };
    CellSurroundings::from_file(
        mill.robot().clone(),
        &path,
        Arc::new(mill.kinematics().clone()),
    )
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]

    use kerf_approach::Surroundings;
    use nalgebra::Point3;

    use super::*;

    fn shipped() -> (MillCell, CellSurroundings) {
        let mill = MillCell::default_cell().unwrap();
        let s = milling_surroundings(&mill, None).unwrap();
        (mill, s)
    }

    #[test]
    fn the_cutter_in_the_stock_is_a_collision_except_in_the_process() {
        let (mill, s) = shipped();
        let q = mill.joints_at_parameter(0.0, 0.0, None).unwrap();
        // 3 mm axial depth of cut (urdf/cells/irb6660_plate.yaml).
        let c = s.clearance(&q, false);
        assert!((c.distance + 0.003).abs() < 1e-6, "{c:?}");
        assert_eq!(c.obstacle, "stock (cutter on tool0)");
        // Without the working contact: the holder, 30 mm above the tip, 27 mm above the stock.
        let c = s.clearance(&q, true);
        assert!((c.distance - 0.027).abs() < 1e-6, "{c:?}");
        assert_eq!(c.obstacle, "stock (holder on tool0)");
        // Far from everything: the cut-off, a lower bound.
        let c = s.clearance(&[0.0; 6], false);
        assert_eq!(c.distance, crate::surroundings::EXACT_UP_TO, "{c:?}");
        // Malformed configurations are refused (NaN), never far.
        assert!(s.clearance(&[0.0; 5], false).distance.is_nan());
        assert!(s.clearance(&[f64::NAN; 6], true).distance.is_nan());
    }

    #[test]
    fn backing_off_lifts_the_tool_tip_along_its_axis() {
        let (mill, s) = shipped();
        let kin = mill.kinematics();
        let q = mill.joints_at_parameter(0.5, 0.0, None).unwrap();
        let back = s.back_off(&q, 0.03).unwrap();
        let (a, b) = (
            kin.tcp_pose(&q).unwrap(),
            kin.tcp_pose(&<[f64; 6]>::try_from(back.as_slice()).unwrap())
                .unwrap(),
        );
        // The default plane is horizontal, the tool pointing down: 30 mm straight up.
        let d = b.translation.vector - a.translation.vector;
        assert!(
            (d - nalgebra::Vector3::new(0.0, 0.0, 0.03)).norm() < 1e-8,
            "{d}"
        );
        assert!(a.rotation.angle_to(&b.rotation) < 1e-8);
        let c = s.clearance(&back, false);
        assert!((c.distance - 0.027).abs() < 1e-6, "{c:?}");
        // Bad inputs name what is wrong.
        assert!(matches!(
            s.back_off(&q[..5], 0.03),
            Err(ApproachError::JointCount { found: 5, .. })
        ));
        assert!(matches!(
            s.back_off(&q, f64::NAN),
            Err(ApproachError::InvalidRetractDistance { .. })
        ));
        // 5 m up is out of reach.
        assert!(matches!(
            s.back_off(&q, 5.0),
            Err(ApproachError::IkFailed { .. } | ApproachError::OutOfLimits { .. })
        ));
    }

    #[test]
    fn no_shape_point_moves_farther_than_the_lipschitz_bound() {
        let (mill, s) = shipped();
        let l = s.lipschitz();
        assert_eq!(l.len(), 6);
        assert!(l[0] > 3.5 && l[0] < 4.0, "{l:?}");
        // The cut-off of the exact distances covers the clearance plus one control period's
        // sweep at the velocity limits (crate::surroundings::EXACT_UP_TO).
        let sweep: f64 = l
            .iter()
            .zip(mill.robot().joints())
            .map(|(l, j)| l * j.max_velocity * 0.004)
            .sum();
        assert!(0.01 + sweep < crate::surroundings::EXACT_UP_TO, "{sweep}");
        let chain = s.chain();
        let corners = |q: &[f64]| -> Vec<Point3<f64>> {
            let mut bodies = Vec::new();
            chain.body_poses(q, &mut bodies);
            s.shapes()
                .iter()
                .flat_map(|sh| {
                    let pose = match sh.body {
                        Some(b) => crate::geometry::to_pose(&bodies[b]) * sh.local,
                        None => sh.local,
                    };
                    let iso = crate::geometry::to_isometry(&pose);
                    let bb = sh.shape.compute_local_aabb();
                    (0..8).map(move |k| {
                        let pick =
                            |bit: usize, lo: f64, hi: f64| if k >> bit & 1 == 0 { lo } else { hi };
                        iso * Point3::new(
                            pick(0, bb.mins.x, bb.maxs.x),
                            pick(1, bb.mins.y, bb.maxs.y),
                            pick(2, bb.mins.z, bb.maxs.z),
                        )
                    })
                })
                .collect()
        };
        // Deterministic pseudo-random configurations along the path and steps from them.
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for i in 0..50 {
            let q = mill
                .joints_at_parameter(i as f64 / 49.0, 0.0, None)
                .unwrap();
            let dq: Vec<f64> = (0..6).map(|_| 0.2 * next()).collect();
            let q1: Vec<f64> = q.iter().zip(&dq).map(|(a, d)| a + d).collect();
            let bound: f64 = l.iter().zip(&dq).map(|(l, d)| l * d.abs()).sum();
            for (a, b) in corners(&q).iter().zip(corners(&q1).iter()) {
                assert!(
                    (b - a).norm() <= bound + 1e-12,
                    "{} > {bound}",
                    (b - a).norm()
                );
            }
        }
    }
}
