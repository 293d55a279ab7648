//! Stale-feedback detection latency and stop distance against the simulated driver
//! (`tools/sim_driver`, issue 27): the executor drives the IRB 6660 on `hardware: topic`, a
//! 3 s move is interrupted by the driver's `drop` fault (it stops publishing joint states but
//! keeps following commands) at a random time, and the run records:
//!
//! * **latency**: from the stamp of the last joint state the driver sent to the stamp of the
//!   executor's ABORTED trajectory status (the abort reaches the request thread within a
//!   millisecond of the control cycle that found the feedback stale);
//! * **stop distance**: the largest joint travel of the commands from the abort to rest (the
//!   controlled stop, `kerf_executor::StopProfile`), with the speed at the abort;
//! * **travel since the last state**: the largest joint travel of the commands from the last
//!   state's stamp to rest: what the robot moved without the executor seeing it.
//!
//! For `hardware.feedback_timeout_periods` 2, 5 (the default) and 10, `N` trials each.
//!
//! Run: `cargo bench -p kerf_trajectory_executor --bench driver_faults` (builds
//! `sim_driver` in release first if `target/release/sim_driver` is missing). DDS stays on
//! 127.0.0.1, domain 190 (of the 185-195 range of `tests/driver_e2e.rs`: do not run both at
//! once).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a bench reports failures by panicking

use std::{
    io::{BufRead, BufReader},
    path::{Path, PathBuf},
    process::{Child, Command, Stdio},
    sync::{
        atomic::{AtomicBool, Ordering},
        Arc, Mutex,
    },
    thread::JoinHandle,
    time::{Duration, Instant},
};

use kerf_msgs::{
    builtin_interfaces::Duration as RosDuration,
    control_msgs::{
        FollowJointTrajectoryFeedback, FollowJointTrajectoryGoal, FollowJointTrajectoryResult,
    },
    msg::TrajectoryStatus,
    sensor_msgs::JointState,
    std_msgs::StringMsg,
    trajectory_msgs::{JointTrajectory, JointTrajectoryPoint},
    RosType,
};
use kerf_ros::{
    qos, ros2_client::ServiceMapping, DiscoveryRange, KerfNode, RosArgs, RosEnv, StopToken,
};
use ros2_client::{
    action::{ActionClient, GoalStatusEnum},
    Subscription,
};

const ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
const DOMAIN: u16 = 190;
const TRIALS: usize = 12;
const WAIT: Duration = Duration::from_secs(30);
const START: [f64; 6] = [0.1, 0.2, 0.3, 0.0, 0.5, 0.0];
const DELTA: [f64; 6] = [0.6, 0.3, -0.3, 0.5, 0.4, 0.8];

type Fjt = ActionClient<
    FollowJointTrajectoryGoal,
    FollowJointTrajectoryResult,
    FollowJointTrajectoryFeedback,
>;

/// `target/release/sim_driver` (next to this bench's `deps/`), built if missing.
fn sim_driver_exe() -> PathBuf {
    let me = std::env::current_exe().unwrap();
    let dir = me.parent().and_then(Path::parent).unwrap().to_path_buf();
    let exe = dir.join("sim_driver");
    if !exe.is_file() {
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
        let ok = Command::new(cargo)
            .args(["build", "--release", "-p", "sim_driver"])
            .current_dir(ROOT)
            .status()
            .unwrap()
            .success();
        assert!(ok && exe.is_file(), "cargo build --release -p sim_driver");
    }
    exe
}

struct Driver(Child);

impl Drop for Driver {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn start_driver(joints: &[String]) -> Driver {
    let q: Vec<String> = START.iter().map(|v| format!("{v:?}")).collect();
    let mut child = Command::new(sim_driver_exe())
        .args(["--joints", &joints.join(","), "--initial", &q.join(",")])
        .env("ROS_DOMAIN_ID", DOMAIN.to_string())
        .env("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let out = BufReader::new(child.stdout.take().unwrap());
    let driver = Driver(child);
    for line in out.lines() {
        if line.unwrap().starts_with("sim_driver ready:") {
            return driver;
        }
    }
    panic!("sim_driver did not get ready");
}

struct Recorder<M> {
    seen: Arc<Mutex<Vec<M>>>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl<M: serde::de::DeserializeOwned + Send + Clone + 'static> Recorder<M> {
    fn new(sub: Subscription<M>) -> Self {
        let seen = Arc::new(Mutex::new(Vec::new()));
        let stop = Arc::new(AtomicBool::new(false));
        let (s, st) = (Arc::clone(&seen), Arc::clone(&stop));
        let thread = std::thread::spawn(move || {
            while !st.load(Ordering::Relaxed) {
                match sub.take() {
                    Ok(Some((m, _))) => s.lock().unwrap().push(m),
                    _ => std::thread::sleep(Duration::from_micros(200)),
                }
            }
        });
        Recorder {
            seen,
            stop,
            thread: Some(thread),
        }
    }

