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
pub mod plan;
pub mod request;
pub mod runs;
pub mod settings;
pub mod timed;

pub use error::GcodePlanError;
pub use machine::{JointBounds, LaserSheet, Machine, MillingPlane, DOF};
pub use plan::{plan_program, GcodePlan, RunReport, ToolEvent};
pub use request::{
    corner_method, feed_method, plan_request, plan_request_within, GcodeRequest, LimitOverrides,
    MachineBase, MachineKind, ProgramSource, FEED_METHODS, METHODS,
};
pub use runs::{read_steps, Reading, Run, RunKind, Step};
pub use settings::PlanSettings;
pub use timed::{PathMotion, TimedRun};
