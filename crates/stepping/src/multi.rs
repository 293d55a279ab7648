//! Stepping along a path of 1 to 6 axes: a 2D/3D tool path, or a joint
//! path of a robot (issue 29, item 3; seed 002 names multi-axis motion as
//! its next step).
//!
//! The points become a [`Spline`] over chord length `s`, and the per-period
//! controller steps `s` on its lattice, so that every axis moves at once
//! and every point is passed by one sample. The path limits follow from
//! the chain rule
//!
//! ```text
//! ẋᵢ = xᵢ′ ṡ,   ẍᵢ = xᵢ″ ṡ² + xᵢ′ s̈,   x⃛ᵢ = xᵢ‴ ṡ³ + 3 xᵢ″ ṡ s̈ + xᵢ′ s⃛
//! ```
//!
//! with the exact bounds D1ᵢ, D2ᵢ, D3ᵢ of |xᵢ′|, |xᵢ″|, |xᵢ‴| over the path
//! ([`Spline::bounds`]). kerf takes the largest path limits that keep every
//! axis inside its own for every state, allotting budgets:
//!
//! ```text
//! V = minᵢ( Vᵢ/D1ᵢ, √(Aᵢ/(2 D2ᵢ)), ∛(Jᵢ/(3 D3ᵢ)) )
//! A = minᵢ( (Aᵢ − D2ᵢ V²)/D1ᵢ, Jᵢ/(9 D2ᵢ V) )
//! J = minᵢ( (Jᵢ − D3ᵢ V³ − 3 D2ᵢ V A)/D1ᵢ )
//! ```
//!
//! These bounds hold for the continuous motion between samples, so the
//! differences of the samples (what a robot receives) hold them too (mean
//! value theorem). The precision on `s` is the precision over max ‖x′‖₂,
//! so a sample within it of a knot is within the precision of the point in
//! space. One uniform bound per path is conservative: a sharp bend slows
//! the whole path (BENCHMARKS "Reference-point stepping").

use serde::Serialize;

use crate::{
    course::Course,
    error::StepError,
    lattice::Lattice,
    limits::Limits,
    run::{run, Controller, Pass, Run},
    spline::{distance, DerivativeBounds, Spline},
};

/// A multi-axis stepping problem: the path, its parameter lattice and
/// course.
#[derive(Debug, Clone)]
pub struct MultiCourse {
    /// The path through the points.
    pub spline: Spline,
    /// Per-axis limits.
    pub axis_limits: Vec<Limits>,
    /// The derivative bounds of the path.
    pub bounds: DerivativeBounds,
    /// The course of the path parameter (points at the knots).
    pub course: Course,
    /// The precision in space [m or rad].
    pub precision: f64,
}

/// One sample of a multi-axis run: per axis position, velocity,
/// acceleration and jerk (the jerk of the period that starts at it).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisSample {
    /// Time [s] from the start.
    pub time: f64,
    /// Positions.
    pub position: Vec<f64>,
    /// Velocities.
    pub velocity: Vec<f64>,
    /// Accelerations.
    pub acceleration: Vec<f64>,
    /// Jerks over the following period (0 for the last sample).
    pub jerk: Vec<f64>,
}

/// A multi-axis run: the parameter run and its samples in axis space.
#[derive(Debug, Clone)]
pub struct MultiRun {
    /// The run of the path parameter.
    pub run: Run,
    /// Samples in axis space, one per state of the run.
    pub samples: Vec<AxisSample>,
    /// Passes with their distance in axis space (Euclidean).
    pub passes: Vec<Pass>,
}

