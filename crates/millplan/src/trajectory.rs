//! The joint trajectory of a plan: the executor's own trajectory type
//! ([`kerf_executor::TrajectoryRequest`], the one ROS-free joint-trajectory
//! type of kerf) with two per-point side tables that only the milling
//! planner needs (the arc length along the path and the plan segment).
//!
//! # Why the executor's type
//! The samples a plan is judged by are the samples the executor runs: a
//! [`JointTrajectory`] holds no second copy of positions, velocities or
//! times, so `kerf_executor::validate` (the executability check) reads
//! exactly what [`crate::timing::time_scale`] produced and what the node
//! publishes. The planner fills positions, velocities and times only:
//! accelerations and effort are empty (the executor interpolates cubic
//! Hermite segments) and `start_time` is `None` (start on receipt).
//!
//! # Invariant
//! `arc_length`, `segment` and `request.points` have one entry per point,
//! and every point has one position and one velocity per joint name;
//! [`JointTrajectory::check`] verifies it (the planner's trajectories
//! satisfy it by construction; [`crate::timing::time_scale`] checks it on
//! its input).

use crate::error::MillPlanError;

pub use kerf_executor::{TrajectoryPoint, TrajectoryRequest};

/// The IRB-6660 joint trajectory of a plan (module documentation; its
/// points: [`crate::planned`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct JointTrajectory {
    /// The joint samples in the executor's form: `joint_1` … `joint_6`;
    /// per point positions \[rad\], velocities \[rad/s\] and the time from
    /// the start of the cut \[s\]; no accelerations, no effort;
    /// `start_time` `None`.
    pub request: TrajectoryRequest,
    /// Per point: the arc length along the path \[m\].
    pub arc_length: Vec<f64>,
    /// Per point: the plan segment whose planned state holds there.
    pub segment: Vec<usize>,
}

impl JointTrajectory {
    /// The joint names (`request.joint_names`).
    pub fn joint_names(&self) -> &[String] {
        &self.request.joint_names
    }

    /// The points (`request.points`): path start, segment midpoints, path
    /// end.
    pub fn points(&self) -> &[TrajectoryPoint] {
        &self.request.points
    }

    /// The time of the last point \[s\] (0 without points).
    pub fn duration(&self) -> f64 {
        self.request
            .points
            .last()
            .map_or(0.0, |p| p.time_from_start)
    }

    /// Checks the invariant of the module documentation.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] naming the first side table or
    /// point whose length does not match.
    pub fn check(&self) -> Result<(), MillPlanError> {
        let bad = |reason: String| MillPlanError::InvalidConfig {
            name: "joint trajectory".to_string(),
            reason,
        };
        let m = self.request.points.len();
        if self.arc_length.len() != m || self.segment.len() != m {
            return Err(bad(format!(
                "{m} points, {} arc lengths and {} segments (one each per point)",
                self.arc_length.len(),
                self.segment.len()
            )));
        }
        let n = self.request.joint_names.len();
        for (k, p) in self.request.points.iter().enumerate() {
            if p.positions.len() != n || p.velocities.len() != n {
                return Err(bad(format!(
                    "point {k} has {} positions and {} velocities for {n} joints",
                    p.positions.len(),
                    p.velocities.len()
                )));
            }
        }
        Ok(())
    }
}
