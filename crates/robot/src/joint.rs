//! Movable joints of the kinematic chain.

use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};

/// The kind of a movable joint.
///
/// URDF `continuous`, `floating`, `planar` and `spherical` joints are
/// rejected when a model is loaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointKind {
    /// Rotation about the joint axis; position in rad.
    Revolute,
    /// Translation along the joint axis; position in m.
    Prismatic,
}

/// One movable joint with its geometry and merged limits.
///
/// Units are SI: positions in m (prismatic) or rad (revolute), and their
/// first, second and third time derivatives in m/s, m/s², m/s³ or rad/s,
/// rad/s², rad/s³.
#[derive(Debug, Clone, PartialEq)]
pub struct JointSpec {
    /// Joint name as in the URDF.
    pub name: String,
    /// Revolute or prismatic.
    pub kind: JointKind,
    /// Name of the parent link.
    pub parent_link: String,
    /// Name of the child link.
    pub child_link: String,
    /// Transform from the parent link frame to the joint frame at zero
    /// position (URDF `<origin>`).
    pub origin: Isometry3<f64>,
    /// Unit joint axis in the joint frame (URDF `<axis>`, normalised).
    pub axis: Unit<Vector3<f64>>,
    /// Lower position limit (m or rad).
    pub min_position: f64,
    /// Upper position limit (m or rad), strictly greater than `min_position`.
    pub max_position: f64,
    /// Maximum speed (m/s or rad/s), strictly positive.
    pub max_velocity: f64,
    /// Maximum effort from the URDF (N or N·m), strictly positive.
    pub max_effort: f64,
    /// Maximum acceleration (m/s² or rad/s²), if the limits YAML gives one.
    pub max_acceleration: Option<f64>,
    /// Maximum jerk (m/s³ or rad/s³), if the limits YAML gives one.
    pub max_jerk: Option<f64>,
}

impl JointSpec {
    /// The joint motion at position `q`, expressed in the joint frame.
    ///
    /// Revolute: rotation by `q` about `axis`; prismatic: translation by
    /// `q * axis` (URDF specification, ROS wiki `urdf/XML/joint`).
    ///
    /// # Arguments
    /// * `q` - joint position (rad or m). Not checked against the limits.
    ///
    /// # Returns
    /// The displacement of the child link frame relative to the joint frame.
    ///
    /// # Performance
    /// O(1), no allocation.
    pub fn motion(&self, q: f64) -> Isometry3<f64> {
        match self.kind {
            JointKind::Revolute => Isometry3::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_axis_angle(&self.axis, q),
            ),
            JointKind::Prismatic => Isometry3::from_parts(
                Translation3::from(self.axis.into_inner() * q),
                UnitQuaternion::identity(),
            ),
        }
    }

    /// Transform from the parent link frame to the child link frame at `q`:
    /// `origin * motion(q)` (URDF specification, ROS wiki `urdf/XML/joint`).
    ///
    /// # Arguments
    /// * `q` - joint position (rad or m). Not checked against the limits.
    ///
    /// # Returns
    /// The parent-to-child transform.
    ///
    /// # Performance
    /// O(1), no allocation.
    pub fn transform(&self, q: f64) -> Isometry3<f64> {
        self.origin * self.motion(q)
    }

    /// Whether `q` lies within `[min_position, max_position]` (bounds
    /// included). NaN is never within.
    pub fn contains(&self, q: f64) -> bool {
        q >= self.min_position && q <= self.max_position
    }
}
