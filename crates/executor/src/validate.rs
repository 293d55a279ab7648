//! Validation of a trajectory request against the robot model and the current state.

use std::cell::{Cell, RefCell};
use std::sync::Arc;

use crate::error::ExecutorError;
use crate::roots::extrema;
use crate::slack::{position_ok, rate_ok};
use crate::spline::{
    acceleration_coefficients, coefficients, evaluate, velocity_coefficients, Interpolation, Knot,
};
use crate::trajectory::{
    Body, Lead, Segment, ValidatedTrajectory, HAS_ACCELERATIONS, HAS_VELOCITIES,
};
use crate::types::{check_limits, joint_list, ExecutorConfig, JointLimits, JointSample};
use crate::TrajectoryRequest;

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
///
/// The segments are shared (`Arc`) with every trajectory finished from it: cloning is O(1),
/// and dropping is O(1) unless it holds the last reference to them.
#[derive(Debug, Clone)]
pub struct PreparedTrajectory {
    body: Arc<Body>,
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
    let body = to_model_order(req, &map, n);
    check_waypoints(limits, &body)?;

    // Every segment's exact extrema, then every velocity step between segments (the order
    // in which problems are reported); coefficients are computed per segment, not stored.
    let mut coeffs = Vec::with_capacity(n);
    for k in 0..body.segment_count() {
        body.coefficients_into(k, &mut coeffs);
        check_segments(
            limits,
            std::slice::from_ref(&body.segment(k)),
            &coeffs,
            n,
            0.0,
        )?;
    }
    let mut before = Vec::with_capacity(n);
    if body.segment_count() > 1 {
        body.coefficients_into(0, &mut before);
    }
    for k in 1..body.segment_count() {
        if k > 1 {
            std::mem::swap(&mut before, &mut coeffs);
        }
        body.coefficients_into(k, &mut coeffs);
        let duration = body.segment(k - 1).duration;
        check_velocity_step(
            limits,
            cfg,
            &|j| evaluate(&before[j], duration).1,
            &|j| coeffs[j][1],
            body.times[k],
            &|| format!("point {k}"),
        )?;
    }
    Ok(PreparedTrajectory {
        body: Arc::new(body),
        start_time: req.start_time,
    })
}

impl PreparedTrajectory {
    /// Number of joints (the robot model's).
    pub fn joint_count(&self) -> usize {
        self.body.n
    }

    /// Number of waypoints.
    pub fn point_count(&self) -> usize {
        self.body.point_count()
    }

