//! The planner-node loop: requests in (message and text), one worker in arrival order, one
//! answer per request, latched answers, the trajectory on success, clean shutdown.

use std::{
    collections::BTreeMap,
    fmt::Display,
    sync::{
        atomic::{AtomicBool, Ordering},
        Arc,
    },
    time::Duration,
};

use kerf_msgs::{std_msgs::StringMsg, trajectory_msgs::JointTrajectory, RosType};
use ros2_client::Publisher;

use super::{
    check_text_size, check_trajectory_msg, AnswerKey, Failure, PlanAnswer, PlanningService,
    TRAJECTORY_TOPIC,
};
use crate::{qos, Inbox, KerfNode, Logger, NodeSpec, RosArgs, RosEnv, RosError, StopToken};
use crate::{Worker, WorkerError};

/// How long the node loop sleeps when there is nothing to do.
const POLL: Duration = Duration::from_millis(2);

/// Work for the planner thread. Failed requests travel through it too, so that every answer
/// leaves in arrival order.
pub enum Job<R, A> {
    /// Plan this request.
    Plan(Box<R>),
    /// Already answered (conversion or parse error): pass the answer through.
    Answer(Box<A>),
}

/// Starts a planner node and serves until its stop token (or Ctrl-C) stops it.
///
/// # Arguments
/// * `default_name`, `known_params` — the node's default name (in namespace `/`) and the
///   parameters it reads (others are refused at start-up).
/// * `args`, `env`, `stop` — command line, environment, stop token.
/// * `setup` — reads the node's parameters and builds the service; returns it with the
///   `queue_depth` (requests waiting or being planned before new ones are answered
///   [`Failure::Busy`]). Its error is logged ("cannot start: …") and returned.
///
/// # Returns
/// `Ok` after a clean shutdown; an error if the node could not start (bad parameter, model
/// that does not load, DDS failure). Request errors never end the node.
pub fn run<S, E>(
    default_name: &str,
    known_params: &[&str],
    args: &RosArgs,
    env: &RosEnv,
    stop: StopToken,
    setup: impl FnOnce(&KerfNode) -> Result<(S, usize), E>,
) -> Result<(), E>
where
    S: PlanningService,
    E: From<RosError> + Display,
{
    let spec = NodeSpec {
        default_name,
        default_namespace: "/",
        known_params,
    };
    let node = KerfNode::new(spec, args, env, stop)?;
    let (service, queue_depth) = match setup(&node) {
        Ok(s) => s,
        Err(e) => {
            node.logger().error(&format!("cannot start: {e}"));
            return Err(e);
        }
    };
    let mut n = PlannerNode::new(node, service, queue_depth)?;
    n.spin();
    Ok(())
}

/// Runs one job on the worker thread: an already-answered job passes through; a job queued
/// after the node began to stop is answered [`Failure::Stopped`] without planning; a
/// successful plan whose trajectory the executor would refuse ([`check_trajectory_msg`])
/// becomes [`Failure::NotExecutable`] and is not published as a success.
pub fn work<S: PlanningService>(
    service: &S,
    stopping: &AtomicBool,
    job: Job<S::Request, S::Answer>,
) -> S::Answer {
    let request = match job {
        Job::Answer(m) => return *m,
        Job::Plan(r) => r,
    };
    if stopping.load(Ordering::Relaxed) {
        // Queued when the node stopped: skipped, so that shutdown waits for one plan at most.
        return service.failure(
            &service.key(&request),
            Failure::Stopped,
            "the planner node stopped before planning this request".into(),
        );
    }
    let key = service.key(&request);
    let answer = service.plan(*request);
    if !answer.is_success() {
        return answer;
    }
    match check_trajectory_msg(service.joint_limits(), answer.trajectory()) {
        Ok(()) => answer,
        Err(reason) => service.failure(
            &key,
            Failure::NotExecutable,
            format!(
                "the planned trajectory would be refused by the trajectory executor ({reason}); \
                 it is not published (a planner bug)"
            ),
        ),
    }
}

/// The YAML text of an answer, as published on the plan text topic (serde's YAML of the
/// message: every field, in `.msg` order).
pub fn answer_text<A: PlanAnswer>(answer: &A) -> String {
    serde_yaml_ng::to_string(answer).unwrap_or_else(|e| {
        // Only reachable if serde_yaml_ng refused a value; keep the essentials readable.
        format!(
            "request_id: {:?}\nstatus: {}\nmessage: {:?}\n# full plan not rendered: {e}\n",
            answer.request_id(),
            answer.status(),
            answer.message()
        )
    })
}

/// The node's state. Fields drop in declaration order: DDS endpoints and the worker first,
/// `node` (and its Context) last.
struct PlannerNode<S: PlanningService> {
    requests: Inbox<S::RequestMsg>,
    text_requests: Inbox<StringMsg>,
    plans: Publisher<S::Answer>,
    plan_texts: Publisher<StringMsg>,
    trajectories: Publisher<JointTrajectory>,
    worker: Worker<Job<S::Request, S::Answer>, S::Answer>,
    service: Arc<S>,
    /// Set when the node stops: queued plans are skipped.
    stopping: Arc<AtomicBool>,
    /// Ticket → key of every job submitted and not yet answered.
    pending: BTreeMap<u64, AnswerKey>,
    queue_depth: usize,
    log: Logger,
    node: KerfNode,
}

