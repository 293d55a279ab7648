//! `kerf launch`: the nodes of one cell in one process, each with its own Context and thread,
//! configured by the cell's parameters file — the same file, read by the same rules, as
//! `launch_scripts/kerf.launch.py` (issue 27, item 4).
//!
//! The file is a ROS 2 parameters file with one section per node; its `kerf_launch` section
//! (no node has that name, so every node skips it) holds the launch's own settings:
//!
//! ```yaml
//! kerf_launch:
//!   ros__parameters:
//!     robot: laser_cutter          # laser_cutter | irb6660
//!     namespace: /cell             # leading slash required
//!     planners: [mjto_planner, gcode_planner]   # the robot's planners; [] = none
//!     executor: true               # false: planners only (a planning host)
//!     connect_planners: true       # planners' ~/joint_trajectory to the executor's input
//! ```
//!
//! Without `--params-file` the robot's shipped file is used
//! (`launch_scripts/params/<robot>.yaml` of the kerf data directory). Every node gets the file
//! (`--params-file`), so each node's section (`/**/trajectory_executor`, `/**/mjto_planner`, …)
//! reaches it. The executor runs (unless `executor: false`); the planners run with
//! `--with-planner` or `--sim` (or when the executor does not); `--only` picks nodes of the
//! file's cell. `--print-config` prints every node's command line and effective parameters as
//! JSON instead of starting them.

use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use kerf_ros::{shutdown, ParamSource, ParamValue, Params, RosArgs, RosEnv, StopToken};
use serde_yaml_ng::Value;

use crate::input::InputFile;

/// The robots whose descriptions ship in `urdf/`, named as their files and as the launch
/// file's `robot:=` argument (`laser_cutter`, `irb6660`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
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

    /// The robot named as in a parameters file (canonical names only).
    fn from_stem(s: &str) -> Option<Robot> {
        match s {
            "laser_cutter" => Some(Robot::LaserCutter),
            "irb6660" => Some(Robot::Irb6660),
            _ => None,
        }
    }

    /// The robot's shipped model: `urdf/<robot>.urdf` with `urdf/<robot>_limits.yaml`.
    ///
    /// # Errors
    /// The model's error, naming the file.
    pub(crate) fn model(self) -> Result<kerf_robot::RobotModel, String> {
        let data = |rel: String| kerf_robot::data::default_path(rel);
        let urdf = data(format!("urdf/{}.urdf", self.stem()));
        let limits = data(format!("urdf/{}_limits.yaml", self.stem()));
        kerf_robot::RobotModel::from_files(&urdf, Some(&limits)).map_err(|e| e.to_string())
    }

    /// The robot's shipped cell file, `urdf/cells/<cell>.yaml`.
    fn cell(self) -> &'static str {
        match self {
            Robot::LaserCutter => "laser_bpillar",
            Robot::Irb6660 => "irb6660_plate",
        }
    }

    /// The planners that plan for the robot, in launch order.
    fn planners(self) -> &'static [Node] {
        match self {
            Robot::LaserCutter => &[Node::MjtoPlanner, Node::GcodePlanner],
            Robot::Irb6660 => &[Node::MillingPlanner, Node::GcodePlanner],
        }
    }

    /// The G-code planner's `machine` parameter for the robot.
    fn gcode_machine(self) -> &'static str {
        match self {
            Robot::LaserCutter => "laser-cutter",
            Robot::Irb6660 => "irb6660",
        }
    }
}

/// The nodes a launch can start, named as their binaries and default node names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Node {
    /// The trajectory executor.
    #[value(name = "trajectory_executor")]
    TrajectoryExecutor,
    /// The MJTO laser-cutting planner (laser cutter).
    #[value(name = "mjto_planner")]
    MjtoPlanner,
    /// The milling planner (IRB 6660).
    #[value(name = "milling_planner")]
    MillingPlanner,
    /// The G-code planner (either robot).
    #[value(name = "gcode_planner")]
    GcodePlanner,
}

/// Every planner, as a parameters file may name them.
const PLANNERS: [Node; 3] = [Node::MjtoPlanner, Node::MillingPlanner, Node::GcodePlanner];

/// The parameters file's section of the launch settings.
const SECTION: &str = "kerf_launch";

/// The keys of [`SECTION`].
const KEYS: [&str; 5] = [
    "robot",
    "namespace",
    "planners",
    "executor",
    "connect_planners",
];

/// The executor's input relative to the nodes' namespace: where a connected planner's
/// `~/joint_trajectory` goes.
const EXECUTOR_INPUT: &str = "trajectory_executor/joint_trajectory";

