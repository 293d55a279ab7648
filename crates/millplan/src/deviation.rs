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

/// Samples per block of [`measure`] (the unit of its threads and of its warm start).
const BLOCK: usize = 256;

/// One measured sample: time from the start, distances from the path and the plane.
struct Sample {
    time: f64,
    off_path: f64,
    off_plane: f64,
}

/// What every block of [`measure`] reads.
struct Context<'a> {
    cell: &'a MillCell,
    points: &'a [crate::trajectory::TrajectoryPoint],
    params: &'a [f64],
    origin: Vector3<f64>,
    normal: Vector3<f64>,
    t0: f64,
    t1: f64,
    period: f64,
    steps: usize,
}

impl Context<'_> {
    /// The samples of block `b`: the executor's interpolation at each control period, the tip
    /// by forward kinematics, its closest point on the path (warm-started from the block's
    /// previous two samples) and its distance from the plane.
    fn block(
        &self,
        prepared: &kerf_executor::ValidatedTrajectory,
        b: usize,
    ) -> Result<Vec<Sample>, MillPlanError> {
        let points = self.points;
        let from = b * BLOCK;
        let to = ((b + 1) * BLOCK).min(self.steps + 1);
        let mut out = Vec::with_capacity(to.saturating_sub(from));
        let mut sample = kerf_executor::JointSample::default();
        let first_time = (from as f64 * self.period).min(self.t1 - self.t0);
        let mut cursor = points
            .partition_point(|p| p.time_from_start <= first_time)
            .saturating_sub(1)
            .min(points.len().saturating_sub(2));
        let mut previous: [Option<f64>; 2] = [None, None];
        for k in from..to {
            let t = (self.t0 + k as f64 * self.period).min(self.t1);
            prepared.sample_into(t, &mut sample);
            let mut q = [0.0; 6];
            for (qj, v) in q.iter_mut().zip(&sample.positions) {
                *qj = *v;
            }
            let tip = self.cell.kinematics().tcp_pose(&q)?.translation.vector;
            let off_plane = (tip - self.origin).dot(&self.normal).abs();
            let tr = t - self.t0;
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
            let linear = self.params[cursor] + w * (self.params[next] - self.params[cursor]);
            // Warm start: the foot points of the last two samples, extrapolated (consecutive
            // samples are one control period apart), when they agree with the linear guess.
            let guess = match (previous[0], previous[1]) {
                (Some(a), Some(b)) if ((2.0 * b - a) - linear).abs() < 1e-3 => 2.0 * b - a,
                _ => linear,
            };
            let (off_path, u) = distance_to_path(self.cell, &tip, guess)?;
            previous = [previous[1], Some(u)];
            out.push(Sample {
                time: tr,
                off_path,
                off_plane,
            });
        }
        Ok(out)
    }
}

/// Most closest-point iterations (Gauss–Newton on |P(u) − x|²).
const CLOSEST_ITERATIONS: usize = 12;

/// Coarse samples of the path searched when the local guess lands far from it.
const COARSE_SAMPLES: usize = 2000;

/// Distance from `x` to the path curve extended by straight lines along its end tangents
/// (the run-in and run-out of [`crate::timing::Entry::RunIn`]), starting from parameter
/// `u0`, and the parameter of the closest point on the curve (0 or 1 when the closest point
/// is on an extension).
///
/// Gauss–Newton on |P(u) − x|², stopped when the step is below 1e-13 in u; a guess that
/// ends more than 1 mm away is retried from the best of a coarse scan of the whole curve.
/// A closest point at an end of the curve with `x` beyond it (along the end tangent) is
/// replaced by the foot point on the extension.
pub(crate) fn distance_to_path(
    cell: &MillCell,
    x: &Vector3<f64>,
    u0: f64,
) -> Result<(f64, f64), MillPlanError> {
    let (distance, u) = distance_to_curve(cell, x, u0)?;
    if u > 0.0 && u < 1.0 {
        return Ok((distance, u));
    }
    // The tangent in the path's plane, as the extension's pose has it (none: no extension).
    let (p, tangent) = match cell.point_and_plane_tangent(u) {
        Ok(pt) => pt,
        Err(kerf_mill::MillError::Singular { .. }) => return Ok((distance, u)),
        Err(e) => return Err(e.into()),
    };
    let along = (x - p).dot(&tangent);
    let beyond = if u <= 0.0 { along < 0.0 } else { along > 0.0 };
    if !beyond {
        return Ok((distance, u));
    }
    Ok((((x - p) - along * tangent).norm().min(distance), u))
}

