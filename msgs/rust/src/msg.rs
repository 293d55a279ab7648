//! kerf's own messages (`kerf_msgs/msg`, defined in `msgs/msg/`): the trajectory executor's
//! [`TrajectoryStatus`], the MJTO planner's [`CutRequest`] / [`CutPlan`] (with [`CutRto`], [`CutFeedLimit`],
//! [`CutMetrics`], [`CutCollision`]) and the milling planner's [`MillRequest`] / [`MillPlan`]
//! (with [`MillSegment`], [`MillCandidate`]) and the G-code planner's [`GcodeRequest`] / [`GcodePlan`] (with
//! [`GcodeToolEvent`]), the simulated cell's [`CellContacts`] (with [`CellContact`]), and the
//! executor's stream of [`ReferencePoint`]s answered by [`StreamStatus`].

use serde::{Deserialize, Serialize};

use crate::builtin_interfaces::Time;
use crate::geometry_msgs::{Point, Pose, Vector3};
use crate::ros_type::impl_ros_type;
use crate::std_msgs::Header;
use crate::trajectory_msgs::JointTrajectory;

/// `kerf_msgs/msg/TrajectoryStatus`: status of one trajectory received by the
/// trajectory executor on its `~/joint_trajectory` topic or as a
/// `~/follow_joint_trajectory` action goal; published on `~/trajectory_status`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct TrajectoryStatus {
    /// `header.stamp`: when this status was produced (executor clock).
    pub header: Header,
    /// `header.stamp` of the trajectory this status refers to (zero if it had none).
    pub trajectory_stamp: Time,
    /// Where the trajectory came from: [`SOURCE_TOPIC`](Self::SOURCE_TOPIC),
    /// [`SOURCE_ACTION`](Self::SOURCE_ACTION) or [`SOURCE_STREAM`](Self::SOURCE_STREAM).
    pub source: String,
    /// Action goal id as 32 lowercase hex digits; empty for the topic input.
    pub goal_id: String,
    /// One of the status constants ([`ACCEPTED`](Self::ACCEPTED) …).
    pub status: u8,
    /// A `control_msgs/action/FollowJointTrajectory` result code, see
    /// [`FollowJointTrajectoryResult`](crate::control_msgs::FollowJointTrajectoryResult).
    pub error_code: i32,
    /// Human-readable reason; says exactly what is wrong (joint, point, value, limit).
    pub message: String,
}
impl_ros_type!(TrajectoryStatus, "kerf_msgs", msg, "TrajectoryStatus");

impl TrajectoryStatus {
    /// The trajectory passed validation and was queued or started.
    pub const ACCEPTED: u8 = 1;
    /// The trajectory failed validation and was never executed.
    pub const REJECTED: u8 = 2;
    /// The trajectory was executed to its end within tolerance.
    pub const SUCCEEDED: u8 = 3;
    /// Execution stopped early because a tolerance or limit was violated.
    pub const ABORTED: u8 = 4;
    /// Execution was replaced by a newer trajectory before it finished.
    pub const PREEMPTED: u8 = 5;
    /// Execution was stopped by an action cancel request.
    pub const CANCELED: u8 = 6;

    /// Value of `source` for the topic input. Not an IDL constant: the `.msg`
    /// file documents the allowed values in a comment.
    pub const SOURCE_TOPIC: &'static str = "topic";
    /// Value of `source` for the action input. Not an IDL constant.
    pub const SOURCE_ACTION: &'static str = "action";
    /// Value of `source` for a batch of the reference-point stream (`~/reference_points`).
    /// Not an IDL constant.
    pub const SOURCE_STREAM: &'static str = "stream";

    /// Name of a status value (`"ACCEPTED"` …), or `None` for an unknown value.
    pub fn status_name(status: u8) -> Option<&'static str> {
        match status {
            Self::ACCEPTED => Some("ACCEPTED"),
            Self::REJECTED => Some("REJECTED"),
            Self::SUCCEEDED => Some("SUCCEEDED"),
            Self::ABORTED => Some("ABORTED"),
            Self::PREEMPTED => Some("PREEMPTED"),
            Self::CANCELED => Some("CANCELED"),
            _ => None,
        }
    }
}

/// `kerf_msgs/msg/ReferencePoint`: one reference point of a stream, sent by a cell
/// controller to the trajectory executor's `~/reference_points` topic while the robot moves
/// (issue 29); answered by [`StreamStatus`] on `~/stream_status`. SI units: rad or m.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ReferencePoint {
    /// `header.stamp`: when the point was sent (informational; the point is used on receipt).
    pub header: Header,
    /// The sender's id of the point, echoed in every [`StreamStatus`] about it.
    pub id: u32,
    /// Joint names of `positions`: empty means the robot's joint order; otherwise a
    /// permutation naming every joint of the robot exactly once.
    pub joint_names: Vec<String>,
    /// One position per joint (rad or m).
    pub positions: Vec<f64>,
    /// How close the robot must pass (> 0 and ≤ 1; Euclidean over the joints, rad or m).
    pub precision: f64,
}
impl_ros_type!(ReferencePoint, "kerf_msgs", msg, "ReferencePoint");

/// `kerf_msgs/msg/StreamStatus`: what the trajectory executor did with one
/// [`ReferencePoint`] of a stream, published on `~/stream_status` (issue 29).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct StreamStatus {
    /// `header.stamp`: when this status was produced (executor clock).
    pub header: Header,
    /// The id of the point ([`ReferencePoint::id`]).
    pub id: u32,
    /// One of the status constants ([`START`](Self::START) …).
    pub status: u8,
    /// The batch of the stream the point belongs to (1 = the first); 0 when it is in none.
    pub batch: u64,
    /// [`REACHED`](Self::REACHED): distance of the sample that passed the point to it (rad or
    /// m, Euclidean over the joints); 0 otherwise.
    pub error: f64,
    /// [`REACHED`](Self::REACHED): when that sample was commanded, from the start of its
    /// batch (s); 0 otherwise.
    pub time_from_batch_start: f64,
    /// Human-readable reason (refused, not reached) or note; empty when there is nothing to
    /// report.
    pub message: String,
}
impl_ros_type!(StreamStatus, "kerf_msgs", msg, "StreamStatus");

