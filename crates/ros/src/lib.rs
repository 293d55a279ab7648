//! ROS 2 plumbing shared by every kerf node.
//!
//! * [`RosEnv`] reads `ROS_DOMAIN_ID` and `ROS_AUTOMATIC_DISCOVERY_RANGE` with their ROS 2
//!   Jazzy meanings and builds the DDS participant (`LOCALHOST` = loopback only).
//! * [`RosArgs`] parses `--ros-args` (`-r`, `-p`, `--params-file`, `--log-level`, …) so launch
//!   files work unchanged; [`Params`] gives typed, checked parameter access.
//! * [`qos`] holds the named QoS profiles (reliable, keep-last ≥ 10).
//! * [`Logger`] writes to stderr and `/rosout`.
//! * [`shutdown`] turns Ctrl-C into a flag every node loop polls; [`StopToken`] stops one node.
//! * [`Inbox`] reads (and deserializes) a subscription on its own thread.
//! * [`Streamer`] publishes high-rate streams from a thread, so a control loop never blocks.
//! * [`Worker`] runs slow requests in the background so a node keeps serving.
//! * [`planner`] is the planner-node harness every planner node is built on.
//! * [`KerfNode`] ties these together: one Context per node, names resolved and remapped.

mod args;
mod env;
mod error;
mod inbox;
mod logger;
pub mod memory;
pub mod names;
mod node;
mod params;
pub mod planner;
pub mod qos;
mod realtime;
pub mod shutdown;
mod streamer;
mod worker;

pub use args::{LogLevel, ParamSource, RosArgs};
pub use env::{DiscoveryRange, RosEnv, MAX_DOMAIN_ID};
pub use error::RosError;
pub use inbox::{Inbox, INBOX_CAPACITY, INBOX_POLL};
pub use logger::Logger;
pub use node::{block_on_timeout, KerfNode, NodeSpec};
pub use params::{ParamValue, Params};
pub use realtime::{lock_memory, set_realtime_priority};
pub use shutdown::StopToken;
pub use streamer::Streamer;
pub use worker::{Worker, WorkerError};

/// Re-export, so node crates use exactly the ros2-client version kerf was built against.
pub use ros2_client;
