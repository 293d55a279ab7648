//! [`KerfNode`]: one ROS 2 node with its own Context, spinner thread, parameters, names and logger.
//!
//! ros2-client loses events when two spinning nodes share a Context, so every node owns one.
//! On drop the node is dropped first, then its spinner thread is joined, then the Context,
//! the order ros2-client needs for a clean shutdown.

use std::thread::JoinHandle;

use ros2_client::{
    action::{ActionClient, ActionClientQosPolicies, ActionServer},
    dds::rustdds::{policy::ResourceLimits, QosPolicies, QosPolicyBuilder, Topic, TopicKind},
    qos::History,
    ActionTypeName, Client, Context, Message, MessageTypeName, Name, Node, NodeName, NodeOptions,
    Publisher, QosProfile, Server, ServiceMapping, ServiceTypeName, Subscription,
};
use serde::{de::DeserializeOwned, Serialize};

use crate::{
    names, qos, Inbox, LogLevel, Logger, Params, RosArgs, RosEnv, RosError, StopToken, Streamer,
};

/// What a node binary declares about itself.
#[derive(Debug, Clone, Copy)]
pub struct NodeSpec<'a> {
    /// Base name before `__node:=` remapping.
    pub default_name: &'a str,
    /// Namespace before `__ns:=` remapping.
    pub default_namespace: &'a str,
    /// Parameter names the node reads; `prefix.*` admits a group. Others are refused.
    pub known_params: &'a [&'a str],
}

/// A running ROS 2 node.
pub struct KerfNode {
    node: Option<Node>,
    spinner: Option<JoinHandle<()>>,
    context: Option<Context>,
    name: String,
    namespace: String,
    remaps: Vec<names::Remap>,
    params: Params,
    logger: Logger,
    stop: StopToken,
    service_mapping: ServiceMapping,
}

/// Splits `pkg/kind/Name` and checks the kind.
fn split_type<'t>(ros_type: &'t str, kind: &str) -> Result<(&'t str, &'t str), RosError> {
    let parts: Vec<&str> = ros_type.split('/').collect();
    match parts.as_slice() {
        [pkg, k, name] if *k == kind && !pkg.is_empty() && !name.is_empty() => Ok((pkg, name)),
        _ => Err(RosError::Name {
            name: ros_type.into(),
            reason: format!("expected a type name of the form package/{kind}/Name"),
        }),
    }
}

fn dds_err(what: String) -> impl FnOnce(ros2_client::CreateError) -> RosError {
    move |e| RosError::Dds {
        what,
        reason: e.to_string(),
    }
}

impl KerfNode {
    /// A plain node named `name` in `/`: no parameters, no rosout, no ROS arguments, its own
    /// stop token (the client node of a tool, a test or a bench).
    ///
    /// # Errors
    /// As [`Self::new`]: a bad name or a DDS failure.
    pub fn client(name: &str, env: &RosEnv) -> Result<Self, RosError> {
        Self::new(
            NodeSpec {
                default_name: name,
                default_namespace: "/",
                known_params: &[],
            },
            &RosArgs {
                rosout_logs: false,
                ..RosArgs::default()
            },
            env,
            StopToken::new(),
        )
    }

