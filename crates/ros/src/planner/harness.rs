//! The planner-node loop: requests in (message and text, and goals of the planning action:
//! [`actions`]), one worker in arrival order, one answer per request, latched answers, the
//! trajectory on success, clean shutdown.

mod actions;

use std::{
    collections::VecDeque,
    fmt::Display,
    sync::Arc,
    time::{Duration, Instant},
};

use kerf_isolate::{Outcome, Supervisor, SupervisorSettings};
use kerf_msgs::{
    sensor_msgs::JointState, std_msgs::StringMsg, trajectory_msgs::JointTrajectory, RosType,
};
use ros2_client::Publisher;

use super::{
    action::Origin,
    check_answer, check_text_size, leading_request_id,
    start::{CurrentState, JOINT_STATES_TOPIC},
    work::{HarnessWork, PlanJob, RawRequest},
    AnswerKey, Failure, HarnessSettings, PlanAnswer, PlanningService, HARNESS_PARAMS,
    TRAJECTORY_TOPIC,
};
use crate::{qos, Inbox, KerfNode, Logger, NodeSpec, RosArgs, RosEnv, RosError, StopToken};

/// The system time in ns since the Unix epoch (the clock DDS source timestamps use).
fn now_ns() -> i64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| i64::try_from(d.as_nanos()).unwrap_or(i64::MAX))
        .unwrap_or(0)
}

/// How long after its start a planner node waits for the robot's first joint state before it
/// plans a request whose start may be the robot's current state (`start` left out or
/// `current`): DDS discovery of the executor's `joint_states` writer takes up to a second or two
/// on a busy machine, and a request sent right after a launch must still start where the robot
/// is. After it, such a request plans at once (`start` left out: from the process's first
/// point; `current`: refused, no joint state).
pub const START_STATE_GRACE: Duration = Duration::from_secs(3);

/// How long the node loop sleeps when there is nothing to do.
const POLL: Duration = Duration::from_millis(2);

/// Least time between two returns of freed memory to the system
/// ([`crate::memory::give_back_freed_memory`]), made when the node is idle after answering.
/// Without them a node's RSS rose by 30 MiB over its first 1 500 small requests before it
/// levelled off (the blocks of DDS samples and answer texts freed between live ones;
/// BENCHMARKS.md, "Memory per request").
const TRIM_EVERY: Duration = Duration::from_secs(1);

/// How long a stopping node keeps its writers after answering requests at
/// shutdown. Why: ros2-client 0.12's `Publisher` offers no wait for
/// acknowledgements, and dropping a reliable writer right after a write lost
/// the answer about one time in four over loopback (`tests/deadline_e2e.rs`,
/// `stopping_mid_plan_cancels_and_answers_it`). The linger covers the write
/// itself and one repair: RustDDS's reliable writers announce their samples
/// every second (`HEARTBEAT_PERIOD_SLOW`), and a reader asks for a lost one
/// in reply.
pub const SHUTDOWN_LINGER: Duration = Duration::from_millis(1500);

/// Starts a planner node and serves until its stop token (or Ctrl-C) stops it.
///
/// # Arguments
/// * `default_name`, `known_params` — the node's default name (in namespace `/`) and the
///   parameters it reads (others are refused at start-up).
/// * `args`, `env`, `stop` — command line, environment, stop token.
/// * `setup` — reads the node's parameters and builds the service; returns it with the
///   harness's settings ([`HarnessSettings::from_params`]: `queue_depth`, requests waiting or
///   being planned before new ones are answered [`Failure::Busy`]; `plan_timeout`, the time
///   budget of every plan; `plan_memory`, its memory budget). Its error is logged ("cannot
///   start: …") and returned. The harness's parameters ([`HARNESS_PARAMS`]) are known to the
///   node whether `known_params` lists them or not.
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
    // The harness's own parameters are known to every planner node, listed or not.
    let mut known: Vec<&str> = known_params.to_vec();
    known.extend(HARNESS_PARAMS.iter().filter(|p| !known_params.contains(p)));
    let spec = NodeSpec {
        default_name,
        default_namespace: "/",
        known_params: &known,
    };
    let node = KerfNode::new(spec, args, env, stop)?;
    let (service, settings) = match setup(&node) {
        Ok(s) => s,
        Err(e) => {
            node.logger().error(&format!("cannot start: {e}"));
            return Err(e);
        }
    };
    let mut n = PlannerNode::new(node, env, service, settings)?;
    n.spin();
    Ok(())
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

