//! Independent checks of a planned program: the trajectory as the executor
//! runs it (its own validation and interpolation at the control period),
//! the tool tip by the URDF's forward kinematics (not the planner's), and
//! its exact distance from the programmed lines and arcs.
#![allow(clippy::unwrap_used, dead_code)]

use kerf_executor::{check_executable, ExecutorConfig, JointSample};
use kerf_gcode::{read_program, Motion, ReaderSettings};
use kerf_gcodeplan::GcodePlan;
use kerf_robot::RobotModel;
use nalgebra::Isometry3;

/// The executor's control period \[s\].
pub const PERIOD: f64 = 0.004;

/// The programmed geometry: segments (start, end) and planar XY arcs.
pub enum Shape {
    Segment([f64; 3], [f64; 3]),
    Arc {
        center: [f64; 3],
        radius: f64,
        start_angle: f64,
        sweep: f64,
        z: f64,
    },
}

/// The programmed moves of `text` (G17 arcs only).
pub fn shapes(text: &str) -> Vec<Shape> {
    read_program(text, ReaderSettings::default())
        .unwrap()
        .into_iter()
        .filter_map(|m| match m {
            Motion::Rapid { start, end, .. } | Motion::Line { start, end, .. } => {
                Some(Shape::Segment(start, end))
            }
            Motion::Arc { arc, .. } => {
                assert_eq!(arc.start[2], arc.end[2], "planar arcs only");
                Some(Shape::Arc {
                    center: arc.center,
                    radius: arc.radius,
                    start_angle: (arc.start[1] - arc.center[1]).atan2(arc.start[0] - arc.center[0]),
                    sweep: arc.sweep,
                    z: arc.start[2],
                })
            }
            _ => None,
        })
        .collect()
}

fn segment_distance(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let d: [f64; 3] = std::array::from_fn(|k| b[k] - a[k]);
    let len2: f64 = d.iter().map(|v| v * v).sum();
    let t = if len2 > 0.0 {
        ((0..3).map(|k| (p[k] - a[k]) * d[k]).sum::<f64>() / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (0..3)
        .map(|k| (p[k] - a[k] - t * d[k]).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Exact distance from `p` to the programmed geometry \[m\].
pub fn distance(shapes: &[Shape], p: [f64; 3]) -> f64 {
    shapes
        .iter()
        .map(|s| match s {
            Shape::Segment(a, b) => segment_distance(p, *a, *b),
            Shape::Arc {
                center,
                radius,
                start_angle,
                sweep,
                z,
            } => {
                let (dx, dy) = (p[0] - center[0], p[1] - center[1]);
                let angle = dy.atan2(dx);
                // Is the angle inside the swept range?
                let rel = (angle - start_angle) * sweep.signum();
                let rel = rel.rem_euclid(std::f64::consts::TAU);
                let end_point = |u: f64| {
                    let a = start_angle + u * sweep;
                    [
                        center[0] + radius * a.cos(),
                        center[1] + radius * a.sin(),
                        *z,
                    ]
                };
                let ends = segment_distance(p, end_point(0.0), end_point(0.0))
                    .min(segment_distance(p, end_point(1.0), end_point(1.0)));
                if rel <= sweep.abs() || sweep.abs() >= std::f64::consts::TAU {
                    let radial = dx.hypot(dy) - radius;
                    radial.hypot(p[2] - z).min(ends)
                } else {
                    ends
                }
            }
        })
        .fold(f64::INFINITY, f64::min)
}

/// What the executor runs, sampled at [`PERIOD`].
pub struct Executed {
    pub times: Vec<f64>,
    pub joints: Vec<Vec<f64>>,
}

/// The plan's trajectory through the executor's validation (from rest at
/// its first point) and interpolation.
pub fn execute(robot: &RobotModel, plan: &GcodePlan) -> Executed {
    let limits = robot.executor_limits().unwrap();
    let prepared = check_executable(&limits, &ExecutorConfig::default(), &plan.trajectory).unwrap();
    let (t0, t1) = (prepared.start_time(), prepared.end_time());
    // Two periods past the end: the executor holds the last point.
    let steps = ((t1 - t0) / PERIOD).ceil() as usize + 2;
    let mut sample = JointSample::default();
    let mut out = Executed {
        times: Vec::new(),
        joints: Vec::new(),
    };
    for k in 0..=steps {
        let t = t0 + k as f64 * PERIOD;
        prepared.sample_into(t, &mut sample);
        out.times.push(t - t0);
        out.joints.push(sample.positions.clone());
    }
    out
}

/// The tool tip of every sample, by the URDF's forward kinematics of
/// `robot` then `tcp`, in the program frame (`to_program` of a base-frame
/// point).
pub fn tips(
    robot: &RobotModel,
    executed: &Executed,
    tcp: &Isometry3<f64>,
    to_program: impl Fn([f64; 3]) -> [f64; 3],
) -> Vec<[f64; 3]> {
    executed
        .joints
        .iter()
        .map(|q| {
            let pose = robot.forward_kinematics(q).unwrap() * tcp;
            let t = pose.translation.vector;
            to_program([t.x, t.y, t.z])
        })
        .collect()
}

/// The largest |v|, |a|, |j| of each joint by central differences of the
/// samples, as ratios to `robot`'s limits.
pub fn difference_ratios(robot: &RobotModel, executed: &Executed) -> Vec<[f64; 3]> {
    let q = &executed.joints;
    let t = PERIOD;
    robot
        .joints()
        .iter()
        .enumerate()
        .map(|(j, spec)| {
            let mut r = [0.0f64; 3];
            for k in 1..q.len() - 1 {
                let v = (q[k + 1][j] - q[k - 1][j]) / (2.0 * t);
                let a = (q[k + 1][j] - 2.0 * q[k][j] + q[k - 1][j]) / (t * t);
                r[0] = r[0].max(v.abs() / spec.max_velocity);
                r[1] = r[1].max(a.abs() / spec.max_acceleration.unwrap());
            }
            for k in 1..q.len().saturating_sub(2) {
                let jerk =
                    (q[k + 2][j] - 3.0 * q[k + 1][j] + 3.0 * q[k][j] - q[k - 1][j]) / (t * t * t);
                r[2] = r[2].max(jerk.abs() / spec.max_jerk.unwrap());
            }
            r
        })
        .collect()
}
