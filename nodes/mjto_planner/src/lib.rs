//! The kerf MJTO planner node: laser cutting requests in, minimum-jerk, collision-free joint
//! trajectories of the seed-001 machine out (planner: `kerf_mjto`).
//!
//! | endpoint | type | |
//! |---|---|---|
//! | `~/cut_request` | `kerf_msgs/msg/CutRequest` | input (reliable, keep-last 10) |
//! | `~/cut_request_text` | `std_msgs/msg/String` | input: YAML or the line format ([`text`]) |
//! | `~/cut_plan` | `kerf_msgs/msg/CutPlan` | one answer per request (reliable, transient-local, keep-last 10) |
//! | `~/cut_plan_text` | `std_msgs/msg/String` | the same answer as YAML |
//! | `~/joint_trajectory` | `trajectory_msgs/msg/JointTrajectory` | the planned trajectory, on success only (reliable, volatile) |
//!
//! Remap `~/joint_trajectory` to an executor's input to run plans
//! (`-r ~/joint_trajectory:=/trajectory_executor/joint_trajectory`). The trajectory's first
//! point (time 0) is the machine at the start of the cut and its `header.stamp` is zero, so
//! the executor starts it on receipt and accepts it only when its commanded position is that
//! first point (within its `start_tolerance`). The trajectory topic is volatile on purpose: a
//! restarted executor must not receive an old cut.
//!
//! The node is a [`kerf_ros::planner::PlanningService`] ([`CutService`]) run by the planner-node
//! harness [`kerf_ros::planner::run`]: request → convert and validate → plan (worker thread)
//! → executability check (the trajectory executor's own validation; a plan it would refuse
//! is answered INTERNAL_ERROR and not published) → publish.
//!
//! Planning takes from milliseconds to minutes, so it runs on a worker thread
//! ([`kerf_ros::Worker`]) and the node keeps reading requests meanwhile. Requests are answered
//! in arrival order, each by exactly one `CutPlan`: a request that cannot be read, converted
//! or validated, a planner error and a planner panic are all answered with their status,
//! message and (when known) `request_id`. When `queue_depth` requests are waiting or being
//! planned, a new valid request is answered at once with status INTERNAL_ERROR ("busy"), and a
//! new invalid one at once with its own status. When the node stops, the plan in progress is
//! finished and published and queued requests are answered INTERNAL_ERROR without planning.

pub mod config;
pub mod convert;
pub mod surroundings;
pub mod text;

use std::sync::Mutex;

use std::time::Duration;

use kerf_budget::Budget;
use kerf_executor::JointLimits;
use kerf_mjto::{error::status, planner::Planner, CutRequest, LaserMachine, PlanError};
use kerf_msgs::msg::{self, CutPlan};
use kerf_robot::roots::AllowedRoots;
use kerf_ros::{
    planner::AnswerSize,
    planner::{self, AnswerKey, Failure, PlanningService, Topics},
    RosArgs, RosEnv, StopToken,
};

pub use config::{NodeConfig, KNOWN_PARAMS};

/// Default node name.
pub const DEFAULT_NAME: &str = "mjto_planner";

/// What the MJTO service's set-up can fail on.
#[derive(Debug, thiserror::Error)]
pub enum SetupError {
    /// The machine (URDF + limits) could not be loaded.
    #[error("machine: {0}")]
    Machine(#[from] PlanError),
}

/// Why the node could not start: plumbing, a parameter, or [`SetupError`].
pub type NodeError = planner::NodeError<SetupError>;

/// Runs the node until its stop token (or Ctrl-C) stops it.
///
/// # Returns
/// `Ok` after a clean shutdown; an error if the node could not start (bad parameter,
/// unreadable machine description, DDS failure). Request errors never end the node.
pub fn run(args: &RosArgs, env: &RosEnv, stop: StopToken) -> Result<(), NodeError> {
    planner::run(DEFAULT_NAME, KNOWN_PARAMS, args, env, stop, |node| {
        let cfg = NodeConfig::from_params(node.params())?;
        let service = CutService::new(cfg.machine, cfg.machine_source)
            .map_err(NodeError::setup)?
            .with_allowed_roots(cfg.allowed_roots);
        Ok((service, cfg.harness))
    })
}

/// The MJTO planner as a planning service: cut requests in, `CutPlan` answers out.
pub struct CutService {
    /// The planner; a panic inside [`Planner::plan`] poisons it and the next request gets a
    /// fresh one.
    planner: Mutex<Planner>,
    machine: LaserMachine,
    limits: Vec<JointLimits>,
    approach_limits: Vec<kerf_approach::JointLimit>,
    machine_source: String,
    allowed_roots: AllowedRoots,
}

impl CutService {
    /// A service planning for `machine` (`source`: where it came from, for the start-up log).
    ///
    /// # Errors
    /// [`PlanError`] when the planner cannot be built for the machine.
    pub fn new(machine: LaserMachine, source: String) -> Result<Self, PlanError> {
        let limits = machine
            .robot()
            .executor_limits()
            .map_err(|e| PlanError::invalid("machine", e.to_string()))?;
        let names: Vec<String> = limits.iter().map(|l| l.name.clone()).collect();
        Ok(Self {
            planner: Mutex::new(Planner::new(machine.clone())?),
            approach_limits: surroundings::approach_limits(&machine, &names),
            machine,
            limits,
            machine_source: source,
            allowed_roots: AllowedRoots::any(),
        })
    }