/// A request waiting for the worker, or an answer waiting for its turn (answers leave in
/// arrival order).
enum Queued<M, A> {
    /// Plan it: the request as received, its key, and its time limit.
    Plan {
        key: AnswerKey,
        raw: RawRequest<M>,
        limit: Duration,
        /// Whether its start may be the robot's current state (`start` left out or
        /// `current`): it waits for the robot's first joint state, up to
        /// [`START_STATE_GRACE`] after the node's start.
        wants_state: bool,
    },
    /// Already answered (conversion error, refused before planning).
    Answer(Box<A>),
}

/// A queue entry of a node serving `S`, with its origin.
type Entry<S> = (
    Queued<<S as PlanningService>::RequestMsg, <S as PlanningService>::Answer>,
    Origin,
);

/// The job the worker process runs now.
struct Running {
    id: u64,
    key: AnswerKey,
    /// Who asked: a request topic or a goal.
    origin: Origin,
    /// When it was handed to the worker, and its time limit (a goal's progress).
    started: Instant,
    limit: Duration,
    /// When its goal's client canceled it ([`actions::ACTION_CANCEL_GRACE`]).
    canceled_at: Option<Instant>,
}

/// The node's state. Fields drop in declaration order: DDS endpoints and the worker process
/// first, `node` (and its Context) last.
struct PlannerNode<S: PlanningService> {
    requests: Inbox<S::RequestMsg>,
    text_requests: Inbox<StringMsg>,
    plans: Publisher<S::Answer>,
    plan_texts: Publisher<StringMsg>,
    trajectories: Publisher<JointTrajectory>,
    /// The robot's joint state (the trajectory executor's `joint_states`), for plans that
    /// start where the robot is.
    joint_states: Inbox<JointState>,
    /// The latest joint state and when it arrived.
    current: Option<(JointState, std::time::Instant)>,
    /// `joint_states` resolved, for messages.
    joint_states_topic: String,
    /// Until when a plan that may start from the robot's state waits for its first one.
    state_grace_until: Instant,
    /// The planning action: server, goals, executor client.
    actions: actions::ActionSide<S>,
    supervisor: Supervisor<HarnessWork<S>>,
    /// The worker's work, for a fresh worker when a cancelled plan's worker is stopped.
    work: Arc<HarnessWork<S>>,
    service: Arc<S>,
    /// Requests and answers in arrival order, behind the running job, with their origin.
    queue: VecDeque<Entry<S>>,
    running: Option<Running>,
    next_id: u64,
    /// When the node subscribed to its requests (ns since the epoch): older requests are
    /// not answered (requests are not durable).
    started_ns: i64,
    settings: HarnessSettings,
    /// Whether an answer was published since freed memory was last returned, and when that was.
    answered_since_trim: std::cell::Cell<bool>,
    trimmed_at: std::time::Instant,
    log: Logger,
    node: KerfNode,
}

