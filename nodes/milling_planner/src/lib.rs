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
//! `queue_depth`.
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
//! midpoints, path end) with their joint positions and velocities, from rest to rest (zero
//! velocity at the path start and end, the first and the last half-segment ramps over twice
//! their planned time), time-scaled by the planner so that its cubic Hermite interpolation
//! stays within every joint's velocity and acceleration limit: an interval is slowed where
//! the planned feeds ask too much of a joint, never sped up. The `MillPlan` segments and
//! totals are those of that executed plan (the feeds run, |μ|max re-evaluated at them;
//! `machining_time` is the trajectory's duration); its message also gives the values at the
//! planned feeds. Its first point (time 0) is the robot at the start of the path and
//! its `header.stamp` is zero, so an executor starts it on receipt and accepts it only when
//! its commanded position is that first point (within its `start_tolerance`): move the robot
//! there first, or start the executor with `initial_positions` at the plan's first point
//! (`MillPlan.trajectory.points[0].positions`). The trajectory topic is volatile on purpose: a
//! restarted executor must not receive an old cut.
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

use std::{
    collections::BTreeMap,
    path::PathBuf,
    sync::{
        atomic::{AtomicBool, Ordering},
        Arc,
    },
    time::Duration as StdDuration,
};

use kerf_millplan::{planner::status, MillPlanError, MillPlanner, MillRequest, PlannerKind};
use kerf_msgs::{
    msg::{self, MillPlan},
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
pub const DEFAULT_NAME: &str = "milling_planner";

/// How long the node loop sleeps when there is nothing to do.
const POLL: StdDuration = StdDuration::from_millis(2);

/// Why the node could not start.
#[derive(Debug, thiserror::Error)]
pub enum NodeError {
    /// Environment, arguments, names or DDS.
    #[error(transparent)]
    Ros(#[from] RosError),
    /// The milling cell or the indicator cache could not be loaded.
    #[error("milling planner: {0}")]
    Planner(#[from] MillPlanError),
    /// The milling cell file could not be loaded.
    #[error("milling cell: {0}")]
    Cell(#[from] kerf_mill::MillError),
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
pub enum Job {
    /// Plan this request.
    Plan(Box<MillRequest>),
    /// Already answered (conversion or parse error): pass the answer through.
    Answer(Box<MillPlan>),
}

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

/// Plans one job (on the worker thread): the request with the node's default policy filled
/// in when it names none, answered as a `MillPlan`. The published trajectory is time-scaled
/// by the planner to the robot's velocity and acceleration limits; the node checks it again
/// ([`convert::first_limit_excess`], its guard): a successful plan whose trajectory
/// nevertheless exceeds them (a planner bug) is still SUCCESS, with a WARNING in its message
/// naming the joint, the value and the time. Jobs queued after the node began to stop are answered
/// INTERNAL_ERROR without planning; already-answered jobs pass through.
pub fn work(
    planner: &MillPlanner,
    policies: &DefaultPolicies,
    stopping: &AtomicBool,
    job: Job,
) -> MillPlan {
    let mut request = match job {
        Job::Answer(m) => return *m,
        Job::Plan(r) => r,
    };
    if stopping.load(Ordering::Relaxed) {
        // Queued when the node stopped: skipped, so that shutdown waits for one plan at most.
        return convert::failure_msg(
            &request.request_id,
            convert::answer_planner(&request.planner),
            status::INTERNAL_ERROR,
            "the planner node stopped before planning this request",
        );
    }
    if request.policy_file.is_none() {
        let default = match PlannerKind::parse(&request.planner) {
            Ok(PlannerKind::Ddpg) => Some(&policies.ddpg),
            Ok(PlannerKind::FixedG) => Some(&policies.fixed_g),
            _ => None,
        };
        request.policy_file = default.map(|p| p.display().to_string());
    }
    match planner.plan(&request) {
        Ok(out) => {
            let mut m = convert::output_to_msg(&out);
            if m.status == MillPlan::SUCCESS {
                let limits = robot_limits(planner);
                if let Some(excess) = convert::first_limit_excess(&m.trajectory, &limits) {
                    m.message.push_str(&format!(
                        "; WARNING: the trajectory exceeds the robot's limits ({excess}) \
                         although the planner time-scaled it to them (a planner bug): an \
                         executor with these limits will reject it"
                    ));
                }
            }
            m
        }
        Err(e) => convert::error_to_msg(&request.request_id, &request.planner, &e),
    }
}

/// The velocity and acceleration limits of the planner cell's robot.
pub fn robot_limits(planner: &MillPlanner) -> Vec<convert::JointLimit> {
    planner
        .cell()
        .robot()
        .joints()
        .iter()
        .map(|j| convert::JointLimit {
            name: j.name.clone(),
            max_velocity: j.max_velocity,
            max_acceleration: j.max_acceleration,
        })
        .collect()
}

/// The node's state. Fields drop in declaration order: DDS endpoints and the worker first,
/// `node` (and its Context) last.
struct PlannerNode {
    requests: Inbox<msg::MillRequest>,
    text_requests: Inbox<StringMsg>,
    plans: Publisher<MillPlan>,
    plan_texts: Publisher<StringMsg>,
    trajectories: Publisher<JointTrajectory>,
    worker: Worker<Job, MillPlan>,
    /// Set when the node stops: queued plans are skipped.
    stopping: Arc<AtomicBool>,
    /// Ticket → (request id, planner field) of every job submitted and not yet answered.
    pending: BTreeMap<u64, (String, String)>,
    queue_depth: usize,
    log: Logger,
    node: KerfNode,
}

impl PlannerNode {
    fn new(mut node: KerfNode, cfg: NodeConfig) -> Result<Self, NodeError> {
        let requests = node.inbox(
            "~/mill_request",
            msg::MillRequest::ROS_TYPE,
            qos::commands(),
        )?;
        let text_requests =
            node.inbox("~/mill_request_text", StringMsg::ROS_TYPE, qos::commands())?;
        // Latched, so `kerf echo --transient-local` shows the last answers.
        let plans = node.publisher("~/mill_plan", MillPlan::ROS_TYPE, qos::latched())?;
        let plan_texts = node.publisher("~/mill_plan_text", StringMsg::ROS_TYPE, qos::latched())?;
        // Volatile: a late (restarted) executor must never receive an old cut.
        let trajectories = node.publisher(
            "~/joint_trajectory",
            JointTrajectory::ROS_TYPE,
            qos::commands(),
        )?;
        let log = node.logger();
        let policies = DefaultPolicies {
            ddpg: cfg.ddpg_policy_file.clone(),
            fixed_g: cfg.fixed_g_policy_file.clone(),
        };
        for (kind, path) in [("ddpg", &policies.ddpg), ("fixed_g", &policies.fixed_g)] {
            if !path.is_file() {
                log.warn(&format!(
                    "default {kind} policy {} does not exist (yet): {kind} requests without \
                     policy_file will be answered POLICY_ERROR until it does",
                    path.display()
                ));
            }
        }
        log.info(&format!(
            "serving mill requests on {} and {}; plans on {}, trajectories on {}; cell: {}; {}; \
             |mu|max: {}; default policies: ddpg {}, fixed_g {}; queue_depth {}",
            node.resolve("~/mill_request")?,
            node.resolve("~/mill_request_text")?,
            node.resolve("~/mill_plan")?,
            node.resolve("~/joint_trajectory")?,
            cfg.cell_source,
            cfg.cache_note,
            cfg.indicator_source.name(),
            policies.ddpg.display(),
            policies.fixed_g.display(),
            cfg.queue_depth,
        ));
        let planner = Arc::new(cfg.planner);
        let stopping = Arc::new(AtomicBool::new(false));
        let stopping_w = Arc::clone(&stopping);
        let worker = Worker::spawn("millplan", 1, move |job: Job| {
            work(&planner, &policies, &stopping_w, job)
        })
        .map_err(|e| RosError::Dds {
            what: "planner thread".into(),
            reason: e.to_string(),
        })?;
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

    /// Reads `~/mill_request`; `true` if anything was read.
    fn poll_requests(&mut self) -> bool {
        let mut any = false;
        while let Some(received) = self.requests.try_recv() {
            any = true;
            let job = match received {
                Ok(m) => match convert::request_from_msg(&m) {
                    Ok(r) => Job::Plan(Box::new(r)),
                    Err(e) => Job::Answer(Box::new(convert::error_to_msg(
                        &m.request_id,
                        &m.planner,
                        &e,
                    ))),
                },
                Err(e) => Job::Answer(Box::new(convert::failure_msg(
                    "",
                    "",
                    status::INVALID_REQUEST,
                    format!("could not read a MillRequest sample: {e}"),
                ))),
            };
            self.submit(job, "message");
        }
        any
    }

    /// Reads `~/mill_request_text`; `true` if anything was read.
    fn poll_text_requests(&mut self) -> bool {
        let mut any = false;
        while let Some(received) = self.text_requests.try_recv() {
            any = true;
            let job = match received {
                Ok(m) => match text::parse_request(&m.data) {
                    Ok(r) => Job::Plan(Box::new(r)),
                    Err(e) => Job::Answer(Box::new(convert::error_to_msg(
                        &e.request_id,
                        &e.planner,
                        &e.error,
                    ))),
                },
                Err(e) => Job::Answer(Box::new(convert::failure_msg(
                    "",
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
        let (id, planner) = match &job {
            Job::Plan(r) => (r.request_id.clone(), r.planner.clone()),
            Job::Answer(m) => (m.request_id.clone(), m.planner.clone()),
        };
        if self.pending.len() >= self.queue_depth {
            let answer = match job {
                // Already failed: its own status says more than "busy".
                Job::Answer(m) => *m,
                Job::Plan(_) => convert::failure_msg(
                    &id,
                    convert::answer_planner(&planner),
                    convert::QUEUE_FULL,
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
                "request '{id}' ({source}): {} path points, planner {}, queued behind {} other(s)",
                r.points.len(),
                r.planner,
                self.pending.len()
            ));
        }
        let ticket = self.worker.submit(job);
        self.pending.insert(ticket, (id, planner));
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
    fn answer(&mut self, (ticket, result): (u64, Result<MillPlan, WorkerError>)) {
        let (id, planner) = self.pending.remove(&ticket).unwrap_or_default();
        let answer = match result {
            Ok(plan) => plan,
            Err(WorkerError::Panicked { message, .. }) => convert::failure_msg(
                &id,
                convert::answer_planner(&planner),
                status::INTERNAL_ERROR,
                format!("the planner failed unexpectedly (panic: {message})"),
            ),
        };
        self.publish(answer);
    }

    /// Publishes one answer on `~/mill_plan`, `~/mill_plan_text` and, on success,
    /// `~/joint_trajectory`; logs it.
    fn publish(&self, plan: MillPlan) {
        let name = MillPlan::status_name(plan.status).unwrap_or("?");
        if plan.status == MillPlan::SUCCESS {
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
                .error(&format!("request '{id}': MillPlan not published: {e}"));
        }
        if let Err(e) = self.plan_texts.publish(text) {
            self.log
                .error(&format!("request '{id}': plan text not published: {e}"));
        }
    }
}