    /// Creates the node from the process's ROS arguments and environment.
    ///
    /// # Arguments
    /// * `spec` – default name/namespace and the parameters the node knows.
    /// * `args` – parsed `--ros-args`; `env` – `ROS_DOMAIN_ID` and discovery range.
    /// * `stop` – the token that stops this node.
    ///
    /// # Returns
    /// The node, or an error for a bad name, an unknown or malformed parameter, or a DDS failure.
    pub fn new(
        spec: NodeSpec<'_>,
        args: &RosArgs,
        env: &RosEnv,
        stop: StopToken,
    ) -> Result<Self, RosError> {
        let name = args.node_name(spec.default_name)?;
        let namespace = args.namespace(spec.default_name, spec.default_namespace)?;
        let fqn = if namespace == "/" {
            format!("/{name}")
        } else {
            format!("{namespace}/{name}")
        };
        let params = args.params_for(&fqn, &name)?;
        params.reject_unknown(spec.known_params)?;

        let context = env.create_context()?;
        // Parameters are declared (and validated) while the node is built; after that they are
        // read-only: `ros2 param set` is refused with a reason.
        let started = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        let started_v = std::sync::Arc::clone(&started);
        let mut options = NodeOptions::new()
            .enable_rosout(args.rosout_logs)
            .start_parameter_services(true)
            .parameter_validator(Box::new(move |name: &str, _| {
                if started_v.load(std::sync::atomic::Ordering::SeqCst) {
                    Err(format!(
                        "kerf node parameters are read at start-up; restart the node to change '{name}'"
                    ))
                } else {
                    Ok(())
                }
            }));
        for (k, v) in params.iter() {
            options = options.declare_parameter(k, v.to_ros());
        }
        let node_name = NodeName::new(&namespace, &name).map_err(|e| RosError::Name {
            name: fqn.clone(),
            reason: format!("{e:?}"),
        })?;
        let mut node = context
            .new_node(node_name, options)
            .map_err(|e| RosError::Dds {
                what: format!("node {fqn}"),
                reason: format!("{e:?}"),
            })?;
        let spinner = node
            .spinner()
            .map_err(dds_err(format!("spinner of {fqn}")))?;
        let spin_thread = std::thread::Builder::new()
            .name(format!("spin-{name}"))
            .spawn(move || {
                if let Err(e) = futures::executor::block_on(spinner.spin()) {
                    eprintln!("kerf: spinner stopped with an error: {e:?}");
                }
            })
            .map_err(|e| RosError::Dds {
                what: "spinner thread".into(),
                reason: e.to_string(),
            })?;
        let logger_name = fqn.trim_start_matches('/').replace('/', ".");
        let logger = Logger::new(
            &logger_name,
            args.rosout_logs.then(|| node.logging_handle()),
            args.log_level.unwrap_or(LogLevel::Info),
            args.stdout_logs,
        );
        Ok(Self {
            node: Some(node),
            spinner: Some(spin_thread),
            context: Some(context),
            name,
            namespace,
            remaps: args.remaps.clone(),
            params,
            logger,
            stop,
            service_mapping: env.service_mapping,
        })
    }

    /// The ros2-client node (`None` only while the node is being dropped).
    fn node_mut(&mut self) -> Result<&mut Node, RosError> {
        self.node.as_mut().ok_or_else(|| RosError::Dds {
            what: "an endpoint".into(),
            reason: "the node is shutting down".into(),
        })
    }

    /// Node base name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Node namespace (`/` or `/a/b`).
    pub fn namespace(&self) -> &str {
        &self.namespace
    }

    /// Fully qualified node name.
    pub fn fqn(&self) -> String {
        names::expand("~", &self.namespace, &self.name).unwrap_or_else(|_| self.name.clone())
    }

    /// The node's parameters.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The node's logger (stderr and `/rosout`).
    pub fn logger(&self) -> Logger {
        self.logger.clone()
    }

    /// The node's stop token.
    pub fn stop_token(&self) -> StopToken {
        self.stop.clone()
    }

    /// Whether the node should stop (its token, or Ctrl-C).
    pub fn should_stop(&self) -> bool {
        self.stop.is_stopped()
    }

    /// Topics with a discovered publisher (DDS writer) on the domain: (fully qualified ROS
    /// name, DDS type name), e.g. `("/joint_states", "sensor_msgs::msg::dds_::JointState_")`.
    /// Only ROS topics (`rt/…`) are listed; this node's own writers are included.
    pub fn discovered_topics(&self) -> Vec<(String, String)> {
        let Some(c) = self.context.as_ref() else {
            return Vec::new();
        };
        ros_topics(
            c.domain_participant()
                .discovered_writers()
                .into_iter()
                .map(|w| {
                    let t = w.publication_topic_data;
                    (t.topic_name, t.type_name)
                }),
        )
    }

