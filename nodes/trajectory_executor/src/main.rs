//! `trajectory_executor` binary: `trajectory_executor --ros-args -p urdf_file:=… -p joint_limits_file:=…`.

use std::process::ExitCode;

use kerf_ros::{shutdown, RosArgs, RosEnv, StopToken};

fn main() -> ExitCode {
    let result = (|| -> Result<(), String> {
        let args = RosArgs::parse(std::env::args().skip(1)).map_err(|e| e.to_string())?;
        let env = RosEnv::from_env().map_err(|e| e.to_string())?;
        kerf_ros::memory::release_large_allocations();
        shutdown::install_handler()?;
        kerf_trajectory_executor::run(&args, &env, StopToken::new()).map_err(|e| e.to_string())
    })();
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("trajectory_executor: {e}");
            ExitCode::FAILURE
        }
    }
}
