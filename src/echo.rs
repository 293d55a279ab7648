//! `kerf echo TOPIC`: print a topic as YAML documents, like `ros2 topic echo`.

use std::time::{Duration, Instant};

use clap::Args;
use kerf_ros::{qos, KerfNode};
use ros2_client::{qos::Durability, QosProfile};
use serde::{de::DeserializeOwned, Serialize};

use crate::{
    bounds::{self, Count},
    topic_types::{cli_node, discover, dispatch, ForType, Side},
};

/// `--count`: at least one message.
const COUNT: Count<usize> = Count::new(1, 1_000_000_000, "messages");

/// Arguments of `kerf echo`.
#[derive(Args, Debug)]
pub struct EchoArgs {
    /// Topic, e.g. `/joint_states` or `/trajectory_executor/trajectory_status`.
    topic: String,
    /// ROS type (`sensor_msgs/msg/JointState`); by default it is discovered from the publishers.
    #[arg(long = "type")]
    ros_type: Option<String>,
    /// Exit after this many messages; [1, 1000000000] messages.
    #[arg(long, short = 'n', value_parser = COUNT)]
    count: Option<usize>,
    /// Exit after this many seconds (the exit is an error if nothing arrived); [0, 86400] s.
    #[arg(long, value_parser = bounds::SECONDS)]
    timeout: Option<f64>,
    /// Seconds to wait for a publisher when the type must be discovered; [0, 86400] s.
    #[arg(long, default_value_t = 10.0, value_parser = bounds::SECONDS)]
    discovery_timeout: f64,
    /// Subscribe transient-local, to also get the latched history (e.g. `~/trajectory_status`).
    #[arg(long)]
    transient_local: bool,
}

/// Runs `kerf echo`.
pub fn run(a: EchoArgs) -> Result<(), String> {
    let mut node = cli_node("echo")?;
    let topic = node.resolve(&a.topic).map_err(|e| e.to_string())?;
    let ros_type = match &a.ros_type {
        Some(t) => t.clone(),
        None => discover(&node, &topic, a.discovery_timeout, Side::Publishers)?,
    };
    let mut q = qos::reliable(qos::DEFAULT_DEPTH);
    if a.transient_local {
        q = q.durability(Durability::TransientLocal);
    }
    let echo = Echo {
        node: &mut node,
        topic: &topic,
        qos: q,
        count: a.count,
        timeout: a.timeout,
    };
    dispatch(&ros_type, echo).map_err(|e| format!("kerf echo cannot print topic {topic}: {e}"))?
}

struct Echo<'a> {
    node: &'a mut KerfNode,
    topic: &'a str,
    qos: QosProfile,
    count: Option<usize>,
    timeout: Option<f64>,
}

impl ForType for Echo<'_> {
    type Out = Result<(), String>;

    fn run<M: DeserializeOwned + Serialize + 'static>(self, ros_type: &str) -> Self::Out {
        let node = self.node;
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