impl StreamStatus {
    /// The point starts a stream: the robot is there.
    pub const START: u8 = 1;
    /// The point waits for the next batch of the stream.
    pub const QUEUED: u8 = 2;
    /// The point was refused and changed nothing; `message` says why.
    pub const REFUSED: u8 = 3;
    /// The robot passed the point within its precision; `error` says how close.
    pub const REACHED: u8 = 4;
    /// The point will not be reached; `message` says why.
    pub const NOT_REACHED: u8 = 5;

    /// Name of a status value (`"START"` …), or `None` for an unknown value.
    pub fn status_name(status: u8) -> Option<&'static str> {
        match status {
            Self::START => Some("START"),
            Self::QUEUED => Some("QUEUED"),
            Self::REFUSED => Some("REFUSED"),
            Self::REACHED => Some("REACHED"),
            Self::NOT_REACHED => Some("NOT_REACHED"),
            _ => None,
        }
    }
}

/// `kerf_msgs/msg/CutRequest`: a laser cutting request for the MJTO planner (seed 001), sent
/// to its `~/cut_request` topic; answered by a [`CutPlan`] on `~/cut_plan`.
///
/// SI units: m, m/s, m/s², m/s³, s, rad. Fields documented "0 = default" take the planner's
/// default when 0; nothing else is changed.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct CutRequest {
    /// Any text; echoed in the [`CutPlan`].
    pub request_id: String,
    /// Cutter-location points in the workpiece frame (m); at least 2.
    pub points: Vec<Point>,
    /// Unit tool axes in the workpiece frame, one per CL point.
    pub axes: Vec<Vector3>,
    /// Feedrate along the path (m/s), > 0.
    pub feedrate: f64,
    /// Path acceleration limit of the feed ramps (m/s²); 0 = default 8.
    pub feed_acceleration: f64,
    /// Path jerk limit of the feed ramps (m/s³); 0 = default 80.
    pub feed_jerk: f64,
    /// Controller sample period Δt (s), > 0.
    pub sample_period: f64,
    /// Lead angle limit (rad), in (0, π/2).
    pub max_lead_angle: f64,
    /// Tilt angle limit (rad), in (0, π/2).
    pub max_tilt_angle: f64,
    /// Workpiece mesh: a path, `file://` or `package://kerf/...` URI.
    pub mesh: String,
    /// Pose of the workpiece frame in the machine frame; a unit quaternion (w = 1 = identity).
    pub workpiece_pose: Pose,
    /// B-spline control coefficients n + 1; 0 = automatic (one per 10 mm of path, 12 to 100).
    pub control_points: u32,
    /// Maximum iterations of the collision loop; 0 = default 10.
    pub max_iterations: u32,
    /// GFD samples over q4 (odd); 0 = default.
    pub gfd_q4_steps: u32,
    /// GFD samples over q5 (odd); 0 = default.
    pub gfd_q5_steps: u32,
    /// GFD samples over q6; 0 = default.
    pub gfd_q6_steps: u32,
    /// GFD half width over q4 (rad); 0 = default.
    pub gfd_q4_half_range: f64,
    /// GFD half width over q5 (rad); 0 = default.
    pub gfd_q5_half_range: f64,
    /// CL indices of the initial RTOs; empty = automatic.
    pub rto_indices: Vec<u32>,
    /// Automatic RTOs: largest path length between two RTOs (m); 0 = default.
    pub rto_spacing: f64,
    /// Automatic RTOs: largest tool-axis change between two RTOs (rad); 0 = default.
    pub rto_angle: f64,
    /// Whether [`reference_standoff`](Self::reference_standoff) is given (q6 = 0 is valid, so
    /// 0 cannot mean "default").
    pub has_reference_standoff: bool,
    /// Preferred standoff q6 (m), used when `has_reference_standoff`.
    pub reference_standoff: f64,
    /// Required head–workpiece clearance (m, ≥ 0).
    pub clearance: f64,
    /// Largest tool-tip distance from the CL path (m); 0 = default 0.15 mm.
    pub cl_tolerance: f64,
    /// The time law: "" or "time_optimal" (default), or "constant" (seed 001).
    pub feed_law: String,
    /// RTOs as `"box"` or `"equality"` constraints of the QPs; empty = default `"box"`.
    pub rto_constraint: String,
    /// The q5 QP's lead/tilt allowance corridor: `"allowance"` or `"none"` (seed 001); empty =
    /// default `"allowance"`.
    pub orientation_corridor: String,
    /// Time budget of the plan (s): 0 = the node's `plan_timeout`; else in (0, plan_timeout].
    pub time_budget: f64,
    /// Where the trajectory starts: `""` (current when the node has a joint state, else
    /// none), `"current"`, `"given"` or `"none"` (issue 27).
    pub start: String,
    /// The start configuration with `start = "given"` (the trajectory's joint order).
    pub start_positions: Vec<f64>,
}
impl_ros_type!(CutRequest, "kerf_msgs", msg, "CutRequest");

impl CutRequest {
    /// `start`: the robot's latest joint state.
    pub const START_CURRENT: &'static str = "current";
    /// `start`: the request's `start_positions`.
    pub const START_GIVEN: &'static str = "given";
    /// `start`: the process's first point (no approach, no retract).
    pub const START_NONE: &'static str = "none";
}

/// `kerf_msgs/msg/CutRto`: one representative tool orientation of a [`CutPlan`].
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct CutRto {
    /// Normalized arc length u in [0, 1].
    pub u: f64,
    /// Index of the CL point it sits on.
    pub cl_index: u32,
    /// Rotary axis q4 (rad).
    pub q4: f64,
    /// Rotary axis q5 (rad).
    pub q5: f64,
    /// Standoff axis q6 (m).
    pub q6: f64,
    /// 0 for the initial RTOs, else the iteration that inserted it.
    pub inserted_at_iteration: u32,
}
impl_ros_type!(CutRto, "kerf_msgs", msg, "CutRto");

