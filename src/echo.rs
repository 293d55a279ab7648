//! `kerf echo TOPIC`: print a topic as YAML documents, like `ros2 topic echo`.

use std::time::{Duration, Instant};

use clap::Args;
use kerf_msgs::{
    control_msgs::JointTrajectoryControllerState,
    geometry_msgs,
    msg::{CutPlan, CutRequest, MillPlan, MillRequest, TrajectoryStatus},
    sensor_msgs::JointState,
    std_msgs,
    trajectory_msgs::JointTrajectory,
    RosType,
};
use kerf_ros::{qos, KerfNode, NodeSpec, RosArgs, RosEnv, StopToken};
use ros2_client::{qos::Durability, QosProfile};
use serde::{de::DeserializeOwned, Serialize};

/// Arguments of `kerf echo`.
#[derive(Args, Debug)]
pub struct EchoArgs {
    /// Topic, e.g. `/joint_states` or `/trajectory_executor/trajectory_status`.
    topic: String,
    /// ROS type (`sensor_msgs/msg/JointState`); by default it is discovered from the publishers.
    #[arg(long = "type")]
    ros_type: Option<String>,
    /// Exit after this many messages.
    #[arg(long, short = 'n')]
    count: Option<usize>,
    /// Exit after this many seconds (the exit is an error if nothing arrived).
    #[arg(long)]
    timeout: Option<f64>,
    /// Seconds to wait for a publisher when the type must be discovered.
    #[arg(long, default_value_t = 10.0)]
    discovery_timeout: f64,
    /// Subscribe transient-local, to also get the latched history (e.g. `~/trajectory_status`).
    #[arg(long)]
    transient_local: bool,
}

/// The types `kerf echo` can print: every message kerf publishes or consumes.
const TYPES: &[&str] = &[
    JointTrajectory::ROS_TYPE,
    JointState::ROS_TYPE,
    JointTrajectoryControllerState::ROS_TYPE,
    TrajectoryStatus::ROS_TYPE,
    CutRequest::ROS_TYPE,
    CutPlan::ROS_TYPE,
    MillRequest::ROS_TYPE,
    MillPlan::ROS_TYPE,
    std_msgs::StringMsg::ROS_TYPE,
    std_msgs::Header::ROS_TYPE,
    geometry_msgs::Pose::ROS_TYPE,
    geometry_msgs::Point::ROS_TYPE,
    geometry_msgs::Vector3::ROS_TYPE,
    geometry_msgs::Quaternion::ROS_TYPE,
    "rcl_interfaces/msg/Log",
];

/// `pkg::msg::dds_::Name_` → `pkg/msg/Name`.
fn ros_type_of_dds(dds: &str) -> Option<String> {
    let mut parts = dds.split("::");
    let (pkg, kind, dds_, name) = (parts.next()?, parts.next()?, parts.next()?, parts.next()?);
    (dds_ == "dds_" && parts.next().is_none())
        .then(|| format!("{pkg}/{kind}/{}", name.strip_suffix('_').unwrap_or(name)))
}

