//! The executor holds trajectories compactly and gives them back (issue 33, item 3).
//!
//! * A 10⁶-point, 6-joint quintic trajectory (wire size 152 MB: positions, velocities and
//!   accelerations as f64 and a time per point) is prepared and run by the executor core as
//!   the node's preparation thread and control loop do: the peak growth while preparing must
//!   stay within 1.5 × the wire size, and once it has been served (the request freed, the
//!   node's trim, the trajectory replaced and dropped) RSS comes back within 20 % of the wire
//!   size.
//! * Hundreds of small trajectories, sent one after another to an executor node in this
//!   process over DDS, must not grow it: the RSS slope over the second half stays below
//!   4 KiB per trajectory.
//!
//! RSS from `/proc/self/status` (`kerf_ros::memory::status_kib`); the peak from `VmHWM`,
//! reset through `/proc/self/clear_refs`. The two tests measure one process's memory, so they
//! run one after the other (a lock), not in parallel.

#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::{
    sync::Mutex,
    time::{Duration, Instant},
};

use kerf_executor::{
    prepare, Executor, ExecutorConfig, GoalTolerances, JointLimits, JointSample, TrajectoryPoint,
    TrajectoryRequest,
};
use kerf_msgs::{
    builtin_interfaces::Duration as RosDuration,
    msg::TrajectoryStatus,
    trajectory_msgs::{JointTrajectory, JointTrajectoryPoint},
    RosType,
};
use kerf_ros::{qos, ros2_client::ServiceMapping};

mod support;

/// One test measures the process's memory at a time.
static MEASURING: Mutex<()> = Mutex::new(());

const JOINTS: usize = 6;

fn rss_kib() -> u64 {
    support::status_kib("VmRSS:")
}

/// Resets `VmHWM` to the current RSS (Linux ≥ 4.0).
fn reset_peak() {
    std::fs::write("/proc/self/clear_refs", "5").expect("reset the peak RSS");
}

fn limits() -> Vec<JointLimits> {
    (1..=JOINTS)
        .map(|j| JointLimits {
            name: format!("joint_{j}"),
            min_position: -3.0,
            max_position: 3.0,
            max_velocity: 2.0,
            max_acceleration: 10.0,
        })
        .collect()
}

/// `points` quintic points 10 ms apart of a slow swing (amplitude 0.01 rad), at rest at both
/// ends.
fn request(points: usize) -> TrajectoryRequest {
    let w = 0.5;
    let last = points - 1;
    TrajectoryRequest {
        joint_names: limits().into_iter().map(|l| l.name).collect(),
        points: (0..points)
            .map(|i| {
                let t = 0.01 * i as f64;
                let phase = |j: usize| w * t + j as f64;
                let at_rest = i == 0 || i == last;
                TrajectoryPoint {
                    positions: (0..JOINTS).map(|j| 0.01 * phase(j).sin()).collect(),
                    velocities: (0..JOINTS)
                        .map(|j| {
                            if at_rest {
                                0.0
                            } else {
                                0.01 * w * phase(j).cos()
                            }
                        })
                        .collect(),
                    accelerations: (0..JOINTS)
                        .map(|j| {
                            if at_rest {
                                0.0
                            } else {
                                -0.01 * w * w * phase(j).sin()
                            }
                        })
                        .collect(),
                    effort: Vec::new(),
                    time_from_start: t,
                }
            })
            .collect(),
        start_time: None,
    }
}

#[test]
fn a_million_point_trajectory_costs_about_its_wire_size_and_is_given_back() {
    let _one = MEASURING.lock().unwrap_or_else(|e| e.into_inner());
    kerf_ros::memory::release_large_allocations();
    const POINTS: usize = 1_000_000;
    let wire_kib = (POINTS * (3 * JOINTS * 8 + 8)) as f64 / 1024.0;
    let (limits, cfg) = (limits(), ExecutorConfig::default());
    let base = rss_kib();

    // The preparation thread: the request in, the prepared trajectory out.
    let req = std::thread::spawn(move || request(POINTS)).join().unwrap();
    let with_request = rss_kib();
    reset_peak();
    let started = Instant::now();
    let prepared = prepare(&limits, &cfg, &req).expect("a valid trajectory");
    let prepare_s = started.elapsed().as_secs_f64();
    let peak = support::status_kib("VmHWM:");
    drop(req);
    kerf_trajectory_executor::memory::give_back_freed_memory();
    let held = rss_kib();

    // The control loop: finish it, run a few cycles, replace it by a hold, drop it.
    // At rest at the first point (phase j at t = 0).
    let first: Vec<f64> = (0..JOINTS).map(|j| 0.01 * (j as f64).sin()).collect();
    let mut exec = Executor::new(limits.clone(), cfg.clone(), first.clone()).unwrap();
    exec.defer_drops();
    exec.submit_prepared(&prepared, &GoalTolerances::default(), 0.0)
        .expect("starts at rest at its first point");
    drop(prepared);
    let mut measured = JointSample::at_rest(first);
    for k in 0..1000 {
        let cycle = exec.update(0.004 * k as f64, &measured).unwrap();
        measured = cycle.reference;
    }
    let mut empty = request(2);
    empty.points.truncate(1);
    empty.points[0].positions = exec.commanded().positions.clone();
    empty.points[0].velocities = Vec::new();
    empty.points[0].accelerations = Vec::new();
    empty.points[0].time_from_start = 0.0;
    // A one-point trajectory at the commanded positions replaces the long one.
    exec.submit(&empty, &GoalTolerances::default(), 4.0)
        .expect("a one-point trajectory at the commanded positions");
    let retired = exec.take_retired();
    drop(retired);
    drop(exec);
    kerf_trajectory_executor::memory::give_back_freed_memory();
    let after = rss_kib();

    let growth = peak.saturating_sub(with_request) as f64;
    let kept = after.saturating_sub(base) as f64;
    println!(
        "{POINTS} points, wire {:.0} MB: RSS {:.0} MB before, {:.0} MB with the request, peak \
         growth while preparing {:.0} MB ({:.2} × wire, {prepare_s:.1} s), {:.0} MB held while \
         it runs, {:.0} MB after it was served ({:.2} × wire kept)",
        wire_kib / 1024.0,
        base as f64 / 1024.0,
        with_request as f64 / 1024.0,
        growth / 1024.0,
        growth / wire_kib,
        held.saturating_sub(base) as f64 / 1024.0,
        after as f64 / 1024.0,
        kept / wire_kib
    );
    assert!(
        growth <= 1.5 * wire_kib,
        "preparing grew RSS by {:.0} MB, over 1.5 × the wire size ({:.0} MB)",
        growth / 1024.0,
        wire_kib / 1024.0
    );
    assert!(
        kept <= 0.2 * wire_kib,
        "{:.0} MB of the trajectory were not given back (wire size {:.0} MB)",
        kept / 1024.0,
        wire_kib / 1024.0
    );
}

