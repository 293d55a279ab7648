//! [`NodeError`]: why a planner node could not start.

use crate::RosError;

/// Why a planner node could not start: the plumbing, a parameter, or the service's own
/// set-up (`E`: the model that does not load, …). Request errors never end a node.
#[derive(Debug, thiserror::Error)]
pub enum NodeError<E: std::error::Error + 'static> {
    /// Environment, arguments, names or DDS.
    #[error(transparent)]
    Ros(#[from] RosError),
    /// A parameter has a wrong value.
    #[error("parameter '{name}': {reason}")]
    Config {
        /// Parameter.
        name: String,
        /// What is wrong.
        reason: String,
    },
    /// The service could not be set up (its error says what).
    #[error(transparent)]
    Setup(E),
}

impl<E: std::error::Error + 'static> NodeError<E> {
    /// A [`NodeError::Config`] naming parameter `name`.
    pub fn config(name: &str, reason: impl Into<String>) -> Self {
        Self::Config {
            name: name.to_string(),
            reason: reason.into(),
        }
    }

    /// A [`NodeError::Setup`] from anything the service's error converts from (for
    /// `.map_err(NodeError::setup)?`).
    pub fn setup(e: impl Into<E>) -> Self {
        Self::Setup(e.into())
    }
}
