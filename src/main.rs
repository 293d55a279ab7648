//! `kerf`: the command-line tool of kerf.
//!
//! * `kerf launch` starts every kerf node that exists, each with its own Context, in one
//!   process (today: the trajectory executor).
//!
//! Every failure exits with code 2 and a message on stderr; a closed output pipe ends a
//! command quietly (SIGPIPE).
//! * `kerf echo TOPIC` prints a kerf or standard topic as YAML, with no ROS install.
//! * `kerf pub TOPIC FILE|-` publishes one message written as YAML or JSON, with no ROS
//!   install.
//! * `kerf plan cut --request FILE` plans a laser cut offline (exit code 2 on failure).
//! * `kerf plan mill --request FILE` plans a milling path offline (issue 5; exit code 2 on
//!   failure).
//! * `kerf train mill --out FILE` trains the DDPG milling policy of seed 004 (exit code 2 on
//!   failure).
//! * `kerf demo cut|mill [--mode kinematic|dynamic]` runs a plan on the simulated cell in this
//!   process: request → planner → executor → cell (issue 15; exit code 2 unless the goal
//!   succeeds).
//! * `kerf lobes --segment N --g RAD` draws the stability lobes and the feed × speed chatter
//!   map of a milling state (issue 4) and prints a table (exit code 2 on failure).

mod bounds;
mod cli_model;
mod demo;
mod echo;
mod input;
mod interrupt;
mod launch;
mod lobes;
mod output_paths;
mod plan_cut;
mod plan_gcode;
mod plan_mill;
mod plots;
mod publish;
mod step;
mod topic_types;
mod train_mill;

use std::process::ExitCode;

use clap::{CommandFactory, Parser, Subcommand};

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
    /// Publish one message written as YAML or JSON (`kerf pub TOPIC FILE`, `-` for stdin).
    Pub(publish::PubArgs),
    /// Plan offline, without ROS (`kerf plan cut --request cut.yaml`,
    /// `kerf plan mill --request mill.yaml`).
    Plan(plan_cut::PlanArgs),
    /// Stability lobes and feed map of a milling state (`kerf lobes --segment 50 --g 0`).
    Lobes(lobes::LobesArgs),
    /// Run a plan on the simulated cell in this process: `kerf demo cut`, `kerf demo mill`
    /// (request → planner → executor → cell; prints time, tracking error, contacts, final
    /// state).
    Demo(demo::DemoArgs),
    /// Step through reference points offline, seed 002 (`kerf step points.txt --out run.json`):
    /// prints steps, time and accuracy per point, writes the per-step trajectory as JSON.
    Step(step::StepArgs),
    /// Train a planner's policy (`kerf train mill --out policy.safetensors`).
    Train(Box<train_mill::TrainArgs>),
    /// Every argument of every command as JSON lines (for the bounds test).
    #[command(hide = true, name = "cli-model")]
    CliModel,
}

/// Exit code of every `kerf` failure, with a message on stderr (clap's usage errors exit with
/// 2 too).
pub const EXIT_FAILURE: u8 = 2;

fn main() -> ExitCode {
    restore_default_sigpipe();
    let cli = Cli::parse();
    // The offline commands end on Ctrl-C with exit code 130 and a line saying so; the DDS
    // commands stop their nodes through kerf_ros's handler.
    let offline = match &cli.command {
        Command::Plan(_) => Some("plan"),
        Command::Lobes(_) => Some("lobes"),
        Command::Demo(_) => Some("demo"),
        Command::Train(_) => Some("train"),
        Command::Step(_) => Some("step"),
        _ => None,
    };
    if let Some(name) = offline {
        if let Err(e) = interrupt::exit_on_sigint(name) {
            eprintln!("kerf: {e}");
            return ExitCode::from(EXIT_FAILURE);
        }
    }
    let result = match cli.command {
        Command::Launch(a) => {
            // The nodes' large buffers go back to the system when freed (kerf_ros::memory).
            kerf_ros::memory::release_large_allocations();
            launch::run(a)
        }
        Command::Echo(a) => echo::run(a),
        Command::Pub(a) => publish::run(a),
        Command::Plan(a) => plan_cut::run(a),
        Command::Lobes(a) => lobes::run(a),
        Command::Train(a) => train_mill::run(*a),
        Command::Demo(a) => demo::run(a),
        Command::Step(a) => step::run(a),
        Command::CliModel => {
            print!("{}", cli_model::model(&Cli::command()));
            Ok(())
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("kerf: {e}");
            ExitCode::from(EXIT_FAILURE)
        }
    }
}

/// A closed pipe ends kerf quietly, as it ends `cat` or `grep` (`kerf echo … | head`): the
/// Rust runtime ignores SIGPIPE, so a write to a closed pipe would fail and `print!` panic;
/// with the default disposition the process ends by SIGPIPE at that write instead. DDS uses
/// UDP, which never raises SIGPIPE.
fn restore_default_sigpipe() {
    // SAFETY: signal(2) with SIG_DFL for SIGPIPE, at start-up before any thread exists; it
    // changes no memory of this process.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}