/// `kerf_msgs/msg/CutMetrics`: kinematic figures of one trajectory on its samples, per joint
/// q1..q6.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct CutMetrics {
    /// Peak |velocity| per joint (m/s or rad/s).
    pub peak_velocity: [f64; 6],
    /// Peak |acceleration| per joint (m/s² or rad/s²).
    pub peak_acceleration: [f64; 6],
    /// Peak |jerk| per joint (m/s³ or rad/s³).
    pub peak_jerk: [f64; 6],
    /// RMS jerk per joint (m/s³ or rad/s³).
    pub rms_jerk: [f64; 6],
    /// True when every sample is inside every joint limit.
    pub within_limits: bool,
    /// One line per violated limit.
    pub limit_violations: Vec<String>,
    /// Largest CL point error of forward kinematics against the request (m).
    pub max_cl_error: f64,
    /// Largest |lead angle| (rad).
    pub max_lead_angle: f64,
    /// Largest |tilt angle| (rad).
    pub max_tilt_angle: f64,
    /// Samples at which the head touches the workpiece.
    pub colliding_samples: u32,
}
impl_ros_type!(CutMetrics, "kerf_msgs", msg, "CutMetrics");

/// `kerf_msgs/msg/CellContact`: one contact of the simulated cell (`kerf_cell`): a robot
/// shape nearer to a scene object than the contact threshold, or inside it.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct CellContact {
    /// The robot link (URDF name).
    pub robot_link: String,
    /// The robot shape: `<link>/<collision index>` or a tool shape's name.
    pub robot_shape: String,
    /// The scene object.
    pub scene_object: String,
    /// Signed distance (m): > 0 a gap below the threshold, < 0 a penetration.
    pub distance: f64,
    /// Penetration depth `max(0, -distance)` (m).
    pub depth: f64,
    /// The robot shape's point nearest to (or deepest in) the object, base frame (m).
    pub position: Point,
}
impl_ros_type!(CellContact, "kerf_msgs", msg, "CellContact");

/// `kerf_msgs/msg/CellContacts`: the contacts of the simulated cell in one control period,
/// published by the trajectory executor in sim mode on `~/contacts` every cycle.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct CellContacts {
    /// `stamp`: simulated time at the end of the period; `frame_id`: the robot's base link.
    pub header: Header,
    /// The contacts; empty when none.
    pub contacts: Vec<CellContact>,
}
impl_ros_type!(CellContacts, "kerf_msgs", msg, "CellContacts");

/// `kerf_msgs/msg/CutCollision`: one rejected sample of a [`CutPlan`] with status
/// [`COLLISION`](CutPlan::COLLISION).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct CutCollision {
    /// Normalized arc length u in [0, 1].
    pub u: f64,
    /// Time from the trajectory start (s); −1 when no trajectory exists yet.
    pub time: f64,
    /// Index of the nearest CL point.
    pub cl_index: u32,
    /// Links of the head in contact (empty for an orientation-limit violation).
    pub links: Vec<String>,
    /// Why the sample is rejected.
    pub reason: String,
}
impl_ros_type!(CutCollision, "kerf_msgs", msg, "CutCollision");

/// `kerf_msgs/msg/CutPlan`: the planner's answer to one [`CutRequest`], published on
/// `~/cut_plan`; failures carry their status and message.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct CutPlan {
    /// `request_id` of the request (empty when it could not be read).
    pub request_id: String,
    /// One of the status constants ([`SUCCESS`](Self::SUCCESS) …).
    pub status: u8,
    /// Human-readable result or reason.
    pub message: String,
    /// The joint trajectory q1..q6, one point per sample period; empty unless SUCCESS.
    pub trajectory: JointTrajectory,
    /// Final RTOs in path order.
    pub rtos: Vec<CutRto>,
    /// Metrics of the planned trajectory.
    pub metrics: CutMetrics,
    /// Metrics of the quaternion-interpolation baseline.
    pub qi_metrics: CutMetrics,
    /// Rejected samples (status COLLISION).
    pub collisions: Vec<CutCollision>,
    /// Largest feasible feedrate (m/s) when the feedrate makes a QP infeasible; else 0.
    pub max_feasible_feedrate: f64,
    /// Iterations of the collision loop.
    pub iterations: u32,
    /// Collision queries made.
    pub collision_queries: u32,
    /// Number of B-spline control coefficients.
    pub control_points: u32,
    /// CL path length (m).
    pub path_length: f64,
    /// The time law run: "time_optimal" or "constant" (empty unless SUCCESS).
    pub feed_law: String,
    /// Duration of the cut (s).
    pub cycle_time: f64,
    /// Duration of seed 001's constant-feed plan (s), for comparison.
    pub constant_feed_time: f64,
    /// Largest feed reached (m/s).
    pub peak_feed: f64,
    /// Where the feed is held at a limit, and by which.
    pub feed_limits: Vec<CutFeedLimit>,
    /// Validation and mesh loading (s).
    pub time_setup: f64,
    /// Jerk Hessian (s).
    pub time_hessian: f64,
    /// GFD construction (s).
    pub time_gfd: f64,
    /// Initial RTO selection (s).
    pub time_selection: f64,
    /// Rotary-axis QPs (s).
    pub time_rotary_qp: f64,
    /// M-path QPs (s).
    pub time_mpath_qp: f64,
    /// Collision checks (s).
    pub time_collision: f64,
    /// Sampling and metrics (s).
    pub time_evaluation: f64,
    /// The whole plan (s).
    pub time_total: f64,
    /// The time-optimal feed (s).
    pub time_feed: f64,
    /// Where the trajectory starts and its approach, process and retract stretches.
    pub stretches: PlanStretches,
}
impl_ros_type!(CutPlan, "kerf_msgs", msg, "CutPlan");

/// `kerf_msgs/msg/CutFeedLimit`: one stretch of a [`CutPlan`]'s path where the feed is held at
/// a limit.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct CutFeedLimit {
    /// Start of the stretch along the CL path (m).
    pub s_start: f64,
    /// End of the stretch (m).
    pub s_end: f64,
    /// "feedrate", "path acceleration", "path jerk" or "<joint> velocity|acceleration|jerk".
    pub limited_by: String,
}
impl_ros_type!(CutFeedLimit, "kerf_msgs", msg, "CutFeedLimit");