    /// Topics with a discovered subscription (DDS reader) on the domain, as
    /// [`KerfNode::discovered_topics`] lists publishers: what `kerf pub` can publish to.
    pub fn discovered_subscriptions(&self) -> Vec<(String, String)> {
        let Some(c) = self.context.as_ref() else {
            return Vec::new();
        };
        ros_topics(
            c.domain_participant()
                .discovered_readers()
                .into_iter()
                .map(|r| {
                    let t = r.subscription_topic_data;
                    (t.topic_name().clone(), t.type_name().clone())
                }),
        )
    }

    /// How many DDS readers of the ROS topic `topic` (fully qualified, e.g. `/joint_states`)
    /// of other participants this node's participant knows on the domain (its own are not
    /// counted). A reader whose participant died stays counted until that participant's
    /// lease ends, as it stays matched to every writer of the topic.
    pub fn discovered_reader_count(&self, topic: &str) -> usize {
        let Some(c) = self.context.as_ref() else {
            return 0;
        };
        let dds_name = format!("rt{topic}");
        c.domain_participant()
            .discovered_readers()
            .iter()
            .filter(|r| *r.subscription_topic_data.topic_name() == dds_name)
            .count()
    }

    /// Expands and remaps a topic or service name as this node sees it.
    pub fn resolve(&self, name: &str) -> Result<String, RosError> {
        names::resolve(name, &self.namespace, &self.name, &self.remaps)
    }

    fn ros_name(&self, name: &str) -> Result<Name, RosError> {
        let full = self.resolve(name)?;
        Name::parse(&full).map_err(|e| RosError::Name {
            name: full.clone(),
            reason: format!("{e:?}"),
        })
    }

    /// Creates a publisher on `topic` (e.g. `~/joint_command`, `/joint_states`).
    ///
    /// # Arguments
    /// * `ros_type` – `package/msg/Name`, e.g. `sensor_msgs/msg/JointState`.
    pub fn publisher<M: Serialize>(
        &mut self,
        topic: &str,
        ros_type: &str,
        qos: QosProfile,
    ) -> Result<Publisher<M>, RosError> {
        let (pkg, ty) = split_type(ros_type, "msg")?;
        let name = self.ros_name(topic)?;
        let node = self.node_mut()?;
        let t = node
            .create_topic(&name, MessageTypeName::new(pkg, ty), &qos)
            .map_err(dds_err(format!("topic {name}")))?;
        node.create_publisher(&t, Some(qos))
            .map_err(dds_err(format!("publisher on {name}")))
    }