    /// Requests' meshes must resolve under `roots` (the `allowed_file_roots` parameter).
    pub fn with_allowed_roots(mut self, roots: AllowedRoots) -> Self {
        self.allowed_roots = roots;
        self
    }

    /// Checks the request's mesh against the allowed roots (MESH_ERROR outside them).
    fn check_files(&self, request: CutRequest) -> Result<CutRequest, PlanError> {
        if self.allowed_roots.is_any() {
            return Ok(request);
        }
        let mesh_error = |reason: String| PlanError::Mesh {
            source_name: request.mesh.clone(),
            reason,
        };
        let path = kerf_mjto::mesh::resolve(&request.mesh)?;
        self.allowed_roots.check(&path).map_err(mesh_error)?;
        Ok(request)
    }
}

impl PlanningService for CutService {
    type RequestMsg = msg::CutRequest;
    type Request = CutRequest;
    type Answer = CutPlan;

    fn topics(&self) -> Topics {
        Topics::new("cut")
    }

    fn request_from_msg(&self, m: &msg::CutRequest) -> Result<CutRequest, Box<CutPlan>> {
        convert::request_from_msg(m)
            .and_then(|r| self.check_files(r))
            .map_err(|e| Box::new(convert::error_to_msg(&m.request_id, &e)))
    }

    fn msg_key(&self, m: &msg::CutRequest) -> AnswerKey {
        AnswerKey {
            request_id: m.request_id.clone(),
            label: String::new(),
        }
    }

    fn request_from_text(&self, text: &str) -> Result<CutRequest, Box<CutPlan>> {
        let r = text::parse_request(text)
            .map_err(|e| Box::new(convert::error_to_msg(&e.request_id, &e.error)))?;
        let id = r.request_id.clone();
        self.check_files(r)
            .map_err(|e| Box::new(convert::error_to_msg(&id, &e)))
    }

    fn key(&self, request: &CutRequest) -> AnswerKey {
        AnswerKey {
            request_id: request.request_id.clone(),
            label: String::new(),
        }
    }

    fn describe(&self, request: &CutRequest) -> String {
        format!("{} CL points", request.points.len())
    }

    fn answer_size(&self, request: &CutRequest) -> Option<AnswerSize> {
        Some(AnswerSize {
            points: request.sample_count()?,
            joints: self.limits.len(),
            extra_text_bytes: 0,
        })
    }

    fn requested_budget(&self, request: &CutRequest) -> Option<Duration> {
        // An invalid value is refused by the planner's validation (INVALID_REQUEST).
        kerf_budget::limit_from_seconds(request.time_budget)
            .ok()
            .flatten()
    }

    fn plan(&self, request: CutRequest, budget: &Budget) -> CutPlan {
        let mut guard = match self.planner.lock() {
            Ok(g) => g,
            Err(poisoned) => {
                let mut g = poisoned.into_inner();
                match Planner::new(self.machine.clone()) {
                    Ok(fresh) => *g = fresh,
                    Err(e) => {
                        return convert::failure_msg(
                            &request.request_id,
                            status::INTERNAL_ERROR,
                            format!("the planner could not be restarted after a failure: {e}"),
                        )
                    }
                }
                self.planner.clear_poison();
                g
            }
        };
        match guard.plan_within(&request, budget) {
            Ok(plan) => {
                let mut m = convert::plan_to_msg(&plan);
                m.request_id.clone_from(&request.request_id);
                m
            }
            Err(e) => convert::error_to_msg(&request.request_id, &e),
        }
    }

