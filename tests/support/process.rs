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

/// The stderr lines of a child, read on their own thread as they come.
pub struct Lines {
    rx: std::sync::mpsc::Receiver<String>,
    seen: Vec<String>,
}

impl Lines {
    /// Starts `command` with its stderr piped and read line by line.
    pub fn spawn(mut command: Command) -> (Killed, Lines) {
        use std::io::{BufRead, BufReader};
        let mut child = Killed(
            command
                .stderr(std::process::Stdio::piped())
                .spawn()
                .expect("start the child process"),
        );
        let stderr = child.0.stderr.take().expect("stderr");
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stderr).lines().map_while(Result::ok) {
                let _ = tx.send(line);
            }
        });
        (
            child,
            Lines {
                rx,
                seen: Vec::new(),
            },
        )
    }

    /// The first line from now on that contains `needle`, waiting up to `within`; fails the
    /// test, showing every line seen, if none comes.
    pub fn wait_for(&mut self, needle: &str, within: Duration) -> String {
        let deadline = Instant::now() + within;
        while let Ok(line) = self
            .rx
            .recv_timeout(deadline.saturating_duration_since(Instant::now()))
        {
            self.seen.push(line.clone());
            if line.contains(needle) {
                return line;
            }
        }
        panic!(
            "the child never printed {needle:?}; it printed:\n{}",
            self.seen.join("\n")
        );
    }

    /// The lines that came since the last wait, without waiting.
    pub fn rest(&mut self) -> Vec<String> {
        self.rx.try_iter().collect()
    }
}

/// A `/proc/self/status` field in KiB (`"VmRSS:"`, `"VmHWM:"`); fails the test if missing.
pub fn status_kib(field: &str) -> u64 {
    kerf_ros::memory::status_kib(field)
        .unwrap_or_else(|| panic!("{field} missing from /proc/self/status"))
}
