//! A planner node (MJTO, milling, …) started in this process and a client node talking to it:
//! the shared client of every planner's end-to-end test.
//!
//! Every planner node serves `<node>/<noun>_request` and `<node>/<noun>_request_text` and
//! answers on the latched `<node>/<noun>_plan` and `<node>/<noun>_plan_text`; a success also
//! publishes its trajectory on `<node>/joint_trajectory`. A [`Planner`] names one node, a
//! [`PlannerClient`] runs it and talks to it, and [`expect`] checks one answer.

use std::{fmt::Debug, marker::PhantomData, thread::JoinHandle, time::Duration};

use kerf_msgs::{
    msg::{self, CutPlan, GcodePlan, MillPlan},
    std_msgs::StringMsg,
    trajectory_msgs::JointTrajectory,
    RosType,
};
use kerf_ros::{planner::PlanAnswer, qos, KerfNode, RosArgs, RosEnv, StopToken};
use ros2_client::{Publisher, Subscription};
use serde::{de::DeserializeOwned, Serialize};

use super::{client_node, spawn_node, take, QUICK};

/// A planner node's `run(args, env, stop)`, its error as text.
pub type NodeRun = fn(&RosArgs, &RosEnv, StopToken) -> Result<(), String>;

/// One planner node as its tests reach it: requests `Req`, answers `Plan`.
pub struct Planner<Req, Plan> {
    node: &'static str,
    noun: &'static str,
    run: NodeRun,
    messages: PhantomData<fn() -> (Req, Plan)>,
}

impl<Req, Plan> Planner<Req, Plan> {
    /// A planner node.
    ///
    /// # Arguments
    /// * `node` — its fully qualified name, e.g. `/mjto_planner`.
    /// * `noun` — its topics' prefix: `cut` for `cut_request`, `cut_request_text`,
    ///   `cut_plan` and `cut_plan_text`; the client node is `<noun>_client`.
    /// * `run` — the node's `run`.
    pub fn new(node: &'static str, noun: &'static str, run: NodeRun) -> Self {
        Planner {
            node,
            noun,
            run,
            messages: PhantomData,
        }
    }

    /// The node's topic `<noun>_<what>`, fully qualified.
    fn topic(&self, what: &str) -> String {
        format!("{}/{}_{what}", self.node, self.noun)
    }
}

/// The MJTO laser-cutting planner node (`kerf_mjto_planner`).
pub fn mjto() -> Planner<msg::CutRequest, CutPlan> {
    Planner::new("/mjto_planner", "cut", |a, e, s| {
        kerf_mjto_planner::run(a, e, s).map_err(|e| e.to_string())
    })
}

/// The milling planner node (`kerf_milling_planner`).
pub fn mill() -> Planner<msg::MillRequest, MillPlan> {
    Planner::new("/milling_planner", "mill", |a, e, s| {
        kerf_milling_planner::run(a, e, s).map_err(|e| e.to_string())
    })
}

/// The G-code planner node (`kerf_gcode_planner`).
pub fn gcode() -> Planner<msg::GcodeRequest, GcodePlan> {
    Planner::new("/gcode_planner", "gcode", |a, e, s| {
        kerf_gcode_planner::run(a, e, s).map_err(|e| e.to_string())
    })
}

/// An answer message (`CutPlan`, `MillPlan`, …) as the tests read it: what the harness reads
/// of it ([`PlanAnswer`]: request id, status, message, trajectory) and more.
pub trait Answer: PlanAnswer + DeserializeOwned + Debug + PartialEq {
    /// The SUCCESS status.
    const SUCCESS: u8;
    /// What a failure must not carry, for the failure message ("trajectory", "plan").
    const PLANNED: &'static str;
    /// The name of a status value, `None` for an unknown one.
    fn name_of(status: u8) -> Option<&'static str>;
    /// Whether it carries nothing planned (as every failure must).
    fn is_bare(&self) -> bool;
}

/// Implements [`Answer`] for a plan message with the `SUCCESS` constant and `status_name`;
/// `|p| bare` says whether `p` carries nothing planned.
macro_rules! answer {
    ($plan:ty, $planned:literal, |$p:ident| $bare:expr) => {
        impl Answer for $plan {
            const SUCCESS: u8 = <$plan>::SUCCESS;
            const PLANNED: &'static str = $planned;
            fn name_of(status: u8) -> Option<&'static str> {
                <$plan>::status_name(status)
            }
            fn is_bare(&self) -> bool {
                let $p = self;
                $bare
            }
        }
    };
}

answer!(CutPlan, "trajectory", |p| p.trajectory().points.is_empty());
answer!(MillPlan, "plan", |p| p.trajectory().points.is_empty()
    && p.segments.is_empty());
answer!(GcodePlan, "trajectory", |p| p
    .trajectory()
    .points
    .is_empty()
    && p.tool_events.is_empty());

