//! Serde mirrors of the kerf_msgs ROS 2 interfaces and of the standard ROS 2
//! (Jazzy) messages kerf uses.
//!
//! ros2-client serializes messages with CDR through serde: struct fields go on
//! the wire in declaration order, so every mirror declares exactly the fields of
//! its ROS 2 interface definition, in the same order and with the matching Rust
//! type (`string` → [`String`], `float64` → `f64`,
//! `int32` → `i32`, `uint32` → `u32`, `uint16` → `u16`, `uint8` → `u8`,
//! `bool` → `bool`, `T[]` → `Vec<T>`, `T[N]` → `[T; N]`, nested message →
//! struct). The integration test `tests/drift.rs` checks every mirror against
//! the interface files: kerf's own in `msgs/msg`, `msgs/srv` and `msgs/action`, the standard
//! ones transcribed under `msgs/rust/interfaces/`.
//!
//! Module layout follows the ROS 2 packages: [`builtin_interfaces`],
//! [`std_msgs`], [`geometry_msgs`], [`trajectory_msgs`], [`sensor_msgs`],
//! [`control_msgs`], [`rosgraph_msgs`]; kerf's own interfaces are in [`msg`], [`srv`] and
//! [`action`].
//! Every mirror implements [`RosType`]. With the `ros2` feature every mirror
//! also implements `ros2_client::Message`.
//!
//! [`numbers`] declares the rule of every numeric field of every request message and checks a
//! message against them ([`numbers::NumberFields::check_numbers`]).
//!
//! [`idl`] parses `.msg`, `.srv` and `.action` files (the ROS 2 interface
//! definition format, as `rosidl_adapter` reads it).

pub mod action;
pub mod builtin_interfaces;
pub mod control_msgs;
mod error;
pub mod geometry_msgs;
pub mod idl;
pub mod msg;
pub mod numbers;
mod ros_type;
pub mod rosgraph_msgs;
pub mod sensor_msgs;
pub mod srv;
pub mod std_msgs;
pub mod trajectory_msgs;

pub use error::Error;
pub use ros_type::{InterfaceKind, RosType};
