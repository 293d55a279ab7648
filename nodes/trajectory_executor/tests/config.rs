//! The shipped parameter files load against the shipped robots, and bad parameters are refused
//! with the parameter's name.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_ros::RosArgs;
use kerf_trajectory_executor::{NodeConfig, NodeError};

const ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

fn config(robot: &str, extra: &[&str]) -> Result<NodeConfig, NodeError> {
    let mut args = vec![
        "--ros-args".to_string(),
        "--params-file".into(),
        format!("{ROOT}/launch_scripts/params/{robot}.yaml"),
        "-p".into(),
        format!("urdf_file:={ROOT}/urdf/{robot}.urdf"),
        "-p".into(),
        format!("joint_limits_file:={ROOT}/urdf/{robot}_limits.yaml"),
    ];
    for e in extra {
        args.push("-p".into());
        args.push(e.to_string());
    }
    let args = RosArgs::parse(args)?;
    let params = args.params_for("/trajectory_executor", "trajectory_executor")?;
    NodeConfig::from_params(&params)
}

#[test]
fn shipped_params_load() {
    for robot in ["irb6660", "laser_cutter"] {
        let c = config(robot, &[]).unwrap_or_else(|e| panic!("{robot}: {e}"));
        assert_eq!(c.limits.len(), 6);
        assert_eq!(c.executor.control_period, 1.0 / 250.0);
        assert_eq!(c.executor.path_tolerances.len(), 6);
        assert_eq!(c.executor.goal_tolerances.len(), 6);
    }
    let c = config("laser_cutter", &[]).unwrap();
    assert_eq!(c.initial_positions, vec![0.8, 0.7, 1.5, 0.0, 0.0, -0.05]);
    assert_eq!(c.limits[0].max_acceleration, 12.0); // seed 001 Table 2, q1
}

#[test]
fn bad_parameters_are_named() {
    let cases: &[(&str, &str)] = &[
        ("control_rate:=0.0", "control_rate"),
        ("control_rate:=fast", "control_rate"),
        ("initial_positions:=[0.0, 0.0]", "initial_positions"),
        (
            "initial_positions:=[9.0, 0.0, 0.0, 0.0, 0.0, 0.0]",
            "initial_positions",
        ),
        ("constraints.joint_9.goal:=0.1", "constraints.joint_9.goal"),
        ("constraints.joint_1.goal:=-0.1", "constraints.joint_1.goal"),
        ("hardware.lag:=0.1", "hardware.lag"),
        ("realtime_priority:=120", "realtime_priority"),
        ("realtime_priority:=0.5", "realtime_priority"),
        ("urdf_file:=/nonexistent.urdf", "nonexistent"),
    ];
    for (p, needle) in cases {
        let err = config("irb6660", &[p])
            .err()
            .unwrap_or_else(|| panic!("{p} accepted"));
        assert!(err.to_string().contains(needle), "{p}: {err}");
    }
}
