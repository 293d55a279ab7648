//! Validation of a trajectory request against the robot model and the current state.

use std::cell::Cell;

use crate::error::ExecutorError;
use crate::roots::extrema;
use crate::spline::{
    acceleration_coefficients, coefficients, evaluate, velocity_coefficients, Interpolation, Knot,
};
use crate::trajectory::{Segment, ValidatedTrajectory};
use crate::types::{check_limits, joint_list, ExecutorConfig, JointLimits, JointSample};
use crate::TrajectoryRequest;

/// Relative slack on every limit check, so that trajectories generated exactly at a limit
/// (and then rounded) are not rejected. A velocity `v` passes when
/// `|v| <= max_velocity · (1 + LIMIT_SLACK)`; a position passes when it lies within the
/// limits widened by `LIMIT_SLACK · max(1, |limit|)` joint units.
pub const LIMIT_SLACK: f64 = 1e-9;

/// Whether a position lies within the joint's limits, widened by [`LIMIT_SLACK`].
pub(crate) fn position_ok(p: f64, l: &JointLimits) -> bool {
    let lo = l.min_position - LIMIT_SLACK * l.min_position.abs().max(1.0);
    let hi = l.max_position + LIMIT_SLACK * l.max_position.abs().max(1.0);
    p >= lo && p <= hi
}

/// Whether `|value| <= limit · (1 + LIMIT_SLACK)`.
fn rate_ok(value: f64, limit: f64) -> bool {
    value.abs() <= limit * (1.0 + LIMIT_SLACK)
}

/// One point in model joint order.
struct ModelPoint {
    positions: Vec<f64>,
    velocities: Option<Vec<f64>>,
    accelerations: Option<Vec<f64>>,
    time_from_start: f64,
}

impl ModelPoint {
    fn knot(&self, j: usize) -> Knot {
        Knot {
            p: self.positions[j],
            v: self.velocities.as_ref().map_or(0.0, |v| v[j]),
            a: self.accelerations.as_ref().map_or(0.0, |a| a[j]),
        }
    }
}

