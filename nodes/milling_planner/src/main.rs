//! `milling_planner` binary: `milling_planner [--ros-args -p queue_depth:=… -p cell_file:=…
//! -r ~/joint_trajectory:=/trajectory_executor/joint_trajectory]`.

use std::process::ExitCode;

use kerf_ros::{shutdown, RosArgs, RosEnv, StopToken};

fn main() -> ExitCode {
    let result = (|| -> Result<(), String> {
        let args = RosArgs::parse(std::env::args().skip(1)).map_err(|e| e.to_string())?;
        if let Some(extra) = args.other.first() {
            return Err(format!(
                "unexpected argument {extra:?}; ROS arguments go after --ros-args"
            ));
        }
        let env = RosEnv::from_env().map_err(|e| e.to_string())?;
        shutdown::install_handler()?;
        kerf_milling_planner::run(&args, &env, StopToken::new()).map_err(|e| e.to_string())
    })();
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("milling_planner: {e}");
            ExitCode::FAILURE
        }
    }
}
