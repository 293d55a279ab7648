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
#[derive(Debug, Clone)]
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

/// A request checked against the robot model alone, on time relative to its start time.
///
/// [`prepare`] does everything that depends only on the request and the robot: joint mapping,
/// point structure, times, finiteness, the final state at rest, waypoint positions, and the
/// exact position, velocity and acceleration extrema of every segment between waypoints with
/// the velocity steps between them. That is nearly all of the cost (O(points · joints)).
/// [`PreparedTrajectory::finish`] then adds what depends on the current state and the clock —
/// the start time, the start segment or first-point match, and the velocity steps into the
/// trajectory and into the final hold — in O(joints), so a node can prepare on a worker thread
/// and finish in its control loop without missing a cycle.
#[derive(Debug, Clone)]
pub struct PreparedTrajectory {
    n: usize,
    points: Vec<ModelPoint>,
    /// Segments between waypoints, on time from the start (`t0 = time_from_start` of their
    /// first point).
    segments: Vec<Segment>,
    coeffs: Vec<[f64; 6]>,
    start_time: Option<f64>,
}

/// Checks a request against the robot model and builds its segments between waypoints.
///
/// # Arguments
/// * `limits` — the robot model, in model joint order.
/// * `cfg` — executor configuration (control period for velocity steps).
/// * `req` — the request, joints in any order.
///
/// # Returns
/// The prepared trajectory, or the first problem found; times in errors are seconds from
/// the trajectory's start time (`time_from_start`).
///
/// # Performance
/// O(points · joints); each joint of each segment costs three root isolations of degree ≤ 4,
/// about 0.5 µs in a release build (6 joints × 1000 quintic points: about 3 ms).
pub fn prepare(
    limits: &[JointLimits],
    cfg: &ExecutorConfig,
    req: &TrajectoryRequest,
) -> Result<PreparedTrajectory, ExecutorError> {
    check_limits(limits)?;
    cfg.check(limits)?;
    let n = limits.len();
    let map = map_joints(limits, &req.joint_names)?;
    if req.points.is_empty() {
        return Err(ExecutorError::EmptyTrajectory);
    }
    check_points(req)?;
    if let Some(s) = req.start_time {
        // Any finite time on the executor's clock; negative times lie before its origin
        // (e.g. a stamp from before the node started) and are simply in the past.
        if !s.is_finite() {
            return Err(ExecutorError::InvalidStartTime { value: s });
        }
    }
    let points = to_model_order(req, &map, n);
    check_waypoints(limits, &points)?;

    let mut segments = Vec::with_capacity(points.len().saturating_sub(1));
    let mut coeffs = Vec::with_capacity(points.len().saturating_sub(1) * n);
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
            t0: a.time_from_start,
            t1: b.time_from_start,
            duration,
            kind,
            from: Some(k),
        });
    }
    check_segments(limits, &segments, &coeffs, n, 0.0)?;
    for k in 1..segments.len() {
        let before = &coeffs[(k - 1) * n..k * n];
        let after = &coeffs[k * n..(k + 1) * n];
        let duration = segments[k - 1].duration;
        check_velocity_step(
            limits,
            cfg,
            &|j| evaluate(&before[j], duration).1,
            &|j| after[j][1],
            segments[k].t0,
            &|| format!("point {k}"),
        )?;
    }
    Ok(PreparedTrajectory {
        n,
        points,
        segments,
        coeffs,
        start_time: req.start_time,
    })
}

impl PreparedTrajectory {
    /// Number of joints (the robot model's).
    pub fn joint_count(&self) -> usize {
        self.n
    }

    /// Number of waypoints.
    pub fn point_count(&self) -> usize {
        self.points.len()
    }

    /// `time_from_start` of the last point (s).
    pub fn duration(&self) -> f64 {
        self.points.last().map_or(0.0, |p| p.time_from_start)
    }

