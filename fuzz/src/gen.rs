//! Messages built from fuzzer bytes with [`arbitrary::Unstructured`].
//!
//! Every byte string gives a message (missing bytes read as zeros), so no input is wasted on
//! a decoding error, and the values are drawn where the conversions and validations have
//! their edges: NaN, ±∞, ±0, the largest and smallest floats, raw bit patterns, small "sane"
//! numbers, near-unit axes, arrays whose lengths match the joint count or not, joint names of
//! the real robots or not, times at and past the `nanosec` limit.

use arbitrary::{Result, Unstructured};
use kerf_msgs::{
    builtin_interfaces::{Duration, Time},
    geometry_msgs::{Point, Pose, Quaternion, Vector3},
    msg,
    std_msgs::Header,
    trajectory_msgs::{JointTrajectory, JointTrajectoryPoint},
};

/// A float: an edge value, raw bits, or (most often) a small number in a plausible range.
pub fn float(u: &mut Unstructured) -> Result<f64> {
    Ok(match u.int_in_range(0u8..=15)? {
        0 => f64::NAN,
        1 => f64::INFINITY,
        2 => f64::NEG_INFINITY,
        3 => 0.0,
        4 => -0.0,
        5 => f64::MAX,
        6 => f64::MIN_POSITIVE,
        7 => 5e-324,
        8 => f64::from_bits(u.arbitrary()?),
        9 => 1e308 * if u.arbitrary()? { 1.0 } else { -1.0 },
        _ => f64::from(u.arbitrary::<i16>()?) / 1000.0,
    })
}

/// A float that is usually a valid positive parameter (feedrate, period, angle limit).
fn positive(u: &mut Unstructured, typical: f64) -> Result<f64> {
    Ok(match u.int_in_range(0u8..=3)? {
        0 => float(u)?,
        _ => typical * (0.5 + f64::from(u.arbitrary::<u8>()?) / 255.0),
    })
}

/// A count: 0 (the message's "default"), small, or any `u32`.
fn count(u: &mut Unstructured, small: u32) -> Result<u32> {
    Ok(match u.int_in_range(0u8..=3)? {
        0 => 0,
        1 => u.arbitrary()?,
        _ => u.int_in_range(0..=small)?,
    })
}

/// A string: empty, one of `known`, or arbitrary text.
fn string(u: &mut Unstructured, known: &[&str]) -> Result<String> {
    let pick = u.int_in_range(0..=known.len() + 1)?;
    Ok(match pick {
        0 => String::new(),
        i if i <= known.len() => known[i - 1].to_string(),
        _ => u.arbitrary::<&str>()?.to_string(),
    })
}

/// `n` points along a line (with the odd wild coordinate), coplanar when `planar`.
fn points(u: &mut Unstructured, n: usize, planar: bool) -> Result<Vec<Point>> {
    let origin = [float(u)?, float(u)?, float(u)?];
    let step = [
        f64::from(u.arbitrary::<i8>()?) / 1000.0,
        f64::from(u.arbitrary::<i8>()?) / 1000.0,
        if planar {
            0.0
        } else {
            f64::from(u.arbitrary::<i8>()?) / 1000.0
        },
    ];
    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        let wild = u.ratio(1u8, 16)?;
        let c = |i: usize| origin[i] + step[i] * k as f64;
        out.push(if wild {
            Point {
                x: float(u)?,
                y: float(u)?,
                z: float(u)?,
            }
        } else {
            Point {
                x: c(0),
                y: c(1),
                z: c(2),
            }
        });
    }
    Ok(out)
}

/// A tool axis: a unit vector of a few kinds, or arbitrary components.
fn axis(u: &mut Unstructured) -> Result<Vector3> {
    let v = |x, y, z| Vector3 { x, y, z };
    Ok(match u.int_in_range(0u8..=5)? {
        0 => v(0.0, 0.0, 1.0),
        1 => v(0.0, 0.6, 0.8),
        2 => v(float(u)?, float(u)?, float(u)?),
        3 => v(0.0, 0.0, 1.0 + 1e-6 * f64::from(u.arbitrary::<i8>()?)),
        _ => {
            let (a, b) = (
                f64::from(u.arbitrary::<i8>()?) / 128.0,
                f64::from(u.arbitrary::<i8>()?) / 128.0,
            );
            let n = (a * a + b * b + 1.0).sqrt();
            v(a / n, b / n, 1.0 / n)
        }
    })
}