/// Validates a trajectory request and builds its interpolation.
///
/// Checks the robot model, the configuration, the current state and the request (joint names,
/// point structure, times, finiteness, a final state at rest, the start time) and then the
/// limits on the whole interpolated curve: positions, velocities and accelerations at their
/// exact extrema on every segment (roots of the derivative polynomials, see [`crate::roots`]),
/// and every velocity step (at linear segments, see the crate docs) as an acceleration
/// `Δv / control_period`.
///
/// # Arguments
/// * `limits` — the robot model, in model joint order.
/// * `cfg` — executor configuration (control period, start tolerance).
/// * `req` — the request, joints in any order.
/// * `current` — the state the motion starts from (model order); empty velocities or
///   accelerations count as zero.
/// * `now` — current absolute time (s).
///
/// # Returns
/// The trajectory in model order, or the first problem found. See [`ExecutorError`] and its
/// [`ExecutorError::error_code`].
///
/// # Performance
/// O(points · joints); each joint of each segment costs three root isolations of degree ≤ 4,
/// about 1 µs in a release build (6 joints × 1000 quintic points: about 6.5 ms).
pub fn validate(
    limits: &[JointLimits],
    cfg: &ExecutorConfig,
    req: &TrajectoryRequest,
    current: &JointSample,
    now: f64,
) -> Result<ValidatedTrajectory, ExecutorError> {
    check_limits(limits)?;
    cfg.check(limits)?;
    if !now.is_finite() {
        return Err(ExecutorError::NonFiniteTime {
            what: "now",
            value: now,
        });
    }
    current.check("current state", limits, false)?;
    let n = limits.len();

    let map = map_joints(limits, &req.joint_names)?;
    if req.points.is_empty() {
        return Err(ExecutorError::EmptyTrajectory);
    }
    check_points(req)?;
    let points = to_model_order(req, &map, n);

    // Start time (JTC: header.stamp 0 = now).
    let start = match req.start_time {
        None => now,
        Some(0.0) => now,
        Some(s) => {
            // Any finite time on the executor's clock; negative times lie before its origin
            // (e.g. a stamp from before the node started) and are simply in the past.
            if !s.is_finite() {
                return Err(ExecutorError::InvalidStartTime { value: s });
            }
            s
        }
    };
    let first_abs = start + points[0].time_from_start;
    if start < now && first_abs <= now {
        return Err(ExecutorError::OldHeaderTimestamp {
            start_time: start,
            first_point_time: first_abs,
            now,
        });
    }

    let initial = JointSample {
        positions: current.positions.clone(),
        velocities: full_or_zero(&current.velocities, n),
        accelerations: full_or_zero(&current.accelerations, n),
    };
    let at_rest = initial.velocities.iter().all(|&v| v == 0.0)
        && initial.accelerations.iter().all(|&a| a == 0.0);
    // Hold until a future start time when at rest; a moving state cannot be held, so then the
    // start segment begins now, as in JTC.
    let t_begin = if start > now && at_rest { start } else { now };

    let mut segments = Vec::with_capacity(points.len());
    let mut coeffs = Vec::with_capacity(points.len() * n);
    if first_abs > t_begin {
        let p0 = &points[0];
        let kind = Interpolation::between(
            true,
            true,
            p0.velocities.is_some(),
            p0.accelerations.is_some(),
        );
        let duration = first_abs - t_begin;
        for j in 0..n {
            let k0 = Knot {
                p: initial.positions[j],
                v: initial.velocities[j],
                a: initial.accelerations[j],
            };
            coeffs.push(coefficients(kind, k0, p0.knot(j), duration));
        }
        segments.push(Segment {
            t0: t_begin,
            t1: first_abs,
            duration,
            kind,
            from: None,
        });
    } else {
        // The first point is due now: it must be where the robot is commanded to be.
        for (j, l) in limits.iter().enumerate() {
            let difference = (points[0].positions[j] - initial.positions[j]).abs();
            if difference > cfg.start_tolerance {
                return Err(ExecutorError::StartMismatch {
                    joint: l.name.clone(),
                    current: initial.positions[j],
                    first: points[0].positions[j],
                    difference,
                    tolerance: cfg.start_tolerance,
                });
            }
        }
    }
    for (k, w) in points.windows(2).enumerate() {
        let (a, b) = (&w[0], &w[1]);
        let kind = Interpolation::between(
            a.velocities.is_some(),
            a.accelerations.is_some(),
            b.velocities.is_some(),
            b.accelerations.is_some(),
        );
        let duration = b.time_from_start - a.time_from_start;
        for j in 0..n {
            coeffs.push(coefficients(kind, a.knot(j), b.knot(j), duration));
        }
        segments.push(Segment {
            t0: start + a.time_from_start,
            t1: start + b.time_from_start,
            duration,
            kind,
            from: Some(k),
        });
    }
    let last = points.len() - 1;
    let traj = ValidatedTrajectory {
        n,
        segments,
        coeffs,
        initial,
        final_positions: points[last].positions.clone(),
        accepted_time: now,
        start_time: start,
        end_time: start + points[last].time_from_start,
        cursor: Cell::new(0),
    };

    check_waypoints(limits, &points, start)?;
    check_segments(limits, &traj)?;
    check_velocity_steps(limits, cfg, &traj, last)?;
    Ok(traj)
}

fn full_or_zero(v: &[f64], n: usize) -> Vec<f64> {
    if v.is_empty() {
        vec![0.0; n]
    } else {
        v.to_vec()
    }
}

/// `map[k]` = model index of the request's k-th joint. All joints required (JTC
/// `allow_partial_joints_goal: false`).
fn map_joints(limits: &[JointLimits], names: &[String]) -> Result<Vec<usize>, ExecutorError> {
    if names.is_empty() {
        return Err(ExecutorError::NoJointNames);
    }
    let mut map = Vec::with_capacity(names.len());
    for (k, name) in names.iter().enumerate() {
        if names[..k].contains(name) {
            return Err(ExecutorError::DuplicateJoint {
                joint: name.clone(),
            });
        }
        match limits.iter().position(|l| &l.name == name) {
            Some(j) => map.push(j),
            None => {
                return Err(ExecutorError::UnknownJoint {
                    joint: name.clone(),
                    known: joint_list(limits),
                })
            }
        }
    }
    let missing: Vec<&str> = limits
        .iter()
        .enumerate()
        .filter(|(j, _)| !map.contains(j))
        .map(|(_, l)| l.name.as_str())
        .collect();
    if !missing.is_empty() {
        return Err(ExecutorError::MissingJoints {
            missing: missing.join(", "),
        });
    }
    Ok(map)
}