impl MultiCourse {
    /// The course through `points` (start first) with per-axis limits
    /// (one per axis, or one for all).
    ///
    /// # Errors
    /// [`Spline::new`], [`Course::new`], [`Lattice::new`] errors; a count
    /// of limits that is neither 1 nor the axes'; path limits that are not
    /// positive (a bend too sharp for the limits).
    pub fn new(
        points: Vec<Vec<f64>>,
        limits: &[Limits],
        precision: f64,
        period: f64,
    ) -> Result<Self, StepError> {
        crate::error::check_positive("precision", precision)?;
        let spline = Spline::new(points, precision)?;
        let dim = spline.axes();
        let axis_limits: Vec<Limits> = match limits.len() {
            1 => vec![limits[0]; dim],
            n if n == dim => limits.to_vec(),
            n => {
                return Err(StepError::InvalidParameter {
                    name: "number of axis limits".to_string(),
                    value: n as f64,
                    reason: format!("one for all axes or one per axis ({dim})"),
                })
            }
        };
        for l in &axis_limits {
            l.validate()?;
        }
        let bounds = spline.bounds();
        let path = path_limits(&axis_limits, &bounds)?;
        let lattice = Lattice::new(path, period)?;
        let precision_s = precision / bounds.speed.max(f64::MIN_POSITIVE);
        let course = Course::new(lattice, spline.knots.clone(), precision_s)?;
        Ok(Self {
            spline,
            axis_limits,
            bounds,
            course,
            precision,
        })
    }

    /// Runs `controller` on the parameter course and maps the run to axis
    /// space.
    ///
    /// # Errors
    /// [`run`]'s errors.
    pub fn run(
        &self,
        controller: &mut dyn Controller,
        max_steps: usize,
    ) -> Result<MultiRun, StepError> {
        let r = run(&self.course, controller, max_steps)?;
        Ok(self.map(r))
    }

    /// Maps a parameter run to axis space.
    pub fn map(&self, r: Run) -> MultiRun {
        let lat = &self.course.lattice;
        let mut buf = self.spline.buffer();
        let mut samples = Vec::with_capacity(r.states.len());
        for (k, st) in r.states.iter().enumerate() {
            let s = lat.position(*st);
            let (sd, sdd) = (lat.velocity(*st), lat.acceleration(*st));
            let sddd = r.actions.get(k).map_or(0.0, |a| lat.jerk(a.sign()));
            self.spline.eval(s, &mut buf);
            let [x, d1, d2, d3] = &buf;
            samples.push(AxisSample {
                time: k as f64 * lat.period,
                position: x.clone(),
                velocity: d1.iter().map(|v| v * sd).collect(),
                acceleration: d2
                    .iter()
                    .zip(d1)
                    .map(|(c, v)| c * sd * sd + v * sdd)
                    .collect(),
                jerk: d3
                    .iter()
                    .zip(d2)
                    .zip(d1)
                    .map(|((t, c), v)| t * sd.powi(3) + 3.0 * c * sd * sdd + v * sddd)
                    .collect(),
            });
        }
        let passes = r
            .passes
            .iter()
            .map(|p| Pass {
                point: p.point,
                step: p.step,
                error: distance(&samples[p.step].position, &self.spline.points[p.point]),
            })
            .collect();
        MultiRun {
            run: r,
            samples,
            passes,
        }
    }
}

/// The path-parameter limits of the module documentation.
///
/// # Errors
/// [`StepError::InvalidParameter`] when a limit comes out not positive.
pub fn path_limits(axis: &[Limits], b: &DerivativeBounds) -> Result<Limits, StepError> {
    let tiny = f64::MIN_POSITIVE;
    let mut v = f64::INFINITY;
    for (i, l) in axis.iter().enumerate() {
        v = v.min(l.velocity / b.first[i].max(tiny));
        v = v.min((l.acceleration / (2.0 * b.second[i].max(tiny))).sqrt());
        v = v.min((l.jerk / (3.0 * b.third[i].max(tiny))).cbrt());
    }
    let mut a = f64::INFINITY;
    for (i, l) in axis.iter().enumerate() {
        a = a.min((l.acceleration - b.second[i] * v * v) / b.first[i].max(tiny));
        a = a.min(l.jerk / (9.0 * b.second[i].max(tiny) * v));
    }
    let mut j = f64::INFINITY;
    for (i, l) in axis.iter().enumerate() {
        j = j.min(
            (l.jerk - b.third[i] * v.powi(3) - 3.0 * b.second[i] * v * a) / b.first[i].max(tiny),
        );
    }
    let limits = Limits::new(v, a, j);
    limits.validate().map_err(|e| StepError::InvalidParameter {
        name: "path limits".to_string(),
        value: v.min(a).min(j),
        reason: format!("{e}: the path bends too sharply for the axis limits"),
    })?;
    Ok(limits)
}
