//! The driver's DDS side: one participant, one node with its spinner thread, and the
//! endpoints under the namespace. Dropping [`Dds`] shuts it down in the order ros2-client
//! needs: endpoints, node (which tells the spinner to stop), spinner thread, Context.

use std::thread::JoinHandle;

use kerf_msgs::{
    control_msgs::{
        FollowJointTrajectoryFeedback, FollowJointTrajectoryGoal, FollowJointTrajectoryResult,
    },
    sensor_msgs::JointState,
    std_msgs::{Float64MultiArray, StringMsg},
    RosType,
};
use ros2_client::{
    action::{ActionServer, ActionServerQosPolicies},
    dds::rustdds::{policy::ResourceLimits, QosPolicies, QosPolicyBuilder, Topic, TopicKind},
    qos::{Durability, History, Reliability, WhenFull},
    ActionTypeName, Context, MessageTypeName, Name, Node, NodeName, NodeOptions, Publisher,
    QosProfile, Subscription,
};
use serde::de::DeserializeOwned;

use crate::{
    cli::{CommandType, Config},
    command,
    env::RosEnv,
};

/// The node's base name.
pub const NODE_NAME: &str = "sim_driver";
/// Keep-last depth of every topic endpoint.
pub const DEPTH: usize = 10;
/// How long the state writer goes on without an acknowledgement from a reader (s): longer
/// than the 50 s lease after which a RustDDS participant that died is dropped, so a killed
/// reader never fills the send window and stalls the driver.
const READER_LEASE_HORIZON: f64 = 64.0;
/// RustDDS's send window without resource limits (samples).
const RUSTDDS_DEFAULT_WINDOW: usize = 8192;

/// The FollowJointTrajectory action server.
pub type FjtServer = ActionServer<
    FollowJointTrajectoryGoal,
    FollowJointTrajectoryResult,
    FollowJointTrajectoryFeedback,
>;

/// Reliable, volatile, keep-last `depth` (ROS 2's default topic QoS).
fn reliable(depth: usize) -> QosProfile {
    QosProfile::publisher_default()
        .reliability(Reliability::Reliable {
            when_full: WhenFull::DEFAULT,
        })
        .durability(Durability::Volatile)
        .history(History::KeepLast { depth })
}

/// rcl_action's QoS: services and feedback reliable and volatile, status transient-local
/// keep-last 1.
fn action_qos() -> ActionServerQosPolicies {
    ActionServerQosPolicies {
        goal_service: reliable(DEPTH),
        result_service: reliable(DEPTH),
        cancel_service: reliable(DEPTH),
        // A stalled feedback reader must not block the driver: a full window drops the sample.
        feedback_publisher: reliable(DEPTH).reliability(Reliability::Reliable {
            when_full: WhenFull::Fail,
        }),
        status_publisher: reliable(1).durability(Durability::TransientLocal),
    }
}

/// The command subscription, of the configured type.
pub enum CommandInput {
    /// `std_msgs/msg/Float64MultiArray`.
    Array(Subscription<Float64MultiArray>),
    /// `sensor_msgs/msg/JointState`.
    State(Subscription<JointState>),
}

fn take<M: DeserializeOwned + 'static>(s: &Subscription<M>) -> Option<Result<M, String>> {
    match s.take() {
        Ok(Some((m, _))) => Some(Ok(m)),
        Ok(None) => None,
        Err(e) => Some(Err(format!("unreadable sample: {e:?}"))),
    }
}

impl CommandInput {
    /// The next command in joint order, `Err` with the reason it is ignored, or `None`.
    pub fn next(&self, joints: &[String]) -> Option<Result<Vec<f64>, String>> {
        match self {
            CommandInput::Array(s) => {
                take(s).map(|m| m.and_then(|m| command::from_array(&m, joints.len())))
            }
            CommandInput::State(s) => {
                take(s).map(|m| m.and_then(|m| command::from_joint_state(&m, joints)))
            }
        }
    }
}

/// The driver's endpoints.
pub struct Endpoints {
    /// `<ns>/commands`.
    pub commands: CommandInput,
    /// `<ns>/fault`.
    pub faults: Subscription<StringMsg>,
    /// `<ns>/joint_states`.
    pub states: Publisher<JointState>,
    /// `<ns>/follow_joint_trajectory`.
    pub action: FjtServer,
}

impl Endpoints {
    /// The next fault text on `<ns>/fault`, or `None`.
    pub fn next_fault(&self) -> Option<Result<String, String>> {
        take(&self.faults).map(|m| m.map(|m| m.data))
    }
}

/// Joins the spinner thread when dropped.
struct Spinner(Option<JoinHandle<()>>);

impl Drop for Spinner {
    fn drop(&mut self) {
        if let Some(h) = self.0.take() {
            let _ = h.join();
        }
    }
}

