//! `gcode_planner` binary: `gcode_planner [--ros-args -p machine:=irb6660 -p queue_depth:=…
//! -r ~/joint_trajectory:=/trajectory_executor/joint_trajectory]`.

fn main() -> std::process::ExitCode {
    kerf_ros::planner::node_main("gcode_planner", kerf_gcode_planner::run)
}
