"""Launch kerf's nodes on a ROS 2 Jazzy install.

kerf's binaries are plain executables built by cargo (pure-Rust ROS 2 over RustDDS), not
ament packages, so they are started with ExecuteProcess and the usual --ros-args.

    ros2 launch launch_scripts/kerf.launch.py robot:=irb6660
    ros2 launch launch_scripts/kerf.launch.py params_file:=my_cell.yaml
    ros2 launch launch_scripts/kerf.launch.py robot:=laser_cutter sim:=true sim_mode:=dynamic
    ros2 launch /opt/kerf/share/kerf/launch/kerf.launch.py robot:=laser_cutter   # installed

One parameters file per cell, read by this file and by `kerf launch` alike (README, "One
launch configuration"): launch_scripts/params/<robot>.yaml unless params_file names another.
Its `kerf_launch` section (no node has that name, so every node ignores it) says which robot,
which namespace (with its leading slash), which planners, whether the executor runs here and
whether the planners' ~/joint_trajectory goes to the executor; the other sections are the
nodes' parameters. Every node gets the file (--params-file) and reads its own section.

Arguments:
    robot        laser_cutter | irb6660; default: the file's kerf_launch.robot, else
                 laser_cutter (a robot that contradicts the file's is refused)
    params_file  the cell's parameters file (default launch_scripts/params/<robot>.yaml of
                 the kerf data directory)
    with_planner true (default): the file's planners run (kerf_launch.planners; the robot's
                 planners when the file names none); false: the executor alone, as
                 `kerf launch` without --with-planner
    nodes        comma-separated nodes to start, out of the file's (e.g. nodes:=mjto_planner
                 on a planning host; `kerf launch --only`); default: all of them
    sim          true: the executor drives the robot's simulated cell (hardware:=sim,
                 urdf/cells/laser_bpillar.yaml or irb6660_plate.yaml); default false
    sim_mode     kinematic or dynamic, with sim:=true (default: the executor's, kinematic)
    kerf_root    a kerf source tree: its data, and its binaries in target/<profile>
    profile      cargo profile of a source tree's binaries: release (default) or debug
    bin_dir      the directory of the node binaries (default: PREFIX/bin when this file is
                 installed in PREFIX/share/kerf/launch, else <kerf_root>/target/<profile>)

Where things are found: this file installed as PREFIX/share/kerf/launch/kerf.launch.py
(launch_scripts/install.sh) runs PREFIX/bin/<node> on the data in PREFIX/share/kerf; run from
a source tree's launch_scripts/, it runs <tree>/target/<profile>/<node> on the tree's data.
KERF_DATA_DIR, when set, names the data directory (as for every kerf binary) and
KERF_URDF_DIR the robot descriptions (as for `kerf launch`).

Build first (source tree): cargo build --release --workspace
The nodes honour ROS_DOMAIN_ID and ROS_AUTOMATIC_DISCOVERY_RANGE like any Jazzy node.
"""

import os
import re

import yaml

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess, OpaqueFunction
from launch.substitutions import LaunchConfiguration

HERE = os.path.dirname(os.path.abspath(__file__))

# The rules below are those of src/launch.rs (`kerf launch`); tests/launch_file.rs checks that
# both launchers give every node the same command line.
EXECUTOR = "trajectory_executor"
PLANNERS = ("mjto_planner", "milling_planner", "gcode_planner")
ROBOTS = {
    # robot: (its planners, in launch order; its simulated cell; the G-code planner's machine)
    "laser_cutter": (("mjto_planner", "gcode_planner"), "laser_bpillar", "laser-cutter"),
    "irb6660": (("milling_planner", "gcode_planner"), "irb6660_plate", "irb6660"),
}
SECTION = "kerf_launch"
KEYS = ("robot", "namespace", "planners", "executor", "connect_planners")
DEFAULT_ROBOT = "laser_cutter"
# The executor's input, relative to the nodes' namespace.
EXECUTOR_INPUT = f"{EXECUTOR}/joint_trajectory"
# A ROS name token: a letter or '_', then letters, digits, '_'; never '__'.
TOKEN = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
# The data directory's marker (kerf_robot::data::MARKER).
MARKER = os.path.join("urdf", "laser_cutter.urdf")


