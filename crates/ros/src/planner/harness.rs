//! The planner-node loop: requests in (message and text), one worker in arrival order, one
//! answer per request, latched answers, the trajectory on success, clean shutdown.

use std::{collections::BTreeMap, fmt::Display, sync::Arc, time::Duration};

use kerf_budget::{Budget, CancelToken};
use kerf_msgs::{std_msgs::StringMsg, trajectory_msgs::JointTrajectory, RosType};
use ros2_client::Publisher;

use super::{
    check_answer, check_points, check_text_size, check_trajectory_msg, AnswerKey, Failure,
    HarnessSettings, PlanAnswer, PlanningService, TRAJECTORY_TOPIC,
};
use crate::{qos, Inbox, KerfNode, Logger, NodeSpec, RosArgs, RosEnv, RosError, StopToken};
use crate::{Worker, WorkerError};

/// How long the node loop sleeps when there is nothing to do.
const POLL: Duration = Duration::from_millis(2);

/// How long a stopping node keeps its writers after answering requests at
/// shutdown. Why: ros2-client 0.12's `Publisher` offers no wait for
/// acknowledgements, and dropping a reliable writer right after a write lost
/// the answer about one time in four over loopback (`tests/deadline_e2e.rs`,
/// `stopping_mid_plan_cancels_and_answers_it`). The linger covers the write
/// itself and one repair: RustDDS's reliable writers announce their samples
/// every second (`HEARTBEAT_PERIOD_SLOW`), and a reader asks for a lost one
/// in reply.
pub const SHUTDOWN_LINGER: Duration = Duration::from_millis(1500);

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
///   harness's settings ([`HarnessSettings::from_params`]: `queue_depth`, requests waiting or
///   being planned before new ones are answered [`Failure::Busy`]; `plan_timeout`, the time
///   budget of every plan). Its error is logged ("cannot start: …") and returned.
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
    setup: impl FnOnce(&KerfNode) -> Result<(S, HarnessSettings), E>,
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
    let (service, settings) = match setup(&node) {
        Ok(s) => s,
        Err(e) => {
            node.logger().error(&format!("cannot start: {e}"));
            return Err(e);
        }
    };
    let mut n = PlannerNode::new(node, service, settings)?;
    n.spin();
    Ok(())
}