    /// Creates a publisher on `topic` that runs on its own thread behind a queue of `capacity`
    /// samples ([`Streamer`]): publishing never blocks the caller.
    ///
    /// Its DDS writer's send window is [`qos::send_window`]`(rate_hz)` samples, so that a
    /// reader that stops acknowledging (its process died or stopped) is dropped by its
    /// participant's lease before the window fills: the other readers never see it (the
    /// [`qos`] module docs).
    ///
    /// # Arguments
    /// * `rate_hz` – how often the stream is published (Hz).
    ///
    /// # Errors
    /// A bad topic or type name, a `rate_hz` out of range (named), or a DDS failure.
    pub fn streamer<M: Serialize + Send + 'static>(
        &mut self,
        topic: &str,
        ros_type: &str,
        qos: QosProfile,
        capacity: usize,
        rate_hz: f64,
    ) -> Result<Streamer<M>, RosError> {
        let window = qos::send_window(rate_hz).map_err(|reason| RosError::Dds {
            what: format!("publisher on {topic}"),
            reason,
        })?;
        let (pkg, ty) = split_type(ros_type, "msg")?;
        let name = self.ros_name(topic)?;
        let t = self.limited_topic(&name, MessageTypeName::new(pkg, ty), &qos, window)?;
        let p = self
            .node_mut()?
            .create_publisher(&t, Some(qos))
            .map_err(dds_err(format!("publisher on {name}")))?;
        Streamer::new(p, capacity, topic.trim_start_matches(['~', '/'])).map_err(|e| {
            RosError::Dds {
                what: format!("publisher thread for {topic}"),
                reason: e.to_string(),
            }
        })
    }

    /// Creates a subscription on `topic`.
    pub fn subscription<M: DeserializeOwned + 'static>(
        &mut self,
        topic: &str,
        ros_type: &str,
        qos: QosProfile,
    ) -> Result<Subscription<M>, RosError> {
        let (pkg, ty) = split_type(ros_type, "msg")?;
        let name = self.ros_name(topic)?;
        let depth = match qos.history {
            History::KeepLast { depth } => depth,
            History::KeepAll => qos::DEFAULT_DEPTH,
        };
        let t = self.limited_topic(&name, MessageTypeName::new(pkg, ty), &qos, depth)?;
        self.node_mut()?
            .create_subscription(&t, Some(qos))
            .map_err(dds_err(format!("subscription on {name}")))
    }

    /// Creates the DDS topic `name` with a resource limit of `max_samples` samples.
    ///
    /// * For a subscription, `max_samples` is its keep-last depth. RustDDS keeps every
    ///   received sample in the participant's topic cache, taken or not, until newer ones push
    ///   it out; the count it keeps is the largest of the topic's `ResourceLimits::max_samples`
    ///   and history depths ever given, and ros2-client sets no resource limit, so RustDDS's
    ///   default of 64 applies: 64 large samples per topic stay in memory (issue 11, item 5).
    ///   With the limit, the cache keeps at most `depth` samples. The limit is only ever
    ///   raised: another topic of the same name created in this participant (a publisher on
    ///   it) raises it again, so publishers leave topics that are subscribed alone.
    /// * For a stream's writer, `max_samples` is its send window ([`qos::send_window`]): a
    ///   writer's QoS takes the topic's resource limits, and RustDDS's window is their
    ///   `max_samples`.
    fn limited_topic(
        &self,
        name: &Name,
        type_name: MessageTypeName,
        qos: &QosProfile,
        max_samples: usize,
    ) -> Result<Topic, RosError> {
        let context = self.context.as_ref().ok_or_else(|| RosError::Dds {
            what: format!("topic {name}"),
            reason: "the node is shutting down".into(),
        })?;
        let node_name = NodeName::new(&self.namespace, &self.name).map_err(|e| RosError::Name {
            name: self.fqn(),
            reason: format!("{e:?}"),
        })?;
        let limit = i32::try_from(max_samples.max(1)).unwrap_or(i32::MAX);
        let limits = QosPolicyBuilder::new()
            .resource_limits(ResourceLimits {
                max_samples: limit,
                max_instances: 1,
                max_samples_per_instance: limit,
            })
            .build();
        let dds_qos = QosPolicies::from(qos).modify_by(&limits);
        context
            .domain_participant()
            .create_topic(
                name.to_dds_name("rt", &node_name, ""),
                type_name.dds_msg_type(),
                &dds_qos,
                TopicKind::NoKey,
            )
            .map_err(|e| RosError::Dds {
                what: format!("topic {name}"),
                reason: e.to_string(),
            })
    }

    /// Creates a subscription read on its own thread ([`Inbox`]): taking and deserializing
    /// samples never costs the caller's thread.
    pub fn inbox<M: DeserializeOwned + Send + 'static>(
        &mut self,
        topic: &str,
        ros_type: &str,
        qos: QosProfile,
    ) -> Result<Inbox<M>, RosError> {
        let sub = self.subscription(topic, ros_type, qos)?;
        Inbox::new(sub, topic.trim_start_matches(['~', '/'])).map_err(|e| RosError::Dds {
            what: format!("subscription thread for {topic}"),
            reason: e.to_string(),
        })
    }

    /// Creates an action server (`package/action/Name`) with rcl_action's QoS and the service
    /// mapping of the environment ([`RosEnv::service_mapping`]; Enhanced for Fast DDS, Jazzy's
    /// default RMW).
    pub fn action_server<G, R, F>(
        &mut self,
        name: &str,
        ros_type: &str,
    ) -> Result<ActionServer<G, R, F>, RosError>
    where
        G: Message + Clone + 'static,
        R: Message + Clone + 'static,
        F: Message + 'static,
    {
        let (pkg, ty) = split_type(ros_type, "action")?;
        let name = self.ros_name(name)?;
        let mapping = self.service_mapping;
        self.node_mut()?
            .create_action_server(
                mapping,
                &name,
                &ActionTypeName::new(pkg, ty),
                qos::action_server(),
            )
            .map_err(dds_err(format!("action server {name}")))
    }

    /// Creates a service server (`package/srv/Name`) with the environment's service mapping.
    pub fn service_server<Req, Resp>(
        &mut self,
        name: &str,
        ros_type: &str,
    ) -> Result<Server<Req, Resp>, RosError>
    where
        Req: Message + Clone + 'static,
        Resp: Message + 'static,
    {
        let (pkg, ty) = split_type(ros_type, "srv")?;
        let name = self.ros_name(name)?;
        let mapping = self.service_mapping;
        self.node_mut()?
            .create_server(
                mapping,
                &name,
                &ServiceTypeName::new(pkg, ty),
                qos::services(),
                qos::services(),
            )
            .map_err(dds_err(format!("service {name}")))
    }
}