impl<S: PlanningService> PlannerNode<S> {
    fn new(
        mut node: KerfNode,
        env: &RosEnv,
        service: S,
        settings: HarnessSettings,
    ) -> Result<Self, RosError> {
        let topics = service.topics();
        let started_ns = now_ns();
        let requests = node.inbox(&topics.request, S::RequestMsg::ROS_TYPE, qos::commands())?;
        let text_requests =
            node.inbox(&topics.request_text, StringMsg::ROS_TYPE, qos::commands())?;
        // Latched, so `kerf echo --transient-local` shows the last answers.
        let plans = node.publisher(&topics.plan, S::Answer::ROS_TYPE, qos::latched())?;
        let plan_texts = node.publisher(&topics.plan_text, StringMsg::ROS_TYPE, qos::latched())?;
        // Volatile: a late (restarted) executor must never receive an old plan.
        let trajectories =
            node.publisher(TRAJECTORY_TOPIC, JointTrajectory::ROS_TYPE, qos::commands())?;
        let joint_states = node.inbox(JOINT_STATES_TOPIC, JointState::ROS_TYPE, qos::state())?;
        let joint_states_topic = node.resolve(JOINT_STATES_TOPIC)?;
        let plan_topic = node.resolve(&topics.plan)?;
        let actions = actions::ActionSide::new(
            &mut node,
            topics.noun,
            &settings.execute_action,
            env.range,
            plan_topic,
        )?;
        let log = node.logger();
        settings.check_reach(service.approach_limits())?;
        let service = Arc::new(service);
        let work = Arc::new(HarnessWork {
            service: Arc::clone(&service),
            framing: settings.framing.clone(),
        });
        let mut supervisor = Supervisor::new(
            Arc::clone(&work),
            SupervisorSettings::new(settings.plan_memory),
        );
        // The worker is forked now, with the service loaded: the first request does not wait.
        supervisor.warm().map_err(|e| RosError::Dds {
            what: "planner worker process".into(),
            reason: e.to_string(),
        })?;
        log.info(&format!(
            "serving {} requests on {} and {} and goals on {} (executed on {}); plans on {}, \
             trajectories on {}; {}; queue_depth {}, plan_timeout {} s, plan_memory {} (plans \
             run in worker process {})",
            topics.noun,
            node.resolve(&topics.request)?,
            node.resolve(&topics.request_text)?,
            actions.name,
            actions.execute_action,
            node.resolve(&topics.plan)?,
            node.resolve(TRAJECTORY_TOPIC)?,
            service.startup_note(),
            settings.queue_depth,
            settings.plan_timeout.as_secs_f64(),
            kerf_budget::format_bytes(settings.plan_memory),
            supervisor.worker_pid().unwrap_or(0),
        ));
        Ok(Self {
            requests,
            text_requests,
            plans,
            plan_texts,
            trajectories,
            joint_states,
            current: None,
            joint_states_topic,
            state_grace_until: Instant::now() + START_STATE_GRACE,
            actions,
            supervisor,
            work,
            service,
            queue: VecDeque::new(),
            running: None,
            next_id: 0,
            started_ns,
            settings,
            answered_since_trim: std::cell::Cell::new(false),
            trimmed_at: std::time::Instant::now(),
            log,
            node,
        })
    }

    /// Requests waiting or being planned.
    fn pending(&self) -> usize {
        self.queue.len() + usize::from(self.running.is_some())
    }

    fn spin(&mut self) {
        while !self.node.should_stop() {
            self.poll_joint_states();
            let mut busy = self.poll_requests();
            busy |= self.poll_text_requests();
            busy |= self.poll_action();
            busy |= self.advance();
            if !busy {
                self.give_back_memory_when_idle();
                std::thread::sleep(POLL);
            }
        }
        self.shut_down();
    }

    /// Keeps the latest joint state of the robot (an unreadable sample is logged and left out).
    fn poll_joint_states(&mut self) {
        while let Some(sample) = self.joint_states.try_recv() {
            match sample {
                Ok(state) => self.current = Some((state, std::time::Instant::now())),
                Err(e) => self.log.warn(&format!(
                    "unreadable joint state on {}: {e}",
                    self.joint_states_topic
                )),
            }
        }
    }

    /// The robot's latest joint state as the worker takes it.
    fn current_state(&self) -> Option<CurrentState> {
        self.current.as_ref().map(|(state, at)| CurrentState {
            names: state.name.clone(),
            positions: state.position.clone(),
            velocities: state.velocity.clone(),
            age: at.elapsed().as_secs_f64(),
            topic: self.joint_states_topic.clone(),
        })
    }

    /// Returns freed memory to the system when nothing is pending, answers were published since
    /// the last return, and [`TRIM_EVERY`] has passed: the node's RSS then stays where it
    /// was after its first requests.
    fn give_back_memory_when_idle(&mut self) {
        if self.pending() == 0
            && self.answered_since_trim.get()
            && self.trimmed_at.elapsed() >= TRIM_EVERY
        {
            crate::memory::give_back_freed_memory();
            self.answered_since_trim.set(false);
            self.trimmed_at = std::time::Instant::now();
        }
    }