/// Runs one job on the worker thread: an already-answered job passes through; a job queued
/// after the node began to stop is answered [`Failure::Stopped`] without planning; a plan
/// runs under a budget of `plan_timeout` (tightened by the request's own, started now, and
/// cancelled by `cancel`); a successful plan whose trajectory the executor would refuse
/// ([`check_trajectory_msg`]) becomes [`Failure::NotExecutable`] and is not published as a
/// success.
pub fn work<S: PlanningService>(
    service: &S,
    cancel: &CancelToken,
    plan_timeout: Duration,
    job: Job<S::Request, S::Answer>,
) -> S::Answer {
    let request = match job {
        Job::Answer(m) => return *m,
        Job::Plan(r) => r,
    };
    if cancel.is_cancelled() {
        // Queued when the node stopped: skipped, so that shutdown waits for one plan at most.
        return service.failure(
            &service.key(&request),
            Failure::Stopped,
            "the planner node stopped before planning this request".into(),
        );
    }
    let key = service.key(&request);
    let budget = Budget::new(Some(plan_timeout), cancel.clone())
        .tightened(service.requested_budget(&request));
    let answer = service.plan(*request, &budget);
    if !answer.is_success() {
        return answer;
    }
    // Checked before anything renders the answer (its YAML text would be ~6× its size).
    let trajectory = answer.trajectory();
    if let Err(reason) = check_points(trajectory.points.len(), trajectory.joint_names.len()) {
        return service.failure(&key, Failure::TooLarge, reason);
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

/// Longest `request_id` a request may have (bytes).
pub const MAX_REQUEST_ID_BYTES: usize = 256;

/// The beginning of a request id over [`MAX_REQUEST_ID_BYTES`] (cut at a character boundary);
/// `None` when it is within the limit.
fn cut_request_id(id: &str) -> Option<String> {
    if id.len() <= MAX_REQUEST_ID_BYTES {
        return None;
    }
    let mut end = MAX_REQUEST_ID_BYTES;
    while !id.is_char_boundary(end) {
        end -= 1;
    }
    id.get(..end).map(str::to_string)
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
    /// Cancelled when the node stops: the plan in progress ends, queued plans are skipped.
    cancel: CancelToken,
    /// Ticket → key of every job submitted and not yet answered.
    pending: BTreeMap<u64, AnswerKey>,
    settings: HarnessSettings,
    log: Logger,
    node: KerfNode,
}

impl<S: PlanningService> PlannerNode<S> {
    fn new(mut node: KerfNode, service: S, settings: HarnessSettings) -> Result<Self, RosError> {
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
            "serving {} requests on {} and {}; plans on {}, trajectories on {}; {}; queue_depth {}, \
             plan_timeout {} s",
            topics.noun,
            node.resolve(&topics.request)?,
            node.resolve(&topics.request_text)?,
            node.resolve(&topics.plan)?,
            node.resolve(TRAJECTORY_TOPIC)?,
            service.startup_note(),
            settings.queue_depth,
            settings.plan_timeout.as_secs_f64(),
        ));
        let service = Arc::new(service);
        let cancel = CancelToken::new();
        let (service_w, cancel_w) = (Arc::clone(&service), cancel.clone());
        let timeout = settings.plan_timeout;
        let worker = Worker::spawn("plan", 1, move |job| {
            work(&*service_w, &cancel_w, timeout, job)
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
            service,
            cancel,
            pending: BTreeMap::new(),
            settings,
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
        // The plan in progress (if any) is cancelled through its budget and answered; queued
        // requests are answered "stopped" without planning: no request is left without an
        // answer, and the node stops as soon as the planner reaches its next budget check.
        self.cancel.cancel();
        if !self.pending.is_empty() {
            self.log.warn(&format!(
                "shutting down: cancelling the plan in progress and answering {} request(s)",
                self.pending.len()
            ));
        }
        let answered_at_shutdown = !self.pending.is_empty();
        while !self.pending.is_empty() {
            match self.worker.recv_timeout(Duration::from_secs(1)) {
                Some(done) => self.answer(done),
                None => self
                    .log
                    .warn("shutting down: the plan in progress has not reached a budget check yet"),
            }
        }
        if answered_at_shutdown {
            // Let the reliable writers deliver (and repair) the answers just written.
            std::thread::sleep(SHUTDOWN_LINGER);
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
                    Ok(r) => self.plan_job(r),
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
                        Ok(r) => self.plan_job(r),
                        Err(answer) => Job::Answer(answer),
                    },
                },
                Err(e) => self.unreadable("text request", e),
            };
            self.submit(job, "text");
        }
        any
    }

    /// The job of a converted request: planned, unless it asks for a larger time budget than
    /// the node's `plan_timeout` ([`Failure::OverBudget`]) or its answer would be too large
    /// ([`Failure::TooLarge`]).
    fn plan_job(&self, request: S::Request) -> Job<S::Request, S::Answer> {
        if let Some(size) = self.service.answer_size(&request) {
            if let Err(reason) = size.check() {
                return Job::Answer(Box::new(self.service.failure(
                    &self.service.key(&request),
                    Failure::TooLarge,
                    format!("request refused before planning: {reason}"),
                )));
            }
        }
        let limit = self.settings.plan_timeout;
        match self.service.requested_budget(&request) {
            Some(asked) if asked > limit => Job::Answer(Box::new(self.service.failure(
                &self.service.key(&request),
                Failure::OverBudget,
                format!(
                    "time_budget = {} s is over the node's plan_timeout of {} s: a request may \
                     ask for less, not more (send 0 for the node's budget)",
                    asked.as_secs_f64(),
                    limit.as_secs_f64()
                ),
            ))),
            _ => Job::Plan(Box::new(request)),
        }
    }

    /// Queues a job, or answers at once when the queue is full.
    fn submit(&mut self, job: Job<S::Request, S::Answer>, source: &str) {
        let mut key = match &job {
            Job::Plan(r) => self.service.key(r),
            Job::Answer(m) => m.key(),
        };
        // A request id is echoed in the answer and in the log: a long one is refused, and
        // the answer carries its beginning.
        let job = match cut_request_id(&key.request_id) {
            None => job,
            Some(short) => {
                let message = format!(
                    "request_id is {} bytes, over the limit of {MAX_REQUEST_ID_BYTES}; this \
                     answer carries its first {} bytes",
                    key.request_id.len(),
                    short.len()
                );
                key.request_id = short;
                Job::Answer(Box::new(self.service.failure(
                    &key,
                    Failure::TooLarge,
                    message,
                )))
            }
        };
        if self.pending.len() >= self.settings.queue_depth {
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
                        self.settings.queue_depth
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

    /// Publishes one answer on the plan topics and, on success, the trajectory; logs it. An
    /// answer with a sample over [`super::MAX_ANSWER_BYTES`] is replaced by
    /// [`Failure::TooLarge`] (one large sample would block every later one of its topic).
    fn publish(&self, plan: S::Answer) {
        let mut text = answer_text(&plan);
        let plan = match check_answer(&plan, &text, plan.trajectory()) {
            Ok(()) => plan,
            Err(reason) => {
                let failure = self.service.failure(&plan.key(), Failure::TooLarge, reason);
                text = answer_text(&failure);
                failure
            }
        };
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
        let text = StringMsg { data: text };
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

#[cfg(test)]
mod tests {
    use super::{cut_request_id, MAX_REQUEST_ID_BYTES};

    #[test]
    fn long_request_ids_are_cut_at_a_character_boundary() {
        assert_eq!(cut_request_id("job-17"), None);
        assert_eq!(cut_request_id(&"a".repeat(MAX_REQUEST_ID_BYTES)), None);
        let long = format!(
            "{}é{}",
            "a".repeat(MAX_REQUEST_ID_BYTES - 1),
            "b".repeat(10)
        );
        let cut = cut_request_id(&long).unwrap();
        assert_eq!(cut, "a".repeat(MAX_REQUEST_ID_BYTES - 1));
    }
}