    fn all(&self) -> Vec<M> {
        self.seen.lock().unwrap().clone()
    }

    fn len(&self) -> usize {
        self.seen.lock().unwrap().len()
    }
}

impl<M> Drop for Recorder<M> {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

fn secs_of(t: &kerf_msgs::builtin_interfaces::Time) -> f64 {
    t.as_nanos() as f64 * 1e-9
}

fn min_jerk(names: &[String], from: &[f64], to: &[f64], t: f64, n: usize) -> JointTrajectory {
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
                time_from_start: RosDuration::from_secs_f64(s * t).unwrap(),
            }
        })
        .collect();
    JointTrajectory {
        joint_names: names.to_vec(),
        points,
        ..Default::default()
    }
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// One trial's figures.
struct Trial {
    latency_ms: f64,
    stop_mrad: f64,
    since_last_mrad: f64,
    speed: f64,
}

fn quantile(v: &mut [f64], q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q).round() as usize]
}

/// Runs `TRIALS` drops with `periods` allowed missed periods.
fn run_setting(periods: u32, joints: &[String], rng: &mut u64) -> Vec<Trial> {
    let env = RosEnv {
        domain_id: DOMAIN,
        range: DiscoveryRange::Localhost,
        service_mapping: ServiceMapping::Enhanced,
    };
    let words: Vec<String> = [
        "--ros-args".to_string(),
        "--disable-rosout-logs".into(),
        "--log-level".into(),
        "warn".into(),
        "--params-file".into(),
        format!("{ROOT}/launch_scripts/params/irb6660.yaml"),
        "-p".into(),
        format!("urdf_file:={ROOT}/urdf/irb6660.urdf"),
        "-p".into(),
        format!("joint_limits_file:={ROOT}/urdf/irb6660_limits.yaml"),
        "-p".into(),
        "hardware:=topic".into(),
        "-p".into(),
        "hardware.command_topic:=/driver/commands".into(),
        "-p".into(),
        format!("hardware.feedback_timeout_periods:={periods}"),
    ]
    .into();
    let args = RosArgs::parse(words).unwrap();
    let stop = StopToken::new();
    let (e, s) = (env.clone(), stop.clone());
    let executor = std::thread::spawn(move || {
        kerf_trajectory_executor::run(&args, &e, s).map_err(|e| e.to_string())
    });
    let mut client = KerfNode::client("bench", &env).unwrap();
    let action_client: Fjt = client
        .action_client(
            "/trajectory_executor/follow_joint_trajectory",
            "control_msgs/action/FollowJointTrajectory",
        )
        .unwrap();
    let commands: Recorder<JointState> = Recorder::new(
        client
            .subscription(
                "/trajectory_executor/joint_command",
                JointState::ROS_TYPE,
                qos::state(),
            )
            .unwrap(),
    );
    let measured: Recorder<JointState> = Recorder::new(
        client
            .subscription("/driver/joint_states", JointState::ROS_TYPE, qos::state())
            .unwrap(),
    );
    let statuses: Recorder<TrajectoryStatus> = Recorder::new(
        client
            .subscription(
                "/trajectory_executor/trajectory_status",
                TrajectoryStatus::ROS_TYPE,
                qos::latched(),
            )
            .unwrap(),
    );
    let fault = client
        .publisher("/driver/fault", StringMsg::ROS_TYPE, qos::commands())
        .unwrap();
    assert!(client.wait_for_action_server(&action_client, WAIT));
    assert!(client.wait_for_subscriber(&fault, WAIT));
    let action = &action_client;
    let send = |traj: JointTrajectory| {
        let (req, id) = action
            .send_goal(FollowJointTrajectoryGoal {
                trajectory: traj,
                ..Default::default()
            })
            .unwrap();
        let deadline = Instant::now() + WAIT;
        while action.receive_goal_response(req).unwrap().is_none() {
            assert!(Instant::now() < deadline, "no goal response");
            std::thread::sleep(Duration::from_millis(1));
        }
        let req = action.request_result(id).unwrap();
        let deadline = Instant::now() + WAIT;
        move || loop {
            if let Some(r) = action.receive_result(req).unwrap() {
                return r;
            }
            assert!(Instant::now() < deadline, "no result");
            std::thread::sleep(Duration::from_millis(1));
        }
    };
    let measured_now = || {
        let deadline = Instant::now() + WAIT;
        loop {
            if let Some(s) = measured.all().last() {
                return s.position.clone();
            }
            assert!(Instant::now() < deadline, "no joint state from the driver");
            std::thread::sleep(Duration::from_millis(10));
        }
    };
    let mut retries = 0;
    let mut trials = Vec::new();
    let mut sign = 1.0;
    while trials.len() < TRIALS {
        // Wait until goals are accepted (after the previous trial's resume).
        let start = measured_now();
        let target: Vec<f64> = start.iter().zip(DELTA).map(|(q, d)| q + sign * d).collect();
        let statuses_before = statuses.len();
        let result = send(min_jerk(joints, &start, &target, 3.0, 10));
        // A pseudo-random drop time in [0.8, 2.0] s (LCG).
        *rng = rng
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let at = 0.8 + 1.2 * ((*rng >> 11) as f64 / (1u64 << 53) as f64);
        std::thread::sleep(Duration::from_secs_f64(at));
        fault
            .publish(StringMsg {
                data: "drop".into(),
            })
            .unwrap();
        let (status, r) = result();
        if status != GoalStatusEnum::Aborted || !r.error_string.contains("feedback stale") {
            // Refused while coming to rest, or ended otherwise: try again.
            retries += 1;
            assert!(
                retries <= 2 * TRIALS,
                "too many failed trials: {status:?} {r:?}"
            );
            eprintln!("trial repeated: {status:?} {}", r.error_string);
            fault
                .publish(StringMsg {
                    data: "resume".into(),
                })
                .unwrap();
            std::thread::sleep(Duration::from_millis(300));
            continue;
        }
        sign = -sign;
        std::thread::sleep(Duration::from_millis(600));
        let t_abort = statuses.all()[statuses_before..]
            .iter()
            .find(|s| s.status == TrajectoryStatus::ABORTED)
            .map(|s| secs_of(&s.header.stamp))
            .unwrap();
        let t_last = measured
            .all()
            .iter()
            .map(|s| secs_of(&s.header.stamp))
            .fold(f64::NEG_INFINITY, f64::max);
        let cmds = commands.all();
        let at_or_before = |t: f64| {
            cmds.iter()
                .rev()
                .find(|c| secs_of(&c.header.stamp) <= t)
                .unwrap()
        };
        let abort = at_or_before(t_abort);
        let last = at_or_before(t_last);
        let rest = cmds.last().unwrap();
        trials.push(Trial {
            latency_ms: (t_abort - t_last) * 1e3,
            stop_mrad: max_diff(&abort.position, &rest.position) * 1e3,
            since_last_mrad: max_diff(&last.position, &rest.position) * 1e3,
            speed: abort.velocity.iter().fold(0.0f64, |m, v| m.max(v.abs())),
        });
        fault
            .publish(StringMsg {
                data: "resume".into(),
            })
            .unwrap();
        std::thread::sleep(Duration::from_millis(300));
    }
    drop((commands, measured, statuses, fault, action_client));
    stop.stop();
    executor.join().unwrap().unwrap();
    drop(client);
    trials
}

