//! `kerf`: the command-line tool of kerf.
//!
//! * `kerf launch` starts every kerf node that exists, each with its own Context, in one
//!   process (today: the trajectory executor).
//! * `kerf echo TOPIC` prints a kerf or standard topic as YAML, with no ROS install.

mod echo;
mod launch;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

#[derive(Parser, Debug)]
#[command(
    name = "kerf",
    version,
    about = "ROS 2 motion planning and execution for robotic laser cutting and milling"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Start the kerf nodes in this process (Ctrl-C stops them).
    Launch(launch::LaunchArgs),
    /// Print the messages of a topic as YAML.
    Echo(echo::EchoArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Launch(a) => launch::run(a),
        Command::Echo(a) => echo::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("kerf: {e}");
            ExitCode::FAILURE
        }
    }
}