impl CutPlan {
    /// The plan succeeded.
    pub const SUCCESS: u8 = 0;
    /// The request is malformed.
    pub const INVALID_REQUEST: u8 = 1;
    /// The workpiece mesh is missing or unreadable.
    pub const MESH_ERROR: u8 = 2;
    /// A CL point is outside the machine's stroke.
    pub const UNREACHABLE: u8 = 3;
    /// A QP is infeasible.
    pub const INFEASIBLE: u8 = 4;
    /// Collisions remain, or no collision-free orientation exists.
    pub const COLLISION: u8 = 5;
    /// A joint limit is exceeded.
    pub const LIMIT_VIOLATION: u8 = 6;
    /// Solver failure, overload or another internal error (also: cancelled, node stopping).
    pub const INTERNAL_ERROR: u8 = 7;
    /// The request's time budget ran out before the plan was finished.
    pub const TIMEOUT: u8 = 8;
    /// The request queue is full; the request was not planned.
    pub const QUEUE_FULL: u8 = 9;
    /// The plan would need more memory than the node's `plan_memory` allows.
    pub const RESOURCE_LIMIT: u8 = 10;
    /// No collision-free approach or retract exists (or the start is too close to an
    /// obstacle); no trajectory is sent.
    pub const NO_APPROACH: u8 = 11;

    /// Name of a status value (`"SUCCESS"` …), or `None` for an unknown value.
    pub fn status_name(status: u8) -> Option<&'static str> {
        match status {
            Self::SUCCESS => Some("SUCCESS"),
            Self::INVALID_REQUEST => Some("INVALID_REQUEST"),
            Self::MESH_ERROR => Some("MESH_ERROR"),
            Self::UNREACHABLE => Some("UNREACHABLE"),
            Self::INFEASIBLE => Some("INFEASIBLE"),
            Self::COLLISION => Some("COLLISION"),
            Self::LIMIT_VIOLATION => Some("LIMIT_VIOLATION"),
            Self::INTERNAL_ERROR => Some("INTERNAL_ERROR"),
            Self::TIMEOUT => Some("TIMEOUT"),
            Self::QUEUE_FULL => Some("QUEUE_FULL"),
            Self::RESOURCE_LIMIT => Some("RESOURCE_LIMIT"),
            Self::NO_APPROACH => Some("NO_APPROACH"),
            _ => None,
        }
    }
}

/// `kerf_msgs/msg/MillRequest`: a milling request for the milling planner node (seed 004:
/// spindle speed Ω, feed f and redundancy angle g planned per path segment under the chatter
/// constraint, ABB IRB 6660), sent to its `~/mill_request` topic; answered by a [`MillPlan`] on
/// `~/mill_plan`.
///
/// SI units except where a name says rpm. Each group of fields is read only when its `has_*`
/// flag is true; with the flag false the whole group is the cell's
/// (`urdf/irb6660_milling.yaml`). Nothing else is defaulted: every value used is checked.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct MillRequest {
    /// Any text; echoed in the [`MillPlan`].
    pub request_id: String,
    /// Points the cubic B-spline tool path interpolates, robot base frame (m): at least 2,
    /// coplanar within 1e-6 m.
    pub points: Vec<Point>,
    /// Equal-arc-length segments (planning steps); 0 = the cell's 100.
    pub segments: u32,
    /// Whether the tool and cutting parameters below are given; false = the cell's `process:`.
    pub has_process: bool,
    /// Number of teeth, ≥ 1.
    pub teeth: u32,
    /// Tool radius R (m), > 0.
    pub tool_radius: f64,
    /// Axial depth of cut a_p (m), > 0.
    pub axial_depth: f64,
    /// Tangential cutting force coefficient Kt (N/m²), ≥ 0.
    pub kt: f64,
    /// Normal cutting force coefficient Kn (N/m²), ≥ 0.
    pub kn: f64,
    /// Entry angle of the engagement (rad), in [0, π].
    pub entry_angle: f64,
    /// Exit angle of the engagement (rad), in [0, π], > `entry_angle`.
    pub exit_angle: f64,
    /// Whether the state ranges and step bounds below are given; false = the cell's.
    pub has_limits: bool,
    /// Lowest spindle speed (rpm), > 0.
    pub spindle_min_rpm: f64,
    /// Highest spindle speed (rpm), > `spindle_min_rpm`.
    pub spindle_max_rpm: f64,
    /// Lowest feed (m/s), ≥ 0.
    pub feed_min: f64,
    /// Highest feed (m/s), > `feed_min`.
    pub feed_max: f64,
    /// Lowest redundancy angle (rad), ≥ −π.
    pub g_min: f64,
    /// Highest redundancy angle (rad), in (`g_min`, π].
    pub g_max: f64,
    /// Largest spindle-speed change between consecutive segments (rpm), > 0.
    pub max_spindle_step_rpm: f64,
    /// Largest feed change between consecutive segments (m/s), > 0.
    pub max_feed_step: f64,
    /// Largest redundancy-angle change between consecutive segments (rad), > 0.
    pub max_g_step: f64,
    /// Whether the initial state below is given; false = the cell's (2000 rpm, 0.04 m/s, 0 rad).
    pub has_initial_state: bool,
    /// Initial spindle speed (rpm), inside the spindle range.
    pub initial_spindle_rpm: f64,
    /// Initial feed (m/s), inside the feed range.
    pub initial_feed: f64,
    /// Initial redundancy angle (rad), inside the g range.
    pub initial_g: f64,
    /// One of the `PLANNER_*` constants ([`PLANNER_DDPG`](Self::PLANNER_DDPG) …); empty =
    /// `"ddpg"`.
    pub planner: String,
    /// Path of the actor (safetensors) of the ddpg / fixed_g planner; empty = the shipped
    /// policy of that planner.
    pub policy_file: String,
    /// Time budget of the plan (s): 0 = the node's `plan_timeout`; else in (0, plan_timeout].
    pub time_budget: f64,
    /// Whether the tolerances below are given; false = the node's (5e-5 m, no minimum 1/K).
    pub has_tolerances: bool,
    /// Largest distance of the executed tool tip from the path and the plane (m), in
    /// (0, 1e-3].
    pub path_tolerance: f64,
    /// Smallest condition indicator 1/K allowed along the executed trajectory, in [0, 1);
    /// 0 = no minimum.
    pub min_condition_indicator: f64,
    /// Where the trajectory starts: `""` (current when the node has a joint state, else
    /// none), `"current"`, `"given"` or `"none"` (issue 27).
    pub start: String,
    /// The start configuration with `start = "given"` (the trajectory's joint order).
    pub start_positions: Vec<f64>,
    /// Answer a plan that chatters as executed (status CHATTER, with its trajectory) instead
    /// of refusing it (issue 28).
    pub allow_chatter: bool,
    /// Where the tool enters the material: `""` = [`ENTRY_RUN_IN`](Self::ENTRY_RUN_IN),
    /// or [`ENTRY_IN_MATERIAL`](Self::ENTRY_IN_MATERIAL).
    pub entry: String,
}
impl_ros_type!(MillRequest, "kerf_msgs", msg, "MillRequest");

