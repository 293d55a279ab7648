//! `mjto_planner` binary: `mjto_planner [--ros-args -p urdf_file:=… -p joint_limits_file:=…
//! -r ~/joint_trajectory:=/trajectory_executor/joint_trajectory]`.

fn main() -> std::process::ExitCode {
    kerf_ros::planner::node_main("mjto_planner", kerf_mjto_planner::run)
}
