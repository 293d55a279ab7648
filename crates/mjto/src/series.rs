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
        let rtos: Vec<Rto> = plan
            .rtos
            .iter()
            .map(|r| Rto {
                u: r.u,
                q4: r.q4,
                q5: r.q5,
                q6: r.q6,
            })
            .collect();
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{machine::JOINT_NAMES, plan::RtoRecord, LaserMachine};

    /// A straight cut along +x with the head vertical: with both RTOs at q4 = q5 = 0,
    /// q6 = -0.05, the QI baseline is exactly M = C − q6·O (seed 001 eq. 2) with O = (0, 0, 1).
    fn straight() -> (CutRequest, CutPlan) {
        let yaml =
            "request_id: line\npoints: [[0.5, 0.7, 1.0], [0.55, 0.7, 1.0], [0.6, 0.7, 1.0]]\n\
                    axes: [[0, 0, 1], [0, 0, 1], [0, 0, 1]]\nfeedrate: 0.2\nsample_period: 0.01\n\
                    max_lead_angle: 0.1\nmax_tilt_angle: 0.1\nmesh: unused.stl\n\
                    workpiece_pose: {position: [0.0, 0.0, 0.2], orientation: [0, 0, 0, 1]}\n";
        let request = CutRequest::from_yaml(yaml).unwrap();
        let rto = |u, cl_index| RtoRecord {
            u,
            cl_index,
            q4: 0.0,
            q5: 0.0,
            q6: -0.05,
            inserted_at_iteration: 0,
        };
        let plan = CutPlan {
            request_id: "line".into(),
            joint_names: JOINT_NAMES.iter().map(|s| s.to_string()).collect(),
            times: vec![0.0, 0.5, 1.0],
            positions: vec![[0.5, 0.7, 1.25, 0.0, 0.0, -0.05]; 3],
            velocities: vec![[0.0; 6]; 3],
            accelerations: vec![[0.0; 6]; 3],
            rtos: vec![rto(0.0, 0), rto(1.0, 2)],
            metrics: Default::default(),
            qi_metrics: Default::default(),
            iterations: 1,
            collision_queries: 0,
            control_points: 3,
            path_length: 0.1,
            times_per_stage: Default::default(),
        };
        (request, plan)
    }

    #[test]
    fn qi_baseline_of_a_straight_cut() {
        let (request, plan) = straight();
        let machine = LaserMachine::default_machine().unwrap();
        let qi = JointSeries::qi_baseline(&request, &plan, machine.limits()).unwrap();
        let law = TimeLaw::new(0.1, 0.2, 8.0, 80.0).unwrap();
        let want = law.sample_times(0.01);
        assert_eq!(qi.times.len(), want.len());
        assert!(qi
            .times
            .iter()
            .zip(&want)
            .all(|(a, b)| (a - b).abs() < 1e-12));
        assert!(qi.times.len() > 50, "{}", qi.times.len());
        let first = qi.positions.first().unwrap();
        let last = qi.positions.last().unwrap();
        // The workpiece frame is 0.2 m above the machine frame; M = C + 0.05 ẑ.
        for (q, x) in [(first, 0.5), (last, 0.6)] {
            assert!((q[0] - x).abs() < 1e-9, "{q:?}");
            assert!((q[1] - 0.7).abs() < 1e-9, "{q:?}");
            assert!((q[2] - 1.25).abs() < 1e-9, "{q:?}");
            assert!(q[3].abs() < 1e-9 && q[4].abs() < 1e-9, "{q:?}");
            assert!((q[5] + 0.05).abs() < 1e-12, "{q:?}");
        }
        // Along x at the feed: the finite-difference velocity of q1 peaks at the time law's
        // peak feed (within the estimator's error at the ramp joints, 0.1 %).
        let peak = qi.velocities.iter().map(|v| v[0]).fold(0.0, f64::max);
        assert!((peak / law.peak_feed() - 1.0).abs() < 1e-3, "{peak}");
        assert!(qi.jerks.iter().all(|j| j[3] == 0.0 && j[4] == 0.0));
    }

    #[test]
    fn the_plan_series_is_the_plan_with_its_jerk() {
        let (_, plan) = straight();
        let s = JointSeries::of_plan(&plan);
        assert_eq!(s.times, plan.times);
        assert_eq!(s.positions, plan.positions);
        assert_eq!(s.velocities, plan.velocities);
        assert_eq!(s.accelerations, plan.accelerations);
        // Constant positions: zero jerk.
        assert_eq!(s.jerks.len(), plan.times.len());
        assert!(s.jerks.iter().flatten().all(|j| *j == 0.0));
    }

    #[test]
    fn an_invalid_request_has_no_baseline() {
        let (mut request, plan) = straight();
        request.feedrate = -1.0;
        let machine = LaserMachine::default_machine().unwrap();
        assert!(JointSeries::qi_baseline(&request, &plan, machine.limits()).is_err());
    }
}
