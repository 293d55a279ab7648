//! The executed tool path (issue 13, item 1): a milling trajectory as the trajectory executor
//! runs it — its own interpolation (`kerf_executor::check_executable`, JTC cubic Hermite from positions
//! and velocities), sampled at the control period — the tool tip by forward kinematics with
//! the cell's TCP, measured against the planned path and the milling plane.

use kerf_executor::{check_executable, ExecutorConfig};
use kerf_mill::MillCell;
use nalgebra::Vector3;

use crate::error::MillPlanError;
use crate::trajectory::JointTrajectory;

/// How far the executed tool tip leaves the planned path (m).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PathDeviation {
    /// Largest distance from the path curve over the samples.
    pub max_off_path: f64,
    /// 99th percentile of the distance from the path curve.
    pub p99_off_path: f64,
    /// Largest distance from the milling plane (along its normal).
    pub max_off_plane: f64,
    /// Time of the largest distance from the path (s from the start).
    pub time_of_max: f64,
    /// Samples measured (one per control period, both ends included).
    pub samples: usize,
}

/// Most closest-point iterations (Gauss–Newton on |P(u) − x|²).
const CLOSEST_ITERATIONS: usize = 12;

/// Coarse samples of the path searched when the local guess lands far from it.
const COARSE_SAMPLES: usize = 2000;

/// Distance from `x` to the path curve, starting from parameter `u0`, and the parameter of
/// the closest point.
///
/// Gauss–Newton on |P(u) − x|², stopped when the step is below 1e-13 in u; a guess that
/// ends more than 1 mm away is retried from the best of a coarse scan of the whole curve.
pub(crate) fn distance_to_path(
    cell: &MillCell,
    x: &Vector3<f64>,
    u0: f64,
) -> Result<(f64, f64), MillPlanError> {
    let path = cell.path();
    let refine = |mut u: f64| -> Result<(f64, f64), MillPlanError> {
        let mut distance = f64::INFINITY;
        for _ in 0..CLOSEST_ITERATIONS {
            let (p, d) = path.point_and_derivative(u)?;
            distance = (p - x).norm();
            let step = (p - x).dot(&d) / d.norm_squared().max(1e-300);
            let next = (u - step).clamp(0.0, 1.0);
            // Converged when the foot point moves less than 1e-10 m: the distance at u is
            // then exact to ~1e-20 m (the residual is normal to the curve).
            let moved = (next - u).abs() * d.norm();
            u = next;
            if moved <= 1e-10 {
                return Ok((distance, u));
            }
        }
        Ok(((path.point(u)? - x).norm().min(distance), u))
    };
    let first = refine(u0.clamp(0.0, 1.0))?;
    if first.0 < 1e-3 {
        return Ok(first);
    }
    // A guess far from the closest point: scan the whole curve, refine the best.
    let mut best = (f64::INFINITY, 0.0);
    for k in 0..=COARSE_SAMPLES {
        let u = k as f64 / COARSE_SAMPLES as f64;
        let d = (path.point(u)? - x).norm();
        if d < best.0 {
            best = (d, u);
        }
    }
    let second = refine(best.1)?;
    Ok(if second.0 < first.0 { second } else { first })
}

/// Measures the executed tool path of `trajectory` on `cell`.
///
/// # Arguments
/// * `cell` — the milling cell the trajectory was planned for (robot, TCP, path).
/// * `trajectory` — the trajectory as published (joint_1 … joint_6).
/// * `period` — the executor's control period (s), > 0.
///
/// # Returns
/// The largest and 99th-percentile distance of the tool tip from the path curve and the
/// largest distance from the milling plane, over every control period.
///
/// # Errors
/// The executor's refusal of the trajectory ([`MillPlanError::NotExecutable`]), a bad
/// period ([`MillPlanError::InvalidParameter`]), kinematics or path errors.
///
/// # Performance
/// One interpolation, one forward kinematics and a few path evaluations per sample.
pub fn executed_deviation(
    cell: &MillCell,
    trajectory: &JointTrajectory,
    period: f64,
) -> Result<PathDeviation, MillPlanError> {
    Ok(measure(cell, trajectory, period, f64::INFINITY)?.0)
}

