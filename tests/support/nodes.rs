//! Nodes in this process on a loopback-only domain: the environment, a plain client node, any
//! node's `run` on its own thread, and waiting for a writer to be discovered.

use std::{
    thread::JoinHandle,
    time::{Duration, Instant},
};

use kerf_ros::{ros2_client::ServiceMapping, DiscoveryRange, KerfNode, RosArgs, RosEnv, StopToken};

/// A loopback-only environment on `domain`.
pub fn loopback(domain: u16, service_mapping: ServiceMapping) -> RosEnv {
    RosEnv {
        domain_id: domain,
        range: DiscoveryRange::Localhost,
        service_mapping,
    }
}

/// A plain client node (no rosout, no parameters) named `name`.
pub fn client_node(name: &str, env: &RosEnv) -> KerfNode {
    KerfNode::client(name, env).expect("client node")
}

/// Runs a node's `run(args, env, stop)` on its own thread (own Context) with the ROS arguments
/// `words` (everything after the program name, e.g. `["--ros-args", "-p", "a:=1"]`). Stop it
/// with the returned token, then join.
#[allow(dead_code)] // not every crate including this module needs it
pub fn spawn_node(
    env: &RosEnv,
    words: Vec<String>,
    run: impl FnOnce(&RosArgs, &RosEnv, StopToken) -> Result<(), String> + Send + 'static,
) -> (StopToken, JoinHandle<Result<(), String>>) {
    let args = RosArgs::parse(words).expect("node arguments");
    let stop = StopToken::new();
    let (e, s) = (env.clone(), stop.clone());
    let handle = std::thread::spawn(move || run(&args, &e, s));
    (stop, handle)
}

/// Waits until `node` has discovered a writer on `topic` (e.g. a planner's remapped
/// trajectory publisher); fails the test with "`what` was not discovered" after `timeout`.
#[allow(dead_code)] // not every crate including this module needs it
pub fn wait_for_writer(node: &KerfNode, topic: &str, timeout: Duration, what: &str) {
    let deadline = Instant::now() + timeout;
    while !node.discovered_topics().iter().any(|(t, _)| t == topic) {
        assert!(Instant::now() < deadline, "{what} was not discovered");
        std::thread::sleep(Duration::from_millis(20));
    }
}
