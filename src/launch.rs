//! `kerf launch`: every node in one process, each with its own Context and thread: the
//! trajectory executor, and with `--with-planner` the robot's planners (laser cutter: the MJTO
//! planner; IRB 6660: the milling planner; both: the G-code planner for that machine).
//! `--sim` runs the executor on the robot's simulated cell (`hardware: sim`, issue 15),
//! starts the planners too and connects their trajectories to the executor.

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use kerf_ros::{shutdown, ParamSource, ParamValue, RosArgs, RosEnv, StopToken};

use crate::input::InputFile;

/// The robots whose descriptions ship in `urdf/`, named as their files and as the launch
/// file's `robot:=` argument (`laser_cutter`, `irb6660`).
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum Robot {
    /// The 6-axis laser cutting machine of seed 001 (`laser-cutter` is accepted too).
    #[value(name = "laser_cutter", alias = "laser-cutter")]
    LaserCutter,
    /// ABB IRB 6660-130/3.1.
    Irb6660,
}

impl Robot {
    fn stem(self) -> &'static str {
        match self {
            Robot::LaserCutter => "laser_cutter",
            Robot::Irb6660 => "irb6660",
        }
    }

    /// The robot's shipped cell file, `urdf/cells/<cell>.yaml`.
    fn cell(self) -> &'static str {
        match self {
            Robot::LaserCutter => "laser_bpillar",
            Robot::Irb6660 => "irb6660_plate",
        }
    }
}

/// Arguments of `kerf launch`.
#[derive(Args, Debug)]
pub struct LaunchArgs {
    /// Robot for the trajectory executor (sets `urdf_file` and `joint_limits_file` from the
    /// shipped descriptions; `-p` arguments after `--ros-args` override them).
    #[arg(long, value_enum, default_value = "laser_cutter")]
    robot: Robot,
    /// Also start the robot's planners: the MJTO laser-cutting planner (`mjto_planner`) for
    /// the laser cutter, the milling planner (`milling_planner`) for the IRB 6660, and the
    /// G-code planner (`gcode_planner`, its `machine` parameter set to the robot). Their
    /// `~/joint_trajectory` reaches the executor only when remapped (README).
    #[arg(long)]
    with_planner: bool,
    /// Run the executor on the robot's simulated cell (`hardware: sim`, `sim_cell` the
    /// shipped `urdf/cells/laser_bpillar.yaml` or `irb6660_plate.yaml`; `-p sim_mode:=dynamic`
    /// and `-p sim_physics_rate:=…` after `--ros-args`), start the planners as
    /// `--with-planner` does, and remap their `~/joint_trajectory` to the executor's input, so
    /// that a request runs in the cell.
    #[arg(long)]
    sim: bool,
    /// Directory holding the robot descriptions (default: `$KERF_URDF_DIR`, else the `urdf/`
    /// of the kerf data directory: `$KERF_DATA_DIR`, the share directory beside the binary,
    /// the source tree kerf was built from).
    #[arg(long)]
    urdf_dir: Option<PathBuf>,
    /// ROS arguments, as for any ROS 2 node: `--ros-args -r __ns:=/cell -p control_rate:=100.0
    /// --params-file params.yaml`. Node-specific rules use the node's default name
    /// (`-r trajectory_executor:__ns:=/cell`).
    #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
    ros_args: Vec<String>,
}

/// The directory of the robot descriptions: `--urdf-dir`, else `$KERF_URDF_DIR`, else `urdf/`
/// of the kerf data directory ([`kerf_robot::data`]).
///
/// # Errors
/// The data search's message (every place searched) when neither is given and no kerf data
/// directory is found.
fn urdf_dir(arg: Option<PathBuf>) -> Result<PathBuf, String> {
    match arg.or_else(|| std::env::var_os("KERF_URDF_DIR").map(PathBuf::from)) {
        Some(dir) => Ok(dir),
        None => kerf_robot::data::path("urdf").map_err(|e| e.to_string()),
    }
}

/// Whether `name` is one of `known` (`prefix.*` admits a group), as `Params::reject_unknown`
/// decides.
fn knows(known: &[&str], name: &str) -> bool {
    known.iter().any(|k| {
        *k == name
            || k.strip_suffix('*')
                .is_some_and(|prefix| prefix.ends_with('.') && name.starts_with(prefix))
    })
}

