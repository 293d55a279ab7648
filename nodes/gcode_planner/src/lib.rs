//! The kerf G-code planner node (issue 14): `kerf_msgs/msg/GcodeRequest` (or its YAML text
//! form) in, `kerf_msgs/msg/GcodePlan` and the machine's joint trajectory out (planner:
//! `kerf_gcodeplan`: the program read, its corners smoothed within the tolerance, its feed
//! planned under the path's limits, the joints checked as the executor runs them).
//!
//! | endpoint | type | |
//! |---|---|---|
//! | `~/gcode_request` | `kerf_msgs/msg/GcodeRequest` | input (reliable, keep-last 10) |
//! | `~/gcode_request_text` | `std_msgs/msg/String` | input: YAML of the `kerf_gcodeplan::GcodeRequest` schema ([`text`]) |
//! | `~/gcode_plan` | `kerf_msgs/msg/GcodePlan` | one answer per request (reliable, transient-local, keep-last 10) |
//! | `~/gcode_plan_text` | `std_msgs/msg/String` | the same answer as YAML |
//! | `~/joint_trajectory` | `trajectory_msgs/msg/JointTrajectory` | the trajectory, on success only (reliable, volatile) |
//!
//! Parameters ([`NodeConfig::from_params`]): `machine`, `queue_depth`, `plan_timeout`,
//! `allowed_file_roots`, `collision_cell_file` (irb6660), and the harness's `approach.*` and
//! `retract.*`.
//!
//! # How to run it
//!
//! ```sh
//! # the laser cutter's executor and this node, the trajectory remapped to the executor
//! ROS_DOMAIN_ID=42 ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST cargo run --release -- launch \
//!   --robot laser_cutter --with-planner
//! # a program (second terminal, same environment)
//! ros2 topic pub --once -w 1 /gcode_planner/gcode_request_text std_msgs/msg/String \
//!   "{data: '{request_id: part-1, program: \"M3\nG1 X20 F3000\nG1 Y20\nM5\n\"}'}"
//! cargo run --release -- echo /gcode_planner/gcode_plan_text --transient-local -n 1
//! ```
//!
//! # Where a plan starts (issue 27)
//! A request with a start (`start` given, `current`, or left out while the node receives the
//! robot's `joint_states`) is framed by the harness: the trajectory starts at that
//! configuration, approaches the program's first point backed off along the tool axis, leads
//! in along it, runs the program unchanged and leads out along the tool axis. The approach
//! keeps `approach.clearance` (0.01 m) from the machine's surroundings ([`surroundings`]): on
//! the laser cutter the head against the sheet under the program ([`sheet`]: the program's
//! plane at its origin, its extent plus 5 cm; a G-code request names no workpiece mesh), on the
//! IRB 6660 the robot and spindle against the collision cell (`collision_cell_file`, the
//! milling planner's). A start inside that clearance, or no clear route, is answered
//! NO_APPROACH naming the obstacle; a start of the wrong length INVALID_REQUEST naming
//! `start_positions`. The answer's `stretches` say where the program starts and ends on the
//! trajectory (its tool event times are the program's, from `process_start_time`).
//!
//! # Behaviour
//! The node is a [`kerf_ros::planner::PlanningService`] ([`GcodeService`]) run by the
//! planner-node harness: requests are answered in arrival order, each by exactly one
//! `GcodePlan` with its `request_id`; a request that cannot be read, converted or validated,
//! a planner error (status from [`convert::status_of`], the program line in `error_line`)
//! and a planner panic are all answered; a full queue answers QUEUE_FULL. The trajectory's
//! first point (time 0) is the plan's start, at rest (above; without one, the tool at the
//! program's start: move the robot there first). A program file (`program_uri`) must lie under `allowed_file_roots`, be a regular
//! file of at most [`kerf_gcodeplan::MAX_PROGRAM_BYTES`] (a FIFO, device or directory is
//! refused before it is opened) and is read as a stream. Every plan runs under the harness's
//! time and memory budget: the planner checks both in every loop that grows with the program
//! and answers TIMEOUT or RESOURCE_LIMIT naming the stage or what grew.

pub mod config;
pub mod convert;
pub mod sheet;
pub mod surroundings;
pub mod text;

use std::time::Duration;

use kerf_budget::Budget;
use kerf_executor::JointLimits;
use kerf_gcodeplan::{
    plan_request_within, GcodePlanError, GcodeRequest, MachineBase, ProgramSource,
};
use kerf_msgs::msg::{self, GcodePlan};
use kerf_robot::roots::AllowedRoots;
use kerf_ros::{
    planner::{self, AnswerKey, AnswerSize, Failure, PlanningService, Topics},
    RosArgs, RosEnv, StopToken,
};
use surroundings::MachineSurroundings;

pub use config::{NodeConfig, KNOWN_PARAMS};

/// Default node name.
pub const DEFAULT_NAME: &str = "gcode_planner";

