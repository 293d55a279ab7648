//! Interop end to end over DDS (loopback only): `kerf launch --robot irb6660` driven by an
//! independent DDS implementation, Cyclone DDS through its Python binding. Two scenarios (see
//! the scripts for their steps):
//!
//! * `tests/cyclone/peer.py`: topics only (trajectories, `/joint_states`, status);
//! * `tests/cyclone/action_client.py`: the FollowJointTrajectory action through
//!   rmw_cyclonedds_cpp's request/reply mapping (16-byte `cdds_request_header_t` in front of
//!   every request and reply), the executor started with `RMW_IMPLEMENTATION=rmw_cyclonedds_cpp`.
//!
//! `tests/cyclone/setup.sh` creates the Python venv (`pip install cyclonedds`, needs PyPI the
//! first time). Set `KERF_SKIP_CYCLONE=1` to skip these tests; otherwise every failure, setup
//! included, fails them. `KERF_CYCLONE_DOMAIN` and `KERF_CYCLONE_ACTION_DOMAIN` override their
//! ROS domains (default 87 and 88).
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
const DEFAULT_ACTION_DOMAIN: u16 = 88;
/// The whole peer scenario (discovery, two 2 s motions, four rejections) takes ~6 s.
const PEER_TIMEOUT: Duration = Duration::from_secs(50);
/// The action client scenario (discovery, a 1.5 s goal, an aborted goal, a goal canceled after
/// 1 s) takes ~3 s; each of its waits is bounded in the script (15 s for discovery).
const ACTION_CLIENT_TIMEOUT: Duration = Duration::from_secs(40);

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

/// The domain in `var`, else `default`.
fn domain(var: &str, default: u16) -> u16 {
    match std::env::var(var) {
        Ok(s) => s
            .trim()
            .parse()
            .unwrap_or_else(|_| panic!("{var}={s:?} is not a domain id")),
        Err(_) => default,
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

/// One Cyclone scenario: a Python script of `tests/cyclone/` against `kerf launch --robot
/// irb6660`, both on `domain`, with extra environment for the executor.
struct Scenario<'a> {
    /// Script in `tests/cyclone/`.
    script: &'a str,
    domain: u16,
    /// Extra environment of the executor (e.g. `RMW_IMPLEMENTATION`).
    executor_env: &'a [(&'a str, &'a str)],
    timeout: Duration,
}

/// Runs `setup.sh`, the executor and the script; panics with both logs if the script fails, the
/// executor exits early, or the script overruns its timeout.
fn run_scenario(sc: Scenario) {
    let t0 = Instant::now();
    let cyclone = root().join("tests/cyclone");
    let stem = sc.script.trim_end_matches(".py");

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
    let domain = sc.domain;
    let (exec_log, exec_file) = log_file(&format!("executor-{stem}-domain{domain}.log"));
    let mut exec_cmd = Command::new(env!("CARGO_BIN_EXE_kerf"));
    exec_cmd
        .args(["launch", "--robot", "irb6660"])
        .env_remove("RMW_IMPLEMENTATION")
        .envs(sc.executor_env.iter().copied())
        .stdin(Stdio::null())
        .stdout(exec_file.try_clone().unwrap())
        .stderr(exec_file);
    let mut exec = Guard::spawn("kerf launch", dds_env(&mut exec_cmd, domain));

    // 3. The Cyclone side runs the scenario.
    let (script_log, script_file) = log_file(&format!("{stem}-domain{domain}.log"));
    let mut script = Guard::spawn(
        "python script",
        dds_env(
            Command::new(cyclone.join(".venv/bin/python"))
                .arg(cyclone.join(sc.script))
                .arg("--domain")
                .arg(domain.to_string())
                .arg("--urdf")
                .arg(root().join("urdf/irb6660.urdf"))
                .stdin(Stdio::null())
                .stdout(script_file.try_clone().unwrap())
                .stderr(script_file),
            domain,
        ),
    );
    let started = Instant::now();
    let mut outcome: Result<(), String> = loop {
        if let Some(status) = script.try_wait() {
            break if status.success() {
                Ok(())
            } else {
                Err(format!("{} failed ({status})", sc.script))
            };
        }
        if let Some(status) = exec.try_wait() {
            break Err(format!("the executor exited early ({status})"));
        }
        if started.elapsed() > sc.timeout {
            break Err(format!(
                "{} did not finish within {:?}",
                sc.script, sc.timeout
            ));
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let script_time = started.elapsed();
    if let (Ok(()), Some(status)) = (&outcome, exec.try_wait()) {
        outcome = Err(format!(
            "the executor exited ({status}) before the end of the test"
        ));
    }
    drop(script);
    drop(exec);

    println!(
        "--- {} (Cyclone DDS), {} ---\n{}",
        sc.script,
        script_log.display(),
        read(&script_log)
    );
    let exec_env: Vec<String> = sc
        .executor_env
        .iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect();
    if let Err(why) = outcome {
        panic!(
            "{why}\n--- executor (kerf launch --robot irb6660, ROS_DOMAIN_ID={domain} {}), {} ---\n{}",
            exec_env.join(" "),
            exec_log.display(),
            read(&exec_log)
        );
    }
    println!(
        "{}: {:.1} s, whole test: {:.1} s",
        sc.script,
        script_time.as_secs_f64(),
        t0.elapsed().as_secs_f64()
    );
}

fn skip() -> bool {
    if std::env::var("KERF_SKIP_CYCLONE").as_deref() == Ok("1") {
        println!("SKIPPED: KERF_SKIP_CYCLONE=1 is set; the Cyclone DDS interop test did not run");
        return true;
    }
    false
}

/// Topics only: `tests/cyclone/peer.py`. The executor runs with the default RPC mapping.
#[test]
fn cyclone_dds_peer_drives_the_executor() {
    if skip() {
        return;
    }
    run_scenario(Scenario {
        script: "peer.py",
        domain: domain("KERF_CYCLONE_DOMAIN", DEFAULT_DOMAIN),
        executor_env: &[],
        timeout: PEER_TIMEOUT,
    });
}

/// The FollowJointTrajectory action from a client that speaks rmw_cyclonedds_cpp's
/// request/reply mapping (`tests/cyclone/action_client.py`), against the executor started
/// with `RMW_IMPLEMENTATION=rmw_cyclonedds_cpp`: success with feedback, an unknown joint
/// (accepted, then aborted with the reason), a cancel with a controlled stop.
///
/// The client checks that every reply carries its request's 16 header bytes unchanged and is
/// taken by the rmw_cyclonedds rule (header guid = the client's request writer instance
/// handle). Note: ros2-client 0.12.1 decodes that header as `[u8; 8]` + `i32` + `u32`
/// (`CycloneHeader` in its `service/wrappers.rs`), so the server-side `RmwRequestId` has the
/// two halves of rmw_cyclonedds's `int64 seq` swapped (seq 1 reads as 2^32); it writes them
/// back the same way, so the wire bytes round-trip exactly.
#[test]
fn cyclone_dds_action_client_with_the_rmw_cyclonedds_mapping() {
    if skip() {
        return;
    }
    run_scenario(Scenario {
        script: "action_client.py",
        domain: domain("KERF_CYCLONE_ACTION_DOMAIN", DEFAULT_ACTION_DOMAIN),
        executor_env: &[("RMW_IMPLEMENTATION", "rmw_cyclonedds_cpp")],
        timeout: ACTION_CLIENT_TIMEOUT,
    });
}
