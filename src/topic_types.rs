//! The message types `kerf echo` prints and `kerf pub` publishes, found by name, and the
//! small DDS client node both commands run.

use std::time::{Duration, Instant};

use kerf_msgs::{
    control_msgs::JointTrajectoryControllerState,
    geometry_msgs,
    msg::{
        CutPlan, CutRequest, MillPlan, MillRequest, ReferencePoint, StreamStatus, TrajectoryStatus,
    },
    sensor_msgs::JointState,
    std_msgs,
    trajectory_msgs::JointTrajectory,
    RosType,
};
use kerf_ros::{KerfNode, RosEnv};
use serde::{de::DeserializeOwned, Serialize};

/// The types kerf can print and publish: every message kerf publishes or consumes.
pub const TYPES: &[&str] = &[
    JointTrajectory::ROS_TYPE,
    JointState::ROS_TYPE,
    JointTrajectoryControllerState::ROS_TYPE,
    TrajectoryStatus::ROS_TYPE,
    CutRequest::ROS_TYPE,
    CutPlan::ROS_TYPE,
    MillRequest::ROS_TYPE,
    MillPlan::ROS_TYPE,
    ReferencePoint::ROS_TYPE,
    StreamStatus::ROS_TYPE,
    std_msgs::StringMsg::ROS_TYPE,
    std_msgs::Header::ROS_TYPE,
    geometry_msgs::Pose::ROS_TYPE,
    geometry_msgs::Point::ROS_TYPE,
    geometry_msgs::Vector3::ROS_TYPE,
    geometry_msgs::Quaternion::ROS_TYPE,
    "rcl_interfaces/msg/Log",
];

/// Something to do with one message type, chosen at run time by its ROS name ([`dispatch`]).
pub trait ForType {
    /// What it gives.
    type Out;
    /// Does it with message type `M`, named `ros_type`.
    fn run<M: DeserializeOwned + Serialize + 'static>(self, ros_type: &str) -> Self::Out;
}

/// Runs `f` with the Rust type of `ros_type`.
///
/// # Errors
/// A type kerf does not know, listing those it does.
pub fn dispatch<F: ForType>(ros_type: &str, f: F) -> Result<F::Out, String> {
    let t = ros_type;
    Ok(match t {
        _ if t == JointTrajectory::ROS_TYPE => f.run::<JointTrajectory>(t),
        _ if t == JointState::ROS_TYPE => f.run::<JointState>(t),
        _ if t == JointTrajectoryControllerState::ROS_TYPE => {
            f.run::<JointTrajectoryControllerState>(t)
        }
        _ if t == TrajectoryStatus::ROS_TYPE => f.run::<TrajectoryStatus>(t),
        _ if t == CutRequest::ROS_TYPE => f.run::<CutRequest>(t),
        _ if t == CutPlan::ROS_TYPE => f.run::<CutPlan>(t),
        _ if t == MillRequest::ROS_TYPE => f.run::<MillRequest>(t),
        _ if t == MillPlan::ROS_TYPE => f.run::<MillPlan>(t),
        _ if t == ReferencePoint::ROS_TYPE => f.run::<ReferencePoint>(t),
        _ if t == StreamStatus::ROS_TYPE => f.run::<StreamStatus>(t),
        _ if t == std_msgs::StringMsg::ROS_TYPE => f.run::<std_msgs::StringMsg>(t),
        _ if t == std_msgs::Header::ROS_TYPE => f.run::<std_msgs::Header>(t),
        _ if t == geometry_msgs::Pose::ROS_TYPE => f.run::<geometry_msgs::Pose>(t),
        _ if t == geometry_msgs::Point::ROS_TYPE => f.run::<geometry_msgs::Point>(t),
        _ if t == geometry_msgs::Vector3::ROS_TYPE => f.run::<geometry_msgs::Vector3>(t),
        _ if t == geometry_msgs::Quaternion::ROS_TYPE => f.run::<geometry_msgs::Quaternion>(t),
        "rcl_interfaces/msg/Log" => f.run::<ros2_client::Log>(t),
        other => {
            return Err(format!(
                "unknown message type {other}; kerf knows: {}",
                TYPES.join(", ")
            ))
        }
    })
}

/// `pkg::msg::dds_::Name_` → `pkg/msg/Name`.
pub fn ros_type_of_dds(dds: &str) -> Option<String> {
    let mut parts = dds.split("::");
    let (pkg, kind, dds_, name) = (parts.next()?, parts.next()?, parts.next()?, parts.next()?);
    (dds_ == "dds_" && parts.next().is_none())
        .then(|| format!("{pkg}/{kind}/{}", name.strip_suffix('_').unwrap_or(name)))
}

/// Which endpoints name a topic's type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// Its publishers (`kerf echo`).
    Publishers,
    /// Its subscriptions (`kerf pub`).
    Subscriptions,
}

/// The ROS type of `topic`, from the first discovered endpoint on `side`.
///
/// # Errors
/// Nothing discovered within `timeout` seconds (or Ctrl-C), or a DDS type name that is no ROS
/// type.
pub fn discover(node: &KerfNode, topic: &str, timeout: f64, side: Side) -> Result<String, String> {
    let deadline = Instant::now() + Duration::from_secs_f64(timeout.max(0.0));
    let what = match side {
        Side::Publishers => "publisher",
        Side::Subscriptions => "subscriber",
    };
    loop {
        let found = match side {
            Side::Publishers => node.discovered_topics(),
            Side::Subscriptions => node.discovered_subscriptions(),
        };
        if let Some((_, ty)) = found.into_iter().find(|(n, _)| n == topic) {
            return ros_type_of_dds(&ty)
                .ok_or_else(|| format!("topic {topic} has an unexpected DDS type name {ty:?}"));
        }
        if Instant::now() >= deadline || node.should_stop() {
            return Err(format!(
                "no {what} of {topic} discovered within {timeout} s; check ROS_DOMAIN_ID and \
                 ROS_AUTOMATIC_DISCOVERY_RANGE, or give --type"
            ));
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// The client node of a `kerf` command (`kerf_<command>_<pid>`, no rosout, no parameters),
/// on the ROS environment of the process, with Ctrl-C stopping it.
///
/// # Errors
/// A refused environment or DDS failure, as text.
pub fn cli_node(command: &str) -> Result<KerfNode, String> {
    let env = RosEnv::from_env().map_err(|e| e.to_string())?;
    kerf_ros::shutdown::install_handler()?;
    KerfNode::client(&format!("kerf_{command}_{}", std::process::id()), &env)
        .map_err(|e| e.to_string())
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

    struct Name;
    impl ForType for Name {
        type Out = String;
        fn run<M: DeserializeOwned + Serialize + 'static>(self, ros_type: &str) -> String {
            format!("{ros_type} -> {}", std::any::type_name::<M>())
        }
    }

    #[test]
    fn every_listed_type_dispatches() {
        for t in TYPES {
            let got = dispatch(t, Name).unwrap();
            let short = t.rsplit('/').next().unwrap();
            assert!(got.contains(short), "{got}");
        }
        assert!(dispatch("foo_msgs/msg/Bar", Name)
            .unwrap_err()
            .contains("sensor_msgs/msg/JointState"));
    }
}
