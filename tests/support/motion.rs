//! Watching the executor move the robot: joint states and trajectory statuses against a plan.

use std::time::Duration;

use kerf_msgs::{
    builtin_interfaces::Duration as RosDuration,
    msg::TrajectoryStatus,
    sensor_msgs::JointState,
    trajectory_msgs::{JointTrajectory, JointTrajectoryPoint},
    RosType,
};
use kerf_ros::{qos, KerfNode, RosEnv};
use ros2_client::{Publisher, Subscription};

use super::{client_node, take, take_newest, wait_for_writer, QUICK};

/// Subscribes `node` to the executor's `/joint_states` and its latched
/// `/trajectory_executor/trajectory_status`.
pub fn watch_executor(
    node: &mut KerfNode,
) -> (Subscription<JointState>, Subscription<TrajectoryStatus>) {
    let states = node
        .subscription("/joint_states", JointState::ROS_TYPE, qos::state())
        .expect("joint states subscription");
    let statuses = node
        .subscription(
            "/trajectory_executor/trajectory_status",
            TrajectoryStatus::ROS_TYPE,
            qos::latched(),
        )
        .expect("trajectory status subscription");
    (states, statuses)
}

/// A publisher of `node` on the executor's trajectory input
/// (`/trajectory_executor/joint_trajectory`), matched to the executor.
pub fn executor_input(node: &mut KerfNode) -> Publisher<JointTrajectory> {
    let input = node
        .publisher(
            "/trajectory_executor/joint_trajectory",
            JointTrajectory::ROS_TYPE,
            qos::commands(),
        )
        .expect("trajectory publisher");
    assert!(
        node.wait_for_subscriber(&input, QUICK),
        "executor input not matched"
    );
    input
}

/// A client node `name` watching the executor ([`watch_executor`]) once the cell is ready: the
/// executor is up with the robot at `first`, and a writer on the executor's trajectory input
/// (a planner's remapped publisher: the topic is volatile) has been discovered.
pub fn watch_cell(
    env: &RosEnv,
    name: &str,
    first: &[f64],
) -> (
    KerfNode,
    Subscription<JointState>,
    Subscription<TrajectoryStatus>,
) {
    let mut watch = client_node(name, env);
    let (states, statuses) = watch_executor(&mut watch);
    assert_starts_at(&states, first);
    wait_for_writer(
        &watch,
        "/trajectory_executor/joint_trajectory",
        QUICK,
        "the planner's remapped trajectory writer",
    );
    (watch, states, statuses)
}

/// Takes the first joint state (the executor is up when it publishes one) and checks that the
/// robot stands at `q` (within 1e-12 per joint).
pub fn assert_starts_at(states: &Subscription<JointState>, q: &[f64]) {
    let start = take(states, QUICK, "first joint state");
    for (got, want) in start.position.iter().zip(q) {
        assert!((got - want).abs() < 1e-12, "{:?} vs {q:?}", start.position);
    }
}

/// After a motion: the newest joint state, read after a short hold (states queued before the
/// end was seen may still be decelerating), is at `q` within `tolerance` per joint and at
/// rest (every |velocity| below 1e-6). `what` names the motion in failures.
pub fn assert_rests_at(states: &Subscription<JointState>, q: &[f64], tolerance: f64, what: &str) {
    std::thread::sleep(Duration::from_millis(200));
    let end = take_newest(states, QUICK, "joint state after the cut");
    for (j, (got, want)) in end.position.iter().zip(q).enumerate() {
        let name = end.name.get(j).map_or("?", String::as_str);
        assert!(
            (got - want).abs() < tolerance,
            "{what}: {name} ends at {got}, plan {want}"
        );
    }
    assert!(
        end.velocity.iter().all(|v| v.abs() < 1e-6),
        "{what}: {:?}",
        end.velocity
    );
}

/// The statuses the executor sent since the last call, in order; fails on REJECTED or
/// ABORTED (`what` names the motion).
pub fn drain_statuses(statuses: &Subscription<TrajectoryStatus>, what: &str) -> Vec<u8> {
    let mut out = Vec::new();
    while let Ok(Some((s, _))) = statuses.take() {
        assert!(
            s.status != TrajectoryStatus::REJECTED && s.status != TrajectoryStatus::ABORTED,
            "{what}: executor {}: {}",
            TrajectoryStatus::status_name(s.status).unwrap_or("?"),
            s.message
        );
        out.push(s.status);
    }
    out
}

/// The largest single-joint step between two consecutive plan points (of 6 joints).
pub fn largest_step<Q: AsRef<[f64]>>(points: &[Q]) -> f64 {
    points
        .windows(2)
        .flat_map(|w| {
            let (a, b) = (w[0].as_ref(), w[1].as_ref());
            (0..6).map(move |j| (b[j] - a[j]).abs())
        })
        .fold(0.0, f64::max)
}

/// How far (largest joint difference) `position` is from the nearest of `points`.
pub fn off_plan<Q: AsRef<[f64]>>(points: &[Q], position: &[f64]) -> f64 {
    points
        .iter()
        .map(|q| {
            q.as_ref()
                .iter()
                .zip(position)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Minimum-jerk rest-to-rest motion `from` → `to` over `t` seconds, `n` segments with exact
/// velocities and accelerations (the executor's quintic interpolation reproduces it), the
/// first point after the start (the motion starts from the current state).
pub fn min_jerk<S: AsRef<str>>(
    names: &[S],
    from: &[f64],
    to: &[f64],
    t: f64,
    n: usize,
) -> JointTrajectory {
    let points = (1..=n)
        .map(|k| {
            let s = k as f64 / n as f64;
            let (p, v, a) = (
                10.0 * s.powi(3) - 15.0 * s.powi(4) + 6.0 * s.powi(5),
                (30.0 * s.powi(2) - 60.0 * s.powi(3) + 30.0 * s.powi(4)) / t,
                (60.0 * s - 180.0 * s.powi(2) + 120.0 * s.powi(3)) / (t * t),
            );
            JointTrajectoryPoint {
                positions: from.iter().zip(to).map(|(f, g)| f + (g - f) * p).collect(),
                velocities: from.iter().zip(to).map(|(f, g)| (g - f) * v).collect(),
                accelerations: from.iter().zip(to).map(|(f, g)| (g - f) * a).collect(),
                effort: vec![],
                time_from_start: RosDuration::from_secs_f64(s * t).expect("a finite time"),
            }
        })
        .collect();
    JointTrajectory {
        joint_names: names.iter().map(|s| s.as_ref().to_string()).collect(),
        points,
        ..Default::default()
    }
}

/// The largest absolute difference between two configurations.
pub fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}
