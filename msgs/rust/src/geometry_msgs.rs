//! Mirrors of `geometry_msgs` (ros2/common_interfaces, Jazzy) used by kerf.
//! Lengths in m, angles in rad, times in s.

use serde::{Deserialize, Serialize};

use crate::ros_type::impl_ros_type;

/// `geometry_msgs/msg/Point`: a position in free space, m.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Point {
    /// x coordinate, m.
    pub x: f64,
    /// y coordinate, m.
    pub y: f64,
    /// z coordinate, m.
    pub z: f64,
}
impl_ros_type!(Point, "geometry_msgs", msg, "Point");

/// `geometry_msgs/msg/Vector3`: a vector in free space (units depend on use).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Vector3 {
    /// x component.
    pub x: f64,
    /// y component.
    pub y: f64,
    /// z component.
    pub z: f64,
}
impl_ros_type!(Vector3, "geometry_msgs", msg, "Vector3");

/// `geometry_msgs/msg/Quaternion`: an orientation as `x i + y j + z k + w`.
///
/// [`Default`] is the identity rotation `(0, 0, 0, 1)`, as the `.msg` file's
/// default values `float64 w 1` specify.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Quaternion {
    /// i component.
    pub x: f64,
    /// j component.
    pub y: f64,
    /// k component.
    pub z: f64,
    /// Real component.
    pub w: f64,
}
impl_ros_type!(Quaternion, "geometry_msgs", msg, "Quaternion");

impl Quaternion {
    /// The identity rotation `(x, y, z, w) = (0, 0, 0, 1)`.
    pub const IDENTITY: Quaternion = Quaternion {
        x: 0.0,
        y: 0.0,
        z: 0.0,
        w: 1.0,
    };
}

impl Default for Quaternion {
    fn default() -> Self {
        Quaternion::IDENTITY
    }
}

/// `geometry_msgs/msg/Pose`: position and orientation.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Pose {
    /// Position, m.
    pub position: Point,
    /// Orientation.
    pub orientation: Quaternion,
}
impl_ros_type!(Pose, "geometry_msgs", msg, "Pose");

/// `geometry_msgs/msg/Transform`: translation and rotation between two frames.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Transform {
    /// Translation, m.
    pub translation: Vector3,
    /// Rotation.
    pub rotation: Quaternion,
}
impl_ros_type!(Transform, "geometry_msgs", msg, "Transform");

/// `geometry_msgs/msg/Twist`: linear and angular velocity.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Twist {
    /// Linear velocity, m/s (or m/s² where used for accelerations).
    pub linear: Vector3,
    /// Angular velocity, rad/s (or rad/s² where used for accelerations).
    pub angular: Vector3,
}
impl_ros_type!(Twist, "geometry_msgs", msg, "Twist");
