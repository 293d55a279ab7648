//! Shared by the end-to-end tests and the DDS benches: an in-process IRB 6660 executor and a
//! client node, both on a loopback-only domain.

use std::thread::JoinHandle;

use kerf_ros::{
    ros2_client::ServiceMapping, DiscoveryRange, KerfNode, NodeSpec, RosArgs, RosEnv, StopToken,
};

/// A loopback-only environment on `domain`.
pub fn loopback(domain: u16, service_mapping: ServiceMapping) -> RosEnv {
    RosEnv {
        domain_id: domain,
        range: DiscoveryRange::Localhost,
        service_mapping,
    }
}

/// An executor for the shipped IRB 6660 running on its own thread (own Context), with
/// `extra` parameters (`name:=value`). Stop it with the returned token, then join.
#[allow(dead_code)] // not every crate including this module needs it
pub fn spawn_executor(
    env: &RosEnv,
    extra: &[String],
) -> (StopToken, JoinHandle<Result<(), String>>) {
    let urdf = concat!(env!("CARGO_MANIFEST_DIR"), "/urdf");
    let mut words = vec![
        "--ros-args".to_string(),
        "--disable-rosout-logs".into(),
        "-p".into(),
        format!("urdf_file:={urdf}/irb6660.urdf"),
        "-p".into(),
        format!("joint_limits_file:={urdf}/irb6660_limits.yaml"),
    ];
    for p in extra {
        words.push("-p".into());
        words.push(p.clone());
    }
    let args = RosArgs::parse(words).expect("executor arguments");
    let stop = StopToken::new();
    let (e, s) = (env.clone(), stop.clone());
    let handle = std::thread::spawn(move || {
        kerf_trajectory_executor::run(&args, &e, s).map_err(|e| e.to_string())
    });
    (stop, handle)
}

/// A plain client node (no rosout, no parameters) named `name`.
pub fn client_node(name: &str, env: &RosEnv) -> KerfNode {
    KerfNode::new(
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
    .expect("client node")
}

/// Runs a node's `run(args, env, stop)` on its own thread (own Context) with the ROS arguments
/// `words` (everything after the program name, e.g. `["--ros-args", "-p", "a:=1"]`). Stop it
/// with the returned token, then join.
#[allow(dead_code)] // used by tests/mjto_e2e.rs; not every crate including this module needs it
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
