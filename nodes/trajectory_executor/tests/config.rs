//! The shipped parameter files load against the shipped robots, and bad parameters are refused
//! with the parameter's name.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_ros::RosArgs;
use kerf_trajectory_executor::{
    hardware::{check_joints, load_cell, Hardware},
    NodeConfig, NodeError,
};

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

/// A scratch directory for files written by a test, removed first.
fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("kerf_exec_config_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn sim_params(cell: &str) -> Vec<String> {
    vec!["hardware:=sim".to_string(), format!("sim_cell:={cell}")]
}

fn sim_config(robot: &str, extra: &[String]) -> Result<NodeConfig, NodeError> {
    let extra: Vec<&str> = extra.iter().map(String::as_str).collect();
    config(robot, &extra)
}

#[test]
fn sim_hardware_loads_the_shipped_cells() {
    for (robot, cell) in [
        ("laser_cutter", "laser_bpillar"),
        ("irb6660", "irb6660_plate"),
    ] {
        let cell = format!("{ROOT}/urdf/cells/{cell}.yaml");
        let mut p = sim_params(&cell);
        p.push("sim_mode:=dynamic".into());
        let c = sim_config(robot, &p).unwrap_or_else(|e| panic!("{robot}: {e}"));
        let sim = c.sim.as_ref().unwrap();
        assert_eq!(sim.mode, kerf_cell::Mode::Dynamic);
        assert_eq!(sim.physics_rate, 1000.0);
        let hw = Hardware::build(&c).unwrap_or_else(|e| panic!("{robot}: {e}"));
        let state = hw.sim_state().unwrap();
        assert_eq!(state.positions, c.initial_positions);
        assert!(state.contacts.is_empty(), "{robot}: {:?}", state.contacts);
        // Holding against gravity takes effort on some joint.
        assert!(
            hw.efforts().iter().any(|e| e.abs() > 1.0),
            "{:?}",
            hw.efforts()
        );
    }
    // Without initial_positions the robot starts at the cell file's.
    let args = RosArgs::parse(vec![
        "--ros-args".to_string(),
        "-p".into(),
        format!("urdf_file:={ROOT}/urdf/laser_cutter.urdf"),
        "-p".into(),
        format!("joint_limits_file:={ROOT}/urdf/laser_cutter_limits.yaml"),
        "-p".into(),
        "hardware:=sim".into(),
        "-p".into(),
        format!("sim_cell:={ROOT}/urdf/cells/laser_bpillar.yaml"),
    ])
    .unwrap();
    let params = args
        .params_for("/trajectory_executor", "trajectory_executor")
        .unwrap();
    let c = NodeConfig::from_params(&params).unwrap();
    assert_eq!(c.initial_positions, vec![0.40, 0.70, 1.20, 0.0, 0.0, -0.07]);
    // The mock stays the default and has no efforts.
    let c = config("laser_cutter", &[]).unwrap();
    assert!(c.sim.is_none());
    assert!(Hardware::build(&c).unwrap().efforts().is_empty());
}

#[test]
fn bad_sim_parameters_are_named() {
    let cell = format!("{ROOT}/urdf/cells/laser_bpillar.yaml");
    let cases: Vec<(Vec<String>, &str)> = vec![
        (vec!["hardware:=gazebo".into()], "hardware"),
        (vec!["hardware:=sim".into()], "sim_cell"),
        (vec![format!("sim_cell:={cell}")], "sim_cell"),
        (
            [sim_params(&cell), vec!["sim_mode:=fast".into()]].concat(),
            "sim_mode",
        ),
        (
            [
                sim_params(&cell),
                vec!["hardware.lag_time_constant:=0.1".into()],
            ]
            .concat(),
            "hardware.lag_time_constant",
        ),
    ];
    for (p, needle) in cases {
        let err = sim_config("laser_cutter", &p)
            .err()
            .unwrap_or_else(|| panic!("{p:?} accepted"));
        assert!(err.to_string().contains(needle), "{p:?}: {err}");
    }
}

