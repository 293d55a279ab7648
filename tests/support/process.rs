//! Child processes of the `kerf` binary: killed when a test ends, and stopped by Ctrl-C.

use std::{
    process::{Child, Command},
    time::{Duration, Instant},
};

/// A child process killed (and reaped) when the test ends, however it ends.
pub struct Killed(pub Child);

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Sends SIGINT (Ctrl-C) to the child.
pub fn interrupt(child: &Child) {
    let pid = child.id().to_string();
    assert!(Command::new("kill")
        .args(["-INT", &pid])
        .status()
        .expect("run kill")
        .success());
}

/// Waits until the child exits, which must be with status 0 within `timeout`.
pub fn assert_clean_exit(child: &mut Child, timeout: Duration) {
    let deadline = Instant::now() + timeout;
    loop {
        if let Some(status) = child.try_wait().expect("child status") {
            assert!(status.success(), "exit status {status}");
            return;
        }
        assert!(
            Instant::now() < deadline,
            "kerf launch did not exit after SIGINT"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}