/// [`executed_deviation`] and the times (s from the start) of the samples whose distance
/// from the path or the plane exceeds `tolerance` \[m\].
///
/// # Errors
/// As [`executed_deviation`].
pub(crate) fn measure(
    cell: &MillCell,
    trajectory: &JointTrajectory,
    period: f64,
    tolerance: f64,
) -> Result<(PathDeviation, Vec<f64>), MillPlanError> {
    if !(period.is_finite() && period > 0.0) {
        return Err(MillPlanError::InvalidParameter {
            name: "control period [s]".into(),
            value: period,
            reason: "must be finite and > 0".into(),
        });
    }
    let not_executable = |reason: String| MillPlanError::NotExecutable { reason };
    let limits = cell
        .robot()
        .executor_limits()
        .map_err(|e| not_executable(e.to_string()))?;
    // What the executor runs: its validation from rest at the first point, on its clock.
    let prepared = check_executable(&limits, &ExecutorConfig::default(), &trajectory.request)
        .map_err(|e| not_executable(e.to_string()))?;
    let path = cell.path();
    let origin = path.point(0.0)?;
    let normal = path.normal();
    let total = path.total_length();
    let points = trajectory.points();
    // The spline parameter of every point, the guesses between them linear in time.
    let params = trajectory
        .arc_length
        .iter()
        .map(|s| path.parameter_at(s.clamp(0.0, total)))
        .collect::<Result<Vec<f64>, _>>()?;
    let (t0, t1) = (prepared.start_time(), prepared.end_time());
    let steps = ((t1 - t0) / period).ceil() as usize;
    let mut off_path = Vec::with_capacity(steps + 1);
    let mut max_off_plane: f64 = 0.0;
    let (mut max_off_path, mut time_of_max) = (0.0, 0.0);
    let mut sample = kerf_executor::JointSample::default();
    let mut cursor = 0;
    let mut over = Vec::new();
    let mut previous: [Option<f64>; 2] = [None, None];
    for k in 0..=steps {
        let t = (t0 + k as f64 * period).min(t1);
        prepared.sample_into(t, &mut sample);
        let mut q = [0.0; 6];
        for (qj, v) in q.iter_mut().zip(&sample.positions) {
            *qj = *v;
        }
        let tip = cell.kinematics().tcp_pose(&q)?.translation.vector;
        let off_plane = (tip - origin).dot(&normal).abs();
        max_off_plane = max_off_plane.max(off_plane);
        let tr = t - t0;
        while cursor + 2 < points.len() && points[cursor + 1].time_from_start <= tr {
            cursor += 1;
        }
        let next = (cursor + 1).min(points.len() - 1);
        let (a, b) = (&points[cursor], &points[next]);
        let span = b.time_from_start - a.time_from_start;
        let w = if span > 0.0 {
            ((tr - a.time_from_start) / span).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let linear = params[cursor] + w * (params[next] - params[cursor]);
        // Warm start: the foot points of the last two samples, extrapolated (consecutive
        // samples are one control period apart), when they agree with the linear guess.
        let guess = match (previous[0], previous[1]) {
            (Some(a), Some(b)) if ((2.0 * b - a) - linear).abs() < 1e-3 => 2.0 * b - a,
            _ => linear,
        };
        let (d, u) = distance_to_path(cell, &tip, guess)?;
        previous = [previous[1], Some(u)];
        if d > max_off_path {
            (max_off_path, time_of_max) = (d, tr);
        }
        off_path.push(d);
        if d.max(off_plane) > tolerance {
            over.push(tr);
        }
    }
    let samples = off_path.len();
    off_path.sort_by(|a, b| a.total_cmp(b));
    let p99_off_path = off_path
        .get(((samples.saturating_sub(1)) as f64 * 0.99).round() as usize)
        .copied()
        .unwrap_or(0.0);
    Ok((
        PathDeviation {
            max_off_path,
            p99_off_path,
            max_off_plane,
            time_of_max,
            samples,
        },
        over,
    ))
}
