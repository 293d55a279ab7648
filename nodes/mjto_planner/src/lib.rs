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
pub mod text;

use std::{
    collections::BTreeMap,
    sync::{
        atomic::{AtomicBool, Ordering},
        Arc, Mutex,
    },
    time::Duration as StdDuration,
};

use kerf_mjto::{error::status, planner::Planner, CutRequest, LaserMachine, PlanError};
use kerf_msgs::{
    msg::{self, CutPlan},
    std_msgs::StringMsg,
    trajectory_msgs::JointTrajectory,
    RosType,
};
use kerf_ros::{
    qos, ros2_client::Publisher, Inbox, KerfNode, Logger, NodeSpec, RosArgs, RosEnv, RosError,
    StopToken, Worker, WorkerError,
};

pub use config::{NodeConfig, KNOWN_PARAMS};

/// Default node name.
pub const DEFAULT_NAME: &str = "mjto_planner";

/// How long the node loop sleeps when there is nothing to do.
const POLL: StdDuration = StdDuration::from_millis(2);

/// Why the node could not start.
#[derive(Debug, thiserror::Error)]
pub enum NodeError {
    /// Environment, arguments, names or DDS.
    #[error(transparent)]
    Ros(#[from] RosError),
    /// The machine (URDF + limits) could not be loaded.
    #[error("machine: {0}")]
    Machine(#[from] PlanError),
    /// A parameter has a wrong value.
    #[error("parameter '{name}': {reason}")]
    Config {
        /// Parameter.
        name: String,
        /// What is wrong.
        reason: String,
    },
}

/// Work for the planner thread. Failed requests travel through it too, so that every answer
/// leaves in arrival order.
enum Job {
    /// Plan this request.
    Plan(Box<CutRequest>),
    /// Already answered (conversion or parse error): pass the answer through.
    Answer(Box<CutPlan>),
}

/// Runs the node until its stop token (or Ctrl-C) stops it.
///
/// # Returns
/// `Ok` after a clean shutdown; an error if the node could not start (bad parameter,
/// unreadable machine description, DDS failure). Request errors never end the node.
pub fn run(args: &RosArgs, env: &RosEnv, stop: StopToken) -> Result<(), NodeError> {
    let node = KerfNode::new(
        NodeSpec {
            default_name: DEFAULT_NAME,
            default_namespace: "/",
            known_params: KNOWN_PARAMS,
        },
        args,
        env,
        stop,
    )?;
    let log = node.logger();
    let cfg = match NodeConfig::from_params(node.params()) {
        Ok(c) => c,
        Err(e) => {
            log.error(&format!("cannot start: {e}"));
            return Err(e);
        }
    };
    let mut n = PlannerNode::new(node, cfg)?;
    n.spin();
    Ok(())
}

/// Plans one job on the worker thread (jobs queued after the node began to stop are answered
/// without planning).
///
/// A panic inside [`Planner::plan`] poisons the mutex; the next job then gets a fresh planner
/// (the panicking request itself is answered by the node from the [`WorkerError`]).
fn work(
    planner: &Mutex<Planner>,
    machine: &LaserMachine,
    stopping: &AtomicBool,
    job: Job,
) -> CutPlan {
    let request = match job {
        Job::Answer(m) => return *m,
        Job::Plan(r) => r,
    };
    if stopping.load(Ordering::Relaxed) {
        // Queued when the node stopped: skipped, so that shutdown waits for one plan at most.
        return convert::failure_msg(
            &request.request_id,
            status::INTERNAL_ERROR,
            "the planner node stopped before planning this request",
        );
    }
    let mut guard = match planner.lock() {
        Ok(g) => g,
        Err(poisoned) => {
            let mut g = poisoned.into_inner();
            match Planner::new(machine.clone()) {
                Ok(fresh) => *g = fresh,
                Err(e) => {
                    return convert::failure_msg(
                        &request.request_id,
                        status::INTERNAL_ERROR,
                        format!("the planner could not be restarted after a failure: {e}"),
                    )
                }
            }
            planner.clear_poison();
            g
        }
    };
    match guard.plan(&request) {
        Ok(plan) => {
            let mut m = convert::plan_to_msg(&plan);
            m.request_id.clone_from(&request.request_id);
            m
        }
        Err(e) => convert::error_to_msg(&request.request_id, &e),
    }
}

/// The node's state. Fields drop in declaration order: DDS endpoints and the worker first,
/// `node` (and its Context) last.
struct PlannerNode {
    requests: Inbox<msg::CutRequest>,
    text_requests: Inbox<StringMsg>,
    plans: Publisher<CutPlan>,
    plan_texts: Publisher<StringMsg>,
    trajectories: Publisher<JointTrajectory>,
    worker: Worker<Job, CutPlan>,
    /// Set when the node stops: queued plans are skipped.
    stopping: Arc<AtomicBool>,
    /// Ticket → request id of every job submitted and not yet answered.
    pending: BTreeMap<u64, String>,
    queue_depth: usize,
    log: Logger,
    node: KerfNode,
}

impl PlannerNode {
    fn new(mut node: KerfNode, cfg: NodeConfig) -> Result<Self, NodeError> {
        let requests = node.inbox("~/cut_request", msg::CutRequest::ROS_TYPE, qos::commands())?;
        let text_requests =
            node.inbox("~/cut_request_text", StringMsg::ROS_TYPE, qos::commands())?;
        // Latched, so `kerf echo --transient-local` shows the last answers.
        let plans = node.publisher("~/cut_plan", CutPlan::ROS_TYPE, qos::latched())?;
        let plan_texts = node.publisher("~/cut_plan_text", StringMsg::ROS_TYPE, qos::latched())?;
        // Volatile: a late (restarted) executor must never receive an old cut.
        let trajectories = node.publisher(
            "~/joint_trajectory",
            JointTrajectory::ROS_TYPE,
            qos::commands(),
        )?;
        let machine = cfg.machine.clone();
        let planner = Mutex::new(Planner::new(cfg.machine.clone())?);
        let stopping = Arc::new(AtomicBool::new(false));
        let stopping_w = Arc::clone(&stopping);
        let worker = Worker::spawn("plan", 1, move |job: Job| {
            work(&planner, &machine, &stopping_w, job)
        })
        .map_err(|e| RosError::Dds {
            what: "planner thread".into(),
            reason: e.to_string(),
        })?;
        let log = node.logger();
        log.info(&format!(
            "serving cut requests on {} and {}; plans on {}, trajectories on {}; machine: {}; \
             queue_depth {}",
            node.resolve("~/cut_request")?,
            node.resolve("~/cut_request_text")?,
            node.resolve("~/cut_plan")?,
            node.resolve("~/joint_trajectory")?,
            cfg.machine_source,
            cfg.queue_depth,
        ));
        Ok(Self {
            requests,
            text_requests,
            plans,
            plan_texts,
            trajectories,
            worker,
            stopping,
            pending: BTreeMap::new(),
            queue_depth: cfg.queue_depth,
            log,
            node,
        })
    }

    fn spin(&mut self) {
        while !self.node.should_stop() {
            let mut busy = self.poll_requests();
            busy |= self.poll_text_requests();
            busy |= self.poll_results();
            if !busy {
                std::thread::sleep(POLL);
            }
        }
        // Queued requests are answered "stopped" without planning; the plan in progress (if
        // any) is awaited and published, so no request is left without an answer.
        self.stopping.store(true, Ordering::Relaxed);
        if !self.pending.is_empty() {
            self.log.warn(&format!(
                "shutting down: answering {} queued request(s); waiting for the plan in progress",
                self.pending.len()
            ));
        }
        while !self.pending.is_empty() {
            match self.worker.recv_timeout(StdDuration::from_secs(1)) {
                Some(done) => self.answer(done),
                None => continue,
            }
        }
        self.log.info("shutting down");
    }

    /// Reads `~/cut_request`; `true` if anything was read.
    fn poll_requests(&mut self) -> bool {
        let mut any = false;
        while let Some(received) = self.requests.try_recv() {
            any = true;
            let job = match received {
                Ok(m) => match convert::request_from_msg(&m) {
                    Ok(r) => Job::Plan(Box::new(r)),
                    Err(e) => Job::Answer(Box::new(convert::error_to_msg(&m.request_id, &e))),
                },
                Err(e) => Job::Answer(Box::new(convert::failure_msg(
                    "",
                    status::INVALID_REQUEST,
                    format!("could not read a CutRequest sample: {e}"),
                ))),
            };
            self.submit(job, "message");
        }
        any
    }

    /// Reads `~/cut_request_text`; `true` if anything was read.
    fn poll_text_requests(&mut self) -> bool {
        let mut any = false;
        while let Some(received) = self.text_requests.try_recv() {
            any = true;
            let job = match received {
                Ok(m) => match text::parse_request(&m.data) {
                    Ok(r) => Job::Plan(Box::new(r)),
                    Err(e) => Job::Answer(Box::new(convert::error_to_msg(&e.request_id, &e.error))),
                },
                Err(e) => Job::Answer(Box::new(convert::failure_msg(
                    "",
                    status::INVALID_REQUEST,
                    format!("could not read a text request sample: {e}"),
                ))),
            };
            self.submit(job, "text");
        }
        any
    }

    /// Queues a job, or answers at once when the queue is full.
    fn submit(&mut self, job: Job, source: &str) {
        let id = match &job {
            Job::Plan(r) => r.request_id.clone(),
            Job::Answer(m) => m.request_id.clone(),
        };
        if self.pending.len() >= self.queue_depth {
            let answer = match job {
                // Already failed: its own status says more than "busy".
                Job::Answer(m) => *m,
                Job::Plan(_) => convert::failure_msg(
                    &id,
                    status::INTERNAL_ERROR,
                    format!(
                        "planner busy: {} request(s) waiting or being planned (queue_depth {}); \
                         request refused, send it again later",
                        self.pending.len(),
                        self.queue_depth
                    ),
                ),
            };
            self.publish(answer);
            return;
        }
        if let Job::Plan(r) = &job {
            self.log.info(&format!(
                "request '{id}' ({source}): {} CL points, queued behind {} other(s)",
                r.points.len(),
                self.pending.len()
            ));
        }
        let ticket = self.worker.submit(job);
        self.pending.insert(ticket, id);
    }

    /// Publishes finished answers; `true` if any.
    fn poll_results(&mut self) -> bool {
        let mut any = false;
        while let Some(done) = self.worker.try_recv() {
            any = true;
            self.answer(done);
        }
        any
    }

    /// Publishes the answer of one finished job (a panic becomes INTERNAL_ERROR).
    fn answer(&mut self, (ticket, result): (u64, Result<CutPlan, WorkerError>)) {
        let id = self.pending.remove(&ticket).unwrap_or_default();
        let answer = match result {
            Ok(plan) => plan,
            Err(WorkerError::Panicked { message, .. }) => convert::failure_msg(
                &id,
                status::INTERNAL_ERROR,
                format!("the planner failed unexpectedly (panic: {message})"),
            ),
        };
        self.publish(answer);
    }

    /// Publishes one answer on `~/cut_plan`, `~/cut_plan_text` and, on success,
    /// `~/joint_trajectory`; logs it.
    fn publish(&self, plan: CutPlan) {
        let name = CutPlan::status_name(plan.status).unwrap_or("?");
        if plan.status == CutPlan::SUCCESS {
            self.log
                .info(&format!("request '{}': {}", plan.request_id, plan.message));
            if let Err(e) = self.trajectories.publish(plan.trajectory.clone()) {
                self.log.error(&format!(
                    "request '{}': trajectory not published: {e}",
                    plan.request_id
                ));
            }
        } else {
            self.log.warn(&format!(
                "request '{}' {name}: {}",
                plan.request_id, plan.message
            ));
        }
        let text = StringMsg {
            data: text::plan_text(&plan),
        };
        let id = plan.request_id.clone();
        if let Err(e) = self.plans.publish(plan) {
            self.log
                .error(&format!("request '{id}': CutPlan not published: {e}"));
        }
        if let Err(e) = self.plan_texts.publish(text) {
            self.log
                .error(&format!("request '{id}': plan text not published: {e}"));
        }
    }
}

#[cfg(test)]
mod tests {
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
        let planner = Arc::new(Mutex::new(Planner::new(machine.clone()).unwrap()));
        let p = Arc::clone(&planner);
        // A panic while planning poisons the mutex.
        let _ = std::thread::spawn(move || {
            let _guard = p.lock().unwrap();
            panic!("planner bug");
        })
        .join();
        assert!(planner.is_poisoned());
        let stopping = AtomicBool::new(false);
        let m = work(
            &planner,
            &machine,
            &stopping,
            Job::Plan(one_point_request()),
        );
        // A fresh planner answered (validation: one point), and the mutex is usable again.
        assert_eq!(m.status, status::INVALID_REQUEST, "{}", m.message);
        assert_eq!(m.request_id, "w1");
        assert!(m.message.contains("at least 2"), "{}", m.message);
        assert!(!planner.is_poisoned());

        // Already-answered jobs pass through unchanged.
        let failed = convert::failure_msg("w2", status::MESH_ERROR, "gone");
        let m = work(
            &planner,
            &machine,
            &stopping,
            Job::Answer(Box::new(failed.clone())),
        );
        assert_eq!(m, failed);

        stopping.store(true, Ordering::Relaxed);
        let m = work(
            &planner,
            &machine,
            &stopping,
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
