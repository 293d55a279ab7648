//! Sampled joint trajectories with every derivative up to jerk, for plots and reports: the
//! plan's own ([`JointSeries::of_plan`]) and the quaternion-interpolation (QI) baseline
//! through the plan's RTOs ([`JointSeries::qi_baseline`]), the comparison of seed 001
//! Figures 10, 13 and 15.
//!
//! Derivatives: the plan's velocities and accelerations are its analytic ones (seed 001
//! eq. 7); the plan's jerk and every QI derivative come from [`finite_differences`], the
//! estimator of the plan's metrics, so the peaks of a series are the ones
//! [`CutPlan::metrics`] and [`CutPlan::qi_metrics`] report.

use crate::{
    baseline::{quaternion_interpolation, Rto},
    machine::AxisLimits,
    metrics::finite_differences,
    orientation::PathFrames,
    timelaw::TimeLaw,
    CutPlan, CutRequest, PlanError,
};

/// A sampled joint trajectory with its derivatives, one row per sample, joints q1..q6.
#[derive(Debug, Clone, PartialEq)]
pub struct JointSeries {
    /// Sample times (s).
    pub times: Vec<f64>,
    /// Positions (m or rad).
    pub positions: Vec<[f64; 6]>,
    /// Velocities (m/s or rad/s).
    pub velocities: Vec<[f64; 6]>,
    /// Accelerations (m/s² or rad/s²).
    pub accelerations: Vec<[f64; 6]>,
    /// Jerks (m/s³ or rad/s³).
    pub jerks: Vec<[f64; 6]>,
}

impl JointSeries {
    /// The plan's samples: analytic positions, velocities and accelerations (eq. 7), jerk by
    /// finite differences of the positions.
    ///
    /// # Arguments
    /// * `plan` – a plan of [`crate::planner::Planner::plan`].
    ///
    /// # Returns
    /// Its series, sample for sample.
    pub fn of_plan(plan: &CutPlan) -> Self {
        let (_, _, jerks) = finite_differences(&plan.times, &plan.positions);
        Self {
            times: plan.times.clone(),
            positions: plan.positions.clone(),
            velocities: plan.velocities.clone(),
            accelerations: plan.accelerations.clone(),
            jerks,
        }
    }

    /// The QI baseline through the plan's RTOs, on the request's time law and Δt
    /// ([`quaternion_interpolation`]), with finite-difference derivatives.
    ///
    /// # Arguments
    /// * `request` – the request `plan` was planned for.
    /// * `plan` – its plan (the RTOs).
    /// * `limits` – the machine's axis limits (the baseline's stroke check).
    ///
    /// # Returns
    /// The baseline's series.
    ///
    /// # Errors
    /// The request's validation errors, a time-law error, or [`PlanError::Unreachable`] when
    /// the baseline leaves a stroke.
    pub fn qi_baseline(
        request: &CutRequest,
        plan: &CutPlan,
        limits: &[AxisLimits; 6],
    ) -> Result<Self, PlanError> {
        let v = request.validate()?;
        let frames = PathFrames::try_new(&v.points, &v.axes, &v.u)?;
        let law = TimeLaw::new(
            v.sigma,
            request.feedrate,
            request.feed_acceleration,
            request.feed_jerk,
        )?;
        let rtos: Vec<Rto> = plan.rtos.iter().map(Rto::from).collect();
        let (times, positions) =
            quaternion_interpolation(&frames, &rtos, &law, v.sigma, request.sample_period, limits)?;
        let (velocities, accelerations, jerks) = finite_differences(&times, &positions);
        Ok(Self {
            times,
            positions,
            velocities,
            accelerations,
            jerks,
        })
    }
}