    /// The plan in progress (if any) is cancelled through its budget and answered (or, when it
    /// does not answer within the cancel grace, its worker is stopped and the harness answers
    /// it); queued requests are answered "stopped" without planning: no request is left
    /// without an answer, and the node stops within 2 s whatever it plans. Goals end with
    /// their answers (ABORTED), executions are cancelled on the executor, and while the node
    /// lingers the action answers result requests and ends new goals at once.
    fn shut_down(&mut self) {
        let answered_at_shutdown = self.pending() > 0 || self.actions_active();
        // Goals arriving from now on end at once; executions are cancelled on the executor.
        self.stop_actions();
        if answered_at_shutdown {
            self.log.warn(&format!(
                "shutting down: cancelling the plan in progress and answering {} request(s)",
                self.pending()
            ));
        }
        if self.running.is_some() {
            self.supervisor.cancel();
            while self.running.is_some() {
                if !self.poll_worker() {
                    std::thread::sleep(Duration::from_millis(1));
                }
            }
        }
        while let Some((q, origin)) = self.queue.pop_front() {
            let answer = match q {
                Queued::Answer(a) => *a,
                Queued::Plan { key, .. } => self.service.failure(
                    &key,
                    Failure::Stopped,
                    "the planner node stopped before planning this request".into(),
                ),
            };
            self.publish_from(answer, origin);
        }
        if answered_at_shutdown {
            // Let the reliable writers deliver (and repair) the answers just written, while
            // the action answers result requests, ends new goals and sees executions end.
            self.linger_actions(SHUTDOWN_LINGER);
        }
        self.log.info("shutting down");
    }

    /// An answer for a sample that could not be read.
    fn unreadable(&self, what: &str, e: String) -> Queued<S::RequestMsg, S::Answer> {
        Queued::Answer(Box::new(self.service.failure(
            &AnswerKey::default(),
            Failure::Unreadable,
            format!("could not read a {what} sample: {e}"),
        )))
    }

    /// Whether a request stamped `stamp` was published before this node subscribed: such a
    /// sample is a writer's history replayed to a new reader (RustDDS replays a writer's
    /// keep-last history to a volatile reader that matches later), and it was answered by an
    /// earlier run of the node, or by no node at all. Requests are not durable: it is logged
    /// and not answered, so a restarted planner never answers a request twice.
    fn published_before_start(&self, stamp: Option<i64>, what: &str) -> bool {
        match stamp {
            Some(t) if t < self.started_ns => {
                self.log.warn(&format!(
                    "a {what} request not answered: published {:.3} s before this node \
                     subscribed (requests are not durable: a request from before a restart \
                     was answered then, or by no node)",
                    (self.started_ns - t) as f64 * 1e-9
                ));
                true
            }
            _ => false,
        }
    }

    /// Reads the request message topic; `true` if anything was read.
    fn poll_requests(&mut self) -> bool {
        let mut any = false;
        while let Some(received) = self.requests.try_recv_stamped() {
            any = true;
            let queued = match received {
                Ok((_, stamp)) if self.published_before_start(stamp, S::RequestMsg::NAME) => {
                    continue
                }
                Ok((m, _)) => self.queued_msg(m, "message"),
                Err(e) => self.unreadable(S::RequestMsg::NAME, e),
            };
            self.submit(queued);
        }
        any
    }

    /// Reads the text request topic; `true` if anything was read.
    fn poll_text_requests(&mut self) -> bool {
        let mut any = false;
        while let Some(received) = self.text_requests.try_recv_stamped() {
            any = true;
            let queued = match received {
                Ok((_, stamp)) if self.published_before_start(stamp, "text") => continue,
                Ok((m, _)) => match check_text_size(&m.data) {
                    Err(reason) => Queued::Answer(Box::new(self.service.failure(
                        &AnswerKey {
                            request_id: leading_request_id(&m.data),
                            label: String::new(),
                        },
                        Failure::Unreadable,
                        reason,
                    ))),
                    Ok(()) => match self.service.request_from_text(&m.data) {
                        Ok(r) => self.plan_job(r, RawRequest::Text(m.data), "text"),
                        Err(answer) => Queued::Answer(answer),
                    },
                },
                Err(e) => self.unreadable("text request", e),
            };
            self.submit(queued);
        }
        any
    }

