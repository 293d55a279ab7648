//! Mirrors of `sensor_msgs` (ros2/common_interfaces, Jazzy) used by kerf.

use serde::{Deserialize, Serialize};

use crate::ros_type::impl_ros_type;
use crate::std_msgs::Header;

/// `sensor_msgs/msg/JointState`: measured state of a set of joints. Each array
/// is either empty or has one entry per name.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct JointState {
    /// `header.stamp` is when the state was measured.
    pub header: Header,
    /// Joint names.
    pub name: Vec<String>,
    /// Positions, rad or m.
    pub position: Vec<f64>,
    /// Velocities, rad/s or m/s.
    pub velocity: Vec<f64>,
    /// Efforts, N·m or N.
    pub effort: Vec<f64>,
}
impl_ros_type!(JointState, "sensor_msgs", msg, "JointState");