/// A two-point trajectory of joint 1 from `from` to `to` in 0.2 s (quintic, at rest at both
/// ends), starting now.
fn small(from: f64, to: f64) -> JointTrajectory {
    let point = |q1: f64, t: u32| JointTrajectoryPoint {
        positions: [q1, 0.0, 0.0, 0.0, 0.0, 0.0].to_vec(),
        velocities: vec![0.0; JOINTS],
        accelerations: vec![0.0; JOINTS],
        effort: Vec::new(),
        time_from_start: RosDuration { sec: 0, nanosec: t },
    };
    JointTrajectory {
        joint_names: (1..=JOINTS).map(|j| format!("joint_{j}")).collect(),
        points: vec![point(from, 0), point(to, 200_000_000)],
        ..Default::default()
    }
}

#[test]
fn sequential_small_trajectories_do_not_grow_the_executor() {
    let _one = MEASURING.lock().unwrap_or_else(|e| e.into_inner());
    kerf_ros::memory::release_large_allocations();
    const REQUESTS: usize = 300;
    let env = support::loopback(157, ServiceMapping::Enhanced);
    let (stop, executor) =
        support::spawn_executor(&env, &[support::initial_positions(&[0.0; JOINTS])]);
    let mut executor = Some(executor);
    let mut client = support::client_node("cell_controller", &env);
    let topic = client
        .publisher::<JointTrajectory>(
            "/trajectory_executor/joint_trajectory",
            JointTrajectory::ROS_TYPE,
            qos::commands(),
        )
        .unwrap();
    let statuses = client
        .subscription::<TrajectoryStatus>(
            "/trajectory_executor/trajectory_status",
            TrajectoryStatus::ROS_TYPE,
            qos::reliable(100),
        )
        .unwrap();
    assert!(client.wait_for_subscriber(&topic, support::QUICK));
    // Each trajectory is answered (a status with its result) before the next one is sent.
    let mut rss = Vec::with_capacity(REQUESTS);
    let deadline = Instant::now() + Duration::from_secs(600);
    for k in 0..REQUESTS {
        let (from, to) = if k % 2 == 0 { (0.0, 0.02) } else { (0.02, 0.0) };
        topic.publish(small(from, to)).unwrap();
        loop {
            assert!(Instant::now() < deadline, "trajectory {k} was not answered");
            match statuses.take() {
                Ok(Some((s, _))) if s.status == TrajectoryStatus::SUCCEEDED => break,
                Ok(Some((s, _)))
                    if s.status == TrajectoryStatus::REJECTED
                        || s.status == TrajectoryStatus::ABORTED =>
                {
                    panic!("trajectory {k}: {s:?}")
                }
                Ok(_) => std::thread::sleep(Duration::from_millis(2)),
                Err(e) => panic!("reading statuses: {e:?}"),
            }
        }
        rss.push(rss_kib() as f64);
    }
    support::stop_and_join(&stop, &mut executor);

    // Least-squares slope over the second half (KiB per trajectory).
    let half = &rss[REQUESTS / 2..];
    let n = half.len() as f64;
    let mean_x = (n - 1.0) / 2.0;
    let mean_y = half.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (i, y) in half.iter().enumerate() {
        let dx = i as f64 - mean_x;
        sxy += dx * (y - mean_y);
        sxx += dx * dx;
    }
    let slope = sxy / sxx;
    println!(
        "{REQUESTS} trajectories: RSS {:.1} MB after the first, {:.1} MB at half, {:.1} MB at the \
         end; slope over the second half {slope:.2} KiB per trajectory",
        rss[0] / 1024.0,
        rss[REQUESTS / 2] / 1024.0,
        rss[REQUESTS - 1] / 1024.0
    );
    assert!(
        slope < 4.0,
        "RSS grows by {slope:.1} KiB per trajectory over the second half"
    );
}
