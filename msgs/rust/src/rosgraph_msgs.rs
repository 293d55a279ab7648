//! Mirrors of `rosgraph_msgs` (ros2/rcl_interfaces, Jazzy) used by kerf.

use serde::{Deserialize, Serialize};

use crate::builtin_interfaces::Time;
use crate::ros_type::impl_ros_type;

/// `rosgraph_msgs/msg/Clock`: the current time, published on `/clock` by a simulator for
/// nodes with `use_sim_time` (ROS 2 design article "Clock and Time").
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Clock {
    /// The current (simulated) time.
    pub clock: Time,
}
impl_ros_type!(Clock, "rosgraph_msgs", msg, "Clock");
