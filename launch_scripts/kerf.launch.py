"""Launch kerf's nodes on a ROS 2 Jazzy install.

kerf's binaries are plain executables built by cargo (pure-Rust ROS 2 over RustDDS), not
ament packages, so they are started with ExecuteProcess and the usual --ros-args.

    ros2 launch launch_scripts/kerf.launch.py robot:=irb6660
    ros2 launch launch_scripts/kerf.launch.py robot:=laser_cutter namespace:=/cell
    ros2 launch launch_scripts/kerf.launch.py robot:=laser_cutter sim:=true sim_mode:=dynamic

Arguments:
    robot       laser_cutter | irb6660 (selects urdf/<robot>.urdf and its limits YAML);
                laser_cutter also starts the MJTO planner (mjto_planner), irb6660 the
                milling planner (milling_planner); both start the G-code planner
                (gcode_planner, machine:= the robot); each planner's ~/joint_trajectory is
                remapped to the executor's input
    namespace   node namespace (default /)
    params_file executor parameters (default launch_scripts/params/<robot>.yaml)
    kerf_root   the kerf source tree (default: the parent of this file's directory)
    profile     cargo profile whose binaries to run: release (default) or debug
    sim         true: the executor drives the robot's simulated cell (hardware:=sim,
                urdf/cells/laser_bpillar.yaml or irb6660_plate.yaml); default false (mock)
    sim_mode    kinematic (default) or dynamic, with sim:=true

Build first: cargo build --release --workspace
The nodes honour ROS_DOMAIN_ID and ROS_AUTOMATIC_DISCOVERY_RANGE like any Jazzy node.
"""

import os

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess, OpaqueFunction
from launch.substitutions import LaunchConfiguration

HERE = os.path.dirname(os.path.abspath(__file__))


def _nodes(context):
    root = LaunchConfiguration("kerf_root").perform(context) or os.path.dirname(HERE)
    robot = LaunchConfiguration("robot").perform(context)
    if robot not in ("laser_cutter", "irb6660"):
        raise RuntimeError(f"robot must be laser_cutter or irb6660, got {robot!r}")
    namespace = LaunchConfiguration("namespace").perform(context)
    profile = LaunchConfiguration("profile").perform(context)
    params = LaunchConfiguration("params_file").perform(context) or os.path.join(
        HERE, "params", f"{robot}.yaml"
    )
    urdf_dir = os.path.join(root, "urdf")
    sim = LaunchConfiguration("sim").perform(context).lower()
    if sim not in ("true", "false"):
        raise RuntimeError(f"sim must be true or false, got {sim!r}")
    sim_mode = LaunchConfiguration("sim_mode").perform(context)
    if sim_mode not in ("kinematic", "dynamic"):
        raise RuntimeError(f"sim_mode must be kinematic or dynamic, got {sim_mode!r}")
    sim_params = []
    if sim == "true":
        # The simulated cell (issue 15): the executor publishes /clock and ~/contacts.
        cell = "laser_bpillar" if robot == "laser_cutter" else "irb6660_plate"
        sim_params = [
            "-p", "hardware:=sim",
            "-p", f"sim_cell:={os.path.join(urdf_dir, 'cells', cell + '.yaml')}",
            "-p", f"sim_mode:={sim_mode}",
        ]
    binary = os.path.join(root, "target", profile, "trajectory_executor")
    if not os.path.exists(binary):
        raise RuntimeError(f"{binary} not found: run 'cargo build --{profile} --workspace' in {root}")
    executor = ExecuteProcess(
        name="trajectory_executor",
        output="screen",
        cmd=[
            binary,
            "--ros-args",
            "-r", f"__ns:={namespace}",
            "--params-file", params,
            "-p", f"urdf_file:={os.path.join(urdf_dir, robot + '.urdf')}",
            "-p", f"joint_limits_file:={os.path.join(urdf_dir, robot + '_limits.yaml')}",
        ]
        + sim_params,
    )
    ns = namespace.rstrip("/")

    def planner(name, *params):
        """A planner node whose trajectories go straight to the executor."""
        planner_binary = os.path.join(root, "target", profile, name)
        if not os.path.exists(planner_binary):
            raise RuntimeError(f"{planner_binary} not found: run 'cargo build --{profile} --workspace' in {root}")
        cmd = [
            planner_binary,
            "--ros-args",
            "-r", f"__ns:={namespace}",
            "-r", f"~/joint_trajectory:={ns}/trajectory_executor/joint_trajectory",
        ]
        for p in params:
            cmd += ["-p", p]
        return ExecuteProcess(name=name, output="screen", cmd=cmd)

    nodes = [executor]
    if robot == "laser_cutter":
        # The MJTO planner (issue 3).
        nodes.append(
            planner(
                "mjto_planner",
                f"urdf_file:={os.path.join(urdf_dir, robot + '.urdf')}",
                f"joint_limits_file:={os.path.join(urdf_dir, robot + '_limits.yaml')}",
            )
        )
    if robot == "irb6660":
        # The milling planner (issue 5): the shipped cell urdf/irb6660_milling.yaml, its
        # indicator cache and policies.
        nodes.append(planner("milling_planner"))
    # The G-code planner (issue 14) for the robot.
    machine = "laser-cutter" if robot == "laser_cutter" else "irb6660"
    nodes.append(planner("gcode_planner", f"machine:={machine}"))
    return nodes


def generate_launch_description():
    return LaunchDescription(
        [
            DeclareLaunchArgument("robot", default_value="laser_cutter"),
            DeclareLaunchArgument("namespace", default_value="/"),
            DeclareLaunchArgument("params_file", default_value=""),
            DeclareLaunchArgument("kerf_root", default_value=""),
            DeclareLaunchArgument("profile", default_value="release"),
            DeclareLaunchArgument("sim", default_value="false"),
            DeclareLaunchArgument("sim_mode", default_value="kinematic"),
            OpaqueFunction(function=_nodes),
        ]
    )
