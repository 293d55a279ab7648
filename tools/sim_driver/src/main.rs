#![doc = include_str!("help.md")]

mod action;
mod cli;
mod command;
mod delay;
mod driver;
mod env;
mod faults;
mod goals;
mod node;
mod noise;
mod serve;
mod trajectory;

use std::{
    process::ExitCode,
    sync::{
        atomic::{AtomicBool, Ordering},
        Arc,
    },
};

fn main() -> ExitCode {
    let cfg = match cli::parse() {
        Ok(c) => c,
        // Prints the error (exit code 2) or the help (0).
        Err(e) => e.exit(),
    };
    let env = match env::RosEnv::from_env() {
        Ok(e) => e,
        Err(e) => {
            serve::log(&format!("error: {e}"));
            return ExitCode::from(2);
        }
    };
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    if let Err(e) = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst)) {
        serve::log(&format!("error: cannot handle SIGINT/SIGTERM: {e}"));
        return ExitCode::from(1);
    }
    let dds = match node::Dds::open(&cfg, &env) {
        Ok(d) => d,
        Err(e) => {
            serve::log(&format!("error: {e}"));
            return ExitCode::from(1);
        }
    };
    let c = serve::serve(&cfg, &dds.endpoints, &stop);
    drop(dds);
    serve::log(&format!(
        "stopped: {} states published; commands: {} applied, {} malformed, {} during a goal; \
         goals: {} accepted, {} rejected",
        c.states,
        c.commands,
        c.invalid_commands,
        c.commands_during_goal,
        c.goals_accepted,
        c.goals_rejected
    ));
    ExitCode::SUCCESS
}