/// What the service's set-up can fail on.
#[derive(Debug, thiserror::Error)]
pub enum SetupError {
    /// The machine could not be loaded.
    #[error("machine: {0}")]
    Machine(GcodePlanError),
}

/// Why the node could not start: plumbing, a parameter, or [`SetupError`].
pub type NodeError = planner::NodeError<SetupError>;

/// Runs the node until its stop token (or Ctrl-C) stops it.
///
/// # Returns
/// `Ok` after a clean shutdown; an error if the node could not start. Request errors never
/// end the node.
pub fn run(args: &RosArgs, env: &RosEnv, stop: StopToken) -> Result<(), NodeError> {
    planner::run(DEFAULT_NAME, KNOWN_PARAMS, args, env, stop, |node| {
        let cfg = NodeConfig::from_params(node.params())?;
        let harness = cfg.harness;
        let service = GcodeService::with_surroundings(cfg.machine, cfg.surroundings)?
            .with_allowed_roots(cfg.allowed_roots);
        Ok((service, harness))
    })
}

/// The G-code planner as a planning service.
pub struct GcodeService {
    machine: MachineBase,
    limits: Vec<JointLimits>,
    approach_limits: Vec<kerf_approach::JointLimit>,
    surroundings: MachineSurroundings,
    allowed_roots: AllowedRoots,
}

impl GcodeService {
    /// A service planning for `machine`, its approaches kept clear of the machine's shipped
    /// surroundings ([`MachineSurroundings::load`]).
    ///
    /// # Errors
    /// [`NodeError::Config`] (`collision_cell_file`) when they do not load; as
    /// [`GcodeService::with_surroundings`].
    pub fn new(machine: MachineBase) -> Result<Self, NodeError> {
        let surroundings = MachineSurroundings::load(&machine, None)
            .map_err(|reason| NodeError::config("collision_cell_file", reason))?;
        Self::with_surroundings(machine, surroundings)
    }

    /// A service planning for `machine`; the approach and retract of every plan with a start
    /// keep clear of `surroundings` (issue 27).
    ///
    /// # Errors
    /// [`NodeError::Config`] (`machine`) when a joint has no acceleration limit (the
    /// executability check needs it) or no jerk limit (the approach needs it).
    pub fn with_surroundings(
        machine: MachineBase,
        surroundings: MachineSurroundings,
    ) -> Result<Self, NodeError> {
        let limits = machine
            .robot()
            .executor_limits()
            .map_err(|e| NodeError::config("machine", e.to_string()))?;
        let approach_limits = kerf_cell::approach_limits(machine.robot())
            .map_err(|e| NodeError::config("machine", e.to_string()))?;
        Ok(Self {
            machine,
            limits,
            approach_limits,
            surroundings,
            allowed_roots: AllowedRoots::any(),
        })
    }

    /// Requests' program files must resolve under `roots`.
    pub fn with_allowed_roots(mut self, roots: AllowedRoots) -> Self {
        self.allowed_roots = roots;
        self
    }

    /// The machine's name.
    fn machine_name(&self) -> &'static str {
        self.machine.kind().name()
    }

    /// Checks the request before it is queued: its settings, its machine, its program file
    /// against the allowed roots.
    fn check(&self, request: GcodeRequest) -> Result<GcodeRequest, Box<GcodePlan>> {
        let fail =
            |e: GcodePlanError| Box::new(convert::error_to_msg(&request, self.machine_name(), &e));
        request.settings().map_err(fail)?;
        self.machine.place(&request).map_err(fail)?;
        if let ProgramSource::File(path) = request.source().map_err(fail)? {
            let bad = |reason: String| {
                fail(GcodePlanError::InvalidRequest {
                    field: format!("program_uri {}", path.display()),
                    reason,
                })
            };
            self.allowed_roots.check(&path).map_err(bad)?;
            // A FIFO, device or directory, or a file over the cap, is answered at once, before
            // it is queued; the planner checks it again when it opens it (O_NONBLOCK).
            kerf_robot::file::check_regular_file(&path, kerf_gcodeplan::MAX_PROGRAM_BYTES)
                .map_err(|reason| {
                    bad(format!(
                        "{reason} (programs are read from regular files of at most {} bytes)",
                        kerf_gcodeplan::MAX_PROGRAM_BYTES
                    ))
                })?;
        }
        Ok(request)
    }
}

impl PlanningService for GcodeService {
    type RequestMsg = msg::GcodeRequest;
    type Request = GcodeRequest;
    type Answer = GcodePlan;

    fn topics(&self) -> Topics {
        Topics::new("gcode")
    }