    /// The queue entry of a converted request: planned, unless it asks for a larger time
    /// budget than the node's `plan_timeout` ([`Failure::OverBudget`]) or its answer would be
    /// too large ([`Failure::TooLarge`]). The converted request itself is dropped: the worker
    /// converts `raw` again.
    fn plan_job(
        &self,
        request: S::Request,
        raw: RawRequest<S::RequestMsg>,
        source: &str,
    ) -> Queued<S::RequestMsg, S::Answer> {
        let key = self.service.key(&request);
        if let Some(size) = self.service.answer_size(&request) {
            if let Err(reason) = size.check() {
                return Queued::Answer(Box::new(self.service.failure(
                    &key,
                    Failure::TooLarge,
                    format!("request refused before planning: {reason}"),
                )));
            }
        }
        let node_limit = self.settings.plan_timeout;
        let limit = match self.service.requested_budget(&request) {
            Some(asked) if asked > node_limit => {
                return Queued::Answer(Box::new(self.service.failure(
                    &key,
                    Failure::OverBudget,
                    format!(
                        "time_budget = {} s is over the node's plan_timeout of {} s: a request \
                         may ask for less, not more (send 0 for the node's budget)",
                        asked.as_secs_f64(),
                        node_limit.as_secs_f64()
                    ),
                )))
            }
            Some(asked) => asked,
            None => node_limit,
        };
        if cut_request_id(&key.request_id).is_none() {
            self.log.info(&format!(
                "request '{}' ({source}): {}, queued behind {} other(s)",
                key.request_id,
                self.service.describe(&request),
                self.pending()
            ));
        }
        let wants_state = matches!(
            self.service.start_of(&request),
            kerf_approach::StartSpec::Default | kerf_approach::StartSpec::Current
        );
        Queued::Plan {
            key,
            raw,
            limit,
            wants_state,
        }
    }

    /// Queues an entry from a request topic, or answers at once when the queue is full.
    fn submit(&mut self, queued: Queued<S::RequestMsg, S::Answer>) {
        self.submit_from(queued, Origin::Topic);
    }

    /// Queues an entry, or answers at once when the queue is full.
    fn submit_from(&mut self, queued: Queued<S::RequestMsg, S::Answer>, origin: Origin) {
        let mut key = match &queued {
            Queued::Plan { key, .. } => key.clone(),
            Queued::Answer(m) => m.key(),
        };
        // A request id is echoed in the answer and in the log: a long one is refused, and
        // the answer carries its beginning.
        let queued = match cut_request_id(&key.request_id) {
            None => queued,
            Some(short) => {
                let message = format!(
                    "request_id is {} bytes, over the limit of {MAX_REQUEST_ID_BYTES}; this \
                     answer carries its first {} bytes",
                    key.request_id.len(),
                    short.len()
                );
                key.request_id = short;
                Queued::Answer(Box::new(self.service.failure(
                    &key,
                    Failure::TooLarge,
                    message,
                )))
            }
        };
        if self.pending() >= self.settings.queue_depth {
            let answer = match queued {
                // Already failed: its own status says more than "busy".
                Queued::Answer(m) => *m,
                Queued::Plan { .. } => self.service.failure(
                    &key,
                    Failure::Busy,
                    format!(
                        "planner busy: {} request(s) waiting or being planned (queue_depth {}); \
                         request refused, send it again later",
                        self.pending(),
                        self.settings.queue_depth
                    ),
                ),
            };
            self.publish_from(answer, origin);
            return;
        }
        self.queue.push_back((queued, origin));
    }

    /// Publishes the running job's answer when it has one; `true` if it did.
    fn poll_worker(&mut self) -> bool {
        let Some((id, outcome)) = self.supervisor.poll() else {
            return false;
        };
        let Some(running) = self.running.take() else {
            return false;
        };
        if running.id != id {
            self.log.error(&format!(
                "the worker answered job {id}, job {} was running",
                running.id
            ));
        }
        let answer = if running.canceled_at.is_some() {
            self.canceled_answer(&running, matches!(outcome, Outcome::Stopped))
        } else {
            self.answer_of(&running.key, outcome)
        };
        self.publish_from(answer, running.origin);
        true
    }

    /// Stops the worker process now (SIGKILL, reaped) and puts a fresh supervisor in its
    /// place; the next plan forks a new worker.
    fn replace_worker(&mut self) {
        let settings = self.supervisor.settings();
        self.supervisor = Supervisor::new(Arc::clone(&self.work), settings);
    }