/// Structure, times and finiteness of every point; the last point at rest.
fn check_points(req: &TrajectoryRequest) -> Result<(), ExecutorError> {
    let n = req.joint_names.len();
    for (index, pt) in req.points.iter().enumerate() {
        let time = pt.time_from_start;
        if !(time.is_finite() && time >= 0.0) {
            return Err(ExecutorError::InvalidTimeFromStart { index, time });
        }
        if index > 0 {
            let previous = req.points[index - 1].time_from_start;
            if time <= previous {
                return Err(ExecutorError::NonIncreasingTime {
                    index,
                    time,
                    previous_index: index - 1,
                    previous,
                });
            }
        }
        if !pt.effort.is_empty() {
            return Err(ExecutorError::EffortNotSupported { index });
        }
        let fields: [(&'static str, &Vec<f64>, bool); 3] = [
            ("positions", &pt.positions, false),
            ("velocities", &pt.velocities, true),
            ("accelerations", &pt.accelerations, true),
        ];
        for (field, values, may_be_empty) in fields {
            if values.len() != n && !(may_be_empty && values.is_empty()) {
                return Err(ExecutorError::WrongLength {
                    index,
                    field,
                    actual: values.len(),
                    expected: n,
                    empty_note: if may_be_empty { " or none" } else { "" },
                });
            }
        }
        if !pt.accelerations.is_empty() && pt.velocities.is_empty() {
            return Err(ExecutorError::AccelerationsWithoutVelocities { index });
        }
        for (field, values, _) in fields {
            for (value, joint) in values.iter().zip(&req.joint_names) {
                if !value.is_finite() {
                    return Err(ExecutorError::NonFiniteValue {
                        index,
                        field,
                        joint: joint.clone(),
                        value: *value,
                    });
                }
            }
        }
    }
    // JTC Jazzy `allow_nonzero_velocity_at_trajectory_end: false`.
    let index = req.points.len() - 1;
    let last = &req.points[index];
    for (field, values) in [
        ("velocity", &last.velocities),
        ("acceleration", &last.accelerations),
    ] {
        for (value, joint) in values.iter().zip(&req.joint_names) {
            if *value != 0.0 {
                return Err(ExecutorError::NonZeroFinalState {
                    index,
                    field,
                    joint: joint.clone(),
                    value: *value,
                });
            }
        }
    }
    Ok(())
}

fn to_model_order(req: &TrajectoryRequest, map: &[usize], n: usize) -> Vec<ModelPoint> {
    let reorder = |values: &[f64]| {
        let mut out = vec![0.0; n];
        for (k, &j) in map.iter().enumerate() {
            out[j] = values[k];
        }
        out
    };
    req.points
        .iter()
        .map(|pt| ModelPoint {
            positions: reorder(&pt.positions),
            velocities: (!pt.velocities.is_empty()).then(|| reorder(&pt.velocities)),
            accelerations: (!pt.accelerations.is_empty()).then(|| reorder(&pt.accelerations)),
            time_from_start: pt.time_from_start,
        })
        .collect()
}

fn check_waypoints(
    limits: &[JointLimits],
    points: &[ModelPoint],
    start: f64,
) -> Result<(), ExecutorError> {
    for (index, pt) in points.iter().enumerate() {
        for (p, l) in pt.positions.iter().zip(limits) {
            if !position_ok(*p, l) {
                return Err(ExecutorError::PositionLimit {
                    joint: l.name.clone(),
                    location: format!("point {index}"),
                    time: start + pt.time_from_start,
                    value: *p,
                    min: l.min_position,
                    max: l.max_position,
                });
            }
        }
    }
    Ok(())
}

/// Exact extrema of position, velocity and acceleration on every segment.
fn check_segments(limits: &[JointLimits], traj: &ValidatedTrajectory) -> Result<(), ExecutorError> {
    let n = traj.n;
    for (s, seg) in traj.segments.iter().enumerate() {
        let degree = match seg.kind {
            Interpolation::Linear => 1,
            Interpolation::Cubic => 3,
            Interpolation::Quintic => 5,
        };
        for (j, l) in limits.iter().enumerate() {
            let c = &traj.coeffs[s * n + j];
            let ((t_min, p_min), (t_max, p_max)) = extrema(&c[..=degree], 0.0, seg.duration);
            for (tau, p) in [(t_min, p_min), (t_max, p_max)] {
                if !position_ok(p, l) {
                    return Err(ExecutorError::PositionLimit {
                        joint: l.name.clone(),
                        location: seg.location(),
                        time: seg.t0 + tau,
                        value: p,
                        min: l.min_position,
                        max: l.max_position,
                    });
                }
            }
            let vc = velocity_coefficients(c);
            let (tau, v) = worst(extrema(&vc[..degree], 0.0, seg.duration));
            if !rate_ok(v, l.max_velocity) {
                return Err(ExecutorError::VelocityLimit {
                    joint: l.name.clone(),
                    location: seg.location(),
                    time: seg.t0 + tau,
                    value: v,
                    limit: l.max_velocity,
                });
            }
            if degree > 1 {
                let ac = acceleration_coefficients(c);
                let (tau, a) = worst(extrema(&ac[..degree - 1], 0.0, seg.duration));
                if !rate_ok(a, l.max_acceleration) {
                    return Err(ExecutorError::AccelerationLimit {
                        joint: l.name.clone(),
                        location: seg.location(),
                        time: seg.t0 + tau,
                        value: a,
                        limit: l.max_acceleration,
                    });
                }
            }
        }
    }
    Ok(())
}

/// The extremum of larger magnitude.
fn worst(((t_min, v_min), (t_max, v_max)): ((f64, f64), (f64, f64))) -> (f64, f64) {
    if v_max.abs() >= v_min.abs() {
        (t_max, v_max)
    } else {
        (t_min, v_min)
    }
}

/// Velocity discontinuities (linear segments, a linear start segment from a moving state, the
/// stop at the end of a linear segment) are commanded within one control period: check
/// `|Δv| / control_period` against the acceleration limit.
fn check_velocity_steps(
    limits: &[JointLimits],
    cfg: &ExecutorConfig,
    traj: &ValidatedTrajectory,
    last_point: usize,
) -> Result<(), ExecutorError> {
    let n = traj.n;
    let mut left = traj.initial.velocities.clone();
    let check = |left: &[f64],
                 right: &dyn Fn(usize) -> f64,
                 time: f64,
                 location: &dyn Fn() -> String|
     -> Result<(), ExecutorError> {
        for (j, l) in limits.iter().enumerate() {
            let to = right(j);
            let acceleration = (to - left[j]).abs() / cfg.control_period;
            if !rate_ok(acceleration, l.max_acceleration) {
                return Err(ExecutorError::VelocityStep {
                    joint: l.name.clone(),
                    location: location(),
                    time,
                    from: left[j],
                    to,
                    period: cfg.control_period,
                    acceleration,
                    limit: l.max_acceleration,
                });
            }
        }
        Ok(())
    };
    for (s, seg) in traj.segments.iter().enumerate() {
        let c = &traj.coeffs[s * n..(s + 1) * n];
        let location = || match (s, seg.from) {
            (_, None) => "start of the start segment, current state → point 0".to_string(),
            (0, Some(0)) => "point 0, due at the start time".to_string(),
            (_, Some(k)) => format!("point {k}"),
        };
        check(&left, &|j| c[j][1], seg.t0, &location)?;
        for (j, cj) in c.iter().enumerate() {
            left[j] = evaluate(cj, seg.duration).1;
        }
    }
    let location = || {
        if traj.segments.is_empty() {
            "point 0, due at the start time; the trajectory ends there at rest".to_string()
        } else {
            format!("last point {last_point}, where the trajectory ends at rest")
        }
    };
    check(&left, &|_| 0.0, traj.end_time, &location)
}
