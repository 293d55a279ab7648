//! The one error type of the test-part generators.

use thiserror::Error;

/// Everything that can make generating a test part or a cut request fail.
#[derive(Debug, Error)]
pub enum TestPartError {
    /// A parameter of the part, of a path on it or of a case is out of
    /// range (shown as `invalid request: field: reason`, the text the
    /// generator printed when it lived in `kerf_mjto`).
    #[error("invalid request: {field}: {reason}")]
    Invalid {
        /// The parameter at fault (e.g. `bpillar.foot.depth`).
        field: String,
        /// Why it is rejected.
        reason: String,
    },
}

impl TestPartError {
    /// Shorthand for [`TestPartError::Invalid`].
    ///
    /// # Arguments
    /// * `field` - the parameter at fault.
    /// * `reason` - why it is rejected.
    ///
    /// # Returns
    /// The error.
    pub fn invalid(field: impl Into<String>, reason: impl Into<String>) -> Self {
        TestPartError::Invalid {
            field: field.into(),
            reason: reason.into(),
        }
    }
}