impl KerfNode {
    /// Creates an action client (`package/action/Name`) with rcl_action's QoS and the
    /// environment's service mapping. Used by tools and tests that play a cell controller.
    pub fn action_client<G, R, F>(
        &mut self,
        name: &str,
        ros_type: &str,
    ) -> Result<ActionClient<G, R, F>, RosError>
    where
        G: Message + Clone + 'static,
        R: Message + Clone + 'static,
        F: Message + 'static,
    {
        let (pkg, ty) = split_type(ros_type, "action")?;
        let name = self.ros_name(name)?;
        let s = qos::action_server();
        let policies = ActionClientQosPolicies {
            goal_service: s.goal_service,
            result_service: s.result_service,
            cancel_service: s.cancel_service,
            feedback_subscription: s.feedback_publisher,
            status_subscription: s.status_publisher,
        };
        let mapping = self.service_mapping;
        self.node_mut()?
            .create_action_client(mapping, &name, &ActionTypeName::new(pkg, ty), policies)
            .map_err(dds_err(format!("action client {name}")))
    }

    /// Creates a service client (`package/srv/Name`) with the environment's service mapping.
    pub fn service_client<Req, Resp>(
        &mut self,
        name: &str,
        ros_type: &str,
    ) -> Result<Client<Req, Resp>, RosError>
    where
        Req: Message + Clone + 'static,
        Resp: Message + 'static,
    {
        let (pkg, ty) = split_type(ros_type, "srv")?;
        let name = self.ros_name(name)?;
        let mapping = self.service_mapping;
        self.node_mut()?
            .create_client(
                mapping,
                &name,
                &ServiceTypeName::new(pkg, ty),
                qos::services(),
                qos::services(),
            )
            .map_err(dds_err(format!("service client {name}")))
    }

    /// Waits until a server is matched on all three services of an action client.
    ///
    /// # Returns
    /// `false` if `timeout` passed first. A request sent before matching would be lost
    /// (volatile QoS), so a client waits for this before its first goal.
    pub fn wait_for_action_server<G, R, F>(
        &self,
        client: &ActionClient<G, R, F>,
        timeout: std::time::Duration,
    ) -> bool
    where
        G: Message + Clone + 'static,
        R: Message + Clone + 'static,
        F: Message + 'static,
    {
        let Some(node) = self.node.as_ref() else {
            return false;
        };
        poll_until(timeout, |slice| {
            let all = async {
                futures::join!(
                    client.goal_client().wait_for_service(node),
                    client.cancel_client().wait_for_service(node),
                    client.result_client().wait_for_service(node),
                )
            };
            block_on_timeout(all, slice).is_some()
        })
    }

