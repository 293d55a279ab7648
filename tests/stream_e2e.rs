//! The executor's streaming mode end to end (issue 29, item 5): a cell controller publishes
//! reference points on `/trajectory_executor/reference_points` while the robot moves, and
//! reads the answer to each on `/trajectory_executor/stream_status`.
//!
//! * mock hardware: a start at the robot's position and a few points, each REACHED within its
//!   precision; `/joint_states` ends within the precision of the last point;
//! * bad input (a start away from the robot, NaN, out of reach, repeated, precision 0, a jump,
//!   an unknown joint name): each REFUSED naming the reason, and the next good point is
//!   REACHED;
//! * a stream faster than the robot (`stream.queue` 4, twelve points at once): the points
//!   beyond the queue are REFUSED by the queue rule, the accepted ones REACHED, and every
//!   joint velocity on `/joint_states` stays within the URDF's limits;
//! * `hardware: sim` (the IRB 6660 in its plate cell): a short stream is REACHED;
//! * `hardware: topic` with a driver in another process (`tools/sim_driver`): a short stream
//!   is REACHED and the measured robot rests on its last point.
//!
//! Loopback DDS, domains 226-230 (233-236 are beyond the largest domain id, 232: RustDDS's
//! ports overflow there).

#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::{
    collections::HashMap,
    thread::JoinHandle,
    time::{Duration, Instant},
};

use kerf_msgs::{
    msg::{ReferencePoint, StreamStatus},
    sensor_msgs::JointState,
    RosType,
};
use kerf_ros::{qos, KerfNode, StopToken};
use ros2_client::{Publisher, ServiceMapping, Subscription};

#[allow(dead_code)] // shared with the other end-to-end tests
mod support;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");
/// Waiting for discovery and for the answer to a point.
const QUICK: Duration = Duration::from_secs(30);
/// Waiting for a stream's motion to end (debug builds, two cores shared).
const MOTION: Duration = Duration::from_secs(60);
/// The IRB 6660's joints.
const JOINTS: [&str; 6] = [
    "joint_1", "joint_2", "joint_3", "joint_4", "joint_5", "joint_6",
];
/// The IRB 6660's velocity limits (rad/s, its URDF).
const VELOCITY: [f64; 6] = [
    1.9198621771937625,
    2.2689280275926285,
    2.2689280275926285,
    2.6179938779914944,
    2.0943951023931953,
    4.1887902047863905,
];
/// The points' precision (rad, Euclidean over the joints).
const PRECISION: f64 = 1e-3;

/// An executor and a cell controller streaming to it.
struct Cell {
    points: Publisher<ReferencePoint>,
    statuses: Subscription<StreamStatus>,
    states: Subscription<JointState>,
    /// Every status read so far, in order.
    seen: Vec<StreamStatus>,
    /// The largest |velocity| / limit over the joint states read so far.
    velocity_ratio: f64,
    last_state: Option<JointState>,
    _client: KerfNode,
    stop: StopToken,
    executor: Option<JoinHandle<Result<(), String>>>,
}

impl Drop for Cell {
    fn drop(&mut self) {
        support::stop_and_join(&self.stop, &mut self.executor);
    }
}

impl Cell {
    fn start(domain: u16, extra: &[String]) -> Cell {
        let env = support::loopback(domain, ServiceMapping::Enhanced);
        let (stop, executor) = support::spawn_robot_executor(&env, "irb6660", extra);
        let mut client = support::client_node("cell_controller", &env);
        let points = client
            .publisher(
                "/trajectory_executor/reference_points",
                ReferencePoint::ROS_TYPE,
                qos::reliable(1000),
            )
            .unwrap();
        let statuses = client
            .subscription(
                "/trajectory_executor/stream_status",
                StreamStatus::ROS_TYPE,
                qos::reliable(1000),
            )
            .unwrap();
        let states = client
            .subscription("/joint_states", JointState::ROS_TYPE, qos::state())
            .unwrap();
        assert!(
            client.wait_for_subscriber(&points, QUICK),
            "the executor's reference_points subscription was not discovered"
        );
        let mut cell = Cell {
            points,
            statuses,
            states,
            seen: Vec::new(),
            velocity_ratio: 0.0,
            last_state: None,
            _client: client,
            stop,
            executor: Some(executor),
        };
        cell.read_states(QUICK);
        // The status writer is matched with the joint-state writer of the same participant;
        // a moment more for our reader to be matched by it.
        std::thread::sleep(Duration::from_millis(500));
        cell
    }