impl Node {
    /// The default node name, which is also the binary's name.
    fn name(self) -> &'static str {
        match self {
            Node::TrajectoryExecutor => kerf_trajectory_executor::DEFAULT_NAME,
            Node::MjtoPlanner => kerf_mjto_planner::DEFAULT_NAME,
            Node::MillingPlanner => kerf_milling_planner::DEFAULT_NAME,
            Node::GcodePlanner => kerf_gcode_planner::DEFAULT_NAME,
        }
    }

    fn from_name(s: &str) -> Option<Node> {
        [Node::TrajectoryExecutor]
            .into_iter()
            .chain(PLANNERS)
            .find(|n| n.name() == s)
    }

    fn is_planner(self) -> bool {
        self != Node::TrajectoryExecutor
    }

    /// The parameters the node reads: a planner's own and the planner harness's
    /// (`kerf_ros::planner::HARNESS_PARAMS`: `plan_memory`, `approach.*`, `retract.*`, …,
    /// which every planner node knows).
    fn known(self) -> &'static [&'static str] {
        use std::sync::LazyLock;
        fn with_harness(own: &[&'static str]) -> Vec<&'static str> {
            let mut all = own.to_vec();
            all.extend(
                kerf_ros::planner::HARNESS_PARAMS
                    .iter()
                    .filter(|p| !own.contains(p)),
            );
            all
        }
        static MJTO: LazyLock<Vec<&'static str>> =
            LazyLock::new(|| with_harness(kerf_mjto_planner::KNOWN_PARAMS));
        static MILL: LazyLock<Vec<&'static str>> =
            LazyLock::new(|| with_harness(kerf_milling_planner::KNOWN_PARAMS));
        static GCODE: LazyLock<Vec<&'static str>> =
            LazyLock::new(|| with_harness(kerf_gcode_planner::KNOWN_PARAMS));
        match self {
            Node::TrajectoryExecutor => kerf_trajectory_executor::KNOWN_PARAMS,
            Node::MjtoPlanner => &MJTO,
            Node::MillingPlanner => &MILL,
            Node::GcodePlanner => &GCODE,
        }
    }

    /// Runs the node until its stop token (or Ctrl-C) stops it.
    fn run(self, args: &RosArgs, env: &RosEnv, stop: StopToken) -> Result<(), String> {
        match self {
            Node::TrajectoryExecutor => {
                kerf_trajectory_executor::run(args, env, stop).map_err(|e| e.to_string())
            }
            Node::MjtoPlanner => kerf_mjto_planner::run(args, env, stop).map_err(|e| e.to_string()),
            Node::MillingPlanner => {
                kerf_milling_planner::run(args, env, stop).map_err(|e| e.to_string())
            }
            Node::GcodePlanner => {
                kerf_gcode_planner::run(args, env, stop).map_err(|e| e.to_string())
            }
        }
    }
}

/// Arguments of `kerf launch`.
#[derive(Args, Debug)]
pub struct LaunchArgs {
    /// Robot of the cell: its URDF and limits from the shipped descriptions, and its shipped
    /// parameters file `launch_scripts/params/<robot>.yaml` when --params-file is not given
    /// (default: the file's `kerf_launch.robot`, else laser_cutter; one that contradicts the
    /// file is refused).
    #[arg(long, value_enum)]
    robot: Option<Robot>,
    /// The cell's parameters file (ROS 2 format, at most 1 MiB; default: the robot's shipped
    /// one): its `kerf_launch` section sets the robot, the namespace, the planners, whether
    /// the executor runs and whether the planners connect to it; every node gets the file and
    /// reads its own section (README, "One launch configuration").
    #[arg(long, value_name = "FILE")]
    params_file: Option<InputFile>,
    /// Also start the planners: the file's `kerf_launch.planners`, or the robot's (the MJTO
    /// planner for the laser cutter, the milling planner for the IRB 6660, the G-code planner
    /// for both) when the file names none. Their `~/joint_trajectory` goes to the executor's
    /// input (`kerf_launch.connect_planners`, default true).
    #[arg(long)]
    with_planner: bool,
    /// Start only these nodes of the file's cell (repeat or separate with commas), e.g.
    /// `--only mjto_planner` on a planning host and `--only trajectory_executor` on the cell's
    /// controller, both with the same file (README, "Across hosts").
    #[arg(long, value_enum, value_delimiter = ',', value_name = "NODE")]
    only: Vec<Node>,
    /// Run the executor on the robot's simulated cell (`hardware: sim`, `sim_cell` the
    /// shipped `urdf/cells/laser_bpillar.yaml` or `irb6660_plate.yaml` unless the file sets
    /// one; `-p sim_mode:=dynamic` and `-p sim_physics_rate:=…` after `--ros-args`) and start
    /// the planners as `--with-planner` does, so that a request runs in the cell.
    #[arg(long)]
    sim: bool,
    /// Print the nodes this launch would start, each with its command line (as for the node's
    /// own binary), name, namespace, where its `~/joint_trajectory` goes and its effective
    /// parameters, as JSON, and exit without starting them.
    #[arg(long)]
    print_config: bool,
    /// Directory holding the robot descriptions (default: `$KERF_URDF_DIR`, else the `urdf/`
    /// of the kerf data directory: `$KERF_DATA_DIR`, the share directory beside the binary,
    /// the source tree kerf was built from).
    #[arg(long)]
    urdf_dir: Option<PathBuf>,
    /// ROS arguments, as for any ROS 2 node: `--ros-args -r __ns:=/cell -p control_rate:=100.0
    /// --params-file params.yaml`, after the cell's file. Node-specific rules use the node's
    /// default name (`-r trajectory_executor:__ns:=/cell`); each `-p` goes to the nodes that
    /// read it.
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

/// What the launch starts, from the parameters file and the command line.
#[derive(Debug, Clone, PartialEq)]
struct Plan {
    robot: Robot,
    /// The nodes' namespace, with its leading slash.
    namespace: String,
    /// Whether the planners' `~/joint_trajectory` is remapped to the executor's input.
    connect_planners: bool,
    /// The cell's parameters file, as every node gets it.
    params_file: PathBuf,
    /// The nodes to start, in launch order.
    nodes: Vec<Node>,
}

/// The launch's switches besides the file.
#[derive(Debug, Clone, Default)]
struct Switches {
    robot: Option<Robot>,
    with_planner: bool,
    sim: bool,
    only: Vec<Node>,
}

/// A ROS name token: a letter or `_`, then letters, digits or `_`; never `__`.
fn is_token(t: &str) -> bool {
    let mut chars = t.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
        && !t.contains("__")
}

/// The namespace rule of both launchers: `/`, or `/token[/token…]` without a trailing slash.
///
/// # Errors
/// A message starting with `where`, naming the namespace and what is wrong.
fn check_namespace(place: &str, ns: &str) -> Result<(), String> {
    if !ns.starts_with('/') {
        return Err(format!(
            "{place}: '{ns}' must start with '/' (e.g. /{})",
            ns.trim_start_matches('/')
        ));
    }
    if ns == "/" {
        return Ok(());
    }
    if ns.ends_with('/') {
        return Err(format!(
            "{place}: '{ns}' must not end with '/' (e.g. {})",
            ns.trim_end_matches('/')
        ));
    }
    if let Some(bad) = ns[1..].split('/').find(|t| !is_token(t)) {
        return Err(format!(
            "{place}: '{ns}' is not a ROS namespace: '{bad}' must be a letter or '_' followed \
             by letters, digits or '_' (no '__')"
        ));
    }
    Ok(())
}

/// A YAML value as a message shows it: a string in single quotes (as `kerf.launch.py`
/// shows it), anything else as YAML.
fn show(v: &Value) -> String {
    match v {
        Value::String(s) => format!("'{s}'"),
        _ => serde_yaml_ng::to_string(v)
            .map(|s| s.trim().to_string())
            .unwrap_or_else(|_| format!("{v:?}")),
    }
}

/// The `kerf_launch` settings of a parameters file (empty when it has no such section).
///
/// # Errors
/// A message naming the file and the key: not YAML, not a mapping, the section twice or
/// without `ros__parameters`, an unknown key.
fn launch_section(file: &Path, text: &str) -> Result<serde_yaml_ng::Mapping, String> {
    let path = file.display();
    let doc: Value =
        serde_yaml_ng::from_str(text).map_err(|e| format!("params_file {path}: not YAML: {e}"))?;
    let nodes = match doc {
        Value::Mapping(m) => m,
        Value::Null => return Ok(serde_yaml_ng::Mapping::new()),
        _ => {
            return Err(format!(
                "params_file {path}: the top level must be a mapping of node names"
            ))
        }
    };
    let mut bodies = nodes.iter().filter_map(|(k, body)| {
        k.as_str()
            .filter(|k| k.trim_start_matches('/') == SECTION)
            .map(|_| body)
    });
    let Some(body) = bodies.next() else {
        return Ok(serde_yaml_ng::Mapping::new());
    };
    if bodies.next().is_some() {
        return Err(format!("{path}: {SECTION} appears more than once"));
    }
    let Some(Value::Mapping(settings)) = body.get("ros__parameters") else {
        return Err(format!(
            "{path}: {SECTION} must hold a 'ros__parameters' mapping"
        ));
    };
    for key in settings.keys() {
        let name = key.as_str().map_or_else(|| show(key), str::to_string);
        if !KEYS.contains(&name.as_str()) {
            return Err(format!(
                "{path}: {SECTION}.{name}: unknown key; {SECTION} takes {}",
                KEYS.join(", ")
            ));
        }
    }
    Ok(settings.clone())
}

/// The launch plan: the file's settings, validated, and the switches.
///
/// # Arguments
/// * `file` — the cell's parameters file, as the nodes get it; `text` — its contents.
///
/// # Errors
/// A message naming the file and the key, as `kerf.launch.py` words it: an unknown robot or
/// planner, a planner that does not plan for the robot, a robot that contradicts `--robot`,
/// a namespace without its leading slash, a node `--only` names that the cell does not have,
/// nothing to launch.
fn plan(file: &Path, text: &str, switches: &Switches) -> Result<Plan, String> {
    let settings = launch_section(file, text)?;
    let place = format!("{}: {SECTION}", file.display());
    let get = |key: &str| settings.get(key);
    let file_robot = match get("robot") {
        None => None,
        Some(v) => Some(v.as_str().and_then(Robot::from_stem).ok_or_else(|| {
            format!(
                "{place}.robot: unknown robot '{}'; kerf knows laser_cutter, irb6660",
                v.as_str().map_or_else(|| show(v), str::to_string)
            )
        })?),
    };
    if let (Some(arg), Some(f)) = (switches.robot, file_robot) {
        if arg != f {
            return Err(format!(
                "robot {} contradicts {place}.robot: {}; give the file's robot or leave it out",
                arg.stem(),
                f.stem()
            ));
        }
    }
    let robot = switches.robot.or(file_robot).unwrap_or(Robot::LaserCutter);
    let namespace = match get("namespace") {
        None => "/".to_string(),
        Some(Value::String(ns)) => ns.clone(),
        Some(v) => {
            return Err(format!(
                "{place}.namespace: expected a string such as /cell, got {}",
                show(v)
            ))
        }
    };
    check_namespace(&format!("{place}.namespace"), &namespace)?;
    let own = robot.planners();
    let own_names = || own.iter().map(|p| p.name()).collect::<Vec<_>>().join(", ");
    let planners = match get("planners") {
        None => own.to_vec(),
        Some(Value::Sequence(items)) => {
            let mut planners: Vec<Node> = Vec::new();
            for item in items {
                let Some(name) = item.as_str() else {
                    return Err(format!(
                        "{place}.planners: expected a list of planner names such as [{}], got {}",
                        own_names(),
                        show(item)
                    ));
                };
                let node = Node::from_name(name)
                    .filter(|n| n.is_planner())
                    .ok_or_else(|| {
                        format!(
                            "{place}.planners: unknown planner '{name}'; kerf has {}",
                            PLANNERS.map(Node::name).join(", ")
                        )
                    })?;
                if !own.contains(&node) {
                    return Err(format!(
                        "{place}.planners: {name} does not plan for {} (its planners: {})",
                        robot.stem(),
                        own_names()
                    ));
                }
                if planners.contains(&node) {
                    return Err(format!("{place}.planners: {name} is listed twice"));
                }
                planners.push(node);
            }
            planners
        }
        Some(v) => {
            return Err(format!(
                "{place}.planners: expected a list of planner names such as [{}], got {}",
                own_names(),
                show(v)
            ))
        }
    };
    let flag = |key: &str| match get(key) {
        None => Ok(true),
        Some(Value::Bool(b)) => Ok(*b),
        Some(v) => Err(format!(
            "{place}.{key}: expected true or false, got {}",
            show(v)
        )),
    };
    let executor = flag("executor")?;
    let connect_planners = flag("connect_planners")?;
    let mut cell = Vec::new();
    if executor {
        cell.push(Node::TrajectoryExecutor);
    }
    cell.extend(&planners);
    let nodes: Vec<Node> = if switches.only.is_empty() {
        let run_planners = switches.with_planner || switches.sim || !executor;
        cell.iter()
            .copied()
            .filter(|n| !n.is_planner() || run_planners)
            .collect()
    } else {
        if let Some(n) = switches.only.iter().find(|n| !cell.contains(n)) {
            let names: Vec<&str> = cell.iter().map(|n| n.name()).collect();
            return Err(format!(
                "node '{}' is not in the cell of {} (its nodes: {}: {SECTION}.executor and \
                 .planners)",
                n.name(),
                file.display(),
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            ));
        }
        cell.iter()
            .copied()
            .filter(|n| switches.only.contains(n))
            .collect()
    };
    if nodes.is_empty() {
        return Err(format!(
            "nothing to launch: {place}.executor is false and {SECTION}.planners is empty"
        ));
    }
    Ok(Plan {
        robot,
        namespace,
        connect_planners,
        params_file: file.to_path_buf(),
        nodes,
    })
}

/// The ROS arguments the launch gives one node (after the binary), in `kerf.launch.py`'s
/// order: the namespace and the connection to the executor, the launchers' defaults (the
/// robot description, the G-code machine, with `--sim` the shipped cell), the cell's file
/// (which may override those defaults), then with `--sim` `hardware:=sim`.
fn node_arguments(plan: &Plan, node: Node, urdf: &Path, sim: bool) -> Vec<String> {
    let path = |p: PathBuf| p.display().to_string();
    let mut a = vec![
        "--ros-args".to_string(),
        "-r".into(),
        format!("__ns:={}", plan.namespace),
    ];
    if node.is_planner() && plan.connect_planners {
        a.extend(["-r".into(), format!("~/joint_trajectory:={EXECUTOR_INPUT}")]);
    }
    let stem = plan.robot.stem();
    let mut param = |name: &str, value: String| a.extend(["-p".into(), format!("{name}:={value}")]);
    match node {
        Node::TrajectoryExecutor => {
            param("urdf_file", path(urdf.join(format!("{stem}.urdf"))));
            param(
                "joint_limits_file",
                path(urdf.join(format!("{stem}_limits.yaml"))),
            );
            if sim {
                let cell = urdf
                    .join("cells")
                    .join(format!("{}.yaml", plan.robot.cell()));
                param("sim_cell", path(cell));
            }
        }
        Node::MjtoPlanner => {
            param("urdf_file", path(urdf.join("laser_cutter.urdf")));
            param(
                "joint_limits_file",
                path(urdf.join("laser_cutter_limits.yaml")),
            );
        }
        Node::GcodePlanner => param("machine", plan.robot.gcode_machine().to_string()),
        Node::MillingPlanner => {}
    }
    a.extend(["--params-file".into(), path(plan.params_file.clone())]);
    if node == Node::TrajectoryExecutor && sim {
        a.extend(["-p".into(), "hardware:=sim".into()]);
    }
    a
}

/// The user's ROS arguments (after `--ros-args`) as items: remap rules, and everything else
/// (parameters, parameter files, log settings), each with its value.
#[derive(Debug, Clone, Default, PartialEq)]
struct UserArgs {
    remaps: Vec<[String; 2]>,
    others: Vec<Vec<String>>,
}

impl UserArgs {
    /// Splits `words`, which [`RosArgs::parse`] has accepted.
    fn split(words: &[String]) -> UserArgs {
        let mut out = UserArgs::default();
        let mut it = words.iter();
        while let Some(w) = it.next() {
            match w.as_str() {
                "--ros-args" | "--" => {}
                "-r" | "--remap" => {
                    if let Some(v) = it.next() {
                        out.remaps.push([w.clone(), v.clone()]);
                    }
                }
                "-p" | "--param" | "--params-file" | "--log-level" => {
                    out.others
                        .push(std::iter::once(w).chain(it.next()).cloned().collect());
                }
                _ => out.others.push(vec![w.clone()]),
            }
        }
        out
    }

    /// The items one node gets: every remap (the rules name their node), and every other
    /// item except a `-p` parameter this node does not read but another node of the launch
    /// does (it is meant for that one). A parameter no node reads stays, so that the nodes
    /// refuse it as a typo.
    fn for_node(&self, known: &[&str], all_known: &[&[&str]]) -> (Vec<String>, Vec<String>) {
        let remaps = self.remaps.iter().flatten().cloned().collect();
        let others = self
            .others
            .iter()
            .filter(|item| match item.as_slice() {
                [flag, rule] if flag == "-p" || flag == "--param" => {
                    let name = rule.split_once(":=").map_or(rule.as_str(), |(n, _)| n);
                    knows(known, name) || !all_known.iter().any(|k| knows(k, name))
                }
                _ => true,
            })
            .flatten()
            .cloned()
            .collect();
        (remaps, others)
    }
}

/// One node of the launch: its command line (after the binary): `--ros-args`, the user's
/// remap rules (the first matching rule wins, so theirs come first), the launch's arguments,
/// the user's other arguments (later parameters win, so theirs come last).
fn node_argv(launch: &[String], user: (Vec<String>, Vec<String>)) -> Vec<String> {
    let (remaps, others) = user;
    let mut argv = vec!["--ros-args".to_string()];
    argv.extend(remaps);
    argv.extend(launch.iter().skip(1).cloned());
    argv.extend(others);
    argv
}

/// A parameter value as JSON.
fn param_json(v: &ParamValue) -> serde_json::Value {
    use serde_json::Value as J;
    match v {
        ParamValue::Bool(b) => J::from(*b),
        ParamValue::Integer(i) => J::from(*i),
        ParamValue::Double(d) => J::from(*d),
        ParamValue::String(s) => J::from(s.clone()),
        ParamValue::BoolArray(a) => J::from(a.clone()),
        ParamValue::IntegerArray(a) => J::from(a.clone()),
        ParamValue::DoubleArray(a) => J::from(a.clone()),
        ParamValue::StringArray(a) => J::from(a.clone()),
    }
}

/// What a node with command line `argv` is: its name, namespace, where its
/// `~/joint_trajectory` resolves, its effective parameters (files read), as JSON.
///
/// # Errors
/// A bad remap or name, an unreadable parameter file, naming the node.
fn effective(node: Node, argv: &[String]) -> Result<serde_json::Value, String> {
    let what = |e: kerf_ros::RosError| format!("{}: {e}", node.name());
    let args = RosArgs::parse(argv.iter().cloned()).map_err(what)?;
    let name = args.node_name(node.name()).map_err(what)?;
    let namespace = args.namespace(node.name(), "/").map_err(what)?;
    let fqn = kerf_ros::names::expand("~", &namespace, &name).map_err(what)?;
    let params: Params = args.params_for(&fqn, &name).map_err(what)?;
    let trajectory =
        kerf_ros::names::resolve("~/joint_trajectory", &namespace, &name, &args.remaps)
            .map_err(what)?;
    let parameters: serde_json::Map<String, serde_json::Value> = params
        .iter()
        .map(|(k, v)| (k.clone(), param_json(v)))
        .collect();
    Ok(serde_json::json!({
        "executable": node.name(),
        "arguments": argv,
        "name": name,
        "namespace": namespace,
        "joint_trajectory": trajectory,
        "parameters": parameters,
    }))
}

/// Runs `kerf launch` until Ctrl-C or until a node fails (or prints the configuration).
pub fn run(a: LaunchArgs) -> Result<(), String> {
    let user = RosArgs::parse(a.ros_args.iter().cloned()).map_err(|e| e.to_string())?;
    if let Some(extra) = user.other.first() {
        return Err(format!(
            "unexpected argument {extra:?}; ROS arguments go after --ros-args"
        ));
    }
    // Every node reads each parameter file: regular files under the cap only (a FIFO would
    // block the first node, and could not be read twice anyway).
    for src in &user.params {
        if let ParamSource::File(path) = src {
            let file = InputFile::from(path.clone().into_os_string());
            crate::input::check_file("--params-file", &file, crate::input::PARAMS_CAP)?;
        }
    }
    let urdf = urdf_dir(a.urdf_dir)?;
    let file = match a.params_file {
        Some(f) => f,
        None => {
            let stem = a.robot.unwrap_or(Robot::LaserCutter).stem();
            let p = kerf_robot::data::path(format!("launch_scripts/params/{stem}.yaml"))
                .map_err(|e| e.to_string())?;
            InputFile::from(p.into_os_string())
        }
    };
    crate::input::check_file("--params-file", &file, crate::input::PARAMS_CAP)?;
    let text = crate::input::read_text("--params-file", &file, crate::input::PARAMS_CAP)?;
    let switches = Switches {
        robot: a.robot,
        with_planner: a.with_planner,
        sim: a.sim,
        only: a.only,
    };
    let plan = plan(file.path(), &text, &switches)?;
    let items = UserArgs::split(&a.ros_args);
    let all_known: Vec<&[&str]> = plan.nodes.iter().map(|n| n.known()).collect();
    let nodes: Vec<(Node, Vec<String>)> = plan
        .nodes
        .iter()
        .map(|&n| {
            let launch = node_arguments(&plan, n, &urdf, a.sim);
            (n, node_argv(&launch, items.for_node(n.known(), &all_known)))
        })
        .collect();

    if a.print_config {
        let nodes = nodes
            .iter()
            .map(|(n, argv)| effective(*n, argv))
            .collect::<Result<Vec<_>, _>>()?;
        let out = serde_json::json!({
            "robot": plan.robot.stem(),
            "namespace": plan.namespace,
            "params_file": plan.params_file.display().to_string(),
            "connect_planners": plan.connect_planners,
            "nodes": nodes,
        });
        println!(
            "{}",
            serde_json::to_string_pretty(&out).map_err(|e| e.to_string())?
        );
        return Ok(());
    }

    let env = RosEnv::from_env().map_err(|e| e.to_string())?;
    shutdown::install_handler()?;
    let stop = StopToken::new();
    eprintln!(
        "kerf launch: {} in {} for {} (parameters {})",
        plan.nodes
            .iter()
            .map(|n| n.name())
            .collect::<Vec<_>>()
            .join(", "),
        plan.namespace,
        plan.robot.stem(),
        plan.params_file.display()
    );
    let mut handles = Vec::new();
    for (node, argv) in nodes {
        let args = RosArgs::parse(argv).map_err(|e| format!("{}: {e}", node.name()))?;
        let (env, stop) = (env.clone(), stop.clone());
        let name = node.name();
        let h = std::thread::Builder::new()
            .name(name.to_string())
            .spawn(move || {
                let r = node.run(&args, &env, stop.clone());
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

    fn root() -> &'static Path {
        Path::new(env!("CARGO_MANIFEST_DIR"))
    }

    /// The plan of the shipped file of `robot`.
    fn shipped(robot: Robot, switches: &Switches) -> Result<Plan, String> {
        let file = root().join(format!("launch_scripts/params/{}.yaml", robot.stem()));
        let text = std::fs::read_to_string(&file).unwrap();
        plan(&file, &text, switches)
    }

    fn names(plan: &Plan) -> Vec<&'static str> {
        plan.nodes.iter().map(|n| n.name()).collect()
    }

    #[test]
    fn the_shipped_files_name_each_robots_cell() {
        let p = shipped(Robot::LaserCutter, &Switches::default()).unwrap();
        assert_eq!((p.robot, p.namespace.as_str()), (Robot::LaserCutter, "/"));
        assert_eq!(names(&p), ["trajectory_executor"]);
        let with = Switches {
            with_planner: true,
            ..Switches::default()
        };
        let p = shipped(Robot::LaserCutter, &with).unwrap();
        assert_eq!(
            names(&p),
            ["trajectory_executor", "mjto_planner", "gcode_planner"]
        );
        let p = shipped(Robot::Irb6660, &with).unwrap();
        assert_eq!(
            names(&p),
            ["trajectory_executor", "milling_planner", "gcode_planner"]
        );
        // The shipped file is the robot's: another robot contradicts it.
        let wrong = Switches {
            robot: Some(Robot::LaserCutter),
            ..Switches::default()
        };
        let e = shipped(Robot::Irb6660, &wrong).unwrap_err();
        assert!(
            e.contains("contradicts") && e.contains("kerf_launch.robot"),
            "{e}"
        );
    }

    /// A fresh `…cell.yaml` in the temporary directory holding `settings` as its
    /// `kerf_launch` parameters (the nodes' parameter readers can open it).
    fn settings_file(settings: &str) -> PathBuf {
        static N: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let n = N.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let file = std::env::temp_dir().join(format!(
            "kerf_launch_unit_{}_{n}_cell.yaml",
            std::process::id()
        ));
        std::fs::write(
            &file,
            format!("kerf_launch:\n  ros__parameters:\n{settings}"),
        )
        .unwrap();
        file
    }

    /// The plan of a file holding `settings` as its `kerf_launch` parameters.
    fn with_settings(settings: &str, switches: &Switches) -> Result<Plan, String> {
        let file = settings_file(settings);
        let p = plan(&file, &std::fs::read_to_string(&file).unwrap(), switches);
        std::fs::remove_file(&file).unwrap();
        p
    }

    #[test]
    fn settings_are_validated_naming_the_key() {
        let none = Switches::default();
        for (settings, needle) in [
            (
                "    namespace: cell\n",
                "kerf_launch.namespace: 'cell' must start with '/'",
            ),
            ("    namespace: /cell/\n", "must not end with '/'"),
            ("    namespace: /9cell\n", "'9cell' must be a letter"),
            ("    namespace: /a__b\n", "is not a ROS namespace"),
            (
                "    namespace: 3\n",
                "kerf_launch.namespace: expected a string",
            ),
            ("    planners: [cutter]\n", "unknown planner 'cutter'"),
            (
                "    planners: [milling_planner]\n",
                "kerf_launch.planners: milling_planner does not plan for laser_cutter",
            ),
            (
                "    robot: irb6660\n    planners: [mjto_planner]\n",
                "mjto_planner does not plan for irb6660",
            ),
            (
                "    planners: [gcode_planner, gcode_planner]\n",
                "listed twice",
            ),
            (
                "    planners: gcode_planner\n",
                "expected a list of planner names",
            ),
            ("    robot: ur5\n", "kerf_launch.robot: unknown robot 'ur5'"),
            (
                "    executor: yes\n",
                "kerf_launch.executor: expected true or false",
            ),
            ("    spare: 1\n", "kerf_launch.spare: unknown key"),
            (
                "    executor: false\n    planners: []\n",
                "cell.yaml: kerf_launch.executor is false and kerf_launch.planners is empty",
            ),
        ] {
            let e = with_settings(settings, &none).unwrap_err();
            assert!(e.contains(needle), "{settings}: {e}");
            assert!(e.contains("cell.yaml"), "{settings}: {e}");
        }
        let e = plan(
            Path::new("x.yaml"),
            "kerf_launch: {robot: irb6660}\n",
            &none,
        )
        .unwrap_err();
        assert!(e.contains("'ros__parameters'"), "{e}");
        let e = plan(Path::new("x.yaml"), "[1, 2]\n", &none).unwrap_err();
        assert!(e.contains("top level"), "{e}");
    }

    #[test]
    fn the_switches_pick_the_nodes() {
        let s = |with_planner, sim, only: &[Node]| Switches {
            robot: None,
            with_planner,
            sim,
            only: only.to_vec(),
        };
        let cell = "    robot: irb6660\n    namespace: /cell\n    planners: [gcode_planner]\n";
        let p = with_settings(cell, &s(false, false, &[])).unwrap();
        assert_eq!(names(&p), ["trajectory_executor"]);
        assert_eq!(p.namespace, "/cell");
        for (w, sim) in [(true, false), (false, true)] {
            let p = with_settings(cell, &s(w, sim, &[])).unwrap();
            assert_eq!(names(&p), ["trajectory_executor", "gcode_planner"]);
        }
        // Planners only: they run without --with-planner.
        let planning = format!("{cell}    executor: false\n");
        let p = with_settings(&planning, &s(false, false, &[])).unwrap();
        assert_eq!(names(&p), ["gcode_planner"]);
        // --only picks out of the cell, in launch order.
        let p = with_settings(
            cell,
            &s(
                false,
                false,
                &[Node::GcodePlanner, Node::TrajectoryExecutor],
            ),
        )
        .unwrap();
        assert_eq!(names(&p), ["trajectory_executor", "gcode_planner"]);
        let e = with_settings(cell, &s(false, false, &[Node::MillingPlanner])).unwrap_err();
        assert!(
            e.contains("'milling_planner' is not in the cell")
                && e.contains("trajectory_executor, gcode_planner"),
            "{e}"
        );
        let e =
            with_settings(&planning, &s(false, false, &[Node::TrajectoryExecutor])).unwrap_err();
        assert!(
            e.contains("'trajectory_executor' is not in the cell"),
            "{e}"
        );
        // No kerf_launch section: the robot's defaults.
        let p = plan(
            Path::new("old.yaml"),
            "trajectory_executor:\n  ros__parameters:\n    control_rate: 100.0\n",
            &Switches {
                robot: Some(Robot::Irb6660),
                with_planner: true,
                ..Switches::default()
            },
        )
        .unwrap();
        assert_eq!(
            names(&p),
            ["trajectory_executor", "milling_planner", "gcode_planner"]
        );
        assert!(p.connect_planners);
    }

    #[test]
    fn planners_connect_to_the_executor_in_the_namespace() {
        let file = settings_file("    namespace: /cell\n");
        let with = Switches {
            with_planner: true,
            ..Switches::default()
        };
        let p = plan(&file, &std::fs::read_to_string(&file).unwrap(), &with).unwrap();
        let urdf = root().join("urdf");
        for node in [Node::MjtoPlanner, Node::GcodePlanner] {
            let argv = node_arguments(&p, node, &urdf, false);
            let v = effective(node, &argv).unwrap();
            assert_eq!(v["namespace"], "/cell");
            assert_eq!(
                v["joint_trajectory"], "/cell/trajectory_executor/joint_trajectory",
                "{v}"
            );
        }
        let exec = effective(
            Node::TrajectoryExecutor,
            &node_arguments(&p, Node::TrajectoryExecutor, &urdf, false),
        )
        .unwrap();
        assert_eq!(
            exec["joint_trajectory"],
            "/cell/trajectory_executor/joint_trajectory"
        );
        // connect_planners: false leaves the planners' trajectories on their own topic.
        std::fs::remove_file(&file).unwrap();
        let file = settings_file("    connect_planners: false\n");
        let p = plan(&file, &std::fs::read_to_string(&file).unwrap(), &with).unwrap();
        let argv = node_arguments(&p, Node::MjtoPlanner, &urdf, false);
        let v = effective(Node::MjtoPlanner, &argv).unwrap();
        assert_eq!(v["joint_trajectory"], "/mjto_planner/joint_trajectory");
        // The user's rules come first and win.
        let user = UserArgs::split(&[
            "--ros-args".into(),
            "-r".into(),
            "mjto_planner:~/joint_trajectory:=/elsewhere".into(),
        ]);
        let argv = node_argv(&argv, user.for_node(Node::MjtoPlanner.known(), &[]));
        let v = effective(Node::MjtoPlanner, &argv).unwrap();
        assert_eq!(v["joint_trajectory"], "/elsewhere");
        std::fs::remove_file(&file).unwrap();
    }

    #[test]
    fn sim_names_the_shipped_cell_of_each_robot() {
        let dir = root().join("urdf");
        for robot in [Robot::LaserCutter, Robot::Irb6660] {
            let p = shipped(
                robot,
                &Switches {
                    robot: Some(robot),
                    sim: true,
                    ..Switches::default()
                },
            )
            .unwrap();
            let argv = node_arguments(&p, Node::TrajectoryExecutor, &dir, true);
            let v = effective(Node::TrajectoryExecutor, &argv).unwrap();
            assert_eq!(v["parameters"]["hardware"], "sim", "{v}");
            let cell = v["parameters"]["sim_cell"].as_str().unwrap();
            assert!(Path::new(cell).is_file(), "{cell}");
            // The cell is the robot's: its executor configuration loads it.
            let args = RosArgs::parse(argv).unwrap();
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
        for n in [Node::TrajectoryExecutor].into_iter().chain(PLANNERS) {
            assert_eq!(Node::from_str(n.name(), false).unwrap(), n);
            assert_eq!(Node::from_name(n.name()), Some(n));
        }
    }

    #[test]
    fn parameters_go_to_the_nodes_that_know_them() {
        let words: Vec<String> = [
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
            "--log-level",
            "warn",
        ]
        .map(String::from)
        .to_vec();
        let user = UserArgs::split(&words);
        let exec = kerf_trajectory_executor::KNOWN_PARAMS;
        let planner = kerf_mjto_planner::KNOWN_PARAMS;
        let all = [exec, planner];
        let params = |known: &[&str], all: &[&[&str]]| -> Vec<String> {
            let (_, others) = user.for_node(known, all);
            others
                .chunks(2)
                .filter(|c| c[0] == "-p")
                .map(|c| c[1].split_once(":=").unwrap().0.to_string())
                .collect()
        };
        assert_eq!(
            params(exec, &all),
            [
                "control_rate",
                "urdf_file",
                "constraints.goal_time",
                "no_such_param"
            ]
        );
        assert_eq!(
            params(planner, &all),
            ["queue_depth", "urdf_file", "no_such_param"]
        );
        // The IRB 6660 launch: the milling planner's parameters go to it alone.
        let mill = kerf_milling_planner::KNOWN_PARAMS;
        let words: Vec<String> = [
            "--ros-args",
            "-p",
            "queue_depth:=2",
            "-p",
            "cell_file:=/c.yaml",
            "-p",
            "urdf_file:=/u.urdf",
        ]
        .map(String::from)
        .to_vec();
        let user = UserArgs::split(&words);
        let params = |known: &[&str], all: &[&[&str]]| -> Vec<String> {
            let (_, others) = user.for_node(known, all);
            others
                .chunks(2)
                .map(|c| c[1].split_once(":=").unwrap().0.to_string())
                .collect()
        };
        assert_eq!(params(mill, &[exec, mill]), ["queue_depth", "cell_file"]);
        assert_eq!(params(exec, &[exec, mill]), ["urdf_file"]);
        assert!(knows(exec, "constraints.q1.goal"));
        assert!(!knows(exec, "constraints"));
        assert!(!knows(planner, "queue"));
        // Only the G-code planner reads `machine`.
        let gcode = Node::GcodePlanner.known();
        assert!(knows(gcode, "machine"));
        assert!(!knows(exec, "machine") && !knows(planner, "machine") && !knows(mill, "machine"));
        // The planner harness's parameters (issue 27's approach, plan_memory) go to every
        // planner and not to the executor.
        let words: Vec<String> = [
            "--ros-args",
            "-p",
            "approach.clearance:=0.02",
            "-p",
            "plan_memory:=1000000000",
        ]
        .map(String::from)
        .to_vec();
        let user = UserArgs::split(&words);
        let nodes = [
            Node::TrajectoryExecutor,
            Node::MjtoPlanner,
            Node::GcodePlanner,
        ];
        let all: Vec<&[&str]> = nodes.iter().map(|n| n.known()).collect();
        for n in nodes {
            let (_, others) = user.for_node(n.known(), &all);
            let got: Vec<&str> = others
                .chunks(2)
                .map(|c| c[1].split_once(":=").unwrap().0)
                .collect();
            if n.is_planner() {
                assert_eq!(got, ["approach.clearance", "plan_memory"], "{n:?}");
            } else {
                assert!(got.is_empty(), "{got:?}");
            }
        }
    }
}
