//! G-code to a joint trajectory for either kerf machine (issue 14, item 5):
//! the program read into runs ([`runs`]), each smoothed within a tolerance
//! and timed by `kerf_toolpath`, mapped to the joints of the laser cutter
//! over a flat sheet or the IRB 6660 on a milling plane ([`machine`]), with
//! points dense enough that the executor's own interpolation keeps the tool
//! within the tolerance ([`knots`]), checked as the executor runs it
//! ([`plan`]).

pub mod error;
pub mod knots;
pub mod machine;
mod memory;
pub mod network;
pub mod plan;
pub mod preprocess;
pub mod request;
pub mod runs;
pub mod settings;
pub mod timed;

pub use error::GcodePlanError;
/// The reader's error, as carried by [`GcodePlanError::Program`].
pub use kerf_gcode::GcodeError;
pub use machine::{JointBounds, LaserSheet, Machine, MillingPlane, DOF};
pub use network::{committed_network, load_network, NETWORK_FILE};
pub use plan::{plan_program, plan_program_with, GcodePlan, RunReport, ToolEvent};
pub use request::{
    corner_method, feed_method, open_program, plan_request, plan_request_reading,
    plan_request_within, GcodeRequest, LimitOverrides, MachineBase, MachineKind, ProgramSource,
    Range, DRLS_NET, FEED_METHODS, MAX_PROGRAM_BYTES, METHODS, RANGES,
};
pub use runs::{read_steps, read_steps_within, Reading, Run, RunKind, Step};
pub use settings::PlanSettings;
pub use timed::{PathMotion, TimedRun};
