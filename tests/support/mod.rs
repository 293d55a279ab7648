//! Shared by the end-to-end tests and the DDS benches: nodes in this process on a
//! loopback-only domain (an executor for a shipped robot, a planner node, client nodes), and
//! the checks the tests make of what they publish.
//!
//! * [`nodes`]: the environment, client nodes, running a node, discovery.
//! * [`driver`]: the simulated robot driver (`tools/sim_driver`) as a child process.
//! * [`executor`]: the trajectory executor for a shipped robot.
//! * [`motion`]: joint states and trajectory statuses against a plan.
//! * [`planner`]: a planner node and its client ([`PlannerClient`]), answers ([`expect`]).
//! * [`take`], [`scratch`]: reading a subscription with a deadline, scratch directories.
//! * [`requests`]: request files as request messages.
//! * [`stubborn`]: a planning service whose plans never check their budget.
//! * [`Killed`], [`interrupt`], [`assert_clean_exit`]: `kerf` child processes.

use std::time::Duration;

#[allow(dead_code)] // not every crate including this module needs it
pub mod driver;
#[allow(dead_code)] // not every crate including this module needs it
mod executor;
#[allow(dead_code)] // the moving-robot checks; not every crate including this module needs them
mod motion;
#[allow(dead_code)] // not every crate including this module needs it
mod nodes;
#[allow(dead_code)] // the planner tests' client; not every crate including this module needs it
pub mod planner;
#[allow(dead_code)] // not every crate including this module needs it
mod process;
#[allow(dead_code)] // not every crate including this module needs it
pub mod requests;
#[allow(dead_code)] // not every crate including this module needs it
pub mod rss;
#[allow(dead_code)] // not every crate including this module needs it
mod scratch;
#[allow(dead_code)] // the planning-action tests and the cancel bench
pub mod stubborn;
#[allow(dead_code)] // not every crate including this module needs it
mod take;

#[allow(unused_imports)] // not every crate including this module needs all of them
pub use {
    executor::{initial_positions, spawn_executor, spawn_robot_executor, stop_and_join},
    motion::{
        assert_rests_at, assert_starts_at, drain_statuses, executor_input, largest_step, max_diff,
        min_jerk, off_plan, watch_cell, watch_executor,
    },
    nodes::{client_node, loopback, spawn_node, wait_for_writer},
    planner::{expect, PlannerClient},
    process::{assert_clean_exit, interrupt, status_kib, Killed, Lines},
    scratch::scratch,
    take::{take, take_newest},
};

/// Waiting for what needs no planning: matching, a joint state, the answer to a bad request.
#[allow(dead_code)] // not every crate including this module needs it
pub const QUICK: Duration = Duration::from_secs(30);
