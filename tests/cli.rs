//! The `kerf` tool as a user runs it: `kerf launch` serves, `kerf echo` prints a topic as YAML,
//! `kerf pub` publishes a message written as YAML,
//! Ctrl-C (SIGINT) stops the launch cleanly, and bad ROS arguments are refused. Loopback DDS.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::{
    process::{Command, Stdio},
    time::Duration,
};

const DOMAIN: &str = "48";

fn kerf() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_kerf"));
    c.env("ROS_DOMAIN_ID", DOMAIN)
        .env("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
        .env_remove("ROS_STATIC_PEERS");
    c
}

mod support;

use support::{assert_clean_exit, interrupt, Lines};

#[test]
fn launch_echo_and_ctrl_c() {
    let mut command = kerf();
    command.args(["launch", "--robot", "laser_cutter"]);
    let (mut launch, mut lines) = Lines::spawn(command);
    let mut wait_line = |needle: &str| lines.wait_for(needle, Duration::from_secs(20));
    let ready = wait_line("ready");
    assert!(ready.contains("q1, q2, q3, q4, q5, q6"), "{ready}");

    let out = kerf()
        .args(["echo", "/joint_states", "-n", "1", "--timeout", "20"])
        .output()
        .expect("run kerf echo");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let yaml = String::from_utf8_lossy(&out.stdout);
    assert!(
        yaml.contains("- q6") && yaml.contains("position:"),
        "{yaml}"
    );

    // The node logs to /rosout too (transient-local, last message kept): its start-up line.
    let out = kerf()
        .args([
            "echo",
            "/rosout",
            "--transient-local",
            "-n",
            "1",
            "--timeout",
            "20",
        ])
        .output()
        .expect("run kerf echo /rosout");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let log = String::from_utf8_lossy(&out.stdout);
    assert!(
        log.contains("trajectory_executor") && log.contains("ready"),
        "{log}"
    );

    // kerf pub: a move of q1 written as YAML on stdin, its type discovered from the
    // executor's subscription; the executor accepts and runs it.
    let mut publish = kerf()
        .args(["pub", "/trajectory_executor/joint_trajectory", "-"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run kerf pub");
    {
        use std::io::Write;
        let mut stdin = publish.stdin.take().expect("stdin");
        stdin
            .write_all(
                b"header: {stamp: {sec: 0, nanosec: 0}, frame_id: ''}\n\
                  joint_names: [q1, q2, q3, q4, q5, q6]\n\
                  points:\n\
                  - {positions: [0.8, 0.7, 1.5, 0, 0, -0.05], velocities: [0, 0, 0, 0, 0, 0], \
                     accelerations: [], effort: [], time_from_start: {sec: 0, nanosec: 0}}\n\
                  - {positions: [0.81, 0.7, 1.5, 0, 0, -0.05], velocities: [0, 0, 0, 0, 0, 0], \
                     accelerations: [], effort: [], time_from_start: {sec: 1, nanosec: 0}}\n",
            )
            .unwrap();
    }
    let out = publish.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        String::from_utf8_lossy(&out.stdout)
            .contains("published 1 trajectory_msgs/msg/JointTrajectory"),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    let out = kerf()
        .args([
            "echo",
            "/trajectory_executor/trajectory_status",
            "--transient-local",
            "-n",
            "1",
            "--timeout",
            "20",
        ])
        .output()
        .expect("run kerf echo trajectory_status");
    let status = String::from_utf8_lossy(&out.stdout);
    assert!(
        status.contains("source: topic") && status.contains("status: 1"),
        "{status}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // A document that is no JointTrajectory: exit code 2, naming the field.
    let dir = std::env::temp_dir().join(format!("kerf_cli_pub_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.yaml");
    std::fs::write(
        &bad,
        "header: {stamp: {sec: 0, nanosec: 0}, frame_id: ''}\njoint_names: []\npoints: []\n\
         joint_nmes: [q1]\n",
    )
    .unwrap();
    let out = kerf()
        .args(["pub", "/trajectory_executor/joint_trajectory"])
        .arg(&bad)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("joint_nmes"), "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);

    // Ctrl-C: a clean shutdown and exit status 0.
    interrupt(&launch.0);
    wait_line("shutting down");
    assert_clean_exit(&mut launch.0, Duration::from_secs(10));
}

#[test]
fn bad_arguments_and_environment_are_refused() {
    let out = kerf()
        .args(["launch", "--ros-args", "-p", "no_such_param:=1"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    // Every kerf failure exits with code 2 (issue 11, item 8).
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no_such_param"));

    let out = kerf()
        .args(["launch"])
        .env("ROS_AUTOMATIC_DISCOVERY_RANGE", "NEARBY")
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("ROS_AUTOMATIC_DISCOVERY_RANGE"));

    let out = kerf()
        .args(["echo", "/nothing_here", "--discovery-timeout", "0.5"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no publisher of /nothing_here"));
}

/// A closed output pipe (`kerf … | head`) ends a command quietly: by SIGPIPE at the first write
/// after the close, or successfully if everything was written before it; never a panic.
#[test]
fn a_closed_pipe_ends_kerf_quietly() {
    use std::os::unix::process::ExitStatusExt;
    let dir = std::env::temp_dir().join(format!("kerf_cli_pipe_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let runs: [&[&str]; 2] = [
        &[
            "lobes",
            "--segment",
            "50",
            "--g",
            "0",
            "--rpm",
            "2000:4000:2",
            "--feed",
            "0.02:0.06:2",
            "--out",
            dir.to_str().unwrap(),
        ],
        &["plan", "--help"],
    ];
    for args in runs {
        let mut child = kerf()
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // The reader goes away before kerf writes (or while it writes).
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert!(
            out.status.success() || out.status.signal() == Some(libc::SIGPIPE),
            "{args:?}: {} {stderr}",
            out.status
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
