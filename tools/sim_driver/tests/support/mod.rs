//! Test support: the `sim_driver` process, and a ros2-client node on loopback DDS that talks
//! to it (its own Context, spinner thread; dropped node → spinner → Context).
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use std::{
    io::{BufRead, BufReader, Read},
    net::Ipv4Addr,
    process::{Child, Command, ExitStatus, Stdio},
    sync::{mpsc, Arc, Mutex},
    thread::JoinHandle,
    time::{Duration, Instant},
};

use kerf_msgs::{
    control_msgs::{
        FollowJointTrajectoryFeedback, FollowJointTrajectoryGoal, FollowJointTrajectoryResult,
    },
    RosType,
};
use ros2_client::{
    action::{ActionClient, ActionClientQosPolicies},
    qos::{Durability, History, Reliability, WhenFull},
    ActionTypeName, Context, MessageTypeName, Name, Node, NodeName, NodeOptions, Publisher,
    QosProfile, ServiceMapping, Subscription,
};
use serde::{de::DeserializeOwned, Serialize};

/// How long a test waits for anything DDS does.
pub const TIMEOUT: Duration = Duration::from_secs(20);

/// The FollowJointTrajectory action client.
pub type Fjt = ActionClient<
    FollowJointTrajectoryGoal,
    FollowJointTrajectoryResult,
    FollowJointTrajectoryFeedback,
>;

/// A running `sim_driver` process on a loopback domain; killed when dropped.
pub struct DriverProcess {
    child: Child,
    stderr: Arc<Mutex<String>>,
    stderr_thread: Option<JoinHandle<()>>,
}