fn main() {
    // `cargo bench` passes `--bench`; any other argument is not ours.
    let joints: Vec<String> = (1..=6).map(|i| format!("joint_{i}")).collect();
    let _driver = start_driver(&joints);
    let mut rng = 27u64;
    println!(
        "| feedback_timeout_periods | trials | latency p50 / p95 / max (ms) | stop travel p50 / max (mrad) | travel since the last state p50 / max (mrad) | speed at the abort p50 (rad/s) |"
    );
    println!("|---|---|---|---|---|---|");
    for periods in [2u32, 5, 10] {
        let trials = run_setting(periods, &joints, &mut rng);
        let mut lat: Vec<f64> = trials.iter().map(|t| t.latency_ms).collect();
        let mut stop: Vec<f64> = trials.iter().map(|t| t.stop_mrad).collect();
        let mut since: Vec<f64> = trials.iter().map(|t| t.since_last_mrad).collect();
        let mut speed: Vec<f64> = trials.iter().map(|t| t.speed).collect();
        println!(
            "| {periods} ({:.0} ms) | {} | {:.1} / {:.1} / {:.1} | {:.1} / {:.1} | {:.1} / {:.1} | {:.3} |",
            periods as f64 * 4.0,
            trials.len(),
            quantile(&mut lat, 0.5),
            quantile(&mut lat, 0.95),
            quantile(&mut lat, 1.0),
            quantile(&mut stop, 0.5),
            quantile(&mut stop, 1.0),
            quantile(&mut since, 0.5),
            quantile(&mut since, 1.0),
            quantile(&mut speed, 0.5),
        );
    }
}
