//! Period jitter of the executor's `/joint_states` stream over loopback DDS.
//!
//! Starts the trajectory executor (IRB 6660, 250 Hz) in this process and a subscriber node,
//! both on loopback (own Contexts, ROS domain 97), collects `KERF_JITTER_SAMPLES` samples
//! (default 5000 = 20 s) and prints p50/p99/max of
//! * the publish period, from consecutive `header.stamp`s (the control loop's schedule), and
//! * the arrival period, from the subscriber's receive times (adds DDS and polling delay;
//!   the subscriber polls every 50 µs).
//!
//! With `KERF_JITTER_LOAD=1`, a 5000-point six-joint quintic trajectory (20 s at 4 ms, the
//! density a planner produces) is sent on `~/joint_trajectory` after 1000 and 3000 samples, so
//! the figures include validating large trajectories while the loop runs.
//!
//! With `KERF_JITTER_RT=N`, the executor's control thread runs `SCHED_FIFO` at priority N
//! (parameter `realtime_priority`; needs CAP_SYS_NICE).
//!
//! With `KERF_JITTER_SIM=kinematic` or `dynamic`, the executor drives the simulated cell of
//! the IRB 6660 (`hardware: sim`, `urdf/cells/irb6660_plate.yaml`, physics 1 kHz) from all
//! joints at 0 (so that the load trajectory is the same). Its `header.stamp`s are then
//! simulated time, exactly one period apart: the arrival period is the figure to compare.
//!
//! Run: `cargo bench --bench joint_states_jitter`. Timings are reported, never asserted.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::time::{Duration, Instant};

use kerf_msgs::{
    builtin_interfaces::Duration as RosDuration,
    sensor_msgs::JointState,
    trajectory_msgs::{JointTrajectory, JointTrajectoryPoint},
    RosType,
};
#[path = "../tests/support/mod.rs"]
mod support;

use kerf_ros::{qos, ros2_client::ServiceMapping};

/// Minimum-jerk rest-to-rest motion of every joint from 0 to `d` and back over `t` seconds,
/// sampled every 4 ms with exact velocities and accelerations.
fn dense_trajectory(d: f64, t: f64) -> JointTrajectory {
    let n = (t / 0.004).round() as usize;
    let names = (1..=6).map(|i| format!("joint_{i}")).collect();
    let points = (1..=n)
        .map(|k| {
            let s = k as f64 / n as f64;
            // Out and back: phase 2s in [0, 1] twice.
            let (u, sign) = if s <= 0.5 {
                (2.0 * s, 1.0)
            } else {
                (2.0 - 2.0 * s, -1.0)
            };
            let h = t / 2.0;
            let p = d * (10.0 * u.powi(3) - 15.0 * u.powi(4) + 6.0 * u.powi(5));
            let v = sign * d * (30.0 * u.powi(2) - 60.0 * u.powi(3) + 30.0 * u.powi(4)) / h;
            let a = d * (60.0 * u - 180.0 * u.powi(2) + 120.0 * u.powi(3)) / (h * h);
            let last = k == n;
            JointTrajectoryPoint {
                positions: vec![if last { 0.0 } else { p }; 6],
                velocities: vec![if last { 0.0 } else { v }; 6],
                accelerations: vec![if last { 0.0 } else { a }; 6],
                effort: vec![],
                time_from_start: RosDuration::from_secs_f64(s * t).expect("finite"),
            }
        })
        .collect();
    JointTrajectory {
        joint_names: names,
        points,
        ..Default::default()
    }
}

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
    let env = support::loopback(97, ServiceMapping::Enhanced);
    let rt = std::env::var("KERF_JITTER_RT").unwrap_or_else(|_| "0".into());
    let mut params = vec![format!("realtime_priority:={rt}")];
    let sim = std::env::var("KERF_JITTER_SIM").ok();
    if let Some(mode) = &sim {
        let cell = concat!(env!("CARGO_MANIFEST_DIR"), "/urdf/cells/irb6660_plate.yaml");
        params.extend([
            "hardware:=sim".to_string(),
            format!("sim_cell:={cell}"),
            format!("sim_mode:={mode}"),
            support::initial_positions(&[0.0; 6]),
        ]);
    }
    let (stop, exec) = support::spawn_executor(&env, &params);
    let mut sub_node = support::client_node("jitter_probe", &env);
    let sub = sub_node
        .subscription::<JointState>("/joint_states", JointState::ROS_TYPE, qos::state())
        .expect("subscription");
    let load = std::env::var("KERF_JITTER_LOAD").as_deref() == Ok("1");
    let traj_pub = sub_node
        .publisher::<JointTrajectory>(
            "/trajectory_executor/joint_trajectory",
            JointTrajectory::ROS_TYPE,
            qos::commands(),
        )
        .expect("publisher");
    if load {
        assert!(
            sub_node.wait_for_subscriber(&traj_pub, Duration::from_secs(20)),
            "executor did not subscribe"
        );
    }
    let heavy = dense_trajectory(0.3, 20.0);
    let mut sent = 0;
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
                    if load && (stamps.len() == 1000 || stamps.len() == 3000) {
                        traj_pub.publish(heavy.clone()).expect("publish trajectory");
                        sent += 1;
                    }
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
    drop(traj_pub);
    println!(
        "joint_states jitter at 250 Hz over loopback, {} ({} samples; {sent} trajectories of {} points sent during the run)",
        match &sim {
            Some(mode) => format!("simulated cell ({mode})"),
            None => "mock hardware".to_string(),
        },
        stamps.len(),
        heavy.points.len()
    );
    report("publish (header.stamp)", publish, 0.004);
    report("arrival (subscriber)  ", arrive, 0.004);
}