impl MillRequest {
    /// `entry`: a straight run-in along the start tangent, the material entered at feed.
    pub const ENTRY_RUN_IN: &'static str = "run_in";
    /// `entry`: the ramps from and to rest on the path.
    pub const ENTRY_IN_MATERIAL: &'static str = "in_material";
}

impl MillRequest {
    /// `start`: the robot's latest joint state.
    pub const START_CURRENT: &'static str = "current";
    /// `start`: the request's `start_positions`.
    pub const START_GIVEN: &'static str = "given";
    /// `start`: the process's first point (no approach, no retract).
    pub const START_NONE: &'static str = "none";
}

impl MillRequest {
    /// DDPG actor of seed 004 Algorithm 1, optimizing Ω, f and g.
    pub const PLANNER_DDPG: &'static str = "ddpg";
    /// DDPG actor trained with g held at 0 (seed 004 Fig. 8 ablation).
    pub const PLANNER_FIXED_G: &'static str = "fixed_g";
    /// Dynamic programming over a discretized (Ω, f, g) grid (the deterministic optimum).
    pub const PLANNER_DP: &'static str = "dp";
    /// Constant feed and spindle speed.
    pub const PLANNER_NAIVE: &'static str = "naive";
    /// Greedy ramp from the initial state at the step bounds, g held at the initial g.
    pub const PLANNER_GREEDY: &'static str = "greedy";
    /// The greedy ramp with the best fixed g, reached from the initial g at the step bound.
    pub const PLANNER_GREEDY_BEST_G: &'static str = "greedy_best_g";
    /// The fastest chatter-free plan as executed among the other planners but dp (issue 28).
    pub const PLANNER_BEST: &'static str = "best";
}

/// `kerf_msgs/msg/MillCandidate`: how one candidate planner did in the `best` choice of a
/// [`MillPlan`] (issue 28).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct MillCandidate {
    /// The planner (a `MillRequest::PLANNER_*` value).
    pub planner: String,
    /// Its [`MillPlan`] status had it been asked alone.
    pub status: u8,
    /// The error's message; empty for a plan.
    pub message: String,
    /// The executed trajectory's duration from rest to rest (s).
    pub trajectory_duration: f64,
    /// Chatter-free at every executed sample in the material.
    pub chatter_free: bool,
    /// The largest executed |μ|max.
    pub max_mu: f64,
    /// The smallest 1/K along the trajectory.
    pub min_condition_indicator: f64,
}
impl_ros_type!(MillCandidate, "kerf_msgs", msg, "MillCandidate");

/// `kerf_msgs/msg/MillSegment`: one planned segment of a [`MillPlan`], with the model's
/// figures evaluated directly.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct MillSegment {
    /// Segment index along the path, from 0.
    pub index: u32,
    /// Spindle speed Ω (rpm).
    pub spindle_rpm: f64,
    /// Feed f (m/s).
    pub feed: f64,
    /// Redundancy angle g (rad).
    pub redundancy_angle: f64,
    /// Chatter indicator |μ|max; chatter-free when < 1.
    pub mu_max: f64,
    /// Singularity indicator 1/K of seed 004 eq. 14, in [0, 1].
    pub condition_indicator: f64,
    /// Segment time, arc length / feed (s).
    pub time: f64,
    /// Reward of the segment (seed 004 eq. 12).
    pub reward: f64,
    /// Joint positions joint_1..joint_6 (rad) at the segment's midpoint.
    pub joint_positions: Vec<f64>,
}
impl_ros_type!(MillSegment, "kerf_msgs", msg, "MillSegment");

/// `kerf_msgs/msg/MillPlan`: the milling planner's answer to one [`MillRequest`], published on
/// `~/mill_plan`; failures carry their status and message.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct MillPlan {
    /// `request_id` of the request (empty when it could not be read).
    pub request_id: String,
    /// One of the status constants ([`SUCCESS`](Self::SUCCESS) …).
    pub status: u8,
    /// Human-readable result or reason.
    pub message: String,
    /// The planner that produced the plan (a `MillRequest::PLANNER_*` value).
    pub planner: String,
    /// The IRB 6660 joint trajectory joint_1..joint_6, timed by the planned feed; empty unless
    /// SUCCESS.
    pub trajectory: JointTrajectory,
    /// One entry per segment, in path order; empty unless SUCCESS.
    pub segments: Vec<MillSegment>,
    /// Machining time, Σ segment times (s).
    pub machining_time: f64,
    /// Every segment has |μ|max < 1.
    pub chatter_free: bool,
    /// Largest |μ|max.
    pub max_mu: f64,
    /// Smallest condition indicator 1/K.
    pub min_condition_indicator: f64,
    /// Σ segment rewards (seed 004 eq. 12).
    pub total_reward: f64,
    /// Largest distance of the executed tool tip from the path (m).
    pub max_path_deviation: f64,
    /// Largest distance of the executed tool tip from the milling plane (m).
    pub max_plane_deviation: f64,
    /// The tolerance both are within (m).
    pub path_tolerance: f64,
    /// Smallest condition indicator 1/K over the trajectory's points.
    pub min_condition_indicator_path: f64,
    /// Arc length where it is (m).
    pub min_condition_arc_length: f64,
    /// Where the trajectory starts and its approach, process and retract stretches.
    pub stretches: PlanStretches,
    /// The milling trajectory's duration from rest to rest, run-in and run-out included (s).
    pub trajectory_duration: f64,
    /// Length of the run-in before the path (m).
    pub run_in: f64,
    /// Length of the run-out after the path (m).
    pub run_out: f64,
    /// Control-period samples in the material judged for chatter.
    pub judged_samples: u32,
    /// Direct evaluations of the chatter model the judge took.
    pub judge_evaluations: u32,
    /// With planner `best`: every candidate's outcome.
    pub candidates: Vec<MillCandidate>,
}
impl_ros_type!(MillPlan, "kerf_msgs", msg, "MillPlan");