/// [`distance_to_path`] on the curve only (no extensions).
fn distance_to_curve(
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
    Ok(measure(cell, trajectory, period, f64::INFINITY, None, 1)?.0)
}

/// [`executed_deviation`] and the times (s from the start) of the samples whose distance
/// from the path or the plane exceeds `tolerance` \[m\]; `params` are the path's spline
/// parameters at the trajectory's points when the caller has them (else computed from the
/// arc lengths). The samples are measured in blocks of [`BLOCK`] on `threads` threads (the
/// result is the same for every thread count).
///
/// # Errors
/// As [`executed_deviation`].
pub(crate) fn measure(
    cell: &MillCell,
    trajectory: &JointTrajectory,
    period: f64,
    tolerance: f64,
    params: Option<&[f64]>,
    threads: usize,
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
    let params = match params {
        Some(p) if p.len() == points.len() => p.to_vec(),
        _ => trajectory
            .arc_length
            .iter()
            .map(|s| path.parameter_at(s.clamp(0.0, total)))
            .collect::<Result<Vec<f64>, _>>()?,
    };
    let (t0, t1) = (prepared.start_time(), prepared.end_time());
    let steps = ((t1 - t0) / period).ceil() as usize;
    let blocks = (steps + 1).div_ceil(BLOCK);
    let context = Context {
        cell,
        points,
        params: &params,
        origin,
        normal,
        t0,
        t1,
        period,
        steps,
    };
    // Blocks are independent (each starts its warm start afresh), so the result does not
    // depend on how many threads share them.
    let workers = threads.clamp(1, blocks.max(1));
    let results: Vec<Result<Vec<Sample>, MillPlanError>> = if workers == 1 {
        vec![(0..blocks).try_fold(Vec::new(), |mut all, b| {
            all.extend(context.block(&prepared, b)?);
            Ok(all)
        })]
    } else {
        std::thread::scope(|scope| {
            let handles: Vec<_> = (0..workers)
                .map(|w| {
                    let context = &context;
                    // The executor's trajectory keeps a sampling cursor: one copy per thread.
                    let prepared = prepared.clone();
                    scope.spawn(move || {
                        let (from, to) = (w * blocks / workers, (w + 1) * blocks / workers);
                        (from..to).try_fold(Vec::new(), |mut all, b| {
                            all.extend(context.block(&prepared, b)?);
                            Ok(all)
                        })
                    })
                })
                .collect();
            handles
                .into_iter()
                .map(|h| {
                    h.join().unwrap_or_else(|_| {
                        Err(MillPlanError::NotExecutable {
                            reason: "a tool-path measurement thread panicked".to_string(),
                        })
                    })
                })
                .collect()
        })
    };
    let mut off_path = Vec::with_capacity(steps + 1);
    let mut max_off_plane: f64 = 0.0;
    let (mut max_off_path, mut time_of_max) = (0.0, 0.0);
    let mut over = Vec::new();
    for result in results {
        for sample in result? {
            max_off_plane = max_off_plane.max(sample.off_plane);
            if sample.off_path > max_off_path {
                (max_off_path, time_of_max) = (sample.off_path, sample.time);
            }
            off_path.push(sample.off_path);
            if sample.off_path.max(sample.off_plane) > tolerance {
                over.push(sample.time);
            }
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
