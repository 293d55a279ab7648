//! [`straight_cut`]: the smallest cut with a known quaternion-interpolation baseline, for the
//! tests of the series and plots that draw a plan beside it.

use kerf_mjto::optimal_feed::FeedMode;
use kerf_mjto::plan::{FeedReport, RtoRecord};
use kerf_mjto::{machine::JOINT_NAMES, CutPlan, CutRequest, PlanError};

/// A straight cut along +x with the head vertical (a request and a hand-made plan of it): with
/// both RTOs at q4 = q5 = 0, q6 = -0.05, the QI baseline is exactly M = C − q6·O (seed 001
/// eq. 2) with O = (0, 0, 1).
///
/// # Errors
/// None in practice: the request is a fixed, valid document ([`CutRequest::from_yaml`]).
pub fn straight_cut() -> Result<(CutRequest, CutPlan), PlanError> {
    let yaml = "request_id: line\npoints: [[0.5, 0.7, 1.0], [0.55, 0.7, 1.0], [0.6, 0.7, 1.0]]\n\
                axes: [[0, 0, 1], [0, 0, 1], [0, 0, 1]]\nfeedrate: 0.2\nsample_period: 0.01\n\
                max_lead_angle: 0.1\nmax_tilt_angle: 0.1\nmesh: unused.stl\n\
                workpiece_pose: {position: [0.0, 0.0, 0.2], orientation: [0, 0, 0, 1]}\n";
    let request = CutRequest::from_yaml(yaml)?;
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
        path_positions: vec![0.0, 0.05, 0.1],
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
        feed: FeedReport {
            law: FeedMode::Constant,
            cycle_time: 1.0,
            constant_feed_time: 1.0,
            peak_feed: 0.2,
            limits: Vec::new(),
        },
        times_per_stage: Default::default(),
    };
    Ok((request, plan))
}