fn pose(u: &mut Unstructured) -> Result<Pose> {
    let orientation = match u.int_in_range(0u8..=3)? {
        0 => Quaternion {
            x: float(u)?,
            y: float(u)?,
            z: float(u)?,
            w: float(u)?,
        },
        1 => Quaternion::default(),
        _ => Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 1.0,
        },
    };
    Ok(Pose {
        position: Point {
            x: float(u)?,
            y: float(u)?,
            z: float(u)?,
        },
        orientation,
    })
}

/// A `kerf_msgs/msg/CutRequest`.
pub fn cut_request(u: &mut Unstructured) -> Result<msg::CutRequest> {
    let n = u.int_in_range(0..=12)?;
    let points = points(u, n, false)?;
    let n_axes = if u.ratio(1u8, 8)? {
        u.int_in_range(0..=12)?
    } else {
        n
    };
    let axes = (0..n_axes).map(|_| axis(u)).collect::<Result<Vec<_>>>()?;
    let rto_indices = match u.int_in_range(0u8..=2)? {
        0 => Vec::new(),
        1 => vec![0, u32::try_from(n.saturating_sub(1)).unwrap_or(u32::MAX)],
        _ => u.arbitrary()?,
    };
    Ok(msg::CutRequest {
        request_id: string(u, &["slot-3", "bpillar-case1-side-trim"])?,
        points,
        axes,
        feedrate: positive(u, 0.3)?,
        feed_acceleration: if u.arbitrary()? { 0.0 } else { float(u)? },
        feed_jerk: if u.arbitrary()? { 0.0 } else { float(u)? },
        sample_period: positive(u, 0.004)?,
        max_lead_angle: positive(u, 0.087)?,
        max_tilt_angle: positive(u, 0.087)?,
        mesh: string(u, &["package://kerf/urdf/meshes/bpillar.obj", " "])?,
        workpiece_pose: pose(u)?,
        control_points: count(u, 40)?,
        max_iterations: count(u, 20)?,
        gfd_q4_steps: count(u, 103)?,
        gfd_q5_steps: count(u, 103)?,
        gfd_q6_steps: count(u, 103)?,
        gfd_q4_half_range: if u.arbitrary()? { 0.0 } else { float(u)? },
        gfd_q5_half_range: if u.arbitrary()? { 0.0 } else { float(u)? },
        rto_indices,
        rto_spacing: if u.arbitrary()? { 0.0 } else { float(u)? },
        rto_angle: if u.arbitrary()? { 0.0 } else { float(u)? },
        has_reference_standoff: u.arbitrary()?,
        reference_standoff: float(u)?,
        clearance: if u.arbitrary()? { 0.0 } else { float(u)? },
        cl_tolerance: if u.arbitrary()? { 0.0 } else { float(u)? },
        feed_law: string(u, &["", "time_optimal", "constant", "variable"])?,
        rto_constraint: string(u, &["box", "equality"])?,
        orientation_corridor: string(u, &["", "allowance", "none", "off"])?,
        time_budget: if u.arbitrary()? { 0.0 } else { float(u)? },
    })
}

