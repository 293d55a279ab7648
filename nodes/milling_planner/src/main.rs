//! `milling_planner` binary: `milling_planner [--ros-args -p queue_depth:=… -p cell_file:=…
//! -r ~/joint_trajectory:=/trajectory_executor/joint_trajectory]`.

fn main() -> std::process::ExitCode {
    kerf_ros::planner::node_main("milling_planner", kerf_milling_planner::run)
}
