//! The command line of the `sim_driver` binary: bad input exits 2 with a message naming the
//! argument (before any DDS is started), `--help` documents the interface.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::process::{Command, Output};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sim_driver"))
        .args(args)
        // Kept on loopback in case a case is accepted by mistake.
        .env("ROS_DOMAIN_ID", "184")
        .env("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
        .output()
        .unwrap()
}

#[test]
fn bad_arguments_exit_2_naming_the_argument() {
    let base = ["--joints", "q1,q2", "--initial", "0,0"];
    let cases: &[(&[&str], &str)] = &[
        (&["--rate", "0"], "--rate"),
        (&["--rate", "2001"], "--rate"),
        (&["--rate", "nan"], "--rate"),
        (&["--rate", "fast"], "--rate"),
        (&["--delay", "-0.001"], "--delay"),
        (&["--delay", "1.5"], "--delay"),
        (&["--delay", "inf"], "--delay"),
        (&["--noise", "0.011"], "--noise"),
        (&["--noise", "-1e-9"], "--noise"),
        (&["--seed", "x"], "--seed"),
        (&["--fault", "1:melt"], "--fault"),
        (&["--fault", "nan:drop"], "--fault"),
        (&["--fault", "drop"], "--fault"),
        (&["--namespace", "robot"], "--namespace"),
        (&["--command-type", "twist"], "--command-type"),
    ];
    for (extra, needle) in cases {
        let mut args = base.to_vec();
        args.extend_from_slice(extra);
        let out = run(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(out.stdout.is_empty(), "{args:?}: not ready");
    }
    let others: &[(&[&str], &str)] = &[
        (&["--joints", "q1,q2", "--initial", "0"], "--initial"),
        (&["--joints", "q1,q2", "--initial", "0,1e7"], "--initial"),
        (&["--joints", "q1,q2", "--initial", "0,inf"], "--initial"),
        (&["--joints", "q1,q1", "--initial", "0,0"], "--joints"),
        (&["--joints", "q1,,q2", "--initial", "0,0,0"], "--joints"),
        (&["--initial", "0"], "--joints"),
        (&["--joints", "q1"], "--initial"),
    ];
    for (args, needle) in others {
        let out = run(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
    let out = Command::new(env!("CARGO_BIN_EXE_sim_driver"))
        .args(base)
        .env("ROS_DOMAIN_ID", "999")
        .env("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("ROS_DOMAIN_ID"));
}

#[test]
fn help_documents_the_interface() {
    let out = run(&["--help"]);
    assert_eq!(out.status.code(), Some(0));
    let help = String::from_utf8_lossy(&out.stdout);
    for needle in [
        "<ns>/commands",
        "<ns>/joint_states",
        "<ns>/follow_joint_trajectory",
        "<ns>/fault",
        "std_msgs/msg/Float64MultiArray",
        "sensor_msgs/msg/JointState",
        "control_msgs/action/FollowJointTrajectory",
        "PATH_TOLERANCE_VIOLATED (-4)",
        "stamp_back",
        "fewer_joints",
        "reject_goals",
        "ROS_AUTOMATIC_DISCOVERY_RANGE",
        "sim_driver ready: <n> joints, namespace <ns>",
    ] {
        assert!(help.contains(needle), "--help lacks {needle:?}");
    }
}