/// The arguments one node of the launch gets: every `-p` parameter, except those this node
/// does not know but another node of the launch does (they are meant for that node). A
/// parameter no node knows stays, so the nodes refuse it as a typo. Parameter files are
/// passed unchanged (use node keys in them).
fn args_for(args: &RosArgs, known: &[&str], all_known: &[&[&str]]) -> RosArgs {
    let mut out = args.clone();
    out.params.retain(|p| match p {
        ParamSource::Inline(name, _) => {
            knows(known, name) || !all_known.iter().any(|other| knows(other, name))
        }
        ParamSource::File(_) => true,
    });
    out
}

/// A node of the launch: default name, known parameters, entry point.
type LaunchNode = (
    &'static str,
    &'static [&'static str],
    fn(&RosArgs, &RosEnv, StopToken) -> Result<(), String>,
);

/// The planner of `--with-planner` for `robot`: the MJTO planner plans for the laser cutter,
/// the milling planner for the IRB 6660.
fn planner_node(robot: Robot) -> LaunchNode {
    match robot {
        Robot::LaserCutter => (
            kerf_mjto_planner::DEFAULT_NAME,
            kerf_mjto_planner::KNOWN_PARAMS,
            |a, e, s| kerf_mjto_planner::run(a, e, s).map_err(|e| e.to_string()),
        ),
        Robot::Irb6660 => (
            kerf_milling_planner::DEFAULT_NAME,
            kerf_milling_planner::KNOWN_PARAMS,
            |a, e, s| kerf_milling_planner::run(a, e, s).map_err(|e| e.to_string()),
        ),
    }
}

/// The G-code planner of `--with-planner`, for any robot (its `machine` parameter names it).
fn gcode_node() -> LaunchNode {
    (
        kerf_gcode_planner::DEFAULT_NAME,
        kerf_gcode_planner::KNOWN_PARAMS,
        |a, e, s| kerf_gcode_planner::run(a, e, s).map_err(|e| e.to_string()),
    )
}

/// The G-code planner's `machine` parameter for `robot`.
fn gcode_machine(robot: Robot) -> &'static str {
    match robot {
        Robot::LaserCutter => "laser-cutter",
        Robot::Irb6660 => "irb6660",
    }
}

/// The remap rules of `--sim`: the robot's planners' `~/joint_trajectory` to the executor's
/// input (`<planner>:~/joint_trajectory:=/trajectory_executor/joint_trajectory`), as
/// `kerf.launch.py` connects them.
fn sim_connections(robot: Robot) -> Vec<String> {
    let planner = match robot {
        Robot::LaserCutter => kerf_mjto_planner::DEFAULT_NAME,
        Robot::Irb6660 => kerf_milling_planner::DEFAULT_NAME,
    };
    [planner, kerf_gcode_planner::DEFAULT_NAME]
        .iter()
        .map(|node| {
            format!(
                "{node}:~/joint_trajectory:=/{}/joint_trajectory",
                kerf_trajectory_executor::DEFAULT_NAME
            )
        })
        .collect()
}

