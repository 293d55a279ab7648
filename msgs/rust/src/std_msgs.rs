//! Mirrors of `std_msgs` (ros2/common_interfaces, Jazzy) used by kerf.
//!
//! `std_msgs/msg/String` is named [`StringMsg`] here so that it does not shadow
//! Rust's `String` inside this crate or in code that glob-imports the module.

use serde::{Deserialize, Serialize};

use crate::builtin_interfaces::Time;
use crate::ros_type::impl_ros_type;

/// `std_msgs/msg/Header`: stamp and coordinate frame of stamped data.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Header {
    /// When the data was produced or measured.
    pub stamp: Time,
    /// Coordinate frame the data is expressed in (a TF frame id).
    pub frame_id: String,
}
impl_ros_type!(Header, "std_msgs", msg, "Header");

/// `std_msgs/msg/String`: one UTF-8 string.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename = "String")]
pub struct StringMsg {
    /// The text.
    pub data: String,
}
impl_ros_type!(StringMsg, "std_msgs", msg, "String");
