//! Interop end to end over DDS (loopback only): `kerf launch --robot irb6660` driven by an
//! independent DDS implementation, Cyclone DDS through its Python binding
//! (`tests/cyclone/peer.py`, see there for the scenario).
//!
//! `tests/cyclone/setup.sh` creates the Python venv (`pip install cyclonedds`, needs PyPI the
//! first time). Set `KERF_SKIP_CYCLONE=1` to skip this test; otherwise every failure, setup
//! included, fails it. `KERF_CYCLONE_DOMAIN` overrides the ROS domain (default 87).
//!
//! Both sides stay on 127.0.0.1: the executor with `ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`,
//! Cyclone with `tests/cyclone/cyclonedds.xml` (loopback interface, no multicast, unicast
//! discovery of the peer 127.0.0.1).

use std::{
    fs::File,
    path::{Path, PathBuf},
    process::{Child, Command, ExitStatus, Stdio},
    time::{Duration, Instant},
};

const DEFAULT_DOMAIN: u16 = 87;
/// The whole peer scenario (discovery, two 2 s motions, four rejections) takes ~6 s.
const PEER_TIMEOUT: Duration = Duration::from_secs(50);

/// A child process that is killed (and reaped) when dropped, also when the test panics.
struct Guard {
    name: &'static str,
    child: Child,
}

impl Guard {
    fn spawn(name: &'static str, cmd: &mut Command) -> Guard {
        let child = cmd
            .spawn()
            .unwrap_or_else(|e| panic!("cannot start {name} ({cmd:?}): {e}"));
        Guard { name, child }
    }

    fn try_wait(&mut self) -> Option<ExitStatus> {
        self.child
            .try_wait()
            .unwrap_or_else(|e| panic!("waiting for {}: {e}", self.name))
    }
}

impl Drop for Guard {
    fn drop(&mut self) {
        if let Ok(None) = self.child.try_wait() {
            let _ = self.child.kill();
        }
        let _ = self.child.wait();
    }
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| format!("<cannot read {}: {e}>", path.display()))
}

/// A log file for a child's output under cargo's per-test scratch directory.
fn log_file(name: &str) -> (PathBuf, File) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("cyclone_e2e");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    let file = File::create(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    (path, file)
}

fn domain() -> u16 {
    match std::env::var("KERF_CYCLONE_DOMAIN") {
        Ok(s) => s
            .trim()
            .parse()
            .unwrap_or_else(|_| panic!("KERF_CYCLONE_DOMAIN={s:?} is not a domain id")),
        Err(_) => DEFAULT_DOMAIN,
    }
}

/// Loopback-only DDS environment for a child, on `domain`.
fn dds_env(cmd: &mut Command, domain: u16) -> &mut Command {
    cmd.env("ROS_DOMAIN_ID", domain.to_string())
        .env("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
        .env_remove("ROS_LOCALHOST_ONLY")
        .env_remove("ROS_STATIC_PEERS")
        .env(
            "CYCLONEDDS_URI",
            format!(
                "file://{}",
                root().join("tests/cyclone/cyclonedds.xml").display()
            ),
        )
}

#[test]
fn cyclone_dds_peer_drives_the_executor() {
    if std::env::var("KERF_SKIP_CYCLONE").as_deref() == Ok("1") {
        println!("SKIPPED: KERF_SKIP_CYCLONE=1 is set; the Cyclone DDS interop test did not run");
        return;
    }
    let t0 = Instant::now();
    let cyclone = root().join("tests/cyclone");

    // 1. The venv with cyclonedds.
    let setup = Command::new("bash")
        .arg(cyclone.join("setup.sh"))
        .stdin(Stdio::null())
        .output()
        .expect("cannot run bash tests/cyclone/setup.sh");
    println!(
        "{}{}",
        String::from_utf8_lossy(&setup.stdout),
        String::from_utf8_lossy(&setup.stderr)
    );
    assert!(
        setup.status.success(),
        "tests/cyclone/setup.sh failed ({}); set KERF_SKIP_CYCLONE=1 to skip this test",
        setup.status
    );
    println!("setup: {:.1} s", t0.elapsed().as_secs_f64());

    // 2. The executor, as `kerf launch` starts it.
    let domain = domain();
    let (exec_log, exec_file) = log_file(&format!("executor-domain{domain}.log"));
    let mut exec = Guard::spawn(
        "kerf launch",
        dds_env(
            Command::new(env!("CARGO_BIN_EXE_kerf"))
                .args(["launch", "--robot", "irb6660"])
                .stdin(Stdio::null())
                .stdout(exec_file.try_clone().unwrap())
                .stderr(exec_file),
            domain,
        ),
    );

    // 3. The Cyclone peer runs the scenario.
    let (peer_log, peer_file) = log_file(&format!("peer-domain{domain}.log"));
    let mut peer = Guard::spawn(
        "peer.py",
        dds_env(
            Command::new(cyclone.join(".venv/bin/python"))
                .arg(cyclone.join("peer.py"))
                .arg("--domain")
                .arg(domain.to_string())
                .arg("--urdf")
                .arg(root().join("urdf/irb6660.urdf"))
                .stdin(Stdio::null())
                .stdout(peer_file.try_clone().unwrap())
                .stderr(peer_file),
            domain,
        ),
    );
    let started = Instant::now();
    let mut outcome: Result<(), String> = loop {
        if let Some(status) = peer.try_wait() {
            break if status.success() {
                Ok(())
            } else {
                Err(format!("peer.py failed ({status})"))
            };
        }
        if let Some(status) = exec.try_wait() {
            break Err(format!("the executor exited early ({status})"));
        }
        if started.elapsed() > PEER_TIMEOUT {
            break Err(format!("peer.py did not finish within {PEER_TIMEOUT:?}"));
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let peer_time = started.elapsed();
    if let (Ok(()), Some(status)) = (&outcome, exec.try_wait()) {
        outcome = Err(format!(
            "the executor exited ({status}) before the end of the test"
        ));
    }
    drop(peer);
    drop(exec);

    println!(
        "--- peer.py (Cyclone DDS), {} ---\n{}",
        peer_log.display(),
        read(&peer_log)
    );
    if let Err(why) = outcome {
        panic!(
            "{why}\n--- executor (kerf launch --robot irb6660, ROS_DOMAIN_ID={domain}), {} ---\n{}",
            exec_log.display(),
            read(&exec_log)
        );
    }
    println!(
        "peer: {:.1} s, whole test: {:.1} s",
        peer_time.as_secs_f64(),
        t0.elapsed().as_secs_f64()
    );
}
