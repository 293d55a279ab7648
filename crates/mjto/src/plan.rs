//! The result of a successful plan (planner form of `kerf_msgs/msg/CutPlan`).

use serde::{Deserialize, Serialize};

use crate::optimal_feed::{FeedLimit, FeedMode};

/// The feed of a plan (issue 16, item 1).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct FeedReport {
    /// The law the trajectory runs.
    pub law: FeedMode,
    /// Duration of the cut (s), rest to rest.
    pub cycle_time: f64,
    /// Duration of seed 001's constant-feed plan at the requested feedrate with the request's
    /// ramps (s), for comparison ([`crate::timelaw::TimeLaw`]).
    pub constant_feed_time: f64,
    /// Largest feed reached: the tool tip's peak speed over the samples (m/s).
    pub peak_feed: f64,
    /// Where the feed is limited and by what (time-optimal law; empty for the constant one).
    pub limits: Vec<FeedLimit>,
}

/// One representative tool orientation of the final plan: the selected GFD candidate. With
/// `rto_constraint: equality` the trajectory passes through it; with `box` (the default) within
/// the box of free, lead/tilt-feasible candidates around it (`Gfd::free_box`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RtoRecord {
    /// Normalized arc length ũ_i.
    pub u: f64,
    /// Index of the CL point it sits on.
    pub cl_index: usize,
    /// Rotary axis q4 (rad).
    pub q4: f64,
    /// Rotary axis q5 (rad).
    pub q5: f64,
    /// Standoff axis q6 (m).
    pub q6: f64,
    /// 0 for the initial RTOs, else the iteration that inserted it.
    pub inserted_at_iteration: usize,
}

/// Kinematic figures of one trajectory on its dense Δt samples.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    /// Peak |velocity| per joint q1..q6 (m/s or rad/s).
    pub peak_velocity: [f64; 6],
    /// Peak |acceleration| per joint (m/s² or rad/s²).
    pub peak_acceleration: [f64; 6],
    /// Peak |jerk| per joint (m/s³ or rad/s³).
    pub peak_jerk: [f64; 6],
    /// RMS jerk per joint over the samples.
    pub rms_jerk: [f64; 6],
    /// True when every sample is inside every Table 2 limit.
    pub within_limits: bool,
    /// Human-readable limit violations (empty when `within_limits`).
    pub limit_violations: Vec<String>,
    /// Largest distance between the CL point reproduced by forward
    /// kinematics (eq. 2) and the requested CL path (m).
    pub max_cl_error: f64,
    /// Largest |lead angle| against the nominal tool axis (rad).
    pub max_lead_angle: f64,
    /// Largest |tilt angle| against the nominal tool axis (rad).
    pub max_tilt_angle: f64,
    /// Samples at which the head touches the workpiece. For the MJTO
    /// plan this is the result of the loop's last dense check, which must
    /// be clean for a plan to exist (so 0); for QI it is counted on its own
    /// samples.
    pub colliding_samples: usize,
}

/// Wall-clock time of each planner stage (s).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct StageTimes {
    /// Request validation, mesh loading (cached meshes cost nothing).
    pub setup: f64,
    /// Knot vector, basis matrices and the jerk Hessian (eq. 17-18).
    pub hessian: f64,
    /// GFD construction (all RTOs, all iterations).
    pub gfd: f64,
    /// Initial RTO selection (eq. 56).
    pub selection: f64,
    /// The time-optimal feed (TOPP3 solves, all iterations and margins).
    #[serde(default)]
    pub feed: f64,
    /// Rotary-axis QPs (all iterations).
    pub rotary_qp: f64,
    /// M-path QPs (all iterations).
    pub mpath_qp: f64,
    /// Dense collision and tolerance checks (all iterations).
    pub collision: f64,
    /// Sampling, metrics and the QI baseline.
    pub evaluation: f64,
    /// Everything.
    pub total: f64,
}

/// A successful plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CutPlan {
    /// The request id, echoed.
    pub request_id: String,
    /// q1..q6.
    pub joint_names: Vec<String>,
    /// Sample times from the start (s), every Δt, the last at the end.
    pub times: Vec<f64>,
    /// Position along the CL path s (m) per sample: the time law s(t) the joints follow
    /// (u = s/σ, eq. 1).
    pub path_positions: Vec<f64>,
    /// Joint positions per sample.
    pub positions: Vec<[f64; 6]>,
    /// Joint velocities per sample (analytic, eq. 7).
    pub velocities: Vec<[f64; 6]>,
    /// Joint accelerations per sample (analytic, eq. 7).
    pub accelerations: Vec<[f64; 6]>,
    /// Final RTOs in path order.
    pub rtos: Vec<RtoRecord>,
    /// MJTO metrics.
    pub metrics: Metrics,
    /// The quaternion-interpolation baseline's metrics on the same RTOs.
    pub qi_metrics: Metrics,
    /// Iterations of the loop of Figure 6.
    pub iterations: usize,
    /// Collision queries (GFD candidates and dense samples).
    pub collision_queries: usize,
    /// Number of B-spline control coefficients n + 1.
    pub control_points: usize,
    /// Path length σ (m).
    pub path_length: f64,
    /// The feed: law, cycle time, the constant-feed time, where the feed is limited.
    pub feed: FeedReport,
    /// Stage timings.
    pub times_per_stage: StageTimes,
}
