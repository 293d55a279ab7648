//! Process-wide shutdown flag, set by Ctrl-C (SIGINT) or SIGTERM, or by the program itself.
//!
//! Every node loop polls [`requested`] each cycle, so one Ctrl-C stops every node of a
//! `kerf launch` process; nodes then drop their DDS entities in the order ros2-client needs.

use std::sync::{
    atomic::{AtomicBool, Ordering},
    Once,
};

static REQUESTED: AtomicBool = AtomicBool::new(false);
static HANDLER: Once = Once::new();

/// Installs the Ctrl-C / SIGTERM handler once per process. Later calls do nothing.
///
/// # Returns
/// An error message if the OS refused the handler (another library installed one first).
pub fn install_handler() -> Result<(), String> {
    let mut result = Ok(());
    HANDLER.call_once(|| {
        result =
            ctrlc::set_handler(request).map_err(|e| format!("cannot install Ctrl-C handler: {e}"));
    });
    result
}

/// Asks every node of this process to stop.
pub fn request() {
    REQUESTED.store(true, Ordering::SeqCst);
}

/// Whether shutdown was requested.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::SeqCst)
}

/// A stop flag for one node or one group of nodes; it also reports the process-wide request.
///
/// Tests run several nodes in one process and stop them one by one through their tokens,
/// without touching the process-wide flag.
#[derive(Debug, Clone, Default)]
pub struct StopToken(std::sync::Arc<AtomicBool>);

impl StopToken {
    /// A fresh, unset token.
    pub fn new() -> Self {
        Self::default()
    }

    /// Stops the holders of this token.
    pub fn stop(&self) {
        self.0.store(true, Ordering::SeqCst);
    }

    /// Whether this token was stopped or process-wide shutdown was requested.
    pub fn is_stopped(&self) -> bool {
        self.0.load(Ordering::SeqCst) || requested()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_are_independent() {
        let a = StopToken::new();
        let b = StopToken::new();
        let a2 = a.clone();
        a.stop();
        assert!(a2.is_stopped());
        assert!(!b.is_stopped());
    }
}