fn discover(node: &KerfNode, topic: &str, timeout: f64) -> Result<String, String> {
    let deadline = Instant::now() + Duration::from_secs_f64(timeout.max(0.0));
    loop {
        if let Some((_, ty)) = node
            .discovered_topics()
            .into_iter()
            .find(|(n, _)| n == topic)
        {
            return ros_type_of_dds(&ty)
                .ok_or_else(|| format!("topic {topic} has an unexpected DDS type name {ty:?}"));
        }
        if Instant::now() >= deadline || node.should_stop() {
            return Err(format!(
                "no publisher of {topic} discovered within {timeout} s; check ROS_DOMAIN_ID and \
                 ROS_AUTOMATIC_DISCOVERY_RANGE, or give --type"
            ));
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// Runs `kerf echo`.
pub fn run(a: EchoArgs) -> Result<(), String> {
    let env = RosEnv::from_env().map_err(|e| e.to_string())?;
    kerf_ros::shutdown::install_handler()?;
    let args = RosArgs {
        rosout_logs: false,
        ..RosArgs::default()
    };
    let name = format!("kerf_echo_{}", std::process::id());
    let mut node = KerfNode::new(
        NodeSpec {
            default_name: &name,
            default_namespace: "/",
            known_params: &[],
        },
        &args,
        &env,
        StopToken::new(),
    )
    .map_err(|e| e.to_string())?;
    let topic = node.resolve(&a.topic).map_err(|e| e.to_string())?;
    let ros_type = match &a.ros_type {
        Some(t) => t.clone(),
        None => discover(&node, &topic, a.discovery_timeout)?,
    };
    let mut q = qos::reliable(qos::DEFAULT_DEPTH);
    if a.transient_local {
        q = q.durability(Durability::TransientLocal);
    }
    let run = Echo {
        topic: &topic,
        qos: q,
        count: a.count,
        timeout: a.timeout,
    };
    match ros_type.as_str() {
        t if t == JointTrajectory::ROS_TYPE => run.echo::<JointTrajectory>(&mut node, t),
        t if t == JointState::ROS_TYPE => run.echo::<JointState>(&mut node, t),
        t if t == JointTrajectoryControllerState::ROS_TYPE => {
            run.echo::<JointTrajectoryControllerState>(&mut node, t)
        }
        t if t == TrajectoryStatus::ROS_TYPE => run.echo::<TrajectoryStatus>(&mut node, t),
        t if t == CutRequest::ROS_TYPE => run.echo::<CutRequest>(&mut node, t),
        t if t == CutPlan::ROS_TYPE => run.echo::<CutPlan>(&mut node, t),
        t if t == MillRequest::ROS_TYPE => run.echo::<MillRequest>(&mut node, t),
        t if t == MillPlan::ROS_TYPE => run.echo::<MillPlan>(&mut node, t),
        t if t == std_msgs::StringMsg::ROS_TYPE => run.echo::<std_msgs::StringMsg>(&mut node, t),
        t if t == std_msgs::Header::ROS_TYPE => run.echo::<std_msgs::Header>(&mut node, t),
        t if t == geometry_msgs::Pose::ROS_TYPE => run.echo::<geometry_msgs::Pose>(&mut node, t),
        t if t == geometry_msgs::Point::ROS_TYPE => run.echo::<geometry_msgs::Point>(&mut node, t),
        t if t == geometry_msgs::Vector3::ROS_TYPE => {
            run.echo::<geometry_msgs::Vector3>(&mut node, t)
        }
        t if t == geometry_msgs::Quaternion::ROS_TYPE => {
            run.echo::<geometry_msgs::Quaternion>(&mut node, t)
        }
        t if t == "rcl_interfaces/msg/Log" => run.echo::<ros2_client::Log>(&mut node, t),
        other => Err(format!(
            "kerf echo cannot print {other} (topic {topic}); it knows: {}",
            TYPES.join(", ")
        )),
    }
}

struct Echo<'a> {
    topic: &'a str,
    qos: QosProfile,
    count: Option<usize>,
    timeout: Option<f64>,
}

impl Echo<'_> {
    fn echo<M: DeserializeOwned + Serialize + 'static>(
        &self,
        node: &mut KerfNode,
        ros_type: &str,
    ) -> Result<(), String> {
        let sub = node
            .subscription::<M>(self.topic, ros_type, self.qos.clone())
            .map_err(|e| e.to_string())?;
        let deadline = self
            .timeout
            .map(|t| Instant::now() + Duration::from_secs_f64(t.max(0.0)));
        let mut n = 0usize;
        while !node.should_stop() && self.count.is_none_or(|c| n < c) {
            match sub.take() {
                Ok(Some((msg, _))) => {
                    let yaml = serde_yaml_ng::to_string(&msg).map_err(|e| e.to_string())?;
                    println!("{yaml}---");
                    n += 1;
                }
                Ok(None) => {
                    if deadline.is_some_and(|d| Instant::now() >= d) {
                        break;
                    }
                    std::thread::sleep(Duration::from_millis(2));
                }
                Err(e) => eprintln!(
                    "kerf echo: could not read a sample of {}: {e:?}",
                    self.topic
                ),
            }
        }
        if n == 0 && deadline.is_some() {
            return Err(format!("no message on {} within the timeout", self.topic));
        }
        drop(sub);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dds_names_map_to_ros_types() {
        assert_eq!(
            ros_type_of_dds("sensor_msgs::msg::dds_::JointState_").as_deref(),
            Some("sensor_msgs/msg/JointState")
        );
        assert_eq!(ros_type_of_dds("JointState"), None);
    }
}
