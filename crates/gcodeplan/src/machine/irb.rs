//! [`MillingPlane`]: the IRB 6660 milling cell with a program on a plane.

use kerf_mill::path::tool_pose;
use kerf_mill::MillCell;
use kerf_robot::RobotModel;
use nalgebra::{Matrix3, Vector3};

use super::{bounds_of, check_finite, JointBounds, Machine, DOF};
use crate::error::GcodePlanError;

/// The ABB IRB 6660 (seed 004) with the program's XY plane on the cell's
/// milling plane.
///
/// # The program frame
/// Its origin is [`MillingPlane::origin`] (by default the cell path's first
/// point, seed 004 Table 1's p1); its z axis is the plane's normal on the
/// side the tool comes from (−approach), its x axis the base frame's x
/// projected on the plane, y = z × x. A program's Z moves along the normal.
///
/// # The tool's orientation
/// Fixed over the program: the cell's tool pose (`kerf_mill::path::tool_pose`)
/// with the program's x axis as the reference direction and the redundancy
/// angle g about the tool axis. Unlike seed 004's path, whose reference is
/// the path tangent, a G-code program turns corners of any angle, and a
/// tangent-following tool would spin the wrist at each; g is a fixed angle
/// from the program's x axis instead.
#[derive(Debug, Clone)]
pub struct MillingPlane {
    cell: MillCell,
    origin: Vector3<f64>,
    axes: Matrix3<f64>,
    g: f64,
    bounds: [JointBounds; DOF],
}

impl MillingPlane {
    /// The shipped cell (`urdf/irb6660_milling.yaml`) with its path's first
    /// point as the origin and g.
    ///
    /// # Errors
    /// As [`MillCell::default_cell`] and [`MillingPlane::new`].
    pub fn default_plane(g: f64) -> Result<Self, GcodePlanError> {
        let cell = MillCell::default_cell().map_err(|e| GcodePlanError::InvalidRequest {
            field: "machine".to_string(),
            reason: e.to_string(),
        })?;
        let origin = cell
            .path()
            .point(0.0)
            .map_err(|e| GcodePlanError::InvalidRequest {
                field: "machine".to_string(),
                reason: e.to_string(),
            })?;
        Self::new(cell, [origin.x, origin.y, origin.z], g)
    }

    /// `cell` with the program's zero at `origin` (base frame \[m\]) and the
    /// redundancy angle `g` \[rad\].
    ///
    /// # Errors
    /// [`GcodePlanError::InvalidSetting`] for a non-finite origin or g, or a
    /// plane whose normal is along the base x axis (no program x axis).
    pub fn new(cell: MillCell, origin: [f64; 3], g: f64) -> Result<Self, GcodePlanError> {
        check_finite("milling plane origin [m]", &origin)?;
        check_finite("redundancy angle g [rad]", &[g])?;
        let z = -cell.path().approach();
        let x = Vector3::x() - Vector3::x().dot(&z) * z;
        if x.norm() < 1e-6 {
            return Err(GcodePlanError::InvalidSetting {
                name: "milling plane".to_string(),
                value: x.norm(),
                reason: "its normal is the base x axis: the program's x axis is undefined"
                    .to_string(),
            });
        }
        let x = x.normalize();
        let y = z.cross(&x);
        let bounds = bounds_of(cell.robot())?;
        Ok(Self {
            cell,
            origin: Vector3::from(origin),
            axes: Matrix3::from_columns(&[x, y, z]),
            g,
            bounds,
        })
    }

    /// The program's zero, base frame \[m\].
    pub fn origin(&self) -> [f64; 3] {
        [self.origin.x, self.origin.y, self.origin.z]
    }

    /// The redundancy angle g \[rad\].
    pub fn redundancy_angle(&self) -> f64 {
        self.g
    }

    /// The cell.
    pub fn cell(&self) -> &MillCell {
        &self.cell
    }
}

impl Machine for MillingPlane {
    fn name(&self) -> &str {
        "irb6660"
    }

    fn robot(&self) -> &RobotModel {
        self.cell.robot()
    }

    fn bounds(&self) -> &[JointBounds; DOF] {
        &self.bounds
    }

    fn joints(
        &self,
        point: [f64; 3],
        reference: Option<&[f64; DOF]>,
    ) -> Result<[f64; DOF], String> {
        let p = self.origin + self.axes * Vector3::from(point);
        let x = self.axes.column(0).into_owned();
        let pose = tool_pose(&p, &x, &self.cell.path().approach(), self.g);
        self.cell
            .kinematics()
            .ik_nearest(&pose, reference.unwrap_or(self.cell.reference_joints()))
            .map_err(|e| e.to_string())
    }

    fn tip(&self, q: &[f64; DOF]) -> Result<[f64; 3], String> {
        let pose = self
            .cell
            .kinematics()
            .tcp_pose(q)
            .map_err(|e| e.to_string())?;
        let local = self.axes.transpose() * (pose.translation.vector - self.origin);
        Ok([local.x, local.y, local.z])
    }
}
