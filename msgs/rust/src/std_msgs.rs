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

/// `std_msgs/msg/MultiArrayDimension`: one dimension of a [`MultiArrayLayout`].
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct MultiArrayDimension {
    /// Label of the dimension.
    pub label: String,
    /// Size of the dimension.
    pub size: u32,
    /// Stride of the dimension.
    pub stride: u32,
}
impl_ros_type!(MultiArrayDimension, "std_msgs", msg, "MultiArrayDimension");

/// `std_msgs/msg/MultiArrayLayout`: how a multi-array's flat data is laid out.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct MultiArrayLayout {
    /// The dimensions (empty for a plain vector).
    pub dim: Vec<MultiArrayDimension>,
    /// Padding elements at the front of `data`.
    pub data_offset: u32,
}
impl_ros_type!(MultiArrayLayout, "std_msgs", msg, "MultiArrayLayout");

/// `std_msgs/msg/Float64MultiArray`: the command message of ros2_control's
/// `forward_command_controller` (one value per joint, in the controller's joint order).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Float64MultiArray {
    /// The layout of `data`.
    pub layout: MultiArrayLayout,
    /// The values.
    pub data: Vec<f64>,
}
impl_ros_type!(Float64MultiArray, "std_msgs", msg, "Float64MultiArray");