/// The DDS participant, node and endpoints. Fields drop in declaration order.
pub struct Dds {
    /// The endpoints.
    pub endpoints: Endpoints,
    _node: Node,
    _spinner: Spinner,
    _context: Context,
}

fn parse_name(full: &str) -> Result<Name, String> {
    Name::parse(full).map_err(|e| format!("ROS name {full}: {e:?}"))
}

impl Dds {
    /// Creates the participant, the node `sim_driver` in the namespace, and every endpoint.
    ///
    /// # Errors
    /// A message naming what DDS refused.
    pub fn open(cfg: &Config, env: &RosEnv) -> Result<Dds, String> {
        let context = env.context()?;
        let node_name = NodeName::new(&cfg.namespace, NODE_NAME)
            .map_err(|e| format!("node name {}/{NODE_NAME}: {e:?}", cfg.namespace))?;
        let options = NodeOptions::new()
            .enable_rosout(false)
            .start_parameter_services(false);
        let mut node = context
            .new_node(node_name.clone(), options)
            .map_err(|e| format!("node: {e:?}"))?;
        let spinner = node.spinner().map_err(|e| format!("spinner: {e:?}"))?;
        let spin_thread = std::thread::Builder::new()
            .name("spin".into())
            .spawn(move || {
                if let Err(e) = futures::executor::block_on(spinner.spin()) {
                    eprintln!("sim_driver: the DDS spinner stopped: {e:?}");
                }
            })
            .map_err(|e| format!("spinner thread: {e}"))?;
        let spinner = Spinner(Some(spin_thread));
        let commands = match cfg.command_type {
            CommandType::Float64MultiArray => CommandInput::Array(subscribe::<Float64MultiArray>(
                &mut node,
                &cfg.topic("commands"),
            )?),
            CommandType::JointState => {
                CommandInput::State(subscribe::<JointState>(&mut node, &cfg.topic("commands"))?)
            }
        };
        let faults = subscribe::<StringMsg>(&mut node, &cfg.topic("fault"))?;
        let states = state_publisher(&context, &mut node, &node_name, cfg)?;
        let action_name = parse_name(&cfg.topic("follow_joint_trajectory"))?;
        let action = node
            .create_action_server(
                env.service_mapping,
                &action_name,
                &ActionTypeName::new("control_msgs", "FollowJointTrajectory"),
                action_qos(),
            )
            .map_err(|e| format!("action server {action_name}: {e:?}"))?;
        Ok(Dds {
            endpoints: Endpoints {
                commands,
                faults,
                states,
                action,
            },
            _node: node,
            _spinner: spinner,
            _context: context,
        })
    }
}

/// A reliable keep-last subscription of `M` (a mirror with its ROS type) on `topic`.
fn subscribe<M: RosType + DeserializeOwned + 'static>(
    node: &mut Node,
    topic: &str,
) -> Result<Subscription<M>, String> {
    let name = parse_name(topic)?;
    let qos = reliable(DEPTH);
    let t = node
        .create_topic(&name, MessageTypeName::new(M::PACKAGE, M::NAME), &qos)
        .map_err(|e| format!("topic {topic}: {e:?}"))?;
    node.create_subscription(&t, Some(qos))
        .map_err(|e| format!("subscription on {topic}: {e:?}"))
}

/// The `joint_states` publisher: reliable keep-last 10, with a send window of
/// `rate` × [`READER_LEASE_HORIZON`] samples (a DDS topic resource limit; RustDDS's window is
/// the topic's `max_samples`, 8192 by default: 33 s at 250 Hz, shorter than the lease of a
/// killed RustDDS reader, after which every write would wait).
fn state_publisher(
    context: &Context,
    node: &mut Node,
    node_name: &NodeName,
    cfg: &Config,
) -> Result<Publisher<JointState>, String> {
    let topic = cfg.topic("joint_states");
    let name = parse_name(&topic)?;
    let qos = reliable(DEPTH);
    let window = ((cfg.rate * READER_LEASE_HORIZON).ceil() as usize).max(RUSTDDS_DEFAULT_WINDOW);
    let limit = i32::try_from(window).unwrap_or(i32::MAX);
    let limits = QosPolicyBuilder::new()
        .resource_limits(ResourceLimits {
            max_samples: limit,
            max_instances: 1,
            max_samples_per_instance: limit,
        })
        .build();
    let dds_qos = QosPolicies::from(&qos).modify_by(&limits);
    let t: Topic = context
        .domain_participant()
        .create_topic(
            name.to_dds_name("rt", node_name, ""),
            MessageTypeName::new(JointState::PACKAGE, JointState::NAME).dds_msg_type(),
            &dds_qos,
            TopicKind::NoKey,
        )
        .map_err(|e| format!("topic {topic}: {e}"))?;
    node.create_publisher(&t, Some(qos))
        .map_err(|e| format!("publisher on {topic}: {e:?}"))
}