    /// Waits until `publisher` has a matched subscription; `false` on timeout. A volatile
    /// sample published before matching is lost, so one-shot publishers wait for this first.
    ///
    /// Polls the publisher's matched-subscription count (every 5 ms) rather than awaiting
    /// ros2-client's `wait_for_subscription`: that future wakes on the node's graph events,
    /// which go through a bounded channel of 8 that drops events when full (ros2-client 0.12
    /// `Node::send_status_event`, `try_send`). In a burst of discovery (several nodes
    /// declaring their topics and services at once) the event of the match can be dropped,
    /// and with no later event the wait never ends although the match is there. The count
    /// is kept by the spinner from the DDS events themselves, so polling it cannot miss.
    pub fn wait_for_subscriber<M: Serialize>(
        &self,
        publisher: &Publisher<M>,
        timeout: std::time::Duration,
    ) -> bool {
        let Some(node) = self.node.as_ref() else {
            return false;
        };
        let deadline = std::time::Instant::now() + timeout;
        loop {
            if publisher.get_subscription_count(node) > 0 {
                return true;
            }
            if std::time::Instant::now() >= deadline {
                return false;
            }
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
    }

    /// Waits until a server is matched for a service client; `false` on timeout.
    pub fn wait_for_service<Req, Resp>(
        &self,
        client: &Client<Req, Resp>,
        timeout: std::time::Duration,
    ) -> bool
    where
        Req: Message + 'static,
        Resp: Message + 'static,
    {
        let Some(node) = self.node.as_ref() else {
            return false;
        };
        poll_until(timeout, |slice| {
            block_on_timeout(client.wait_for_service(node), slice).is_some()
        })
    }
}

/// How long one wait for a match lasts before [`poll_until`] asks again.
const MATCH_POLL: std::time::Duration = std::time::Duration::from_millis(50);

/// Calls `ready` with a slice of the time left (at most [`MATCH_POLL`]) until it returns true
/// or `timeout` has passed.
///
/// ros2-client's waits for a match (`Client::wait_for_service`, the action client's three)
/// check the matched state once when they are created, then wake on the node's graph events,
/// which go through a bounded channel of 8 that drops events when full (ros2-client 0.12
/// `Node::send_status_event`, `try_send`): a dropped match event left the wait hanging until
/// its timeout. A fresh wait every [`MATCH_POLL`] checks the matched state again.
fn poll_until(
    timeout: std::time::Duration,
    mut ready: impl FnMut(std::time::Duration) -> bool,
) -> bool {
    let deadline = std::time::Instant::now() + timeout;
    loop {
        let left = deadline.saturating_duration_since(std::time::Instant::now());
        if ready(left.min(MATCH_POLL)) {
            return true;
        }
        if left.is_zero() {
            return false;
        }
    }
}

/// The ROS topics (`rt/…` DDS topics, the prefix removed) among (DDS topic, DDS type) pairs,
/// sorted, without repeats.
fn ros_topics(topics: impl Iterator<Item = (String, String)>) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = topics
        .filter_map(|(name, ty)| {
            name.strip_prefix("rt")
                .filter(|n| n.starts_with('/'))
                .map(|n| (n.to_string(), ty))
        })
        .collect();
    out.sort();
    out.dedup();
    out
}

/// Runs a future to completion on this thread, giving up after `timeout`.
pub fn block_on_timeout<F: std::future::Future>(
    f: F,
    timeout: std::time::Duration,
) -> Option<F::Output> {
    let (tx, rx) = futures::channel::oneshot::channel::<()>();
    // The timer thread ends as soon as the future does (`done` is dropped on return), so no
    // thread outlives the call (the soak test counts them).
    let (done, finished) = std::sync::mpsc::channel::<()>();
    std::thread::spawn(move || {
        if let Err(std::sync::mpsc::RecvTimeoutError::Timeout) = finished.recv_timeout(timeout) {
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

impl Drop for KerfNode {
    fn drop(&mut self) {
        // Node first (signals the spinner), then the spinner thread, then the Context.
        drop(self.node.take());
        if let Some(h) = self.spinner.take() {
            let _ = h.join();
        }
        drop(self.context.take());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn type_names_are_checked() {
        assert_eq!(
            split_type("trajectory_msgs/msg/JointTrajectory", "msg").unwrap(),
            ("trajectory_msgs", "JointTrajectory")
        );
        assert!(split_type("trajectory_msgs/JointTrajectory", "msg").is_err());
        assert!(split_type("control_msgs/action/FollowJointTrajectory", "msg").is_err());
    }
}