/// Checks an answer: its request id is `id`, its status `status` (compared by name), its
/// message contains every needle, and a failure carries nothing planned.
pub fn expect<P: Answer>(plan: &P, id: &str, status: u8, needles: &[&str]) {
    let name = |s| P::name_of(s).unwrap_or("?");
    assert_eq!(
        (plan.request_id(), name(plan.status())),
        (id, name(status)),
        "{}",
        plan.message()
    );
    for n in needles {
        assert!(
            plan.message().contains(n),
            "{id}: {:?} lacks {n:?}",
            plan.message()
        );
    }
    if status != P::SUCCESS {
        assert!(plan.is_bare(), "{id}: a failure carries no {}", P::PLANNED);
    }
}

/// A planner node running on its own thread plus a client node talking to it.
pub struct PlannerClient<Req: Serialize, Plan> {
    requests: Publisher<Req>,
    texts: Publisher<StringMsg>,
    plans: Subscription<Plan>,
    plan_texts: Subscription<StringMsg>,
    trajectories: Subscription<JointTrajectory>,
    /// Keeps the client node (and its Context) alive; dropped after the endpoints above.
    _client: KerfNode,
    node: &'static str,
    stop: StopToken,
    planner: Option<JoinHandle<Result<(), String>>>,
}

impl<Req: RosType + Serialize + Debug, Plan: Answer> PlannerClient<Req, Plan> {
    /// Starts `planner` on `env` with extra ROS arguments (e.g. `["-p", "queue_depth:=1"]`),
    /// and a client whose request publishers are matched to it.
    pub fn start(planner: &Planner<Req, Plan>, env: &RosEnv, extra: &[&str]) -> Self {
        let mut words: Vec<String> = vec!["--ros-args".into(), "--disable-rosout-logs".into()];
        words.extend(extra.iter().map(|s| s.to_string()));
        let (stop, handle) = spawn_node(env, words, planner.run);
        let mut client = Self::connect(planner, env);
        client.stop = stop;
        client.planner = Some(handle);
        client
    }

    /// A client of `planner` running elsewhere (another process, e.g. `kerf launch
    /// --with-planner`) on `env`: its request publishers matched to it.
    pub fn connect(planner: &Planner<Req, Plan>, env: &RosEnv) -> Self {
        let mut client = client_node(&format!("{}_client", planner.noun), env);
        let (request, request_text) = (planner.topic("request"), planner.topic("request_text"));
        let requests = client
            .publisher(&request, Req::ROS_TYPE, qos::commands())
            .expect("request publisher");
        let texts = client
            .publisher(&request_text, StringMsg::ROS_TYPE, qos::commands())
            .expect("text request publisher");
        let plans = client
            .subscription(&planner.topic("plan"), Plan::ROS_TYPE, qos::latched())
            .expect("plan subscription");
        let plan_texts = client
            .subscription(
                &planner.topic("plan_text"),
                StringMsg::ROS_TYPE,
                qos::latched(),
            )
            .expect("plan text subscription");
        let trajectories = client
            .subscription(
                &format!("{}/joint_trajectory", planner.node),
                JointTrajectory::ROS_TYPE,
                qos::commands(),
            )
            .expect("trajectory subscription");
        // Matching waits longer than QUICK: a parallel test of the same binary may keep both
        // cores busy (policy training), and discovery once took over 30 s in a full run.
        let matching = 3 * QUICK;
        for (matched, topic) in [
            (client.wait_for_subscriber(&requests, matching), request),
            (client.wait_for_subscriber(&texts, matching), request_text),
        ] {
            assert!(matched, "{topic} not matched within {matching:?}");
        }
        PlannerClient {
            requests,
            texts,
            plans,
            plan_texts,
            trajectories,
            _client: client,
            node: planner.node,
            stop: StopToken::new(),
            planner: None,
        }
    }

    /// Starts `planner` on `env` as [`start`](Self::start) does, its trajectories going to
    /// the executor's input (`~/joint_trajectory` remapped to
    /// `/trajectory_executor/joint_trajectory`).
    pub fn start_feeding_executor(planner: &Planner<Req, Plan>, env: &RosEnv) -> Self {
        Self::start(
            planner,
            env,
            &[
                "-r",
                "~/joint_trajectory:=/trajectory_executor/joint_trajectory",
            ],
        )
    }

    /// Publishes a request message.
    pub fn send(&self, m: Req) {
        self.requests
            .publish(m)
            .unwrap_or_else(|e| panic!("publish {}: {e:?}", Req::NAME));
    }

    /// Publishes a text request.
    pub fn send_text(&self, text: &str) {
        self.texts
            .publish(StringMsg { data: text.into() })
            .expect("publish text request");
    }

    /// The next answer on the plan topic, waiting up to `timeout`.
    pub fn next_plan(&self, timeout: Duration) -> Plan {
        take(&self.plans, timeout, Plan::NAME)
    }

