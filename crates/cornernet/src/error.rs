//! The crate's one error type.

use kerf_toolpath::ToolpathError;

/// Everything that can go wrong in the DRLS networks.
#[derive(Debug, thiserror::Error)]
pub enum CornerNetError {
    /// A setting or an argument is out of range.
    #[error("invalid {name} = {value}: {reason}")]
    InvalidParameter {
        /// What was given.
        name: String,
        /// Its value.
        value: f64,
        /// Why it is refused.
        reason: String,
    },
    /// The corner geometry or the swarm of `kerf_toolpath` failed.
    #[error("corner at sample {index}: {source}")]
    Corner {
        /// The sample (or corner) index.
        index: usize,
        /// The toolpath error.
        source: ToolpathError,
    },
    /// A file could not be read or written.
    #[error("{path}: {reason}")]
    Io {
        /// The file.
        path: String,
        /// The operating system's or the format's message.
        reason: String,
    },
    /// A weights file does not fit: other sizes, another distribution, or a bad sidecar.
    #[error("refused network file {path}: {reason}")]
    Mismatch {
        /// The file.
        path: String,
        /// What does not fit.
        reason: String,
    },
    /// candle failed.
    #[error("candle: {reason}")]
    Backend {
        /// candle's message.
        reason: String,
    },
}

impl From<candle_core::Error> for CornerNetError {
    fn from(e: candle_core::Error) -> Self {
        CornerNetError::Backend {
            reason: e.to_string(),
        }
    }
}