impl MillPlan {
    /// The plan succeeded.
    pub const SUCCESS: u8 = 0;
    /// The request is malformed (field and value in the message).
    pub const INVALID_REQUEST: u8 = 1;
    /// A segment has no IK solution at the redundancy angle needed.
    pub const UNREACHABLE: u8 = 2;
    /// The policy file is missing, unreadable or incompatible.
    pub const POLICY_ERROR: u8 = 3;
    /// The chatter model failed.
    pub const CHATTER_MODEL_ERROR: u8 = 4;
    /// The request queue is full; the request was not planned.
    pub const QUEUE_FULL: u8 = 5;
    /// Another internal error (also: cancelled, node stopping).
    pub const INTERNAL_ERROR: u8 = 6;
    /// The request's time budget ran out before the plan was finished.
    pub const TIMEOUT: u8 = 7;
    /// The executed plan passes closer to a singularity than the request allows.
    pub const ILL_CONDITIONED: u8 = 8;
    /// The plan would need more memory than the node's `plan_memory` allows.
    pub const RESOURCE_LIMIT: u8 = 9;
    /// No collision-free approach or retract exists (or the start is too close to an
    /// obstacle); no trajectory is sent.
    pub const NO_APPROACH: u8 = 10;
    /// The plan chatters as executed (issue 28).
    pub const CHATTER: u8 = 11;
    /// The requested planner cannot plan this valid path.
    pub const INFEASIBLE: u8 = 12;

    /// Name of a status value (`"SUCCESS"` …), or `None` for an unknown value.
    pub fn status_name(status: u8) -> Option<&'static str> {
        match status {
            Self::SUCCESS => Some("SUCCESS"),
            Self::INVALID_REQUEST => Some("INVALID_REQUEST"),
            Self::UNREACHABLE => Some("UNREACHABLE"),
            Self::POLICY_ERROR => Some("POLICY_ERROR"),
            Self::CHATTER_MODEL_ERROR => Some("CHATTER_MODEL_ERROR"),
            Self::QUEUE_FULL => Some("QUEUE_FULL"),
            Self::INTERNAL_ERROR => Some("INTERNAL_ERROR"),
            Self::TIMEOUT => Some("TIMEOUT"),
            Self::ILL_CONDITIONED => Some("ILL_CONDITIONED"),
            Self::RESOURCE_LIMIT => Some("RESOURCE_LIMIT"),
            Self::NO_APPROACH => Some("NO_APPROACH"),
            Self::CHATTER => Some("CHATTER"),
            Self::INFEASIBLE => Some("INFEASIBLE"),
            _ => None,
        }
    }
}

/// `kerf_msgs/msg/GcodeRequest`: a G-code program for the G-code planner node (issue 14), sent
/// to its `~/gcode_request` topic; answered by a [`GcodePlan`] on `~/gcode_plan`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct GcodeRequest {
    /// Any text; echoed in the [`GcodePlan`].
    pub request_id: String,
    /// One of the `MACHINE_*` constants; empty = laser-cutter.
    pub machine: String,
    /// The program text (exactly one of `program` and `program_uri` non-empty).
    pub program: String,
    /// A program file: absolute path, `file://` or `package://kerf/` URI.
    pub program_uri: String,
    /// Tolerance of the executed tool tip (m), in (0, 0.01]; 0 = 1e-4.
    pub tolerance: f64,
    /// One of the `METHOD_*` constants; empty = kerf.
    pub method: String,
    /// One of the `FEED_*` constants; empty = near-optimal.
    pub feed_method: String,
    /// Whether the path limits below are given; false = the machine's.
    pub has_limits: bool,
    /// Largest cutting feed (m/s).
    pub max_feed: f64,
    /// Tangential acceleration (m/s²).
    pub tangential_acceleration: f64,
    /// Tangential jerk (m/s³).
    pub tangential_jerk: f64,
    /// Normal acceleration (m/s²).
    pub normal_acceleration: f64,
    /// Normal jerk (m/s³).
    pub normal_jerk: f64,
    /// Chord error per interpolation period (m).
    pub chord_error: f64,
    /// Servo contour error (m).
    pub contour_error: f64,
    /// G0 speed (m/s); 0 = the machine's.
    pub rapid_feed: f64,
    /// Whether the placement below is given; false = the machine's.
    pub has_placement: bool,
    /// The program's zero in the machine's base frame (m).
    pub origin: Point,
    /// IRB 6660: redundancy angle g (rad).
    pub redundancy_angle: f64,
    /// Laser cutter: standoff axis q6 (m).
    pub standoff_axis: f64,
    /// Time budget of the plan (s): 0 = the node's `plan_timeout`.
    pub time_budget: f64,
    /// Where the trajectory starts: `""` (current when the node has a joint state, else
    /// none), `"current"`, `"given"` or `"none"` (issue 27).
    pub start: String,
    /// The start configuration with `start = "given"` (the trajectory's joint order).
    pub start_positions: Vec<f64>,
}
impl_ros_type!(GcodeRequest, "kerf_msgs", msg, "GcodeRequest");

impl GcodeRequest {
    /// `start`: the robot's latest joint state.
    pub const START_CURRENT: &'static str = "current";
    /// `start`: the request's `start_positions`.
    pub const START_GIVEN: &'static str = "given";
    /// `start`: the process's first point (no approach, no retract).
    pub const START_NONE: &'static str = "none";
}

