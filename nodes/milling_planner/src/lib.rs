//! The kerf milling planner node (issue 5): `kerf_msgs/msg/MillRequest` (or its YAML text
//! form) in, `kerf_msgs/msg/MillPlan` and the IRB-6660 joint trajectory out (planner:
//! `kerf_millplan`: spindle speed, feed and redundancy angle per path segment under the
//! chatter constraint of seed 004, by a DDPG policy, the fixed-g ablation, the DP optimum or
//! the naive baseline).
//!
//! | endpoint | type | |
//! |---|---|---|
//! | `~/mill_request` | `kerf_msgs/msg/MillRequest` | input (reliable, keep-last 10) |
//! | `~/mill_request_text` | `std_msgs/msg/String` | input: YAML of the `kerf_millplan::MillRequest` schema ([`text`]) |
//! | `~/mill_plan` | `kerf_msgs/msg/MillPlan` | one answer per request (reliable, transient-local, keep-last 10) |
//! | `~/mill_plan_text` | `std_msgs/msg/String` | the same answer as YAML |
//! | `~/joint_trajectory` | `trajectory_msgs/msg/JointTrajectory` | the trajectory as executed (from rest to rest, time-scaled to the joint limits), on success only (reliable, volatile) |
//!
//! Parameters ([`NodeConfig::from_params`]): `cell_file`, `indicator_cache_file`,
//! `ddpg_policy_file`, `fixed_g_policy_file`, `indicator_source`, `eval_threads`,
//! `queue_depth`, `collision_cell_file`, and the harness's `approach.*` and `retract.*`.
//!
//! # How to run it
//!
//! ```sh
//! # the IRB 6660 executor and this node, the trajectory remapped to the executor's input
//! ROS_DOMAIN_ID=42 ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST cargo run --release -- launch \
//!   --robot irb6660 --with-planner \
//!   --ros-args -r milling_planner:~/joint_trajectory:=/trajectory_executor/joint_trajectory
//! # a request (second terminal, same environment)
//! ros2 topic pub --once -w 1 /milling_planner/mill_request_text std_msgs/msg/String \
//!   "{data: '{request_id: job-1, planner: naive, points: [[1.4, -0.3, 1.7], [1.6, -0.1, 1.7], [1.8, 0.1, 1.7], [2.1, 0.3, 1.7]]}'}"
//! cargo run --release -- echo /milling_planner/mill_plan_text --transient-local -n 1
//! ```
//!
//! The node alone: `cargo run --release -p kerf_milling_planner -- --ros-args
//! -p queue_depth:=4`.
//!
//! # Behaviour
//! The trajectory is the plan as the robot runs it ([`kerf_millplan::Executed`], published as it
//! is by [`convert::trajectory_msg`]): the planner's N + 2 points (path start, the N segment
//! midpoints, path end, and more where the path tolerance needs them) with their joint
//! positions, velocities and accelerations, from rest to rest (zero velocity at the path start
//! and end, the first and the last half-segment ramps over twice their planned time),
//! time-scaled by the planner so that its quintic Hermite interpolation
//! stays within every joint's velocity and acceleration limit: an interval is slowed where
//! the planned feeds ask too much of a joint, never sped up. The `MillPlan` segments and
//! totals are those of that executed plan (the feeds run, |μ|max re-evaluated at them;
//! `machining_time` is the trajectory's duration); its message also gives the values at the
//! planned feeds. Its first point (time 0) is the plan's start (below; without one, the robot
//! at the start of the path) and its `header.stamp` is zero, so an executor starts it on
//! receipt and accepts it only when its commanded position is that first point (within its
//! `start_tolerance`). The trajectory topic is volatile on purpose: a
//! restarted executor must not receive an old cut.
//!
//! # Where a plan starts (issue 27)
//! A request with a start (`start` given, `current`, or left out while the node receives the
//! robot's `joint_states`) is framed by the harness: the trajectory starts at that
//! configuration, approaches the path's first point backed off along the tool axis (direct, or
//! via `approach.safe_pose`), leads in along the tool axis, mills the path unchanged, and leads
//! out along the tool axis (`retract.distance`). The approach keeps `approach.clearance` (0.01 m)
//! from every object of the collision cell (`collision_cell_file`: the shipped
//! `urdf/cells/irb6660_plate.yaml`, the stock under the path and its fixture plate), the robot's
//! links, spindle and cutter measured by exact distance ([`kerf_cell::CellSurroundings`]); the
//! lead moves leave the cutter's engagement in the stock out. A start inside that clearance,
//! or no clear route, is answered NO_APPROACH naming the object; a start of the wrong length or
//! outside the limits INVALID_REQUEST naming `start_positions`. The answer's `stretches` say
//! where the milling starts and ends on the trajectory (its segment times are the process's).
//!
//! The node is a [`kerf_ros::planner::PlanningService`] ([`MillService`]) run by the
//! planner-node harness [`kerf_ros::planner::run`]: request → convert and validate → plan
//! (worker thread) → executability check (the trajectory executor's own validation, a pure
//! function of the trajectory and the robot model: a plan it would refuse is answered
//! INTERNAL_ERROR and its trajectory is not published) → publish.
//!
//! Planning takes from a fraction of a second (a policy) to seconds (`dp`), so it runs on a
//! worker thread ([`kerf_ros::Worker`]) and the node keeps reading requests meanwhile.
//! Requests are answered in arrival order, each by exactly one `MillPlan` with its
//! `request_id`: a request that cannot be read, converted or validated, a planner error
//! (status from [`kerf_millplan::status_of`]) and a planner panic (INTERNAL_ERROR) are all
//! answered with their status and message. When `queue_depth` requests are waiting or being
//! planned, a new valid request is answered at once with status QUEUE_FULL, and a new invalid
//! one at once with its own status. When the node stops, the plan in progress is finished and
//! published and queued requests are answered INTERNAL_ERROR without planning.