    /// Completes validation against the current state at time `now` (see [`validate`]).
    ///
    /// # Arguments
    /// * `limits`, `cfg` — the robot model and configuration this trajectory was prepared for.
    /// * `current` — the state the motion starts from (model order); empty velocities or
    ///   accelerations count as zero.
    /// * `now` — current absolute time (s).
    ///
    /// # Returns
    /// The trajectory on absolute time, or why it cannot start from `current` at `now`.
    ///
    /// # Performance
    /// O(joints), plus a copy of the prepared segments.
    pub fn finish(
        &self,
        limits: &[JointLimits],
        cfg: &ExecutorConfig,
        current: &JointSample,
        now: f64,
    ) -> Result<ValidatedTrajectory, ExecutorError> {
        if limits.len() != self.n {
            return Err(ExecutorError::StateLength {
                what: "prepared trajectory",
                field: "joints",
                actual: self.n,
                expected: limits.len(),
                empty_note: "",
            });
        }
        if !now.is_finite() {
            return Err(ExecutorError::NonFiniteTime {
                what: "now",
                value: now,
            });
        }
        current.check("current state", limits, false)?;
        let n = self.n;
        let points = &self.points;

        // Start time (JTC: header.stamp 0 = now).
        let start = match self.start_time {
            None => now,
            Some(0.0) => now,
            Some(s) => s,
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
        // Hold until a future start time when at rest; a moving state cannot be held, so then
        // the start segment begins now, as in JTC.
        let t_begin = if start > now && at_rest { start } else { now };

        let mut segments = Vec::with_capacity(self.segments.len() + 1);
        let mut coeffs = Vec::with_capacity(self.coeffs.len() + n);
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
            // Times in errors are seconds from the start time, like the waypoints'.
            check_segments(limits, &segments, &coeffs, n, start)?;
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
        let has_start_segment = !segments.is_empty();
        segments.extend(self.segments.iter().map(|s| Segment {
            t0: start + s.t0,
            t1: start + s.t1,
            ..s.clone()
        }));
        coeffs.extend_from_slice(&self.coeffs);

        // Velocity steps into the motion, from the start segment into the waypoint segments,
        // and into the final hold.
        if let Some(first) = segments.first() {
            let c = &coeffs[..n];
            let location = || match first.from {
                None => "start of the start segment, current state → point 0".to_string(),
                Some(_) => "point 0, due at the start time".to_string(),
            };
            check_velocity_step(
                limits,
                cfg,
                &|j| initial.velocities[j],
                &|j| c[j][1],
                first.t0 - start,
                &location,
            )?;
        }
        if has_start_segment && segments.len() > 1 {
            let (c0, c1) = (&coeffs[..n], &coeffs[n..2 * n]);
            let duration = segments[0].duration;
            check_velocity_step(
                limits,
                cfg,
                &|j| evaluate(&c0[j], duration).1,
                &|j| c1[j][1],
                points[0].time_from_start,
                &|| "point 0".to_string(),
            )?;
        }
        let last = points.len() - 1;
        let end_time = start + points[last].time_from_start;
        let end_velocity = |j: usize| match segments.last() {
            Some(seg) => {
                let k = segments.len() - 1;
                evaluate(&coeffs[k * n + j], seg.duration).1
            }
            None => initial.velocities[j],
        };
        let location = || {
            if segments.is_empty() {
                "point 0, due at the start time; the trajectory ends there at rest".to_string()
            } else {
                format!("last point {last}, where the trajectory ends at rest")
            }
        };
        check_velocity_step(
            limits,
            cfg,
            &end_velocity,
            &|_| 0.0,
            end_time - start,
            &location,
        )?;

        Ok(ValidatedTrajectory {
            n,
            segments,
            coeffs,
            initial,
            final_positions: points[last].positions.clone(),
            accepted_time: now,
            start_time: start,
            end_time,
            cursor: Cell::new(0),
        })
    }
}

/// Validates a trajectory request and builds its interpolation: [`prepare`] then
/// [`PreparedTrajectory::finish`].
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
/// [`ExecutorError::error_code`]. Times in errors are seconds from the trajectory's start
/// time.
///
/// # Performance
/// As [`prepare`]: about 3 ms for 6 joints × 1000 quintic points in a release build.
pub fn validate(
    limits: &[JointLimits],
    cfg: &ExecutorConfig,
    req: &TrajectoryRequest,
    current: &JointSample,
    now: f64,
) -> Result<ValidatedTrajectory, ExecutorError> {
    prepare(limits, cfg, req)?.finish(limits, cfg, current, now)
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

/// Waypoint positions within the limits; times in errors are `time_from_start`.
fn check_waypoints(limits: &[JointLimits], points: &[ModelPoint]) -> Result<(), ExecutorError> {
    for (index, pt) in points.iter().enumerate() {
        for (p, l) in pt.positions.iter().zip(limits) {
            if !position_ok(*p, l) {
                return Err(ExecutorError::PositionLimit {
                    joint: l.name.clone(),
                    location: format!("point {index}"),
                    time: pt.time_from_start,
                    value: *p,
                    min: l.min_position,
                    max: l.max_position,
                });
            }
        }
    }
    Ok(())
}

/// Exact extrema of position, velocity and acceleration on every segment (`coeffs`:
/// `segments.len() · n` sets, segment-major). Times in errors are `seg.t0 + τ − origin`.
fn check_segments(
    limits: &[JointLimits],
    segments: &[Segment],
    coeffs: &[[f64; 6]],
    n: usize,
    origin: f64,
) -> Result<(), ExecutorError> {
    for (s, seg) in segments.iter().enumerate() {
        let degree = match seg.kind {
            Interpolation::Linear => 1,
            Interpolation::Cubic => 3,
            Interpolation::Quintic => 5,
        };
        for (j, l) in limits.iter().enumerate() {
            let c = &coeffs[s * n + j];
            let ((t_min, p_min), (t_max, p_max)) = extrema(&c[..=degree], 0.0, seg.duration);
            for (tau, p) in [(t_min, p_min), (t_max, p_max)] {
                if !position_ok(p, l) {
                    return Err(ExecutorError::PositionLimit {
                        joint: l.name.clone(),
                        location: seg.location(),
                        time: seg.t0 + tau - origin,
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
                    time: seg.t0 + tau - origin,
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
                        time: seg.t0 + tau - origin,
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

/// A velocity discontinuity (at linear segments, a linear start segment from a moving state,
/// the stop at the end of a linear segment) is commanded within one control period: check
/// `|Δv| / control_period` against the acceleration limit, for every joint.
///
/// `time` is seconds from the trajectory's start time.
fn check_velocity_step(
    limits: &[JointLimits],
    cfg: &ExecutorConfig,
    left: &dyn Fn(usize) -> f64,
    right: &dyn Fn(usize) -> f64,
    time: f64,
    location: &dyn Fn() -> String,
) -> Result<(), ExecutorError> {
    for (j, l) in limits.iter().enumerate() {
        let (from, to) = (left(j), right(j));
        let acceleration = (to - from).abs() / cfg.control_period;
        if !rate_ok(acceleration, l.max_acceleration) {
            return Err(ExecutorError::VelocityStep {
                joint: l.name.clone(),
                location: location(),
                time,
                from,
                to,
                period: cfg.control_period,
                acceleration,
                limit: l.max_acceleration,
            });
        }
    }
    Ok(())
}
