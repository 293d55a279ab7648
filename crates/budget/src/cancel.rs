//! [`CancelToken`]: a shared flag that cancels the work holding it.

use std::sync::{
    atomic::{AtomicBool, Ordering},
    Arc,
};

/// A cancellation flag shared between the thread that plans and the one that may stop it
/// (a node's shutdown, Ctrl-C). Clones share the flag.
#[derive(Debug, Clone, Default)]
pub struct CancelToken(Arc<AtomicBool>);

impl CancelToken {
    /// A token that is not cancelled.
    pub fn new() -> Self {
        Self::default()
    }

    /// Cancels every [`crate::Budget`] holding this token (or a clone of it). Irreversible.
    pub fn cancel(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// Whether [`Self::cancel`] was called.
    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}