/// The executor parameters of `--sim`: the simulated hardware and the robot's cell file in
/// `dir/cells/`.
fn sim_defaults(dir: &std::path::Path, robot: Robot) -> [(&'static str, String); 2] {
    [
        ("hardware", "sim".to_string()),
        (
            "sim_cell",
            dir.join("cells")
                .join(format!("{}.yaml", robot.cell()))
                .display()
                .to_string(),
        ),
    ]
}

/// Runs `kerf launch` until Ctrl-C or until a node fails.
pub fn run(a: LaunchArgs) -> Result<(), String> {
    let mut args = RosArgs::parse(a.ros_args.iter().cloned()).map_err(|e| e.to_string())?;
    if let Some(extra) = args.other.first() {
        return Err(format!(
            "unexpected argument {extra:?}; ROS arguments go after --ros-args"
        ));
    }
    // Every node reads each parameter file: regular files under the cap only (a FIFO would
    // block the first node, and could not be read twice anyway).
    for src in &args.params {
        if let ParamSource::File(path) = src {
            let file = InputFile::from(path.clone().into_os_string());
            crate::input::check_file("--params-file", &file, crate::input::PARAMS_CAP)?;
        }
    }
    let dir = urdf_dir(a.urdf_dir)?;
    let stem = a.robot.stem();
    // Defaults first: later sources (the user's -p and --params-file) override them.
    let defaults = [
        (
            "urdf_file",
            dir.join(format!("{stem}.urdf")).display().to_string(),
        ),
        (
            "joint_limits_file",
            dir.join(format!("{stem}_limits.yaml"))
                .display()
                .to_string(),
        ),
    ];
    let with_planner = a.with_planner || a.sim;
    let mut defaults: Vec<(&str, String)> = defaults.to_vec();
    if with_planner {
        // Only the G-code planner reads it: without it, no node of the launch would.
        defaults.push(("machine", gcode_machine(a.robot).to_string()));
    }
    if a.sim {
        defaults.extend(sim_defaults(&dir, a.robot));
        // The simulated cell is a whole cell: each planner's trajectory goes to the executor.
        // The rules come after the command line's, whose rules match first.
        for rule in sim_connections(a.robot) {
            args.remaps
                .push(kerf_ros::names::Remap::parse(&rule).map_err(|e| e.to_string())?);
        }
    }
    for (i, (name, value)) in defaults.into_iter().enumerate() {
        args.params.insert(
            i,
            ParamSource::Inline(name.into(), ParamValue::String(value)),
        );
    }
    let env = RosEnv::from_env().map_err(|e| e.to_string())?;
    shutdown::install_handler()?;
    let stop = StopToken::new();

    let mut nodes: Vec<LaunchNode> = vec![(
        kerf_trajectory_executor::DEFAULT_NAME,
        kerf_trajectory_executor::KNOWN_PARAMS,
        |a, e, s| kerf_trajectory_executor::run(a, e, s).map_err(|e| e.to_string()),
    )];
    if with_planner {
        nodes.push(planner_node(a.robot));
        nodes.push(gcode_node());
    }
    let all_known: Vec<&[&str]> = nodes.iter().map(|(_, known, _)| *known).collect();
    let mut handles = Vec::new();
    for (name, known, main) in nodes {
        let args = args_for(&args, known, &all_known);
        let (env, stop) = (env.clone(), stop.clone());
        let h = std::thread::Builder::new()
            .name(name.to_string())
            .spawn(move || {
                let r = main(&args, &env, stop.clone());
                // One node failing stops the launch, as a required node does in ros2 launch.
                stop.stop();
                r.map_err(|e| format!("{name}: {e}"))
            })
            .map_err(|e| format!("cannot start {name}: {e}"))?;
        handles.push(h);
    }
    let mut errors = Vec::new();
    for h in handles {
        match h.join() {
            Ok(Ok(())) => {}
            Ok(Err(e)) => errors.push(e),
            Err(_) => errors.push("a node thread panicked".to_string()),
        }
    }
    if errors.is_empty() {
        Ok(())
    } else {
        Err(errors.join("; "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sim_connects_each_robots_planners_to_the_executor() {
        let laser = sim_connections(Robot::LaserCutter);
        assert_eq!(
            laser,
            [
                "mjto_planner:~/joint_trajectory:=/trajectory_executor/joint_trajectory",
                "gcode_planner:~/joint_trajectory:=/trajectory_executor/joint_trajectory",
            ]
        );
        let irb = sim_connections(Robot::Irb6660);
        assert!(irb[0].starts_with("milling_planner:"), "{irb:?}");
        for rule in laser.iter().chain(&irb) {
            let r = kerf_ros::names::Remap::parse(rule).unwrap();
            assert_eq!(r.to, "/trajectory_executor/joint_trajectory");
        }
    }

    #[test]
    fn sim_names_the_shipped_cell_of_each_robot() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("urdf");
        for robot in [Robot::LaserCutter, Robot::Irb6660] {
            let [(h, hv), (c, cv)] = sim_defaults(&dir, robot);
            assert_eq!((h, hv.as_str()), ("hardware", "sim"));
            assert_eq!(c, "sim_cell");
            assert!(std::path::Path::new(&cv).is_file(), "{cv}");
            // The cell is the robot's: its executor configuration loads it.
            let stem = robot.stem();
            let args = RosArgs::parse([
                "--ros-args".to_string(),
                "-p".into(),
                format!("urdf_file:={}/{stem}.urdf", dir.display()),
                "-p".into(),
                format!("joint_limits_file:={}/{stem}_limits.yaml", dir.display()),
                "-p".into(),
                "hardware:=sim".into(),
                "-p".into(),
                format!("sim_cell:={cv}"),
            ])
            .unwrap();
            let params = args
                .params_for("/trajectory_executor", "trajectory_executor")
                .unwrap();
            let cfg = kerf_trajectory_executor::NodeConfig::from_params(&params).unwrap();
            kerf_trajectory_executor::hardware::Hardware::build(&cfg).unwrap();
        }
    }

    #[test]
    fn robots_are_named_as_in_the_launch_file() {
        for (name, stem) in [
            ("laser_cutter", "laser_cutter"),
            ("laser-cutter", "laser_cutter"),
            ("irb6660", "irb6660"),
        ] {
            assert_eq!(Robot::from_str(name, false).unwrap().stem(), stem);
        }
        assert!(Robot::from_str("laser", false).is_err());
    }

    #[test]
    fn parameters_go_to_the_nodes_that_know_them() {
        let args = RosArgs::parse([
            "--ros-args",
            "-p",
            "control_rate:=100.0",
            "-p",
            "queue_depth:=3",
            "-p",
            "urdf_file:=/u.urdf",
            "-p",
            "constraints.goal_time:=1.0",
            "-p",
            "no_such_param:=1",
        ])
        .unwrap();
        let exec = kerf_trajectory_executor::KNOWN_PARAMS;
        let planner = kerf_mjto_planner::KNOWN_PARAMS;
        let all = [exec, planner];
        let names = |a: RosArgs| -> Vec<String> {
            a.params
                .into_iter()
                .filter_map(|p| match p {
                    ParamSource::Inline(n, _) => Some(n),
                    ParamSource::File(_) => None,
                })
                .collect()
        };
        assert_eq!(
            names(args_for(&args, exec, &all)),
            [
                "control_rate",
                "urdf_file",
                "constraints.goal_time",
                "no_such_param"
            ]
        );
        assert_eq!(
            names(args_for(&args, planner, &all)),
            ["queue_depth", "urdf_file", "no_such_param"]
        );
        // The IRB 6660 launch: the milling planner's parameters go to it alone.
        let mill = kerf_milling_planner::KNOWN_PARAMS;
        let args = RosArgs::parse([
            "--ros-args",
            "-p",
            "queue_depth:=2",
            "-p",
            "cell_file:=/c.yaml",
            "-p",
            "urdf_file:=/u.urdf",
        ])
        .unwrap();
        assert_eq!(
            names(args_for(&args, mill, &[exec, mill])),
            ["queue_depth", "cell_file"]
        );
        assert_eq!(names(args_for(&args, exec, &[exec, mill])), ["urdf_file"]);
        assert!(knows(exec, "constraints.q1.goal"));
        assert!(!knows(exec, "constraints"));
        assert!(!knows(planner, "queue"));
    }

    #[test]
    fn each_robot_gets_its_planner() {
        assert_eq!(planner_node(Robot::LaserCutter).0, "mjto_planner");
        assert_eq!(planner_node(Robot::Irb6660).0, "milling_planner");
        assert!(planner_node(Robot::Irb6660).1.contains(&"cell_file"));
        assert_eq!(gcode_node().0, "gcode_planner");
        // Its machine follows the robot, and only it reads `machine`.
        assert_eq!(gcode_machine(Robot::Irb6660), "irb6660");
        assert_eq!(gcode_machine(Robot::LaserCutter), "laser-cutter");
        let exec = kerf_trajectory_executor::KNOWN_PARAMS;
        let all = [exec, kerf_mjto_planner::KNOWN_PARAMS, gcode_node().1];
        assert!(!all[..2].iter().any(|k| knows(k, "machine")));
        assert!(knows(gcode_node().1, "machine"));
    }
}