    /// Reads the joint states received; waits up to `wait` for the first.
    fn read_states(&mut self, wait: Duration) {
        let deadline = Instant::now() + wait;
        loop {
            while let Ok(Some((s, _))) = self.states.take() {
                for (v, limit) in s.velocity.iter().zip(VELOCITY) {
                    self.velocity_ratio = self.velocity_ratio.max(v.abs() / limit);
                }
                self.last_state = Some(s);
            }
            if self.last_state.is_some() || Instant::now() > deadline {
                return;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    /// The robot's position (the newest joint state).
    fn position(&mut self) -> Vec<f64> {
        self.read_states(QUICK);
        self.last_state
            .as_ref()
            .expect("a joint state")
            .position
            .clone()
    }

    fn send(&self, id: u32, positions: &[f64], precision: f64, names: &[&str]) {
        self.points
            .publish(ReferencePoint {
                id,
                joint_names: names.iter().map(|n| n.to_string()).collect(),
                positions: positions.to_vec(),
                precision,
                ..Default::default()
            })
            .unwrap();
    }

    fn point(&self, id: u32, positions: &[f64]) {
        self.send(id, positions, PRECISION, &[]);
    }

    /// Waits until each of `ids` has a final status (START, REFUSED, REACHED, NOT_REACHED);
    /// returns them.
    fn finals(&mut self, ids: &[u32], wait: Duration) -> HashMap<u32, StreamStatus> {
        let deadline = Instant::now() + wait;
        loop {
            while let Ok(Some((s, _))) = self.statuses.take() {
                self.seen.push(s);
            }
            self.read_states(Duration::ZERO);
            let mut out = HashMap::new();
            for s in &self.seen {
                if s.status != StreamStatus::QUEUED && ids.contains(&s.id) {
                    out.insert(s.id, s.clone());
                }
            }
            if out.len() == ids.len() {
                return out;
            }
            assert!(
                Instant::now() < deadline,
                "no final status for every point of {ids:?} within {wait:?}; seen {:#?}",
                self.seen
            );
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    fn expect(&mut self, id: u32, status: u8, wait: Duration) -> StreamStatus {
        let s = self.finals(&[id], wait).remove(&id).unwrap();
        assert_eq!(
            s.status,
            status,
            "point {id}: want {:?}, got {:?}",
            StreamStatus::status_name(status),
            s
        );
        s
    }
}

/// A bad point: id, positions, precision, joint names, the reason it is refused for.
type Case<'a> = (u32, Vec<f64>, f64, Vec<&'a str>, &'a str);

fn offset(q: &[f64], d: [f64; 6]) -> Vec<f64> {
    q.iter().zip(d).map(|(a, b)| a + b).collect()
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// Streams `deltas` from the robot's position and checks each point REACHED within its
/// precision and the robot at rest on the last one.
fn stream_reaches_every_point(cell: &mut Cell, first_id: u32, deltas: &[[f64; 6]]) {
    let start = cell.position();
    cell.point(first_id, &start);
    cell.expect(first_id, StreamStatus::START, QUICK);
    let mut ids = Vec::new();
    let mut last = start.clone();
    for (k, d) in deltas.iter().enumerate() {
        let id = first_id + 1 + k as u32;
        last = offset(&start, *d);
        cell.point(id, &last);
        ids.push(id);
    }
    let finals = cell.finals(&ids, MOTION);
    for id in &ids {
        let s = &finals[id];
        assert_eq!(s.status, StreamStatus::REACHED, "{s:?}");
        assert!(s.error <= PRECISION, "{s:?}");
        assert!(s.batch >= 1, "{s:?}");
    }
    // Rest on the last point: the joint states after the last batch.
    std::thread::sleep(Duration::from_millis(300));
    let q = cell.position();
    assert!(
        distance(&q, &last) <= PRECISION,
        "the robot rests at {q:?}, {} from the last point {last:?}",
        distance(&q, &last)
    );
}

#[test]
fn a_stream_on_mock_hardware_reaches_every_point() {
    let mut cell = Cell::start(
        227,
        &[support::initial_positions(&[0.1, 0.2, 0.3, 0.0, 0.5, 0.0])],
    );
    stream_reaches_every_point(
        &mut cell,
        1,
        &[
            [0.05, 0.03, -0.02, 0.04, 0.02, 0.05],
            [0.10, 0.05, -0.04, 0.08, 0.05, 0.10],
            [0.12, 0.08, -0.05, 0.10, 0.06, 0.20],
            [0.20, 0.10, -0.08, 0.12, 0.08, 0.25],
        ],
    );
    assert!(cell.velocity_ratio <= 1.0 + 1e-9, "{}", cell.velocity_ratio);
    // A stream that stopped goes on with a new point: a new batch from rest.
    let q = cell.position();
    cell.point(20, &offset(&q, [-0.05, 0.0, 0.0, 0.0, 0.0, 0.0]));
    let s = cell.expect(20, StreamStatus::REACHED, MOTION);
    assert!(s.batch >= 2, "{s:?}");
}

#[test]
fn bad_points_are_refused_with_the_reason_and_the_stream_goes_on() {
    let mut cell = Cell::start(228, &[]);
    let start = cell.position();
    // A start away from the robot.
    cell.point(1, &offset(&start, [0.3, 0.0, 0.0, 0.0, 0.0, 0.0]));
    let s = cell.expect(1, StreamStatus::REFUSED, QUICK);
    assert!(
        s.message.contains("not where the robot is"),
        "{}",
        s.message
    );
    cell.point(2, &start);
    cell.expect(2, StreamStatus::START, QUICK);
    let good = offset(&start, [0.05, 0.0, 0.0, 0.0, 0.0, 0.0]);
    let mut nan = good.clone();
    nan[2] = f64::NAN;
    let mut far = good.clone();
    far[1] = 1.6; // joint_2's range ends at 1.4835
    let cases: Vec<Case> = vec![
        (10, nan, PRECISION, vec![], "joint_3 is NaN"),
        (11, far, PRECISION, vec![], "out of reach"),
        (
            12,
            offset(&start, [1e-4, 0.0, 0.0, 0.0, 0.0, 0.0]),
            PRECISION,
            vec![],
            "repeated",
        ),
        (13, good.clone(), 0.0, vec![], "precision 0"),
        (14, good.clone(), -1.0, vec![], "precision -1"),
        (
            15,
            offset(&start, [0.0, 0.0, 0.0, 0.9, 0.0, 0.0]),
            PRECISION,
            vec![],
            "joint_4 jumps",
        ),
        (
            16,
            good.clone(),
            PRECISION,
            vec![
                "joint_1", "joint_2", "joint_3", "wrist", "joint_5", "joint_6",
            ],
            "unknown joint 'wrist'",
        ),
        (
            17,
            good.clone(),
            PRECISION,
            vec![
                "joint_1", "joint_1", "joint_3", "joint_4", "joint_5", "joint_6",
            ],
            "named twice",
        ),
        (18, good[..5].to_vec(), PRECISION, vec![], "5 coordinates"),
    ];
    for (id, q, precision, names, _) in &cases {
        cell.send(*id, q, *precision, names);
    }
    for (id, _, _, _, reason) in &cases {
        let s = cell.expect(*id, StreamStatus::REFUSED, QUICK);
        assert!(s.message.contains(reason), "point {id}: {}", s.message);
    }
    // The stream goes on; joint names in another order are mapped.
    let mut reversed = good.clone();
    reversed.reverse();
    let mut names = JOINTS.to_vec();
    names.reverse();
    cell.send(30, &reversed, PRECISION, &names);
    let s = cell.expect(30, StreamStatus::REACHED, MOTION);
    assert!(s.error <= PRECISION, "{s:?}");
    std::thread::sleep(Duration::from_millis(300));
    let q = cell.position();
    assert!(distance(&q, &good) <= PRECISION, "{q:?} vs {good:?}");
}

#[test]
fn a_stream_faster_than_the_robot_is_refused_by_the_queue_rule() {
    // A jump bound wide enough that only the queue refuses: the points after a refused one are
    // compared with the last accepted, further back.
    let mut cell = Cell::start(
        229,
        &["stream.queue:=4".into(), "stream.max_jump:=2.0".into()],
    );
    let start = cell.position();
    cell.point(1, &start);
    cell.expect(1, StreamStatus::START, QUICK);
    let ids: Vec<u32> = (2..14).collect();
    for (k, id) in ids.iter().enumerate() {
        let d = 0.04 * (k + 1) as f64;
        cell.point(
            *id,
            &offset(&start, [d, -0.5 * d, 0.5 * d, d, 0.0, 2.0 * d]),
        );
    }
    let finals = cell.finals(&ids, MOTION);
    let refused: Vec<&StreamStatus> = finals
        .values()
        .filter(|s| s.status == StreamStatus::REFUSED)
        .collect();
    assert!(!refused.is_empty(), "{finals:#?}");
    for s in &refused {
        assert!(s.message.contains("queue 4"), "{s:?}");
    }
    // At most the queue waits, and at most one batch had begun when the points arrived.
    let accepted = ids.len() - refused.len();
    assert!(
        (4..=8).contains(&accepted),
        "{accepted} accepted: {finals:#?}"
    );
    for s in finals
        .values()
        .filter(|s| s.status != StreamStatus::REFUSED)
    {
        assert_eq!(s.status, StreamStatus::REACHED, "{s:?}");
        assert!(s.error <= PRECISION, "{s:?}");
    }
    cell.read_states(Duration::ZERO);
    assert!(
        cell.velocity_ratio <= 1.0 + 1e-9,
        "a joint velocity reached {} of its limit",
        cell.velocity_ratio
    );
    assert!(cell.velocity_ratio > 0.01, "the robot moved");
}

#[test]
fn a_stream_on_the_simulated_cell_reaches_every_point() {
    let mut cell = Cell::start(
        230,
        &[
            "hardware:=sim".into(),
            format!("sim_cell:={ROOT}/urdf/cells/irb6660_plate.yaml"),
        ],
    );
    stream_reaches_every_point(
        &mut cell,
        1,
        &[
            [0.05, 0.0, 0.0, 0.0, 0.0, 0.0],
            [0.10, 0.02, 0.0, 0.0, 0.0, 0.05],
        ],
    );
}

/// `hardware: topic`: the batches run through a robot driver in another process
/// (`tools/sim_driver`, no kerf code), judged on its measured states: every point REACHED and
/// the measured robot rests on the last one.
#[test]
fn a_stream_through_a_robot_driver_reaches_every_point() {
    let domain = 226;
    let joints: Vec<String> = (1..=6).map(|j| format!("joint_{j}")).collect();
    let _driver = support::driver::Driver::start(
        domain,
        "stream",
        &[
            "--joints".to_string(),
            joints.join(","),
            "--initial".into(),
            "0.1,0.2,0.3,0.0,0.5,0.0".into(),
        ],
    );
    let mut cell = Cell::start(
        domain,
        &[
            "hardware:=topic".into(),
            "hardware.command_topic:=/driver/commands".into(),
            "hardware.state_topic:=/driver/joint_states".into(),
            "hardware.feedback_timeout_periods:=25".into(),
        ],
    );
    stream_reaches_every_point(
        &mut cell,
        1,
        &[
            [0.03, 0.0, 0.0, 0.0, 0.0, 0.0],
            [0.06, 0.01, 0.0, 0.0, 0.02, 0.0],
        ],
    );
}
