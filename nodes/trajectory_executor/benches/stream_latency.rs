//! Latency of the streaming mode (issue 29, item 5): the executor (IRB 6660, mock hardware,
//! 250 Hz) rests on the last point of a stream; a cell controller publishes the next
//! reference point, and the run records the time from the publish to the first
//! `~/joint_command` sample that moves toward it (the request thread reads the point, plans
//! its batch with RPRO, the prepare worker validates it, the control loop starts it at its
//! next cycle). `TRIALS` points, alternately 0.05 rad forward and back on joint 1; each
//! waits until the previous one is REACHED and the robot rests.
//!
//! Run: `cargo bench -p kerf_trajectory_executor --bench stream_latency`. DDS stays on
//! 127.0.0.1, domain 231.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench reports failures by panicking

use std::time::{Duration, Instant};

use kerf_msgs::{
    msg::{ReferencePoint, StreamStatus},
    sensor_msgs::JointState,
    RosType,
};
use kerf_ros::{
    qos, ros2_client::ServiceMapping, DiscoveryRange, KerfNode, RosArgs, RosEnv, StopToken,
};
use ros2_client::Subscription;

const ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
const DOMAIN: u16 = 231;
const TRIALS: usize = 20;
const WAIT: Duration = Duration::from_secs(30);

fn take<M: serde::de::DeserializeOwned + 'static>(sub: &Subscription<M>, what: &str) -> M {
    let deadline = Instant::now() + WAIT;
    while Instant::now() < deadline {
        if let Ok(Some((m, _))) = sub.take() {
            return m;
        }
        std::thread::sleep(Duration::from_micros(200));
    }
    panic!("no {what} within {WAIT:?}");
}

fn wait_status(sub: &Subscription<StreamStatus>, id: u32, status: u8) -> StreamStatus {
    loop {
        let s = take(sub, "stream status");
        if s.id == id && s.status != StreamStatus::QUEUED {
            assert_eq!(s.status, status, "{s:?}");
            return s;
        }
    }
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    let k = ((sorted.len() as f64 - 1.0) * p).round() as usize;
    sorted[k.min(sorted.len() - 1)]
}

fn main() {
    let env = RosEnv {
        domain_id: DOMAIN,
        range: DiscoveryRange::Localhost,
        service_mapping: ServiceMapping::Enhanced,
    };
    let args = RosArgs::parse(vec![
        "--ros-args".to_string(),
        "--disable-rosout-logs".into(),
        "-p".into(),
        format!("urdf_file:={ROOT}/urdf/irb6660.urdf"),
        "-p".into(),
        format!("joint_limits_file:={ROOT}/urdf/irb6660_limits.yaml"),
    ])
    .unwrap();
    let stop = StopToken::new();
    let (e, s) = (env.clone(), stop.clone());
    let executor = std::thread::spawn(move || kerf_trajectory_executor::run(&args, &e, s));

    let mut client = KerfNode::client("stream_latency", &env).unwrap();
    let points = client
        .publisher::<ReferencePoint>(
            "/trajectory_executor/reference_points",
            ReferencePoint::ROS_TYPE,
            qos::reliable(1000),
        )
        .unwrap();
    let statuses: Subscription<StreamStatus> = client
        .subscription(
            "/trajectory_executor/stream_status",
            StreamStatus::ROS_TYPE,
            qos::reliable(1000),
        )
        .unwrap();
    let commands: Subscription<JointState> = client
        .subscription(
            "/trajectory_executor/joint_command",
            JointState::ROS_TYPE,
            qos::state(),
        )
        .unwrap();
    assert!(client.wait_for_subscriber(&points, WAIT));
    let mut rest = take(&commands, "joint command").position;
    std::thread::sleep(Duration::from_millis(500));
    let send = |id: u32, q: &[f64]| {
        points
            .publish(ReferencePoint {
                id,
                positions: q.to_vec(),
                precision: 1e-3,
                ..Default::default()
            })
            .unwrap();
    };
    send(0, &rest);
    wait_status(&statuses, 0, StreamStatus::START);

    let mut latencies = Vec::with_capacity(TRIALS);
    for trial in 0..TRIALS {
        let id = trial as u32 + 1;
        let step = if trial % 2 == 0 { 0.05 } else { -0.05 };
        let mut target = rest.clone();
        target[0] += step;
        // Only commands after the publish count.
        while let Ok(Some(_)) = commands.take() {}
        let t0 = Instant::now();
        send(id, &target);
        loop {
            let c = take(&commands, "joint command");
            if (c.position[0] - rest[0]) * step > 0.0 {
                latencies.push(t0.elapsed().as_secs_f64() * 1e3);
                break;
            }
        }
        wait_status(&statuses, id, StreamStatus::REACHED);
        // At rest on the point: the last command of the batch.
        std::thread::sleep(Duration::from_millis(100));
        let mut newest = take(&commands, "joint command");
        while let Ok(Some((c, _))) = commands.take() {
            newest = c;
        }
        rest = newest.position;
    }
    stop.stop();
    executor.join().unwrap().unwrap();

    let mut sorted = latencies.clone();
    sorted.sort_by(f64::total_cmp);
    println!(
        "stream latency, publish -> first joint command toward the point ({TRIALS} trials, \
         IRB 6660, mock, 250 Hz): p50 {:.2} ms, p95 {:.2} ms, max {:.2} ms, min {:.2} ms",
        percentile(&sorted, 0.5),
        percentile(&sorted, 0.95),
        sorted[sorted.len() - 1],
        sorted[0]
    );
    println!(
        "trials (ms): {}",
        latencies
            .iter()
            .map(|l| format!("{l:.2}"))
            .collect::<Vec<_>>()
            .join(" ")
    );
}
