//! `tools/sim_driver`, the simulated robot driver no part of kerf runs (issue 27), as a child
//! process of a test.

use std::{
    io::{BufRead, BufReader},
    path::{Path, PathBuf},
    process::{Child, Command, Stdio},
    sync::OnceLock,
    time::Instant,
};

use super::QUICK;

/// `target/<profile>/sim_driver`, next to this test's `deps/` directory; built once with
/// `cargo build -p sim_driver` (the same profile) when it is missing. A test of the root
/// package cannot name another package's binary with `CARGO_BIN_EXE_*`.
pub fn sim_driver_exe() -> &'static Path {
    static EXE: OnceLock<PathBuf> = OnceLock::new();
    EXE.get_or_init(|| {
        let me = std::env::current_exe().expect("test executable");
        // target/<profile>/deps/driver_e2e-<hash>
        let profile_dir = me
            .parent()
            .and_then(Path::parent)
            .expect("target/<profile>")
            .to_path_buf();
        let exe = profile_dir.join("sim_driver");
        if exe.is_file() {
            return exe;
        }
        let profile = profile_dir
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or("debug")
            .to_string();
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
        let mut cmd = Command::new(cargo);
        cmd.args(["build", "-p", "sim_driver"])
            .current_dir(env!("CARGO_MANIFEST_DIR"));
        match profile.as_str() {
            "debug" => {}
            "release" => {
                cmd.arg("--release");
            }
            other => {
                cmd.args(["--profile", other]);
            }
        }
        let status = cmd.status().expect("run cargo build -p sim_driver");
        assert!(status.success(), "cargo build -p sim_driver failed");
        assert!(exe.is_file(), "{} missing after the build", exe.display());
        exe
    })
}

/// The simulated driver, killed and reaped when dropped.
pub struct Driver {
    child: Child,
    log: PathBuf,
}

impl Driver {
    /// Starts `sim_driver` on `domain` (loopback only) with `args`, and waits for its ready
    /// line; its stderr goes to `<CARGO_TARGET_TMPDIR>/sim_driver/<name>.log`, printed when a
    /// test panics.
    pub fn start(domain: u16, name: &str, args: &[String]) -> Driver {
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("sim_driver");
        std::fs::create_dir_all(&dir).unwrap();
        let log = dir.join(format!("{name}.log"));
        let mut child = Command::new(sim_driver_exe())
            .args(args)
            .env("ROS_DOMAIN_ID", domain.to_string())
            .env("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
            .env_remove("ROS_STATIC_PEERS")
            .env_remove("RMW_IMPLEMENTATION")
            .stdout(Stdio::piped())
            .stderr(std::fs::File::create(&log).unwrap())
            .spawn()
            .expect("start sim_driver");
        let stdout = child.stdout.take().unwrap();
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                let _ = tx.send(line);
            }
        });
        let deadline = Instant::now() + QUICK;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match rx.recv_timeout(left) {
                Ok(line) if line.starts_with("sim_driver ready:") => break,
                Ok(_) => {}
                Err(_) => panic!(
                    "sim_driver did not get ready; its log ({}):\n{}",
                    log.display(),
                    std::fs::read_to_string(&log).unwrap_or_default()
                ),
            }
        }
        Driver { child, log }
    }

    /// SIGKILL: a driver crash without any goodbye.
    pub fn kill(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Drop for Driver {
    fn drop(&mut self) {
        self.kill();
        if std::thread::panicking() {
            eprintln!(
                "sim_driver log {}:\n{}",
                self.log.display(),
                std::fs::read_to_string(&self.log).unwrap_or_default()
            );
        }
    }
}