/// A `kerf_msgs/msg/MillRequest`.
pub fn mill_request(u: &mut Unstructured) -> Result<msg::MillRequest> {
    let n = u.int_in_range(0..=10)?;
    let planar = !u.ratio(1u8, 8)?;
    Ok(msg::MillRequest {
        request_id: string(u, &["job-17"])?,
        points: points(u, n, planar)?,
        segments: count(u, 200)?,
        has_process: u.arbitrary()?,
        teeth: count(u, 120)?,
        tool_radius: positive(u, 0.01)?,
        axial_depth: positive(u, 0.002)?,
        kt: positive(u, 6e8)?,
        kn: positive(u, 2e8)?,
        entry_angle: float(u)?,
        exit_angle: positive(u, 3.0)?,
        has_limits: u.arbitrary()?,
        spindle_min_rpm: positive(u, 1000.0)?,
        spindle_max_rpm: positive(u, 10000.0)?,
        feed_min: positive(u, 0.01)?,
        feed_max: positive(u, 0.1)?,
        g_min: float(u)?,
        g_max: float(u)?,
        max_spindle_step_rpm: positive(u, 500.0)?,
        max_feed_step: positive(u, 0.01)?,
        max_g_step: positive(u, 0.1)?,
        has_initial_state: u.arbitrary()?,
        initial_spindle_rpm: positive(u, 2000.0)?,
        initial_feed: positive(u, 0.04)?,
        initial_g: float(u)?,
        planner: string(u, &["ddpg", "fixed_g", "dp", "naive"])?,
        policy_file: string(u, &["crates/millplan/policies/ddpg.json"])?,
        time_budget: if u.arbitrary()? { 0.0 } else { float(u)? },
        has_tolerances: u.arbitrary()?,
        path_tolerance: positive(u, 5e-5)?,
        min_condition_indicator: float(u)?,
    })
}

/// Joint names of the laser cutter and of the IRB 6660 (kerf's two robots).
pub const JOINT_NAMES: [&str; 12] = [
    "q1", "q2", "q3", "q4", "q5", "q6", "joint_1", "joint_2", "joint_3", "joint_4", "joint_5",
    "joint_6",
];

fn duration(u: &mut Unstructured, t: f64) -> Result<Duration> {
    Ok(match u.int_in_range(0u8..=7)? {
        0 => Duration {
            sec: u.arbitrary()?,
            nanosec: u.arbitrary()?,
        },
        1 => Duration {
            sec: u.arbitrary()?,
            nanosec: 999_999_999 + u32::from(u.arbitrary::<u8>()? & 1),
        },
        _ => Duration::from_secs_f64(t).unwrap_or_default(),
    })
}

/// An array of `n` joint values (or of a wrong length), values mostly small.
fn joint_values(u: &mut Unstructured, n: usize) -> Result<Vec<f64>> {
    let len = match u.int_in_range(0u8..=7)? {
        0 => 0,
        1 => u.int_in_range(0..=8)?,
        _ => n,
    };
    (0..len)
        .map(|_| {
            Ok(if u.ratio(1u8, 8)? {
                float(u)?
            } else {
                f64::from(u.arbitrary::<i8>()?) / 100.0
            })
        })
        .collect()
}

/// A `trajectory_msgs/JointTrajectory` for one of kerf's robots (`robot` 0: the laser cutter,
/// else the IRB 6660), mostly with the robot's joint names.
pub fn joint_trajectory(u: &mut Unstructured, robot: usize) -> Result<JointTrajectory> {
    let base = if robot == 0 { 0 } else { 6 };
    let mut joint_names: Vec<String> = (0..6).map(|j| JOINT_NAMES[base + j].into()).collect();
    match u.int_in_range(0u8..=7)? {
        0 => joint_names = u.arbitrary()?,
        1 => {
            let i = u.choose_index(6)?;
            let j = u.choose_index(6)?;
            joint_names.swap(i, j);
        }
        2 => {
            joint_names.pop();
        }
        3 => joint_names.push(JOINT_NAMES[u.choose_index(JOINT_NAMES.len())?].into()),
        _ => {}
    }
    let n = joint_names.len();
    let count = u.int_in_range(0..=8)?;
    let mut t = 0.0;
    let mut points = Vec::with_capacity(count);
    for _ in 0..count {
        let time_from_start = duration(u, t)?;
        t += f64::from(u.arbitrary::<u8>()?) / 100.0;
        points.push(JointTrajectoryPoint {
            positions: joint_values(u, n)?,
            velocities: joint_values(u, n)?,
            accelerations: joint_values(u, n)?,
            effort: if u.ratio(1u8, 8)? {
                joint_values(u, n)?
            } else {
                Vec::new()
            },
            time_from_start,
        });
    }
    let stamp = if u.arbitrary()? {
        Time::default()
    } else {
        Time {
            sec: u.arbitrary()?,
            nanosec: u.arbitrary()?,
        }
    };
    Ok(JointTrajectory {
        header: Header {
            stamp,
            frame_id: String::new(),
        },
        joint_names,
        points,
    })
}