    /// The answer of a finished job.
    fn answer_of(&self, key: &AnswerKey, outcome: Outcome<S::Answer>) -> S::Answer {
        let s = &self.service;
        match outcome {
            Outcome::Answered(a) => a,
            Outcome::Panicked { message } => s.failure(
                key,
                Failure::Panicked,
                format!("the planner failed unexpectedly (panic: {message})"),
            ),
            Outcome::TimedOut { limit, elapsed } => s.failure(
                key,
                Failure::Timeout,
                format!(
                    "time budget of {:.3} s exhausted: the plan had not ended {:.3} s after it \
                     began and was stopped (its worker process was replaced); the request was \
                     not planned (simplify it, or ask for a larger budget up to the node's \
                     plan_timeout)",
                    limit.as_secs_f64(),
                    elapsed.as_secs_f64()
                ),
            ),
            Outcome::OverMemory { limit, grown } => s.failure(
                key,
                Failure::ResourceLimit,
                format!(
                    "memory budget of {} exceeded: the plan's working memory grew by {} and the \
                     plan was stopped (its worker process was replaced); the request was not \
                     planned (simplify it, or raise the node's plan_memory)",
                    kerf_budget::format_bytes(limit),
                    kerf_budget::format_bytes(grown)
                ),
            ),
            Outcome::Crashed { reason } if reason.contains("SIGABRT") => s.failure(
                key,
                Failure::ResourceLimit,
                format!(
                    "the plan's worker process aborted ({reason}); with the node's plan_memory \
                     of {} this is an allocation past its address-space backstop; the request \
                     was not planned",
                    kerf_budget::format_bytes(self.settings.plan_memory)
                ),
            ),
            Outcome::Crashed { reason } => s.failure(
                key,
                Failure::Panicked,
                format!("the planner failed unexpectedly: {reason}; its worker was replaced"),
            ),
            Outcome::Stopped => s.failure(
                key,
                Failure::Stopped,
                "planning cancelled: the planner node is stopping (the plan did not reach a \
                 budget check in time and its worker process was stopped)"
                    .into(),
            ),
        }
    }

    /// Moves the queue on: publishes a finished job's answer, passes answered entries through
    /// and hands the next plan to the worker; `true` if anything happened.
    fn advance(&mut self) -> bool {
        let mut any = self.running.is_some() && self.poll_worker();
        while self.running.is_none() {
            // A goal that executes waits for an earlier goal's execution to end.
            if self.queue.front().is_some_and(|(q, o)| {
                matches!(q, Queued::Plan { .. }) && self.actions.must_wait(*o)
            }) {
                break;
            }
            // Right after start-up the robot's joint state may not have arrived yet (DDS
            // discovery): a plan that would start from it waits for it, a little.
            if self.current.is_none()
                && self.state_grace_until > Instant::now()
                && self.queue.front().is_some_and(|(q, _)| {
                    matches!(
                        q,
                        Queued::Plan {
                            wants_state: true,
                            ..
                        }
                    )
                })
            {
                break;
            }
            let Some((next, origin)) = self.queue.pop_front() else {
                break;
            };
            any = true;
            match next {
                Queued::Answer(a) => self.publish_from(*a, origin),
                Queued::Plan {
                    key, raw, limit, ..
                } => {
                    let id = self.next_id;
                    self.next_id += 1;
                    // The robot's state when its plan begins: a request queued behind others
                    // starts where the robot is then.
                    self.poll_joint_states();
                    let job = PlanJob {
                        raw,
                        current: self.current_state(),
                    };
                    match self.supervisor.submit(id, &job, limit) {
                        Ok(()) => {
                            self.running = Some(Running {
                                id,
                                key,
                                origin,
                                started: Instant::now(),
                                limit,
                                canceled_at: None,
                            });
                            self.goal_planning(origin);
                        }
                        Err(e) => {
                            let answer = self.service.failure(
                                &key,
                                Failure::Panicked,
                                format!("the plan could not be started: {e}"),
                            );
                            self.publish_from(answer, origin);
                        }
                    }
                }
            }
        }
        any
    }

    /// Publishes one answer on the plan topics and, on success of a topic request, the
    /// trajectory; logs it; a goal's answer then ends the goal or starts its execution
    /// ([`Self::goal_answered`]). An answer with a sample over [`super::MAX_ANSWER_BYTES`] is
    /// replaced by [`Failure::TooLarge`] (one large sample would block every later one of its
    /// topic).
    fn publish_from(&mut self, plan: S::Answer, origin: Origin) {
        self.answered_since_trim.set(true);
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
            // A goal's trajectory runs only when the goal says so (`execute`).
            if origin == Origin::Topic {
                if let Err(e) = self.trajectories.publish(plan.trajectory().clone()) {
                    self.log
                        .error(&format!("request '{id}': trajectory not published: {e}"));
                }
            }
        } else {
            self.log.warn(&format!(
                "request '{id}' {}: {}",
                plan.status_name(),
                plan.message()
            ));
        }
        let text = StringMsg { data: text };
        let for_goal = match origin {
            Origin::Goal(goal) => Some((goal, plan.clone())),
            Origin::Topic => None,
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
        if let Some((goal, plan)) = for_goal {
            self.goal_answered(goal, plan);
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
