//! The trajectory executor in this process, for one of the shipped robots.

use std::thread::JoinHandle;

use kerf_ros::{RosEnv, StopToken};

use super::spawn_node;

/// An executor for the shipped IRB 6660 running on its own thread (own Context), with
/// `extra` parameters (`name:=value`). Stop it with the returned token, then join.
#[allow(dead_code)] // not every crate including this module needs it
pub fn spawn_executor(
    env: &RosEnv,
    extra: &[String],
) -> (StopToken, JoinHandle<Result<(), String>>) {
    spawn_robot_executor(env, "irb6660", extra)
}

/// An executor for the shipped robot `robot` (`urdf/<robot>.urdf` with
/// `urdf/<robot>_limits.yaml`, e.g. `laser_cutter`) running on its own thread (own Context),
/// with `extra` parameters (`name:=value`). Stop it with the returned token, then join.
#[allow(dead_code)] // not every crate including this module needs it
pub fn spawn_robot_executor(
    env: &RosEnv,
    robot: &str,
    extra: &[String],
) -> (StopToken, JoinHandle<Result<(), String>>) {
    let urdf = concat!(env!("CARGO_MANIFEST_DIR"), "/urdf");
    let mut words = vec![
        "--ros-args".to_string(),
        "--disable-rosout-logs".into(),
        "-p".into(),
        format!("urdf_file:={urdf}/{robot}.urdf"),
        "-p".into(),
        format!("joint_limits_file:={urdf}/{robot}_limits.yaml"),
    ];
    for p in extra {
        words.push("-p".into());
        words.push(p.clone());
    }
    spawn_node(env, words, |a, e, s| {
        kerf_trajectory_executor::run(a, e, s).map_err(|e| e.to_string())
    })
}

/// The executor parameter that starts the robot at `q`: `initial_positions:=[q1, …]`.
#[allow(dead_code)] // not every crate including this module needs it
pub fn initial_positions(q: &[f64]) -> String {
    let q: Vec<String> = q.iter().map(|v| format!("{v:?}")).collect();
    format!("initial_positions:=[{}]", q.join(", "))
}

/// Stops an executor started by [`spawn_robot_executor`] and joins its thread: for the `Drop`
/// of a test's cell, whose nodes must still be dropped before their Contexts afterwards (the
/// fields keep their order). Panics if the executor ended with an error, unless the test is
/// already panicking.
#[allow(dead_code)] // not every crate including this module needs it
pub fn stop_and_join(stop: &StopToken, executor: &mut Option<JoinHandle<Result<(), String>>>) {
    stop.stop();
    if let Some(h) = executor.take() {
        let r = h.join().expect("executor thread");
        if !std::thread::panicking() {
            r.expect("executor ended cleanly");
        }
    }
}
