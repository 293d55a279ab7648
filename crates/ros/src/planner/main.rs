//! [`node_main`]: the `main` of every kerf node binary.

use std::process::ExitCode;

use crate::{shutdown, RosArgs, RosEnv, StopToken};

/// Parses the command line (`[--ros-args …]`), reads the ROS environment, installs the Ctrl-C
/// / SIGTERM handler and runs the node.
///
/// # Arguments
/// * `program` — the binary's name, prefixed to errors on stderr.
/// * `run` — the node's `run(args, env, stop)`.
///
/// # Returns
/// Success after a clean shutdown; failure (after printing `program: reason`) when the
/// arguments, the environment or the node's start-up are refused.
pub fn node_main<E: std::fmt::Display>(
    program: &str,
    run: impl FnOnce(&RosArgs, &RosEnv, StopToken) -> Result<(), E>,
) -> ExitCode {
    let result = (|| -> Result<(), String> {
        let args = RosArgs::parse(std::env::args().skip(1)).map_err(|e| e.to_string())?;
        if let Some(extra) = args.other.first() {
            return Err(format!(
                "unexpected argument {extra:?}; ROS arguments go after --ros-args"
            ));
        }
        let env = RosEnv::from_env().map_err(|e| e.to_string())?;
        crate::memory::release_large_allocations();
        shutdown::install_handler()?;
        run(&args, &env, StopToken::new()).map_err(|e| e.to_string())
    })();
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{program}: {e}");
            ExitCode::FAILURE
        }
    }
}