    /// `time_from_start` of the last point (s).
    pub fn duration(&self) -> f64 {
        self.body.duration()
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
    /// O(joints): the waypoint segments are shared, not copied.
    pub fn finish(
        &self,
        limits: &[JointLimits],
        cfg: &ExecutorConfig,
        current: &JointSample,
        now: f64,
    ) -> Result<ValidatedTrajectory, ExecutorError> {
        let body = &self.body;
        let n = body.n;
        if limits.len() != n {
            return Err(ExecutorError::StateLength {
                what: "prepared trajectory",
                field: "joints",
                actual: n,
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
        let p0_time = body.times[0];

        // Start time (JTC: header.stamp 0 = now).
        let start = match self.start_time {
            None => now,
            Some(0.0) => now,
            Some(s) => s,
        };
        let first_abs = start + p0_time;
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

        let lead = if first_abs > t_begin {
            let kind = Interpolation::between(
                true,
                true,
                body.has_velocities(0),
                body.has_accelerations(0),
            );
            let duration = first_abs - t_begin;
            let coeffs: Vec<[f64; 6]> = (0..n)
                .map(|j| {
                    let k0 = Knot {
                        p: initial.positions[j],
                        v: initial.velocities[j],
                        a: initial.accelerations[j],
                    };
                    coefficients(kind, k0, body.knot(0, j), duration)
                })
                .collect();
            let segment = Segment {
                t0: t_begin,
                t1: first_abs,
                duration,
                kind,
                from: None,
            };
            // Times in errors are seconds from the start time, like the waypoints'.
            check_segments(limits, std::slice::from_ref(&segment), &coeffs, n, start)?;
            Some(Lead { segment, coeffs })
        } else {
            // The first point is due now: it must be where the robot is commanded to be.
            let first = body.positions(0);
            for (j, l) in limits.iter().enumerate() {
                let difference = (first[j] - initial.positions[j]).abs();
                if difference > cfg.start_tolerance {
                    return Err(ExecutorError::StartMismatch {
                        joint: l.name.clone(),
                        current: initial.positions[j],
                        first: first[j],
                        difference,
                        tolerance: cfg.start_tolerance,
                    });
                }
            }
            None
        };

        // Velocity steps into the motion, from the start segment into the waypoint segments,
        // and into the final hold.
        let mut body_first = Vec::with_capacity(n);
        let body_segment = (body.segment_count() > 0).then(|| {
            body.coefficients_into(0, &mut body_first);
            body.segment(0)
        });
        let first_segment = match (&lead, &body_segment) {
            (Some(l), _) => Some((&l.coeffs[..], l.segment.t0 - start, l.segment.from)),
            (None, Some(s)) => Some((&body_first[..], s.t0, s.from)),
            (None, None) => None,
        };
        if let Some((c, time, from)) = first_segment {
            let location = || match from {
                None => "start of the start segment, current state → point 0".to_string(),
                Some(_) => "point 0, due at the start time".to_string(),
            };
            check_velocity_step(
                limits,
                cfg,
                &|j| initial.velocities[j],
                &|j| c[j][1],
                time,
                &location,
            )?;
        }
        if let (Some(l), Some(_)) = (&lead, &body_segment) {
            let c1 = &body_first[..];
            let duration = l.segment.duration;
            check_velocity_step(
                limits,
                cfg,
                &|j| evaluate(&l.coeffs[j], duration).1,
                &|j| c1[j][1],
                p0_time,
                &|| "point 0".to_string(),
            )?;
        }
        let last = body.point_count() - 1;
        let end_time = start + body.duration();
        let has_segments = lead.is_some() || body_segment.is_some();
        let last_segment = body.segment_count().checked_sub(1).map(|k| {
            let mut c = Vec::with_capacity(n);
            body.coefficients_into(k, &mut c);
            (body.segment(k).duration, c)
        });
        let end_velocity = |j: usize| match (&last_segment, &lead) {
            (Some((duration, c)), _) => evaluate(&c[j], *duration).1,
            (None, Some(l)) => evaluate(&l.coeffs[j], l.segment.duration).1,
            (None, None) => initial.velocities[j],
        };
        let location = || {
            if has_segments {
                format!("last point {last}, where the trajectory ends at rest")
            } else {
                "point 0, due at the start time; the trajectory ends there at rest".to_string()
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
            lead,
            body: Arc::clone(body),
            initial,
            accepted_time: now,
            start_time: start,
            end_time,
            cursor: Cell::new(0),
            cached: RefCell::new((usize::MAX, Vec::with_capacity(n))),
        })
    }
}

impl ValidatedTrajectory {
    /// Whether this trajectory runs the waypoint segments of `prepared` itself (shared by
    /// [`PreparedTrajectory::finish`], not copied).
    pub fn shares_segments_with(&self, prepared: &PreparedTrajectory) -> bool {
        Arc::ptr_eq(&self.body, &prepared.body)
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

/// The request's waypoints in model joint order, stored compactly ([`Body`]).
fn to_model_order(req: &TrajectoryRequest, map: &[usize], n: usize) -> Body {
    let count = req.points.len();
    let mut body = Body {
        n,
        times: Vec::with_capacity(count),
        knots: vec![0.0; 3 * n * count],
        given: Vec::with_capacity(count),
    };
    for (i, pt) in req.points.iter().enumerate() {
        body.times.push(pt.time_from_start);
        let mut given = 0;
        for (f, (values, flag)) in [
            (&pt.positions, 0),
            (&pt.velocities, HAS_VELOCITIES),
            (&pt.accelerations, HAS_ACCELERATIONS),
        ]
        .into_iter()
        .enumerate()
        {
            if values.is_empty() {
                continue;
            }
            given |= flag;
            let row = &mut body.knots[(3 * i + f) * n..(3 * i + f + 1) * n];
            for (k, &j) in map.iter().enumerate() {
                row[j] = values[k];
            }
        }
        body.given.push(given);
    }
    body
}

/// Waypoint positions within the limits; times in errors are `time_from_start`.
fn check_waypoints(limits: &[JointLimits], body: &Body) -> Result<(), ExecutorError> {
    for index in 0..body.point_count() {
        for (p, l) in body.positions(index).iter().zip(limits) {
            if !position_ok(*p, l) {
                return Err(ExecutorError::PositionLimit {
                    joint: l.name.clone(),
                    location: format!("point {index}"),
                    time: body.times[index],
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
