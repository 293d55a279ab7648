//! [`IsolateError`]: why a job could not be handed to a worker process.

use thiserror::Error;

/// Why the supervisor could not start or reach a worker process.
#[derive(Debug, Error)]
pub enum IsolateError {
    /// A system call failed (fork, socketpair, send).
    #[error("worker process: {call} failed: {reason}")]
    System {
        /// The call.
        call: &'static str,
        /// The OS error.
        reason: String,
    },
    /// A job or answer could not be encoded or decoded.
    #[error("worker process: cannot {what}: {reason}")]
    Encoding {
        /// "encode the job", "decode the answer", …
        what: &'static str,
        /// The encoder's message.
        reason: String,
    },
    /// A job was submitted while another one runs.
    #[error("worker process: job {running} is still running; one job at a time")]
    Busy {
        /// The running job's id.
        running: u64,
    },
}

impl IsolateError {
    /// A failed system call with the current OS error.
    pub(crate) fn last_os(call: &'static str) -> Self {
        Self::System {
            call,
            reason: std::io::Error::last_os_error().to_string(),
        }
    }
}
