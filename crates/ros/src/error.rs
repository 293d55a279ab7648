//! The one error type of the plumbing crate.

/// Everything that can go wrong while setting a node up from its environment and command line.
#[derive(Debug, thiserror::Error)]
pub enum RosError {
    /// `ROS_DOMAIN_ID` is not an integer in 0..=232.
    #[error("ROS_DOMAIN_ID={value:?} is invalid: {reason}")]
    DomainId {
        /// The variable's value.
        value: String,
        /// Why it was refused.
        reason: String,
    },
    /// `ROS_AUTOMATIC_DISCOVERY_RANGE` has a value ROS 2 Jazzy does not define, or one kerf cannot honour.
    #[error("ROS_AUTOMATIC_DISCOVERY_RANGE={value:?}: {reason}")]
    DiscoveryRange {
        /// The variable's value.
        value: String,
        /// Why it was refused.
        reason: String,
    },
    /// An environment variable kerf cannot honour is set.
    #[error("{variable}={value:?} is not supported: {reason}")]
    UnsupportedEnv {
        /// Variable name.
        variable: String,
        /// Its value.
        value: String,
        /// Why.
        reason: String,
    },
    /// A malformed `--ros-args` section.
    #[error("invalid ROS command-line argument {arg:?}: {reason}")]
    Args {
        /// The offending argument.
        arg: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A parameters file could not be read or parsed.
    #[error("parameters file {path}: {reason}")]
    ParamsFile {
        /// File path.
        path: String,
        /// What went wrong.
        reason: String,
    },
    /// A parameter is missing or has the wrong type or value.
    #[error("parameter '{name}': {reason}")]
    Param {
        /// Parameter name.
        name: String,
        /// What is wrong.
        reason: String,
    },
    /// A node, topic or namespace name is not a valid ROS 2 name.
    #[error("invalid ROS name {name:?}: {reason}")]
    Name {
        /// The name.
        name: String,
        /// Why it is invalid.
        reason: String,
    },
    /// The DDS layer refused to create an entity.
    #[error("DDS: could not create {what}: {reason}")]
    Dds {
        /// What was being created.
        what: String,
        /// The DDS layer's message.
        reason: String,
    },
}