impl GcodeRequest {
    /// The laser cutter of seed 001.
    pub const MACHINE_LASER_CUTTER: &'static str = "laser-cutter";
    /// The ABB IRB 6660 milling cell of seed 004.
    pub const MACHINE_IRB6660: &'static str = "irb6660";
    /// kerf's curvature-continuous quintic corner, its shape of least jerk norm.
    pub const METHOD_KERF: &'static str = "kerf";
    /// kerf's quintic corner with its shape of least curvature.
    pub const METHOD_KERF_CURVATURE: &'static str = "kerf-curvature";
    /// Inscribed cubic B-spline corner (ICR).
    pub const METHOD_ICR: &'static str = "icr";
    /// Circumscribed double cubic B-spline corner (CCR).
    pub const METHOD_CCR: &'static str = "ccr";
    /// Seed 003's NURBS corner by PSO.
    pub const METHOD_NURBS: &'static str = "nurbs";
    /// Seed 003's learned NURBS corner, verified, with the PSO swarm as its fallback.
    pub const METHOD_DRLS_NET: &'static str = "drls-net";
    /// The near time-optimal feed planner.
    pub const FEED_NEAR_OPTIMAL: &'static str = "near-optimal";
    /// Seed 003's constant-interval feed planner.
    pub const FEED_CONSTANT_INTERVALS: &'static str = "constant-intervals";
}

/// `kerf_msgs/msg/GcodeToolEvent`: a beam or spindle switch of a planned program, at rest.
///
/// Read from text with the earlier key `on` for `tool_on` too (a hand-written `Deserialize`:
/// a serde `alias` would be a fourth field to the drift test's trace).
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct GcodeToolEvent {
    /// Time from the trajectory's start (s).
    pub time: f64,
    /// On after it (`tool_on`, not `on`, which YAML 1.1 readers take for the boolean
    /// `true`; the text key `on` is still read).
    pub tool_on: bool,
    /// Source line.
    pub line: u32,
}
impl_ros_type!(GcodeToolEvent, "kerf_msgs", msg, "GcodeToolEvent");

impl<'de> Deserialize<'de> for GcodeToolEvent {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::{self, MapAccess, SeqAccess, Visitor};
        /// The message's fields, in `.msg` order (what CDR and the drift test see).
        const FIELDS: &[&str] = &["time", "tool_on", "line"];
        struct Event;
        impl<'de> Visitor<'de> for Event {
            type Value = GcodeToolEvent;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("struct GcodeToolEvent")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<GcodeToolEvent, A::Error> {
                let time = seq
                    .next_element()?
                    .ok_or_else(|| de::Error::invalid_length(0, &self))?;
                let tool_on = seq
                    .next_element()?
                    .ok_or_else(|| de::Error::invalid_length(1, &self))?;
                let line = seq
                    .next_element()?
                    .ok_or_else(|| de::Error::invalid_length(2, &self))?;
                Ok(GcodeToolEvent {
                    time,
                    tool_on,
                    line,
                })
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<GcodeToolEvent, A::Error> {
                let (mut time, mut tool_on, mut line) = (None, None, None);
                while let Some(key) = map.next_key::<String>()? {
                    match key.as_str() {
                        "time" if time.is_none() => time = Some(map.next_value()?),
                        "tool_on" | "on" if tool_on.is_none() => tool_on = Some(map.next_value()?),
                        "line" if line.is_none() => line = Some(map.next_value()?),
                        "time" | "line" => return Err(de::Error::duplicate_field("time or line")),
                        "tool_on" | "on" => return Err(de::Error::duplicate_field("tool_on")),
                        // Unknown keys are skipped, as the derived mirrors do.
                        _ => {
                            map.next_value::<de::IgnoredAny>()?;
                        }
                    }
                }
                Ok(GcodeToolEvent {
                    time: time.ok_or_else(|| de::Error::missing_field("time"))?,
                    tool_on: tool_on.ok_or_else(|| de::Error::missing_field("tool_on"))?,
                    line: line.ok_or_else(|| de::Error::missing_field("line"))?,
                })
            }
        }
        d.deserialize_struct("GcodeToolEvent", FIELDS, Event)
    }
}

/// `kerf_msgs/msg/GcodePlan`: the G-code planner's answer to one [`GcodeRequest`], published on
/// `~/gcode_plan`; failures carry their status and message.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct GcodePlan {
    /// `request_id` of the request (empty when it could not be read).
    pub request_id: String,
    /// One of the status constants ([`SUCCESS`](Self::SUCCESS) …).
    pub status: u8,
    /// Human-readable result or reason.
    pub message: String,
    /// The machine planned for.
    pub machine: String,
    /// The corner method planned with.
    pub method: String,
    /// The joint trajectory from rest to rest; empty unless SUCCESS.
    pub trajectory: JointTrajectory,
    /// The program line at fault (0 when none): set for every error of a program line.
    pub error_line: u32,
    /// The trajectory's duration (s).
    pub machining_time: f64,
    /// The feed plans' time as run (s).
    pub feed_time: f64,
    /// T_lb (s).
    pub lower_bound_time: f64,
    /// T_m (the feed plans under the path's limits) / T_lb.
    pub lower_bound_ratio: f64,
    /// Total dwell time (s).
    pub dwell_time: f64,
    /// The tolerance (m).
    pub tolerance: f64,
    /// Largest exact corner deviation (m).
    pub max_corner_deviation: f64,
    /// Largest distance of the executed tip from the planned point (m).
    pub max_interpolation_deviation: f64,
    /// Largest curvature (1/m).
    pub max_curvature: f64,
    /// Largest turning angle (rad).
    pub max_turning_angle: f64,
    /// RMS acceleration (m/s²).
    pub rms_acceleration: f64,
    /// RMS jerk (m/s³).
    pub rms_jerk: f64,
    /// Largest chord error (m).
    pub max_chord_error: f64,
    /// Largest servo contour error (m).
    pub max_contour_error: f64,
    /// Largest uniform slowdown of a run (1 = none).
    pub max_slowdown: f64,
    /// Lines read.
    pub lines: u32,
    /// Runs.
    pub runs: u32,
    /// Cutting runs.
    pub cut_runs: u32,
    /// Corners smoothed.
    pub corners: u32,
    /// Arcs read.
    pub arcs: u32,
    /// `drls-net`: corners where the learned corner fell back to the swarm (0 for the other
    /// methods).
    pub corner_fallbacks: u32,
    /// Beam or spindle switches.
    pub tool_events: Vec<GcodeToolEvent>,
    /// Warnings.
    pub warnings: Vec<String>,
    /// Where the trajectory starts and its approach, process and retract stretches.
    pub stretches: PlanStretches,
}
impl_ros_type!(GcodePlan, "kerf_msgs", msg, "GcodePlan");