class LaunchError(RuntimeError):
    """A bad launch argument or parameters file; the message names what is wrong."""


def _bool_arg(name, text):
    value = text.strip().lower()
    if value not in ("true", "false"):
        raise LaunchError(f"{name} must be true or false, got '{text}'")
    return value == "true"


def check_namespace(where, ns):
    """The namespace rule of both launchers: a string with its leading slash, '/' or
    '/token[/token...]' with ROS name tokens, no trailing slash."""
    if not isinstance(ns, str):
        raise LaunchError(f"{where}: expected a string such as /cell, got {_show(ns)}")
    if not ns.startswith("/"):
        raise LaunchError(f"{where}: '{ns}' must start with '/' (e.g. /{ns.lstrip('/')})")
    if ns == "/":
        return ns
    if ns.endswith("/"):
        raise LaunchError(f"{where}: '{ns}' must not end with '/' (e.g. {ns.rstrip('/')})")
    for token in ns[1:].split("/"):
        if not TOKEN.fullmatch(token) or "__" in token:
            raise LaunchError(
                f"{where}: '{ns}' is not a ROS namespace: '{token}' must be a letter or '_' "
                "followed by letters, digits or '_' (no '__')"
            )
    return ns


class _Yaml12Loader(yaml.SafeLoader):
    """PyYAML's safe loader with YAML 1.2's booleans (true/false only, as rcl and kerf's Rust
    reader): `yes`, `on` and the like stay strings, so both launchers refuse them alike."""


