//! A plan's joint trajectory in kerf's one ROS-free trajectory type
//! ([`kerf_executor::TrajectoryRequest`]): what is published, checked and executed.

use kerf_executor::{TrajectoryPoint, TrajectoryRequest};

use crate::CutPlan;

impl CutPlan {
    /// The plan's samples as the executor's trajectory: joints q1..q6, one point per sample
    /// (every Δt) with positions, velocities and accelerations (the executor interpolates
    /// quintic Hermite between them), no start time (it starts on receipt).
    ///
    /// # Performance
    /// O(samples): one copy of the samples.
    pub fn joint_trajectory(&self) -> TrajectoryRequest {
        let points = self
            .times
            .iter()
            .zip(&self.positions)
            .zip(&self.velocities)
            .zip(&self.accelerations)
            .map(|(((&t, p), v), a)| TrajectoryPoint {
                positions: p.to_vec(),
                velocities: v.to_vec(),
                accelerations: a.to_vec(),
                effort: Vec::new(),
                time_from_start: t,
            })
            .collect();
        TrajectoryRequest {
            joint_names: self.joint_names.clone(),
            points,
            start_time: None,
        }
    }
}