    fn request_from_msg(&self, m: &msg::GcodeRequest) -> Result<GcodeRequest, Box<GcodePlan>> {
        let request = convert::request_from_msg(m).map_err(|e| {
            Box::new(msg::GcodePlan {
                error_line: convert::error_line(&e),
                ..convert::failure_msg(
                    &m.request_id,
                    self.machine_name(),
                    &m.method,
                    convert::status_of(&e),
                    e.to_string(),
                )
            })
        })?;
        self.check(request)
    }

    fn msg_key(&self, m: &msg::GcodeRequest) -> AnswerKey {
        AnswerKey {
            request_id: m.request_id.clone(),
            label: m.method.clone(),
        }
    }

    fn request_from_text(&self, text: &str) -> Result<GcodeRequest, Box<GcodePlan>> {
        let request = text::parse_request(text).map_err(|e| {
            Box::new(convert::failure_msg(
                &e.request_id,
                self.machine_name(),
                &e.planner,
                convert::status_of(&e.error),
                e.error.to_string(),
            ))
        })?;
        self.check(request)
    }

    fn key(&self, request: &GcodeRequest) -> AnswerKey {
        AnswerKey {
            request_id: request.request_id.clone(),
            label: convert::method_name(request),
        }
    }

    fn describe(&self, request: &GcodeRequest) -> String {
        match request.source() {
            Ok(ProgramSource::Text(t)) => format!("{} program lines", t.lines().count()),
            Ok(ProgramSource::File(p)) => format!("program {}", p.display()),
            Err(_) => "no program".to_string(),
        }
    }

    /// Not known before planning (the points depend on the program's runs and the
    /// tolerance): the plan itself stops at the answer's most points
    /// ([`planner::max_answer_points`], TooManyPoints → INVALID_REQUEST).
    fn answer_size(&self, _: &GcodeRequest) -> Option<AnswerSize> {
        None
    }

    fn requested_budget(&self, request: &GcodeRequest) -> Option<Duration> {
        request.time_limit().ok().flatten()
    }

    fn plan(&self, request: GcodeRequest, budget: &Budget) -> GcodePlan {
        // At most what an answer carries: a longer plan is refused as soon as it is known.
        let max_points = planner::max_answer_points(self.limits.len());
        match plan_request_within(&request, &self.machine, budget, Some(max_points)) {
            Ok(plan) => match convert::plan_to_msg(&request, &plan) {
                Ok(m) => m,
                Err(reason) => convert::failure_msg(
                    &request.request_id,
                    self.machine_name(),
                    &convert::method_name(&request),
                    msg::GcodePlan::INTERNAL_ERROR,
                    reason,
                ),
            },
            Err(e) => convert::error_to_msg(&request, self.machine_name(), &e),
        }
    }

    /// Unreadable samples, budgets over `plan_timeout`, bad numbers and unusable starts are
    /// INVALID_REQUEST; no collision-free approach or retract NO_APPROACH; busy QUEUE_FULL;
    /// stopped, canceled, panicked and not executable INTERNAL_ERROR.
    fn failure(&self, key: &AnswerKey, failure: Failure, message: String) -> GcodePlan {
        let code = match failure {
            Failure::Unreadable
            | Failure::OverBudget
            | Failure::TooLarge
            | Failure::BadNumber
            | Failure::BadStart => msg::GcodePlan::INVALID_REQUEST,
            Failure::NoApproach => msg::GcodePlan::NO_APPROACH,
            Failure::Busy => msg::GcodePlan::QUEUE_FULL,
            Failure::Timeout => msg::GcodePlan::TIMEOUT,
            Failure::ResourceLimit => msg::GcodePlan::RESOURCE_LIMIT,
            // No CANCELED status in GcodePlan: answered like a stop (the message says so).
            Failure::Stopped | Failure::Canceled | Failure::Panicked | Failure::NotExecutable => {
                msg::GcodePlan::INTERNAL_ERROR
            }
        };
        convert::failure_msg(
            &key.request_id,
            self.machine_name(),
            &key.label,
            code,
            message,
        )
    }

    fn joint_limits(&self) -> &[JointLimits] {
        &self.limits
    }

    fn start_of(&self, request: &GcodeRequest) -> kerf_approach::StartSpec {
        request.start.clone()
    }

    fn approach_limits(&self) -> &[kerf_approach::JointLimit] {
        &self.approach_limits
    }

    /// The machine's surroundings for `request` ([`MachineSurroundings::for_request`]: the
    /// sheet under the program, or the IRB 6660's collision cell); a program the sheet cannot
    /// be read from is answered with the planner's error.
    fn surroundings(
        &self,
        request: &GcodeRequest,
    ) -> Result<Box<dyn kerf_approach::Surroundings>, Box<GcodePlan>> {
        self.surroundings
            .for_request(&self.approach_limits, request)
            .map_err(|e| Box::new(convert::error_to_msg(request, self.machine_name(), &e)))
    }

    fn startup_note(&self) -> String {
        format!(
            "machine: {}; approach surroundings: {}",
            self.machine_name(),
            self.surroundings.source()
        )
    }
}