impl GcodePlan {
    /// The plan succeeded.
    pub const SUCCESS: u8 = 0;
    /// A field of the request is bad, or the answer would be too large.
    pub const INVALID_REQUEST: u8 = 1;
    /// The program is not valid G-code, uses a refused code, or has no motion.
    pub const PROGRAM_ERROR: u8 = 2;
    /// A programmed point is out of reach.
    pub const UNREACHABLE: u8 = 3;
    /// The request queue is full.
    pub const QUEUE_FULL: u8 = 4;
    /// Another internal error.
    pub const INTERNAL_ERROR: u8 = 5;
    /// The time budget ran out.
    pub const TIMEOUT: u8 = 6;
    /// The plan would need more memory than the node's `plan_memory` allows.
    pub const RESOURCE_LIMIT: u8 = 7;
    /// No collision-free approach or retract exists (or the start is too close to an
    /// obstacle); no trajectory is sent.
    pub const NO_APPROACH: u8 = 8;

    /// Name of a status value, or `None` for an unknown value.
    pub fn status_name(status: u8) -> Option<&'static str> {
        match status {
            Self::SUCCESS => Some("SUCCESS"),
            Self::INVALID_REQUEST => Some("INVALID_REQUEST"),
            Self::PROGRAM_ERROR => Some("PROGRAM_ERROR"),
            Self::UNREACHABLE => Some("UNREACHABLE"),
            Self::QUEUE_FULL => Some("QUEUE_FULL"),
            Self::INTERNAL_ERROR => Some("INTERNAL_ERROR"),
            Self::TIMEOUT => Some("TIMEOUT"),
            Self::RESOURCE_LIMIT => Some("RESOURCE_LIMIT"),
            Self::NO_APPROACH => Some("NO_APPROACH"),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gcode_plan_status_names() {
        let names: Vec<&str> = (0..=u8::MAX).filter_map(GcodePlan::status_name).collect();
        assert_eq!(
            names,
            [
                "SUCCESS",
                "INVALID_REQUEST",
                "PROGRAM_ERROR",
                "UNREACHABLE",
                "QUEUE_FULL",
                "INTERNAL_ERROR",
                "TIMEOUT",
                "RESOURCE_LIMIT",
                "NO_APPROACH"
            ]
        );
    }

    #[test]
    fn status_names() {
        assert_eq!(
            TrajectoryStatus::status_name(TrajectoryStatus::ABORTED),
            Some("ABORTED")
        );
        assert_eq!(TrajectoryStatus::status_name(6), Some("CANCELED"));
        assert_eq!(TrajectoryStatus::status_name(0), None);
        assert_eq!(TrajectoryStatus::status_name(7), None);
    }

    #[test]
    fn cut_plan_status_names() {
        assert_eq!(CutPlan::status_name(CutPlan::SUCCESS), Some("SUCCESS"));
        assert_eq!(CutPlan::status_name(5), Some("COLLISION"));
        assert_eq!(CutPlan::status_name(7), Some("INTERNAL_ERROR"));
        assert_eq!(CutPlan::status_name(8), Some("TIMEOUT"));
        assert_eq!(CutPlan::status_name(9), Some("QUEUE_FULL"));
        assert_eq!(CutPlan::status_name(10), Some("RESOURCE_LIMIT"));
        assert_eq!(CutPlan::status_name(11), Some("NO_APPROACH"));
        assert_eq!(CutPlan::status_name(12), None);
    }

    #[test]
    fn mill_plan_status_names() {
        assert_eq!(MillPlan::status_name(MillPlan::SUCCESS), Some("SUCCESS"));
        assert_eq!(MillPlan::status_name(2), Some("UNREACHABLE"));
        assert_eq!(MillPlan::status_name(3), Some("POLICY_ERROR"));
        assert_eq!(MillPlan::status_name(4), Some("CHATTER_MODEL_ERROR"));
        assert_eq!(MillPlan::status_name(5), Some("QUEUE_FULL"));
        assert_eq!(MillPlan::status_name(6), Some("INTERNAL_ERROR"));
        assert_eq!(MillPlan::status_name(7), Some("TIMEOUT"));
        assert_eq!(MillPlan::status_name(8), Some("ILL_CONDITIONED"));
        assert_eq!(MillPlan::status_name(9), Some("RESOURCE_LIMIT"));
        assert_eq!(MillPlan::status_name(10), Some("NO_APPROACH"));
        assert_eq!(MillPlan::status_name(11), Some("CHATTER"));
        assert_eq!(MillPlan::status_name(12), Some("INFEASIBLE"));
        assert_eq!(MillPlan::status_name(13), None);
        // Every name is distinct and round-trips through its code.
        let names: Vec<&str> = (0..=u8::MAX).filter_map(MillPlan::status_name).collect();
        assert_eq!(names.len(), 13);
        let mut sorted = names.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), 13);
    }
}

/// `kerf_msgs/msg/PlanStretches`: where a planned trajectory starts, and which of its stretches
/// are approach, process and retract (issue 27).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PlanStretches {
    /// `"current"`, `"given"` or `"none"`; empty unless the plan succeeded.
    pub start: String,
    /// The configuration the trajectory starts at.
    pub start_positions: Vec<f64>,
    /// When the process starts (s from the trajectory's start).
    pub process_start_time: f64,
    /// When the process ends (s).
    pub process_end_time: f64,
    /// The trajectory's duration (s).
    pub duration: f64,
    /// `"direct"`, `"via safe pose N"`, `"via the tool axis D m above the first point"`, or empty with start none.
    pub approach_route: String,
    /// `"tool axis"`, `"tool axis, safe pose"`, or empty with start none.
    pub retract_route: String,
    /// Smallest exact distance (m) over the approach and retract outside the lead moves.
    pub min_clearance: f64,
    /// Smallest exact distance (m) over the lead-in and lead-out, process contact left out.
    pub min_lead_clearance: f64,
}
impl_ros_type!(PlanStretches, "kerf_msgs", msg, "PlanStretches");