_Yaml12Loader.yaml_implicit_resolvers = {
    first: [(tag, rx) for tag, rx in resolvers if tag != "tag:yaml.org,2002:bool"]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
_Yaml12Loader.add_implicit_resolver(
    "tag:yaml.org,2002:bool", re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"), list("tTfF")
)


def _show(value):
    """A value as messages show it: strings quoted with ', like `kerf launch`."""
    return f"'{value}'" if isinstance(value, str) else repr(value)


def read_launch_section(path):
    """The kerf_launch settings of a parameters file: {key: value} as written (empty when the
    file has no such section). Raises LaunchError naming the file and the key."""
    try:
        if not os.path.isfile(path):
            raise LaunchError(
                f"params_file {path}: not a regular file (missing, a directory or a FIFO)"
            )
        if os.path.getsize(path) > 1 << 20:
            raise LaunchError(f"params_file {path}: over the limit of 1048576 bytes (1 MiB)")
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except (OSError, UnicodeDecodeError) as e:
        raise LaunchError(f"params_file {path}: cannot read: {e}") from None
    try:
        doc = yaml.load(text, Loader=_Yaml12Loader)
    except yaml.YAMLError as e:
        raise LaunchError(f"params_file {path}: not YAML: {e}") from None
    if doc is None:
        doc = {}
    if not isinstance(doc, dict):
        raise LaunchError(f"params_file {path}: the top level must be a mapping of node names")
    bodies = [
        body for key, body in doc.items() if isinstance(key, str) and key.lstrip("/") == SECTION
    ]
    if not bodies:
        return {}
    if len(bodies) > 1:
        raise LaunchError(f"{path}: {SECTION} appears more than once")
    body = bodies[0]
    if not isinstance(body, dict) or not isinstance(body.get("ros__parameters"), dict):
        raise LaunchError(f"{path}: {SECTION} must hold a 'ros__parameters' mapping")
    settings = body["ros__parameters"]
    for key in settings:
        if key not in KEYS:
            raise LaunchError(
                f"{path}: {SECTION}.{key}: unknown key; {SECTION} takes {', '.join(KEYS)}"
            )
    return settings


def launch_plan(params_file, robot=None, with_planner=False, sim=False, only=None):
    """What to start: {robot, namespace, connect_planners, params_file, nodes: [names]}.

    params_file: the cell's file (already resolved); robot: the robot:= argument or None;
    only: a list of node names or None. The paths of the robot descriptions and the
    simulated cells are added by the caller (node_arguments)."""
    settings = read_launch_section(params_file)
    where = f"{params_file}: {SECTION}"
    file_robot = settings.get("robot")
    if file_robot is not None and (not isinstance(file_robot, str) or file_robot not in ROBOTS):
        raise LaunchError(
            f"{where}.robot: unknown robot '{file_robot}'; kerf knows {', '.join(ROBOTS)}"
        )
    if robot is not None and file_robot is not None and robot != file_robot:
        raise LaunchError(
            f"robot {robot} contradicts {where}.robot: {file_robot}; give the file's robot "
            "or leave it out"
        )
    robot = robot or file_robot or DEFAULT_ROBOT
    robot_planners, _, _ = ROBOTS[robot]
    namespace = check_namespace(f"{where}.namespace", settings.get("namespace", "/"))
    planners = settings.get("planners", list(robot_planners))
    if not isinstance(planners, list) or not all(isinstance(p, str) for p in planners):
        raise LaunchError(
            f"{where}.planners: expected a list of planner names such as "
            f"[{', '.join(robot_planners)}], got {_show(planners)}"
        )
    for i, p in enumerate(planners):
        if p not in PLANNERS:
            raise LaunchError(
                f"{where}.planners: unknown planner '{p}'; kerf has {', '.join(PLANNERS)}"
            )
        if p not in robot_planners:
            raise LaunchError(
                f"{where}.planners: {p} does not plan for {robot} (its planners: "
                f"{', '.join(robot_planners)})"
            )
        if p in planners[:i]:
            raise LaunchError(f"{where}.planners: {p} is listed twice")
    flags = {}
    for key in ("executor", "connect_planners"):
        value = settings.get(key, True)
        if not isinstance(value, bool):
            raise LaunchError(f"{where}.{key}: expected true or false, got {_show(value)}")
        flags[key] = value
    cell = ([EXECUTOR] if flags["executor"] else []) + planners
    if only:
        for name in only:
            if name not in cell:
                raise LaunchError(
                    f"node '{name}' is not in the cell of {params_file} (its nodes: "
                    f"{', '.join(cell) or 'none'}: {SECTION}.executor and .planners)"
                )
        nodes = [n for n in cell if n in only]
    else:
        run_planners = with_planner or sim or not flags["executor"]
        nodes = ([EXECUTOR] if flags["executor"] else []) + (planners if run_planners else [])
    if not nodes:
        raise LaunchError(
            f"nothing to launch: {where}.executor is false and {SECTION}.planners is empty"
        )
    return {
        "robot": robot,
        "namespace": namespace,
        "connect_planners": flags["connect_planners"],
        "params_file": params_file,
        "nodes": nodes,
    }


def node_arguments(plan, name, urdf_dir, sim=False, sim_mode=""):
    """The ROS arguments of one node of a plan (after the binary), in the order of
    `kerf launch`: namespace and remaps, the launchers' defaults, the cell's file, then what
    the launch's own switches choose."""
    robot = plan["robot"]
    _, cell, machine = ROBOTS[robot]
    args = ["--ros-args", "-r", f"__ns:={plan['namespace']}"]
    if name in PLANNERS and plan["connect_planners"]:
        args += ["-r", f"~/joint_trajectory:={EXECUTOR_INPUT}"]
    # Defaults, before the file: its sections may override them.
    if name == EXECUTOR:
        args += [
            "-p", f"urdf_file:={os.path.join(urdf_dir, robot + '.urdf')}",
            "-p", f"joint_limits_file:={os.path.join(urdf_dir, robot + '_limits.yaml')}",
        ]
        if sim:
            args += ["-p", f"sim_cell:={os.path.join(urdf_dir, 'cells', cell + '.yaml')}"]
    elif name == "mjto_planner":
        args += [
            "-p", f"urdf_file:={os.path.join(urdf_dir, 'laser_cutter.urdf')}",
            "-p", f"joint_limits_file:={os.path.join(urdf_dir, 'laser_cutter_limits.yaml')}",
        ]
    elif name == "gcode_planner":
        args += ["-p", f"machine:={machine}"]
    args += ["--params-file", plan["params_file"]]
    # The launch's choices, after the file.
    if name == EXECUTOR and sim:
        args += ["-p", "hardware:=sim"]
        if sim_mode:
            args += ["-p", f"sim_mode:={sim_mode}"]
    return args


def locations(kerf_root="", profile="release", bin_dir="", environ=None):
    """(data directory, robot descriptions directory, binaries directory)."""
    environ = os.environ if environ is None else environ
    installed = os.path.basename(HERE) == "launch" and os.path.isfile(
        os.path.join(os.path.dirname(HERE), MARKER)
    )
    if not re.fullmatch(r"[A-Za-z0-9_-]+", profile):
        raise LaunchError(f"profile must be a cargo profile name such as release, got '{profile}'")
    if kerf_root:
        data = kerf_root
        binaries = os.path.join(kerf_root, "target", profile)
    elif installed:
        # PREFIX/share/kerf/launch/kerf.launch.py: data in PREFIX/share/kerf, binaries in
        # PREFIX/bin.
        data = os.path.dirname(HERE)
        binaries = os.path.join(os.path.dirname(os.path.dirname(data)), "bin")
    else:
        data = os.path.dirname(HERE)
        binaries = os.path.join(data, "target", profile)
    env_data = environ.get("KERF_DATA_DIR")
    if env_data and not kerf_root:
        if not os.path.isfile(os.path.join(env_data, MARKER)):
            raise LaunchError(
                f"KERF_DATA_DIR={env_data} is not a kerf data directory ({MARKER} missing)"
            )
        data = env_data
    if not os.path.isfile(os.path.join(data, MARKER)):
        raise LaunchError(f"{data} is not a kerf data directory ({MARKER} missing)")
    urdf_dir = environ.get("KERF_URDF_DIR") or os.path.join(data, "urdf")
    return data, urdf_dir, bin_dir or binaries


def _nodes(context):
    arg = lambda name: LaunchConfiguration(name).perform(context)  # noqa: E731
    robot = arg("robot") or None
    if robot is not None and robot not in ROBOTS:
        raise LaunchError(f"robot must be {' or '.join(ROBOTS)}, got '{robot}'")
    with_planner = _bool_arg("with_planner", arg("with_planner"))
    sim = _bool_arg("sim", arg("sim"))
    sim_mode = arg("sim_mode")
    if sim_mode and sim_mode not in ("kinematic", "dynamic"):
        raise LaunchError(f"sim_mode must be kinematic or dynamic, got '{sim_mode}'")
    if sim_mode and not sim:
        raise LaunchError(f"sim_mode:={sim_mode} needs sim:=true")
    only = [n.strip() for n in arg("nodes").split(",") if n.strip()]
    for n in only:
        if n != EXECUTOR and n not in PLANNERS:
            raise LaunchError(
                f"nodes: unknown node '{n}'; kerf has {EXECUTOR}, {', '.join(PLANNERS)}"
            )
    data, urdf_dir, bin_dir = locations(arg("kerf_root"), arg("profile"), arg("bin_dir"))
    params = arg("params_file") or os.path.join(
        data, "launch_scripts", "params", f"{robot or DEFAULT_ROBOT}.yaml"
    )
    plan = launch_plan(params, robot, with_planner, sim, only)
    actions = []
    for name in plan["nodes"]:
        binary = os.path.join(bin_dir, name)
        if not os.path.isfile(binary):
            raise LaunchError(
                f"{binary} not found: build it (cargo build --release --workspace) or install "
                "kerf (launch_scripts/install.sh PREFIX), or name the directory with bin_dir:="
            )
        cmd = [binary] + node_arguments(plan, name, urdf_dir, sim, sim_mode)
        actions.append(ExecuteProcess(name=name, output="screen", cmd=cmd))
    return actions


def generate_launch_description():
    return LaunchDescription(
        [
            DeclareLaunchArgument("robot", default_value=""),
            DeclareLaunchArgument("params_file", default_value=""),
            DeclareLaunchArgument("with_planner", default_value="true"),
            DeclareLaunchArgument("nodes", default_value=""),
            DeclareLaunchArgument("sim", default_value="false"),
            DeclareLaunchArgument("sim_mode", default_value=""),
            DeclareLaunchArgument("kerf_root", default_value=""),
            DeclareLaunchArgument("profile", default_value="release"),
            DeclareLaunchArgument("bin_dir", default_value=""),
            OpaqueFunction(function=_nodes),
        ]
    )