/// Start-up refusals of the simulated cell (issue 15, "Bad input"), each naming its
/// parameter: a physics rate that is not a multiple of the control rate, a cell file naming a
/// missing mesh, a URDF with an effort limit ≤ 0, a cell whose joints are not the executor's.
#[test]
fn sim_cell_refusals_are_clear() {
    let cell = format!("{ROOT}/urdf/cells/laser_bpillar.yaml");
    let build = |p: &[String]| -> String {
        let c = sim_config("laser_cutter", p).unwrap();
        Hardware::build(&c).expect_err("refused").to_string()
    };
    // Physics rate.
    let err = build(&[sim_params(&cell), vec!["sim_physics_rate:=1100.0".into()]].concat());
    assert!(err.contains("sim_physics_rate"), "{err}");
    assert!(err.contains("not an integer multiple"), "{err}");

    // Missing mesh.
    let dir = scratch("mesh");
    let text = std::fs::read_to_string(&cell)
        .unwrap()
        .replace(
            "../laser_cutter_inertia.yaml",
            &format!("{ROOT}/urdf/laser_cutter_inertia.yaml"),
        )
        .replace("../meshes/bpillar.obj", "missing_part.obj");
    let bad_cell = dir.join("cell.yaml");
    std::fs::write(&bad_cell, text).unwrap();
    let err = build(&sim_params(bad_cell.to_str().unwrap()));
    assert!(err.contains("sim_cell"), "{err}");
    assert!(err.contains("missing_part.obj"), "{err}");
    assert!(err.contains("does not exist"), "{err}");

    // Effort limit 0 on q1.
    let urdf = std::fs::read_to_string(format!("{ROOT}/urdf/laser_cutter.urdf")).unwrap();
    let first = urdf.find("effort=\"3000.0\"").unwrap();
    let mut zero = urdf.clone();
    zero.replace_range(first..first + "effort=\"3000.0\"".len(), "effort=\"0.0\"");
    let bad_urdf = dir.join("laser_cutter.urdf");
    std::fs::write(&bad_urdf, zero).unwrap();
    // (kerf_robot refuses it when the executor loads the robot, before the cell.)
    let err = sim_config(
        "laser_cutter",
        &[
            sim_params(&cell),
            vec![format!("urdf_file:={}", bad_urdf.display())],
        ]
        .concat(),
    )
    .expect_err("refused")
    .to_string();
    assert!(err.contains("q1"), "{err}");
    assert!(err.contains("effort"), "{err}");
    assert!(err.contains("> 0"), "{err}");

    // Unreadable cell file.
    let err = build(&sim_params("/nonexistent/cell.yaml"));
    assert!(err.contains("sim_cell"), "{err}");
    assert!(err.contains("/nonexistent/cell.yaml"), "{err}");

    // Joints: the executor's list differs from the cell's URDF.
    let c = sim_config("laser_cutter", &sim_params(&cell)).unwrap();
    let sim = c.sim.clone().unwrap();
    let loaded = load_cell(&c, &sim).unwrap();
    let mut renamed = c.limits.clone();
    renamed[2].name = "z_axis".into();
    let err = check_joints(&loaded, &renamed).unwrap_err().to_string();
    assert!(err.contains("sim_cell"), "{err}");
    assert!(err.contains("z_axis"), "{err}");
    assert!(check_joints(&loaded, &c.limits[..5]).is_err());
    check_joints(&loaded, &c.limits).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 27: `hardware: topic` and `hardware: jtc` read their parameters with defaults, and
/// refuse each bad one by name (a `hardware.*` parameter of another hardware among them).
#[test]
fn driver_parameters_have_defaults_and_are_checked_by_name() {
    use kerf_trajectory_executor::config::{
        CommandType, DriverConfig, DEFAULT_COMMAND_TOPIC, DEFAULT_JTC_ACTION, DEFAULT_STATE_TOPIC,
    };
    let c = config("laser_cutter", &["hardware:=topic"]).unwrap();
    let Some(DriverConfig::Topic(t)) = &c.driver else {
        panic!("{:?}", c.driver)
    };
    assert_eq!(t.command_topic, DEFAULT_COMMAND_TOPIC);
    assert_eq!(t.command_type, CommandType::Float64MultiArray);
    assert_eq!(t.state_topic, DEFAULT_STATE_TOPIC);
    assert_eq!(t.feedback_timeout_periods, 5);
    // The mock's builder does not make a driver.
    assert!(Hardware::build(&c).is_err());
    let c = config(
        "irb6660",
        &[
            "hardware:=topic",
            "hardware.command_topic:=/d/commands",
            "hardware.command_type:=sensor_msgs/msg/JointState",
            "hardware.state_topic:=/d/joint_states",
            "hardware.feedback_timeout_periods:=3",
        ],
    )
    .unwrap();
    let Some(DriverConfig::Topic(t)) = &c.driver else {
        panic!("{:?}", c.driver)
    };
    assert_eq!(
        (
            t.command_topic.as_str(),
            t.command_type,
            t.state_topic.as_str()
        ),
        ("/d/commands", CommandType::JointState, "/d/joint_states")
    );
    assert_eq!(t.feedback_timeout_periods, 3);
    let c = config("irb6660", &["hardware:=jtc"]).unwrap();
    let Some(DriverConfig::Jtc(j)) = &c.driver else {
        panic!("{:?}", c.driver)
    };
    assert_eq!(
        (j.action.as_str(), j.state_topic.as_ref(), j.timeout),
        (DEFAULT_JTC_ACTION, None, 1.0)
    );

    let cases: &[(&[&str], &str)] = &[
        (
            &[
                "hardware:=topic",
                "hardware.command_type:=std_msgs/msg/String",
            ],
            "hardware.command_type",
        ),
        (
            &["hardware:=topic", "hardware.feedback_timeout_periods:=0"],
            "hardware.feedback_timeout_periods",
        ),
        (
            &["hardware:=topic", "hardware.feedback_timeout_periods:=2.5"],
            "hardware.feedback_timeout_periods",
        ),
        (
            &["hardware:=topic", "hardware.feedback_timeout_periods:=251"],
            "hardware.feedback_timeout_periods",
        ),
        (
            &["hardware:=topic", "hardware.state_topic:=/bad topic"],
            "hardware.state_topic",
        ),
        (
            &["hardware:=topic", "hardware.command_topic:=~x"],
            "hardware.command_topic",
        ),
        (
            &["hardware:=topic", "hardware.jtc_action:=/a"],
            "hardware.jtc_action",
        ),
        (
            &["hardware:=topic", "hardware.lag_time_constant:=0.1"],
            "hardware.lag_time_constant",
        ),
        (
            &["hardware:=mock", "hardware.state_topic:=/a"],
            "hardware.state_topic",
        ),
        (&["hardware.command_topic:=/a"], "hardware.command_topic"),
        (
            &[
                "hardware:=jtc",
                "hardware.command_type:=sensor_msgs/msg/JointState",
            ],
            "hardware.command_type",
        ),
        (
            &["hardware:=jtc", "hardware.feedback_timeout_periods:=5"],
            "hardware.feedback_timeout_periods",
        ),
        (
            &["hardware:=jtc", "hardware.jtc_timeout:=0.0"],
            "hardware.jtc_timeout",
        ),
        (
            &["hardware:=jtc", "hardware.jtc_timeout:=100.0"],
            "hardware.jtc_timeout",
        ),
        (
            &["hardware:=jtc", "hardware.jtc_action:=no//action"],
            "hardware.jtc_action",
        ),
        (&["hardware:=topic", "sim_mode:=dynamic"], "sim_mode"),
        (&["hardware:=robot"], "hardware"),
        (&["hardware.gain:=1.0"], "hardware.gain"),
    ];
    for (p, needle) in cases {
        let err = config("irb6660", p)
            .err()
            .unwrap_or_else(|| panic!("{p:?} accepted"));
        assert!(
            err.to_string().contains(&format!("'{needle}'")),
            "{p:?}: {err}"
        );
    }
}