pub mod config;
pub mod convert;
pub mod text;

use std::path::PathBuf;

use std::time::Duration;

use kerf_budget::Budget;
use kerf_cell::CellSurroundings;
use kerf_executor::JointLimits;
use kerf_millplan::{planner::status, MillPlanError, MillPlanner, MillRequest, PlannerKind};
use kerf_msgs::msg::{self, MillPlan};
use kerf_robot::roots::AllowedRoots;
use kerf_ros::{
    planner::AnswerSize,
    planner::{self, AnswerKey, Failure, PlanningService, Topics},
    RosArgs, RosEnv, StopToken,
};

pub use config::{NodeConfig, KNOWN_PARAMS};

/// Default node name.
pub const DEFAULT_NAME: &str = "milling_planner";

/// What the milling service's set-up can fail on.
#[derive(Debug, thiserror::Error)]
pub enum SetupError {
    /// The milling cell or the indicator cache could not be loaded.
    #[error("milling planner: {0}")]
    Planner(#[from] MillPlanError),
    /// The milling cell file could not be loaded.
    #[error("milling cell: {0}")]
    Cell(#[from] kerf_mill::MillError),
}

/// Why the node could not start: plumbing, a parameter, or [`SetupError`].
pub type NodeError = planner::NodeError<SetupError>;

/// The policies used by `ddpg` / `fixed_g` requests that name none.
#[derive(Debug, Clone, PartialEq)]
pub struct DefaultPolicies {
    /// For `ddpg`.
    pub ddpg: PathBuf,
    /// For `fixed_g`.
    pub fixed_g: PathBuf,
}

/// Runs the node until its stop token (or Ctrl-C) stops it.
///
/// # Returns
/// `Ok` after a clean shutdown; an error if the node could not start (bad parameter,
/// unreadable cell, DDS failure). Request errors never end the node.
pub fn run(args: &RosArgs, env: &RosEnv, stop: StopToken) -> Result<(), NodeError> {
    planner::run(DEFAULT_NAME, KNOWN_PARAMS, args, env, stop, |node| {
        let cfg = NodeConfig::from_params(node.params())?;
        let policies = DefaultPolicies {
            ddpg: cfg.ddpg_policy_file.clone(),
            fixed_g: cfg.fixed_g_policy_file.clone(),
        };
        for (kind, path) in [("ddpg", &policies.ddpg), ("fixed_g", &policies.fixed_g)] {
            if !path.is_file() {
                node.logger().warn(&format!(
                    "default {kind} policy {} does not exist (yet): {kind} requests without \
                     policy_file will be answered POLICY_ERROR until it does",
                    path.display()
                ));
            }
        }
        let note = format!(
            "cell: {}; {}; |mu|max: {}; default policies: ddpg {}, fixed_g {}",
            cfg.cell_source,
            cfg.cache_note,
            cfg.indicator_source.name(),
            policies.ddpg.display(),
            policies.fixed_g.display(),
        );
        let note = format!("{note}; collision cell: {}", cfg.surroundings.source());
        let harness = cfg.harness;
        let service =
            MillService::with_surroundings(cfg.planner, policies, note, cfg.surroundings)?
                .with_allowed_roots(cfg.allowed_roots);
        Ok((service, harness))
    })
}

/// YAML bytes of one row of a `MillPlan`'s segment table (`kerf_msgs/msg/MillSegment`): 312
/// measured on a 6 988-segment plan (`cargo bench --bench peak_rss`), rounded up.
pub const SEGMENT_TEXT_BYTES: usize = 350;

/// The milling planner as a planning service: mill requests in, `MillPlan` answers out.
pub struct MillService {
    planner: MillPlanner,
    policies: DefaultPolicies,
    limits: Vec<JointLimits>,
    approach_limits: Vec<kerf_approach::JointLimit>,
    surroundings: CellSurroundings,
    note: String,
    allowed_roots: AllowedRoots,
}

impl MillService {
    /// A service planning with `planner`, its approaches and retracts kept clear of the
    /// shipped collision cell ([`kerf_cell::IRB6660_CELL`]); see
    /// [`MillService::with_surroundings`].
    ///
    /// # Errors
    /// [`NodeError::Config`] (`collision_cell_file`) when the shipped cell does not load, and
    /// those of [`MillService::with_surroundings`].
    pub fn new(
        planner: MillPlanner,
        policies: DefaultPolicies,
        note: String,
    ) -> Result<Self, NodeError> {
        let surroundings = kerf_cell::milling_surroundings(planner.cell(), None)
            .map_err(|e| NodeError::config("collision_cell_file", e.to_string()))?;
        Self::with_surroundings(planner, policies, note, surroundings)
    }

    /// A service planning with `planner`; `policies` fill `ddpg` / `fixed_g` requests that
    /// name no policy file; `note` describes the set-up in the start-up log; `surroundings`
    /// are the robot against the cell's objects, for the approach and retract of every plan
    /// with a start (issue 27).
    ///
    /// # Errors
    /// [`NodeError::Config`] (`cell_file`) when a joint of the cell's robot has no
    /// acceleration limit (the executability check needs it) or no jerk limit (the approach
    /// needs it).
    pub fn with_surroundings(
        planner: MillPlanner,
        policies: DefaultPolicies,
        note: String,
        surroundings: CellSurroundings,
    ) -> Result<Self, NodeError> {
        let robot = planner.cell().robot();
        let limits = robot
            .executor_limits()
            .map_err(|e| NodeError::config("cell_file", e.to_string()))?;
        let approach_limits = kerf_cell::approach_limits(robot)
            .map_err(|e| NodeError::config("cell_file", e.to_string()))?;
        Ok(Self {
            planner,
            policies,
            limits,
            approach_limits,
            surroundings,
            note,
            allowed_roots: AllowedRoots::any(),
        })
    }

    /// Requests' policy files must resolve under `roots` (the `allowed_file_roots`
    /// parameter).
    pub fn with_allowed_roots(mut self, roots: AllowedRoots) -> Self {
        self.allowed_roots = roots;
        self
    }

    /// Resolves the request's policy file as the planner will
    /// ([`kerf_millplan::policy::resolve_policy_file`]: a path, `file://` or `package://kerf/`)
    /// and checks it against the allowed roots (POLICY_ERROR for a reference that does not
    /// resolve, or outside the roots).
    fn check_files(&self, request: MillRequest) -> Result<MillRequest, MillPlanError> {
        if let Some(file) = &request.policy_file {
            let path = kerf_millplan::policy::resolve_policy_file(file)?;
            self.allowed_roots
                .check(&path)
                .map_err(|reason| MillPlanError::Policy {
                    path: file.clone(),
                    reason,
                })?;
        }
        Ok(request)
    }

    /// The planner.
    pub fn planner(&self) -> &MillPlanner {
        &self.planner
    }
}

impl PlanningService for MillService {
    type RequestMsg = msg::MillRequest;
    type Request = MillRequest;
    type Answer = MillPlan;

    fn topics(&self) -> Topics {
        Topics::new("mill")
    }

    fn request_from_msg(&self, m: &msg::MillRequest) -> Result<MillRequest, Box<MillPlan>> {
        convert::request_from_msg(m)
            .and_then(|r| self.check_files(r))
            .map_err(|e| Box::new(convert::error_to_msg(&m.request_id, &m.planner, &e)))
    }

    fn msg_key(&self, m: &msg::MillRequest) -> AnswerKey {
        AnswerKey {
            request_id: m.request_id.clone(),
            label: m.planner.clone(),
        }
    }

    fn request_from_text(&self, text: &str) -> Result<MillRequest, Box<MillPlan>> {
        let r = text::parse_request(text)
            .map_err(|e| Box::new(convert::error_to_msg(&e.request_id, &e.planner, &e.error)))?;
        let (id, planner) = (r.request_id.clone(), r.planner.clone());
        self.check_files(r)
            .map_err(|e| Box::new(convert::error_to_msg(&id, &planner, &e)))
    }

    fn key(&self, request: &MillRequest) -> AnswerKey {
        AnswerKey {
            request_id: request.request_id.clone(),
            label: request.planner.clone(),
        }
    }

    fn describe(&self, request: &MillRequest) -> String {
        format!(
            "{} path points, planner {}",
            request.points.len(),
            request.planner
        )
    }

    /// One point per segment plus the two at rest at the ends, and one row of the segment
    /// table per segment.
    fn answer_size(&self, request: &MillRequest) -> Option<AnswerSize> {
        let segments = request
            .segments
            .unwrap_or_else(|| self.planner.cell().path().segments().len());
        Some(AnswerSize {
            // The executed trajectory has at least every segment's ends and midpoint (more
            // where the path tolerance needs them: the answer's own size is checked again
            // before it is published).
            points: segments.checked_mul(2)?.checked_add(1)?,
            joints: self.limits.len(),
            extra_text_bytes: segments.checked_mul(SEGMENT_TEXT_BYTES)?,
        })
    }

    fn requested_budget(&self, request: &MillRequest) -> Option<Duration> {
        // An invalid value is refused by the planner's validation (INVALID_REQUEST).
        request.time_limit().ok().flatten()
    }

    /// Plans one request with the node's default policy filled in when it names none.
    fn plan(&self, mut request: MillRequest, budget: &Budget) -> MillPlan {
        if request.policy_file.is_none() {
            let default = match PlannerKind::parse(&request.planner) {
                Ok(PlannerKind::Ddpg) => Some(&self.policies.ddpg),
                Ok(PlannerKind::FixedG) => Some(&self.policies.fixed_g),
                _ => None,
            };
            request.policy_file = default.map(|p| p.display().to_string());
        }
        match self.planner.plan_within(&request, budget) {
            Ok(out) => convert::output_to_msg(&out),
            Err(e) => convert::error_to_msg(&request.request_id, &request.planner, &e),
        }
    }

    /// Busy is QUEUE_FULL; unreadable samples, budgets over `plan_timeout` and unusable
    /// starts INVALID_REQUEST (no planner named for an unreadable sample); no collision-free
    /// approach or retract NO_APPROACH; stopped, canceled, panicked and not executable
    /// INTERNAL_ERROR.
    fn failure(&self, key: &AnswerKey, failure: Failure, message: String) -> MillPlan {
        let code = match failure {
            Failure::Unreadable
            | Failure::OverBudget
            | Failure::TooLarge
            | Failure::BadNumber
            | Failure::BadStart => status::INVALID_REQUEST,
            Failure::NoApproach => MillPlan::NO_APPROACH,
            Failure::Busy => convert::QUEUE_FULL,
            Failure::Timeout => status::TIMEOUT,
            Failure::ResourceLimit => status::RESOURCE_LIMIT,
            // No CANCELED status in MillPlan: answered like a stop (the message says so).
            Failure::Stopped | Failure::Canceled | Failure::Panicked | Failure::NotExecutable => {
                status::INTERNAL_ERROR
            }
        };
        // An unreadable sample names no planner (not even the default one).
        let planner = match failure {
            Failure::Unreadable => "",
            _ => convert::answer_planner(&key.label),
        };
        convert::failure_msg(&key.request_id, planner, code, message)
    }

    fn joint_limits(&self) -> &[JointLimits] {
        &self.limits
    }

    fn start_of(&self, request: &MillRequest) -> kerf_approach::StartSpec {
        request.start.clone()
    }

    fn approach_limits(&self) -> &[kerf_approach::JointLimit] {
        &self.approach_limits
    }

    /// The robot against the collision cell's objects ([`CellSurroundings`], the same for
    /// every request: a mill request names no workpiece of its own).
    fn surroundings(
        &self,
        _request: &MillRequest,
    ) -> Result<Box<dyn kerf_approach::Surroundings>, Box<MillPlan>> {
        Ok(Box::new(self.surroundings.clone()))
    }

    fn startup_note(&self) -> String {
        self.note.clone()
    }
}
