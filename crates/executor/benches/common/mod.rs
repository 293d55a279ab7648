//! The workload shared by the interpolation bench and the `cycle_cost` example: a 6-joint
//! robot and a long quintic trajectory with exact derivatives.

use std::f64::consts::PI;

use kerf_executor::{
    GoalTolerances, JointLimits, JointTolerance, TrajectoryPoint, TrajectoryRequest,
};

/// Joints of the benchmark robot.
pub const N: usize = 6;
/// Control period (s), 250 Hz.
pub const DT: f64 = 0.004;

/// Six joints with ±3 limits, 2 /s, 10 /s².
pub fn limits() -> Vec<JointLimits> {
    (0..N)
        .map(|i| JointLimits {
            name: format!("j{}", i + 1),
            min_position: -3.0,
            max_position: 3.0,
            max_velocity: 2.0,
            max_acceleration: 10.0,
        })
        .collect()
}

/// `points` quintic waypoints `spacing` s apart of p_j(t) = A (1 − cos ω_j t), A = 0.5,
/// with `cycles(j)` full periods of joint j over the trajectory, ending at rest.
pub fn cosine_request(
    points: usize,
    spacing: f64,
    cycles: impl Fn(usize) -> f64,
) -> TrajectoryRequest {
    let end = spacing * (points - 1) as f64;
    let amp = 0.5;
    let omega: Vec<f64> = (0..N).map(|j| 2.0 * PI * cycles(j) / end).collect();
    let pts = (0..points)
        .map(|k| {
            let t = spacing * k as f64;
            let last = k == points - 1;
            let at_rest = |x: f64| if last { 0.0 } else { x };
            TrajectoryPoint {
                positions: omega.iter().map(|w| amp * (1.0 - (w * t).cos())).collect(),
                velocities: omega
                    .iter()
                    .map(|w| at_rest(amp * w * (w * t).sin()))
                    .collect(),
                accelerations: omega
                    .iter()
                    .map(|w| at_rest(amp * w * w * (w * t).cos()))
                    .collect(),
                effort: vec![],
                time_from_start: t,
            }
        })
        .collect();
    TrajectoryRequest {
        joint_names: limits().iter().map(|l| l.name.clone()).collect(),
        points: pts,
        start_time: None,
    }
}

/// Path tolerance 0.1, goal tolerance 1e-3 (velocity 1) on every joint, goal time 1 s.
pub fn tolerances() -> GoalTolerances {
    let tol = |position| -> Vec<JointTolerance> {
        limits()
            .iter()
            .map(|l| JointTolerance {
                name: l.name.clone(),
                position,
                velocity: 1.0,
                acceleration: 0.0,
            })
            .collect()
    };
    GoalTolerances {
        path: tol(0.1),
        goal: tol(1e-3),
        goal_time: 1.0,
    }
}