impl<S: PlanningService> PlannerNode<S> {
    fn new(mut node: KerfNode, service: S, queue_depth: usize) -> Result<Self, RosError> {
        let topics = service.topics();
        let requests = node.inbox(&topics.request, S::RequestMsg::ROS_TYPE, qos::commands())?;
        let text_requests =
            node.inbox(&topics.request_text, StringMsg::ROS_TYPE, qos::commands())?;
        // Latched, so `kerf echo --transient-local` shows the last answers.
        let plans = node.publisher(&topics.plan, S::Answer::ROS_TYPE, qos::latched())?;
        let plan_texts = node.publisher(&topics.plan_text, StringMsg::ROS_TYPE, qos::latched())?;
        // Volatile: a late (restarted) executor must never receive an old plan.
        let trajectories =
            node.publisher(TRAJECTORY_TOPIC, JointTrajectory::ROS_TYPE, qos::commands())?;
        let log = node.logger();
        log.info(&format!(
            "serving {} requests on {} and {}; plans on {}, trajectories on {}; {}; queue_depth {}",
            topics.noun,
            node.resolve(&topics.request)?,
            node.resolve(&topics.request_text)?,
            node.resolve(&topics.plan)?,
            node.resolve(TRAJECTORY_TOPIC)?,
            service.startup_note(),
            queue_depth,
        ));
        let service = Arc::new(service);
        let stopping = Arc::new(AtomicBool::new(false));
        let (service_w, stopping_w) = (Arc::clone(&service), Arc::clone(&stopping));
        let worker = Worker::spawn("plan", 1, move |job| work(&*service_w, &stopping_w, job))
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
            service,
            stopping,
            pending: BTreeMap::new(),
            queue_depth,
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
            if let Some(done) = self.worker.recv_timeout(Duration::from_secs(1)) {
                self.answer(done);
            }
        }
        self.log.info("shutting down");
    }

    /// A job for a sample that could not be read.
    fn unreadable(&self, what: &str, e: String) -> Job<S::Request, S::Answer> {
        Job::Answer(Box::new(self.service.failure(
            &AnswerKey::default(),
            Failure::Unreadable,
            format!("could not read a {what} sample: {e}"),
        )))
    }

    /// Reads the request message topic; `true` if anything was read.
    fn poll_requests(&mut self) -> bool {
        let mut any = false;
        while let Some(received) = self.requests.try_recv() {
            any = true;
            let job = match received {
                Ok(m) => match self.service.request_from_msg(&m) {
                    Ok(r) => Job::Plan(Box::new(r)),
                    Err(answer) => Job::Answer(answer),
                },
                Err(e) => self.unreadable(S::RequestMsg::NAME, e),
            };
            self.submit(job, "message");
        }
        any
    }

    /// Reads the text request topic; `true` if anything was read.
    fn poll_text_requests(&mut self) -> bool {
        let mut any = false;
        while let Some(received) = self.text_requests.try_recv() {
            any = true;
            let job = match received {
                Ok(m) => match check_text_size(&m.data) {
                    Err(reason) => Job::Answer(Box::new(self.service.failure(
                        &AnswerKey::default(),
                        Failure::Unreadable,
                        reason,
                    ))),
                    Ok(()) => match self.service.request_from_text(&m.data) {
                        Ok(r) => Job::Plan(Box::new(r)),
                        Err(answer) => Job::Answer(answer),
                    },
                },
                Err(e) => self.unreadable("text request", e),
            };
            self.submit(job, "text");
        }
        any
    }

    /// Queues a job, or answers at once when the queue is full.
    fn submit(&mut self, job: Job<S::Request, S::Answer>, source: &str) {
        let key = match &job {
            Job::Plan(r) => self.service.key(r),
            Job::Answer(m) => m.key(),
        };
        if self.pending.len() >= self.queue_depth {
            let answer = match job {
                // Already failed: its own status says more than "busy".
                Job::Answer(m) => *m,
                Job::Plan(_) => self.service.failure(
                    &key,
                    Failure::Busy,
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
                "request '{}' ({source}): {}, queued behind {} other(s)",
                key.request_id,
                self.service.describe(r),
                self.pending.len()
            ));
        }
        let ticket = self.worker.submit(job);
        self.pending.insert(ticket, key);
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

    /// Publishes the answer of one finished job (a panic becomes [`Failure::Panicked`]).
    fn answer(&mut self, (ticket, result): (u64, Result<S::Answer, WorkerError>)) {
        let key = self.pending.remove(&ticket).unwrap_or_default();
        let answer = match result {
            Ok(plan) => plan,
            Err(WorkerError::Panicked { message, .. }) => self.service.failure(
                &key,
                Failure::Panicked,
                format!("the planner failed unexpectedly (panic: {message})"),
            ),
        };
        self.publish(answer);
    }

    /// Publishes one answer on the plan topics and, on success, the trajectory; logs it.
    fn publish(&self, plan: S::Answer) {
        let id = plan.request_id().to_string();
        if plan.is_success() {
            self.log
                .info(&format!("request '{id}': {}", plan.message()));
            if let Err(e) = self.trajectories.publish(plan.trajectory().clone()) {
                self.log
                    .error(&format!("request '{id}': trajectory not published: {e}"));
            }
        } else {
            self.log.warn(&format!(
                "request '{id}' {}: {}",
                plan.status_name(),
                plan.message()
            ));
        }
        let text = StringMsg {
            data: answer_text(&plan),
        };
        if let Err(e) = self.plans.publish(plan) {
            self.log.error(&format!(
                "request '{id}': {} not published: {e}",
                S::Answer::NAME
            ));
        }
        if let Err(e) = self.plan_texts.publish(text) {
            self.log
                .error(&format!("request '{id}': plan text not published: {e}"));
        }
    }
}
