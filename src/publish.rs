//! `kerf pub TOPIC FILE|-`: publish one message, written as YAML or JSON, like
//! `ros2 topic pub --once`, without a ROS install.

use std::time::{Duration, Instant};

use clap::Args;
use kerf_ros::{qos, KerfNode};
use serde::{de::DeserializeOwned, Serialize};

use kerf_robot::document::from_yaml_or_json;

use crate::{
    bounds,
    input::{self, InputFile},
    topic_types::{cli_node, discover, dispatch, ForType, Side},
};

/// Arguments of `kerf pub`.
#[derive(Args, Debug)]
pub struct PubArgs {
    /// Topic, e.g. `/mjto_planner/cut_request_text`.
    topic: String,
    /// The message as a YAML or JSON document (every field of the type; `ros2 topic echo`
    /// and `kerf echo` print this form), read from this file, or from stdin with `-` (at most
    /// 16 MiB).
    file: InputFile,
    /// ROS type (`std_msgs/msg/String`); by default it is discovered from the topic's
    /// subscribers.
    #[arg(long = "type")]
    ros_type: Option<String>,
    /// Seconds to wait for a subscriber: the message is published only once one is matched
    /// (a volatile sample published before matching is lost), else the command fails;
    /// [0, 86400] s.
    #[arg(long, default_value_t = 10.0, value_parser = bounds::SECONDS)]
    wait: f64,
    /// Seconds the publisher stays after publishing, so that the reliable protocol can
    /// deliver (and repair) the sample before the process ends; [0, 86400] s.
    #[arg(long, default_value_t = 1.0, value_parser = bounds::SECONDS)]
    linger: f64,
}

/// Runs `kerf pub`.
///
/// # Errors
/// An unreadable file, a document that is not a message of the type (naming the field), no
/// subscriber within `--wait`, a DDS failure.
pub fn run(a: PubArgs) -> Result<(), String> {
    // Read (capped) before any DDS entity exists, so that Ctrl-C still ends a stalled stdin.
    let text = input::read_text("FILE", &a.file, input::MESSAGE_CAP)?;
    let mut node = cli_node("pub")?;
    let topic = node.resolve(&a.topic).map_err(|e| e.to_string())?;
    let ros_type = match &a.ros_type {
        Some(t) => t.clone(),
        None => discover(&node, &topic, a.wait, Side::Subscriptions)?,
    };
    let publish = Publish {
        node: &mut node,
        topic: &topic,
        text: &text,
        wait: a.wait,
        linger: a.linger,
    };
    dispatch(&ros_type, publish)
        .map_err(|e| format!("kerf pub cannot publish on {topic}: {e}"))??;
    println!("published 1 {ros_type} on {topic}");
    Ok(())
}

/// One message to publish.
struct Publish<'a> {
    node: &'a mut KerfNode,
    topic: &'a str,
    text: &'a str,
    wait: f64,
    linger: f64,
}

impl ForType for Publish<'_> {
    type Out = Result<(), String>;

    fn run<M: DeserializeOwned + Serialize + 'static>(self, ros_type: &str) -> Self::Out {
        let msg: M = parse(self.text).map_err(|e| format!("the message is no {ros_type}: {e}"))?;
        // Reliable, volatile, keep-last 10: what kerf's inputs subscribe with.
        let publisher = self
            .node
            .publisher::<M>(self.topic, ros_type, qos::commands())
            .map_err(|e| e.to_string())?;
        if !self
            .node
            .wait_for_subscriber(&publisher, Duration::from_secs_f64(self.wait))
        {
            return Err(format!(
                "no subscriber of {} matched within {} s; nothing was published (a sample \
                 published before a subscriber matches is lost)",
                self.topic, self.wait
            ));
        }
        publisher
            .publish(msg)
            .map_err(|e| format!("publishing on {}: {e}", self.topic))?;
        let until = Instant::now() + Duration::from_secs_f64(self.linger);
        while Instant::now() < until && !self.node.should_stop() {
            std::thread::sleep(Duration::from_millis(10));
        }
        drop(publisher);
        Ok(())
    }
}

/// A message from YAML, or from JSON YAML cannot read (surrogate-pair `\u` escapes); a key
/// the type does not have is refused, not ignored.
fn parse<M: DeserializeOwned + Serialize>(text: &str) -> Result<M, String> {
    let msg: M = from_yaml_or_json(text)?;
    let given: serde_yaml_ng::Value = from_yaml_or_json(text)?;
    let read = serde_yaml_ng::to_value(&msg).map_err(|e| e.to_string())?;
    match unknown_key(&given, &read, "") {
        Some(path) => Err(format!("unknown field `{path}`")),
        None => Ok(msg),
    }
}

/// The first key of `given` (a document as written) that `read` (the message it was read
/// as, serialized back) does not have, as a dotted path.
fn unknown_key(
    given: &serde_yaml_ng::Value,
    read: &serde_yaml_ng::Value,
    at: &str,
) -> Option<String> {
    use serde_yaml_ng::Value;
    match (given, read) {
        (Value::Mapping(g), Value::Mapping(r)) => g.iter().find_map(|(k, v)| {
            let name = k.as_str().map_or_else(|| format!("{k:?}"), String::from);
            let path = if at.is_empty() {
                name
            } else {
                format!("{at}.{name}")
            };
            match r.get(k) {
                None => Some(path),
                Some(rv) => unknown_key(v, rv, &path),
            }
        }),
        (Value::Sequence(g), Value::Sequence(r)) => g
            .iter()
            .zip(r)
            .enumerate()
            .find_map(|(i, (gv, rv))| unknown_key(gv, rv, &format!("{at}[{i}]"))),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use kerf_msgs::{std_msgs::StringMsg, trajectory_msgs::JointTrajectory};

    use super::parse;

    #[test]
    fn documents_are_read_strictly() {
        let m: StringMsg = parse("data: 'hello'").unwrap();
        assert_eq!(m.data, "hello");
        let m: StringMsg = parse(r#"{"data": "\ud83d\ude00"}"#).unwrap();
        assert_eq!(m.data, "\u{1F600}");
        assert_eq!(
            parse::<StringMsg>("data: x\ndta: y\n").unwrap_err(),
            "unknown field `dta`"
        );
        let t = "header: {stamp: {sec: 0, nanosec: 0}, frame_id: ''}\njoint_names: [a]\n\
                 points: [{positions: [1], velocities: [], accelerations: [], effort: [], \
                 time_from_start: {sec: 1, nanosec: 0}, speed: 2}]\n";
        assert_eq!(
            parse::<JointTrajectory>(t).unwrap_err(),
            "unknown field `points[0].speed`"
        );
        assert!(parse::<StringMsg>("dta: y\n")
            .unwrap_err()
            .contains("missing field `data`"));
    }
}
