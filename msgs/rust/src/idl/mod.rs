//! A parser for ROS 2 interface definition files (`.msg`, `.srv`, `.action`).
//!
//! It follows the grammar and the checks of `rosidl_adapter.parser` (package
//! `rosidl_adapter`, ROS 2 Jazzy; Debian `python3-rosidl`), and the ROS 2
//! design article "Interface definition and language mapping": one field
//! `TYPE NAME [DEFAULT]` or constant `TYPE NAME=VALUE` per line, `#` starts a
//! comment, `---` separates the parts of services and actions. Types are the
//! primitives, `string<=N`, nested messages `pkg/Name` or `Name` (same
//! package), and arrays `T[]`, `T[N]`, `T[<=N]`.
//!
//! kerf uses it to check that its serde mirrors match the interface files.

mod names;
mod parse;
mod types;
mod value;

pub use parse::{parse_action, parse_interface, parse_message, parse_service};
pub use types::{
    Array, BaseType, Constant, Field, FieldType, InterfaceSpec, MessageSpec, Primitive, Value,
};