    /// Unreadable samples, bad numbers, unusable starts and budgets over `plan_timeout` are
    /// INVALID_REQUEST; no approach is NO_APPROACH; busy is QUEUE_FULL; stopped, panicked and not executable are INTERNAL_ERROR.
    fn failure(&self, key: &AnswerKey, failure: Failure, message: String) -> CutPlan {
        let code = match failure {
            Failure::Unreadable
            | Failure::OverBudget
            | Failure::TooLarge
            | Failure::BadNumber
            | Failure::BadStart => status::INVALID_REQUEST,
            Failure::NoApproach => status::NO_APPROACH,
            Failure::Busy => status::QUEUE_FULL,
            Failure::Timeout => status::TIMEOUT,
            Failure::ResourceLimit => status::RESOURCE_LIMIT,
            Failure::Stopped | Failure::Canceled | Failure::Panicked | Failure::NotExecutable => {
                status::INTERNAL_ERROR
            }
        };
        convert::failure_msg(&key.request_id, code, message)
    }

    fn joint_limits(&self) -> &[JointLimits] {
        &self.limits
    }

    fn start_of(&self, request: &CutRequest) -> kerf_approach::StartSpec {
        request.start.clone()
    }

    fn approach_limits(&self) -> &[kerf_approach::JointLimit] {
        &self.approach_limits
    }

    fn surroundings(
        &self,
        request: &CutRequest,
    ) -> Result<Box<dyn kerf_approach::Surroundings>, Box<CutPlan>> {
        // The mesh through the planner's cache: the plan that follows (in this worker) uses it
        // without reading the file again. A poisoned planner is replaced by the plan; here the
        // mesh is read directly.
        let mesh = match self.planner.lock() {
            Ok(mut planner) => planner.mesh(&request.mesh),
            Err(_) => kerf_mjto::mesh::load(&request.mesh).map(std::sync::Arc::new),
        };
        mesh.and_then(|mesh| {
            surroundings::LaserSurroundings::new(
                &self.machine,
                self.approach_limits.clone(),
                request,
                &mesh,
            )
        })
        .map(|s| Box::new(s) as Box<dyn kerf_approach::Surroundings>)
        .map_err(|e| Box::new(convert::error_to_msg(&request.request_id, &e)))
    }

    fn startup_note(&self) -> String {
        format!("machine: {}", self.machine_source)
    }
}

#[cfg(test)]
mod tests {
    use kerf_budget::CancelToken;

    use kerf_ros::planner::{work, Job};

    use super::*;

    fn one_point_request() -> Box<CutRequest> {
        Box::new(
            text::parse_request(
                "request_id: w1\nfeedrate: 0.3\nsample_period: 0.01\nmax_lead_angle: 0.1\n\
                 max_tilt_angle: 0.1\nmesh: m.stl\n0.6 0.2 0.1 0 0 1\n",
            )
            .unwrap(),
        )
    }

    #[test]
    fn work_recovers_a_poisoned_planner_and_skips_when_stopping() {
        let machine = LaserMachine::default_machine().unwrap();
        let service = std::sync::Arc::new(CutService::new(machine, "test".into()).unwrap());
        let s = std::sync::Arc::clone(&service);
        // A panic while planning poisons the mutex.
        let _ = std::thread::spawn(move || {
            let _guard = s.planner.lock().unwrap();
            panic!("planner bug");
        })
        .join();
        assert!(service.planner.is_poisoned());
        let stopping = CancelToken::new();
        let m = work(
            &*service,
            &stopping,
            Duration::from_secs(60),
            Job::Plan(one_point_request()),
        );
        // A fresh planner answered (validation: one point), and the mutex is usable again.
        assert_eq!(m.status, status::INVALID_REQUEST, "{}", m.message);
        assert_eq!(m.request_id, "w1");
        assert!(m.message.contains("at least 2"), "{}", m.message);
        assert!(!service.planner.is_poisoned());

        // Already-answered jobs pass through unchanged.
        let failed = convert::failure_msg("w2", status::MESH_ERROR, "gone");
        let m = work(
            &*service,
            &stopping,
            Duration::from_secs(60),
            Job::Answer(Box::new(failed.clone())),
        );
        assert_eq!(m, failed);

        stopping.cancel();
        let m = work(
            &*service,
            &stopping,
            Duration::from_secs(60),
            Job::Plan(one_point_request()),
        );
        assert_eq!(m.status, status::INTERNAL_ERROR);
        assert!(
            m.message.contains("stopped before planning"),
            "{}",
            m.message
        );
        assert_eq!(m.request_id, "w1");
    }
}