impl DriverProcess {
    /// Starts `sim_driver ARGS` on `domain` (loopback only) and waits for its ready line.
    pub fn start(domain: u16, args: &[&str]) -> DriverProcess {
        let mut child = Command::new(env!("CARGO_BIN_EXE_sim_driver"))
            .args(args)
            .env("ROS_DOMAIN_ID", domain.to_string())
            .env("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
            .env_remove("ROS_STATIC_PEERS")
            .env_remove("RMW_IMPLEMENTATION")
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("start sim_driver");
        let stderr = Arc::new(Mutex::new(String::new()));
        let mut pipe = child.stderr.take().unwrap();
        let sink = Arc::clone(&stderr);
        let stderr_thread = std::thread::spawn(move || {
            let mut buf = [0u8; 4096];
            while let Ok(n) = pipe.read(&mut buf) {
                if n == 0 {
                    break;
                }
                sink.lock()
                    .unwrap()
                    .push_str(&String::from_utf8_lossy(&buf[..n]));
            }
        });
        let stdout = child.stdout.take().unwrap();
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines() {
                let Ok(line) = line else { break };
                let _ = tx.send(line);
            }
        });
        let mut p = DriverProcess {
            child,
            stderr,
            stderr_thread: Some(stderr_thread),
        };
        let line = rx.recv_timeout(TIMEOUT).unwrap_or_else(|_| {
            let status = p.child.try_wait();
            panic!("no ready line ({status:?}); stderr: {}", p.stderr())
        });
        assert!(line.starts_with("sim_driver ready: "), "{line}");
        p
    }

    /// Everything the driver wrote to stderr so far.
    pub fn stderr(&self) -> String {
        self.stderr.lock().unwrap().clone()
    }

    /// Sends `signal` to the process.
    pub fn signal(&self, signal: i32) {
        let pid = libc::pid_t::try_from(self.child.id()).unwrap();
        // SAFETY: kill(2) with the pid of our own child process.
        unsafe { libc::kill(pid, signal) };
    }

    /// Waits for the process to end, at most `timeout`.
    pub fn wait(&mut self, timeout: Duration) -> Option<ExitStatus> {
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(s) = self.child.try_wait().unwrap() {
                if let Some(h) = self.stderr_thread.take() {
                    let _ = h.join();
                }
                return Some(s);
            }
            if Instant::now() >= deadline {
                return None;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// SIGTERM, then the exit status (SIGKILL after 10 s).
    pub fn terminate(&mut self) -> ExitStatus {
        self.signal(libc::SIGTERM);
        match self.wait(Duration::from_secs(10)) {
            Some(s) => s,
            None => panic!(
                "sim_driver did not stop on SIGTERM; stderr: {}",
                self.stderr()
            ),
        }
    }
}

impl Drop for DriverProcess {
    fn drop(&mut self) {
        if self.child.try_wait().ok().flatten().is_none() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

/// Reliable, volatile, keep-last `depth`.
pub fn reliable(depth: usize) -> QosProfile {
    QosProfile::publisher_default()
        .reliability(Reliability::Reliable {
            when_full: WhenFull::DEFAULT,
        })
        .durability(Durability::Volatile)
        .history(History::KeepLast { depth })
}

/// Joins the spinner thread on drop.
struct Spinner(Option<JoinHandle<()>>);

impl Drop for Spinner {
    fn drop(&mut self) {
        if let Some(h) = self.0.take() {
            let _ = h.join();
        }
    }
}

/// A test node on a loopback domain. Endpoints made from it must be dropped before it.
pub struct Client {
    node: Node,
    _spinner: Spinner,
    _context: Context,
}

impl Client {
    /// A node named `name` on `domain`, loopback only.
    pub fn new(domain: u16, name: &str) -> Client {
        let participant = ros2_client::dds::rustdds::DomainParticipantBuilder::new(domain)
            .with_only_networks([Ipv4Addr::LOCALHOST])
            .build()
            .unwrap();
        let context = Context::from_domain_participant(participant).unwrap();
        let mut node = context
            .new_node(
                NodeName::new("/", name).unwrap(),
                NodeOptions::new()
                    .enable_rosout(false)
                    .start_parameter_services(false),
            )
            .unwrap();
        let spinner = node.spinner().unwrap();
        let h = std::thread::spawn(move || {
            let _ = futures::executor::block_on(spinner.spin());
        });
        Client {
            node,
            _spinner: Spinner(Some(h)),
            _context: context,
        }
    }

    fn topic<M: RosType>(
        &mut self,
        topic: &str,
        qos: &QosProfile,
    ) -> ros2_client::dds::rustdds::Topic {
        self.node
            .create_topic(
                &Name::parse(topic).unwrap(),
                MessageTypeName::new(M::PACKAGE, M::NAME),
                qos,
            )
            .unwrap()
    }

    /// A reliable keep-last 10 publisher of `M` on `topic`.
    pub fn publisher<M: RosType + Serialize>(&mut self, topic: &str) -> Publisher<M> {
        let qos = reliable(10);
        let t = self.topic::<M>(topic, &qos);
        self.node.create_publisher(&t, Some(qos)).unwrap()
    }

    /// A reliable keep-last `depth` subscription of `M` on `topic`.
    pub fn subscription<M: RosType + DeserializeOwned + 'static>(
        &mut self,
        topic: &str,
        depth: usize,
    ) -> Subscription<M> {
        let qos = reliable(depth);
        let t = self.topic::<M>(topic, &qos);
        self.node.create_subscription(&t, Some(qos)).unwrap()
    }

    /// A FollowJointTrajectory client of the action `name`, rcl_action's QoS.
    pub fn action_client(&mut self, name: &str) -> Fjt {
        let policies = ActionClientQosPolicies {
            goal_service: reliable(10),
            result_service: reliable(10),
            cancel_service: reliable(10),
            feedback_subscription: reliable(10),
            status_subscription: reliable(1).durability(Durability::TransientLocal),
        };
        self.node
            .create_action_client(
                ServiceMapping::Enhanced,
                &Name::parse(name).unwrap(),
                &ActionTypeName::new("control_msgs", "FollowJointTrajectory"),
                policies,
            )
            .unwrap()
    }

    /// Waits until `p` has matched a subscription (a volatile sample sent before is lost).
    pub fn wait_for_subscriber<M: Serialize>(&self, p: &Publisher<M>) {
        let deadline = Instant::now() + TIMEOUT;
        while p.get_subscription_count(&self.node) == 0 {
            assert!(Instant::now() < deadline, "no subscriber matched");
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    /// Waits until the action's three services have matched the server.
    pub fn wait_for_action_server(&self, c: &Fjt) {
        let deadline = Instant::now() + TIMEOUT;
        loop {
            let all = async {
                futures::join!(
                    c.goal_client().wait_for_service(&self.node),
                    c.cancel_client().wait_for_service(&self.node),
                    c.result_client().wait_for_service(&self.node),
                )
            };
            // ros2-client's waits wake on graph events, which can be dropped: ask again often.
            if block_on_timeout(all, Duration::from_millis(100)).is_some() {
                return;
            }
            assert!(Instant::now() < deadline, "action server not matched");
        }
    }
}

/// Runs `f` on this thread for at most `timeout`.
pub fn block_on_timeout<F: std::future::Future>(f: F, timeout: Duration) -> Option<F::Output> {
    let (tx, rx) = futures::channel::oneshot::channel::<()>();
    let (done, finished) = mpsc::channel::<()>();
    std::thread::spawn(move || {
        if finished.recv_timeout(timeout) == Err(mpsc::RecvTimeoutError::Timeout) {
            let _ = tx.send(());
        }
    });
    let f = std::pin::pin!(f);
    let out = match futures::executor::block_on(futures::future::select(f, rx)) {
        futures::future::Either::Left((out, _)) => Some(out),
        futures::future::Either::Right(_) => None,
    };
    drop(done);
    out
}

/// Takes every sample waiting on `s`.
pub fn drain<M: DeserializeOwned + 'static>(s: &Subscription<M>) -> Vec<M> {
    let mut out = Vec::new();
    while let Some((m, _)) = s.take().unwrap() {
        out.push(m);
    }
    out
}

/// Takes samples from `s` for `span`.
pub fn collect_for<M: DeserializeOwned + 'static>(s: &Subscription<M>, span: Duration) -> Vec<M> {
    let end = Instant::now() + span;
    let mut out = Vec::new();
    while Instant::now() < end {
        out.extend(drain(s));
        std::thread::sleep(Duration::from_millis(1));
    }
    out.extend(drain(s));
    out
}

/// Takes samples from `s` until one satisfies `pred`; returns them all, that one last.
pub fn until<M: DeserializeOwned + 'static>(
    s: &Subscription<M>,
    what: &str,
    mut pred: impl FnMut(&M) -> bool,
) -> Vec<M> {
    let deadline = Instant::now() + TIMEOUT;
    let mut out = Vec::new();
    while Instant::now() < deadline {
        while let Some((m, _)) = s.take().unwrap() {
            let hit = pred(&m);
            out.push(m);
            if hit {
                return out;
            }
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    panic!("timed out waiting for {what} ({} samples seen)", out.len());
}
