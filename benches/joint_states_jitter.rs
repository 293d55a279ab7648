//! Period jitter of the executor's `/joint_states` stream over loopback DDS.
//!
//! Starts the trajectory executor (IRB 6660, 250 Hz) in this process and a subscriber node,
//! both on loopback (own Contexts, ROS domain 97), collects `KERF_JITTER_SAMPLES` samples
//! (default 5000 = 20 s) and prints p50/p99/max of
//! * the publish period, from consecutive `header.stamp`s (the control loop's schedule), and
//! * the arrival period, from the subscriber's receive times (adds DDS and polling delay;
//!   the subscriber polls every 50 µs).
//!
//! Run: `cargo bench --bench joint_states_jitter`. Timings are reported, never asserted.

use std::time::{Duration, Instant};

use kerf_msgs::{sensor_msgs::JointState, RosType};
use kerf_ros::{qos, DiscoveryRange, KerfNode, NodeSpec, RosArgs, RosEnv, StopToken};

fn percentile(sorted: &[f64], p: f64) -> f64 {
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i]
}

fn report(name: &str, mut periods: Vec<f64>, nominal: f64) {
    periods.sort_by(f64::total_cmp);
    let dev: Vec<f64> = {
        let mut d: Vec<f64> = periods.iter().map(|p| (p - nominal).abs()).collect();
        d.sort_by(f64::total_cmp);
        d
    };
    println!(
        "{name}: n={} period p50={:.3} ms p99={:.3} ms max={:.3} ms min={:.3} ms | |period-4ms| p50={:.1} µs p99={:.1} µs max={:.1} µs",
        periods.len(),
        percentile(&periods, 0.5) * 1e3,
        percentile(&periods, 0.99) * 1e3,
        periods[periods.len() - 1] * 1e3,
        periods[0] * 1e3,
        percentile(&dev, 0.5) * 1e6,
        percentile(&dev, 0.99) * 1e6,
        dev[dev.len() - 1] * 1e6,
    );
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return; // `cargo bench -- --list` probes benches; this one is not a criterion bench.
    }
    let samples: usize = std::env::var("KERF_JITTER_SAMPLES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5000);
    let env = RosEnv {
        domain_id: 97,
        range: DiscoveryRange::Localhost,
        ..RosEnv::default()
    };
    let urdf = concat!(env!("CARGO_MANIFEST_DIR"), "/urdf");
    let args = RosArgs::parse([
        "--ros-args".to_string(),
        "-p".into(),
        format!("urdf_file:={urdf}/irb6660.urdf"),
        "-p".into(),
        format!("joint_limits_file:={urdf}/irb6660_limits.yaml"),
        "--disable-rosout-logs".into(),
    ])
    .expect("args");
    let stop = StopToken::new();
    let (a, e, s) = (args.clone(), env.clone(), stop.clone());
    let exec = std::thread::spawn(move || kerf_trajectory_executor::run(&a, &e, s));

    let mut sub_node = KerfNode::new(
        NodeSpec {
            default_name: "jitter_probe",
            default_namespace: "/",
            known_params: &[],
        },
        &RosArgs {
            rosout_logs: false,
            ..RosArgs::default()
        },
        &env,
        StopToken::new(),
    )
    .expect("probe node");
    let sub = sub_node
        .subscription::<JointState>("/joint_states", JointState::ROS_TYPE, qos::state())
        .expect("subscription");
    let mut stamps = Vec::with_capacity(samples);
    let mut arrivals = Vec::with_capacity(samples);
    let deadline =
        Instant::now() + Duration::from_secs(30) + Duration::from_millis(4 * samples as u64);
    // Skip the first second (discovery, start-up).
    let warmup = Instant::now() + Duration::from_secs(1);
    while stamps.len() < samples && Instant::now() < deadline {
        match sub.take() {
            Ok(Some((msg, _))) => {
                let now = Instant::now();
                if now > warmup {
                    stamps.push(msg.header.stamp.as_secs_f64());
                    arrivals.push(now);
                }
            }
            Ok(None) => std::thread::sleep(Duration::from_micros(50)),
            Err(e) => panic!("read error {e:?}"),
        }
    }
    stop.stop();
    let _ = exec.join();
    assert!(stamps.len() > 10, "too few samples: {}", stamps.len());
    let publish: Vec<f64> = stamps.windows(2).map(|w| w[1] - w[0]).collect();
    let arrive: Vec<f64> = arrivals
        .windows(2)
        .map(|w| (w[1] - w[0]).as_secs_f64())
        .collect();
    println!(
        "joint_states jitter at 250 Hz over loopback ({} samples)",
        stamps.len()
    );
    report("publish (header.stamp)", publish, 0.004);
    report("arrival (subscriber)  ", arrive, 0.004);
}