    /// The next answer on the plan text topic, parsed from its YAML.
    pub fn next_plan_text(&self) -> Plan {
        let text = take(&self.plan_texts, QUICK, "plan text");
        serde_yaml_ng::from_str(&text.data)
            .unwrap_or_else(|e| panic!("plan text is a {} as YAML: {e}", Plan::NAME))
    }

    /// The next answer, checked with [`expect`], and checked to come as the same answer on
    /// the plan text topic.
    pub fn expect_in_both_forms(
        &self,
        timeout: Duration,
        id: &str,
        status: u8,
        needles: &[&str],
    ) -> Plan {
        let plan = self.next_plan(timeout);
        expect(&plan, id, status, needles);
        assert_eq!(
            self.next_plan_text(),
            plan,
            "{id}: text form of the same answer"
        );
        plan
    }

    /// How many trajectories the node published since the last call.
    pub fn trajectories_received(&self) -> usize {
        let mut n = 0;
        while let Ok(Some(_)) = self.trajectories.take() {
            n += 1;
        }
        n
    }

    /// A burst of `n` requests `request("burst-0")` … `request("burst-<n-1>")` against a node
    /// with a queue of one: every request is answered exactly once, the first with SUCCESS,
    /// each other with SUCCESS or `busy` naming the full queue, and at least one with `busy`.
    ///
    /// # Returns
    /// The `busy` answers.
    pub fn burst_against_a_queue_of_one(
        &self,
        n: usize,
        request: impl Fn(&str) -> Req,
        busy: u8,
        timeout: Duration,
    ) -> Vec<Plan> {
        let ids: Vec<String> = (0..n).map(|i| format!("burst-{i}")).collect();
        for id in &ids {
            self.send(request(id));
        }
        let mut answers: Vec<Plan> = (0..n).map(|_| self.next_plan(timeout)).collect();
        answers.sort_by(|a, b| a.request_id().cmp(b.request_id()));
        // Every request is answered exactly once: nothing is dropped.
        let answered: Vec<&str> = answers.iter().map(|a| a.request_id()).collect();
        assert_eq!(answered, ids.iter().map(String::as_str).collect::<Vec<_>>());
        expect(&answers[0], "burst-0", Plan::SUCCESS, &[]);
        let busy_answers: Vec<Plan> = answers
            .into_iter()
            .skip(1)
            .filter(|a| a.status() != Plan::SUCCESS)
            .collect();
        for a in &busy_answers {
            expect(a, a.request_id(), busy, &["planner busy", "queue_depth 1"]);
        }
        assert!(
            !busy_answers.is_empty(),
            "no request of the burst found the queue full"
        );
        busy_answers
    }

    /// Fails the test if the planner node has stopped.
    pub fn assert_running(&self) {
        let h = self.planner.as_ref().expect("planner handle");
        assert!(!h.is_finished(), "the planner node {} stopped", self.node);
    }

    /// Asks the planner node to stop (its stop token: what Ctrl-C does) without waiting.
    pub fn request_stop(&self) {
        self.stop.stop();
    }

    /// Whether the planner node's thread has ended.
    pub fn has_stopped(&self) -> bool {
        self.planner.as_ref().is_none_or(|h| h.is_finished())
    }

    /// Stops the planner node (it must end cleanly) and starts it again with the same
    /// arguments, keeping this client and its endpoints: what a node restarted under a cell
    /// controller that keeps running sees.
    pub fn restart(&mut self, planner: &Planner<Req, Plan>, env: &RosEnv, extra: &[&str]) {
        self.stop.stop();
        let h = self.planner.take().expect("planner handle");
        h.join()
            .expect("planner thread")
            .expect("planner ends cleanly");
        let mut words: Vec<String> = vec!["--ros-args".into(), "--disable-rosout-logs".into()];
        words.extend(extra.iter().map(|s| s.to_string()));
        let (stop, handle) = spawn_node(env, words, planner.run);
        self.stop = stop;
        self.planner = Some(handle);
        let matching = 3 * QUICK;
        assert!(
            self._client.wait_for_subscriber(&self.texts, matching),
            "the restarted node did not subscribe within {matching:?}"
        );
    }

    /// The next answer within `timeout`, if one comes.
    pub fn try_next_plan(&self, timeout: Duration) -> Option<Plan> {
        let deadline = std::time::Instant::now() + timeout;
        loop {
            if let Ok(Some((plan, _))) = self.plans.take() {
                return Some(plan);
            }
            if std::time::Instant::now() > deadline {
                return None;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    /// Stops the planner (when this client started it); it must end cleanly.
    pub fn finish(mut self) {
        self.stop.stop();
        if let Some(h) = self.planner.take() {
            h.join()
                .expect("planner thread")
                .expect("planner ends cleanly");
        }
    }
}
