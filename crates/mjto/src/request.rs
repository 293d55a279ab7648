//! A cut request: the CL path, process parameters, workpiece and options.
//!
//! This is the planner's own (ROS-free) form of `kerf_msgs/msg/CutRequest`.
//! It is also the YAML/JSON request file of `kerf plan cut` and the YAML
//! form of the `~/cut_request_text` topic. SI units throughout: m, m/s,
//! m/s², m/s³, s, rad.

use crate::optimal_feed::FeedMode;
use crate::timelaw::TimeLaw;
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use crate::PlanError;

/// Smallest accepted distance between consecutive CL points (m). Closer
/// points are "repeated points": the arc-length parameter would not be
/// strictly increasing.
pub const MIN_SEGMENT_LENGTH: f64 = 1e-7;

/// Largest accepted deviation of an axis norm from 1.
pub const AXIS_NORM_TOLERANCE: f64 = 1e-6;

/// Pose of the workpiece frame in the machine frame (`base_link`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseSpec {
    /// Position (m).
    pub position: [f64; 3],
    /// Orientation quaternion [x, y, z, w] (normalised on use; must not be zero).
    pub orientation: [f64; 4],
}

impl Default for PoseSpec {
    fn default() -> Self {
        Self {
            position: [0.0; 3],
            orientation: [0.0, 0.0, 0.0, 1.0],
        }
    }
}

impl PoseSpec {
    /// The pose as an isometry, after checking it is finite and the
    /// quaternion is not (near) zero.
    pub fn isometry(&self) -> Result<Isometry3<f64>, PlanError> {
        if self
            .position
            .iter()
            .chain(self.orientation.iter())
            .any(|v| !v.is_finite())
        {
            return Err(PlanError::invalid("workpiece_pose", "not finite"));
        }
        let [x, y, z, w] = self.orientation;
        let q = Quaternion::new(w, x, y, z);
        let n = q.norm();
        if (n - 1.0).abs() > 1e-3 {
            return Err(PlanError::invalid(
                "workpiece_pose.orientation",
                format!("quaternion norm {n:.6} is not 1"),
            ));
        }
        let p = self.position;
        Ok(Isometry3::from_parts(
            Translation3::new(p[0], p[1], p[2]),
            UnitQuaternion::from_quaternion(q),
        ))
    }
}

/// Largest GFD grid (candidates q4_steps × q5_steps × q6_steps) a request may ask for: 17 times
/// the default 13 × 9 × 5 = 585. Each candidate costs a kinematics and a collision query per
/// inserted RTO.
pub const MAX_GFD_CANDIDATES: usize = 10_000;

/// The sampling grid of one 3D GFD (section 2.4), centred on the
/// reference configuration of the RTO.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GfdGrid {
    /// Samples over q4 (odd, ≥ 1).
    pub q4_steps: usize,
    /// Samples over q5 (odd, ≥ 1).
    pub q5_steps: usize,
    /// Samples over q6 (≥ 1), spread over the admissible standoff range.
    pub q6_steps: usize,
    /// Half width of the q4 range around the reference, as the angle the
    /// tool axis sweeps (rad): the q4 span is this over sin|q̂5|, at most π
    /// (`gfd::q4_half_span`).
    pub q4_half_range: f64,
    /// Half width of the q5 range around the reference (rad).
    pub q5_half_range: f64,
}

impl Default for GfdGrid {
    fn default() -> Self {
        Self {
            q4_steps: 13,
            q5_steps: 9,
            q6_steps: 5,
            q4_half_range: 0.35,
            q5_half_range: 0.3,
        }
    }
}

/// Weights of eq. 55 (k4, k5, k6) and eq. 56 (k1, k2).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Weights {
    /// Weight of the distance-to-reference term of eq. 56.
    pub k1: f64,
    /// Weight of the RTO-to-RTO change per path length of eq. 56 (m).
    pub k2: f64,
    /// Weight of q4 in eq. 55 (1/rad²).
    pub k4: f64,
    /// Weight of q5 in eq. 55 (1/rad²).
    pub k5: f64,
    /// Weight of q6 in eq. 55 (1/m²).
    pub k6: f64,
}

impl Default for Weights {
    fn default() -> Self {
        Self {
            k1: 1.0,
            k2: 0.5,
            k4: 1.0,
            k5: 1.0,
            k6: 100.0,
        }
    }
}

/// How the RTO orientations enter the QPs (kerf, issue 16 item 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RtoConstraint {
    /// Seed 001 eq. 57-60 and 62-64: the joint splines pass exactly through
    /// the selected GFD candidate (q4, q5, q6) at each RTO.
    Equality,
    /// kerf: at each RTO, q4, q5 and q6 may take any value inside the
    /// largest box of collision-free, lead/tilt-feasible GFD grid samples
    /// grown around the selected candidate (`gfd::Gfd::free_box`); the QPs
    /// choose the values of least jerk. Measured smoother than `equality`
    /// on the committed cases and a tube saddle (BENCHMARKS.md).
    #[default]
    Box,
}

impl RtoConstraint {
    /// The option from its request spelling: `"equality"` or `"box"`; the
    /// empty string is the default ([`RtoConstraint::Box`]).
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] (field `options.rto_constraint`) for any
    /// other text.
    pub fn parse(text: &str) -> Result<Self, PlanError> {
        match text {
            "" => Ok(Self::default()),
            "equality" => Ok(Self::Equality),
            "box" => Ok(Self::Box),
            other => Err(PlanError::invalid(
                "options.rto_constraint",
                format!("{other:?} must be \"equality\" or \"box\""),
            )),
        }
    }

    /// The request spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Equality => "equality",
            Self::Box => "box",
        }
    }
}

/// Where the rotary QPs see the lead/tilt allowance (kerf, issue 16 item 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum OrientationCorridor {
    /// Seed 001 (eq. 57-61): the rotary splines are constrained only at the RTOs and free
    /// between them; the allowance is checked on the dense samples afterwards and a sample
    /// outside it inserts an RTO.
    None,
    /// kerf: the q5 QP also keeps q5, at every CL point between the RTOs, inside the
    /// interval whose tool axis (with the q4 of the q4 QP) is within the lead/tilt
    /// allowance, so it minimizes the jerk over the feasible orientations of the whole cut
    /// (`planner/corridor.rs`). Measured: the tube saddle r/R 0.4 at its requested 10 m/min
    /// instead of 8.95 (BENCHMARKS.md).
    #[default]
    Allowance,
}

impl OrientationCorridor {
    /// The option from its request spelling: `"none"` or `"allowance"`; the empty string is
    /// the default ([`OrientationCorridor::Allowance`]).
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] (field `options.orientation_corridor`) for any other
    /// text.
    pub fn parse(text: &str) -> Result<Self, PlanError> {
        match text {
            "" => Ok(Self::default()),
            "none" => Ok(Self::None),
            "allowance" => Ok(Self::Allowance),
            other => Err(PlanError::invalid(
                "options.orientation_corridor",
                format!("{other:?} must be \"none\" or \"allowance\""),
            )),
        }
    }

    /// The request spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::None => "none",
            Self::Allowance => "allowance",
        }
    }
}

/// Planner options.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CutOptions {
    /// Number of B-spline control coefficients n + 1; 0 = automatic (one
    /// per 10 mm of path, 12 to 100: `planner::automatic_control_points`).
    /// Otherwise 6 ≤ n + 1 ≤ number of CL points; the CL count is the
    /// paper's choice.
    pub control_points: usize,
    /// Maximum iterations of the loop of Figure 6 (≥ 1).
    pub max_iterations: usize,
    /// GFD sampling grid.
    pub gfd: GfdGrid,
    /// Weights of eq. 55 and 56.
    pub weights: Weights,
    /// CL indices of the initial RTOs (strictly increasing, first 0, last
    /// N - 1); empty = automatic (see `rto_spacing`, `rto_angle`).
    pub rto_indices: Vec<usize>,
    /// Automatic initial RTOs: largest path length between two RTOs (m).
    pub rto_spacing: f64,
    /// Automatic initial RTOs: largest change of the nominal tool axis
    /// between two RTOs (rad).
    pub rto_angle: f64,
    /// Preferred standoff q6 (m): the q6 of the GFD reference and the
    /// regularisation target of the M-path QP.
    pub reference_standoff: f64,
    /// Required clearance between head and workpiece (m, ≥ 0); 0 = contact
    /// is a collision.
    pub clearance: f64,
    /// Largest distance of the tool tip (eq. 2) from the requested CL path at the samples and
    /// CL points (m, > 0). With automatic control points the planner doubles them (up to
    /// [`crate::planner::MAX_AUTO_CONTROL_POINTS`] and the CL count) until the plan is within
    /// it; a plan that is not is refused (LIMIT_VIOLATION). Default 0.15 mm. Written only when
    /// not the default (request files written before the option read the same).
    #[serde(skip_serializing_if = "is_default_cl_tolerance")]
    pub cl_tolerance: f64,
    /// The time law: `time_optimal` (default: the fastest law under every limit, the
    /// feedrate its cruise maximum; issue 16) or `constant` (seed 001's constant feedrate with
    /// S-curve ramps). Written only when not the default.
    #[serde(skip_serializing_if = "is_default_feed_law")]
    pub feed_law: FeedMode,
    /// RTOs as equalities (seed 001) or boxes inside the feasible domain
    /// (kerf, the default): `"equality"` or `"box"`. Written only when not
    /// the default (request files written before the option read the same).
    #[serde(skip_serializing_if = "is_default_rto_constraint")]
    pub rto_constraint: RtoConstraint,
    /// The lead/tilt allowance as a corridor of the q5 QP along the whole cut (kerf, the
    /// default: `"allowance"`) or only checked on the dense samples (seed 001: `"none"`).
    /// Written only when not the default (request files written before the option read the
    /// same).
    #[serde(skip_serializing_if = "is_default_orientation_corridor")]
    pub orientation_corridor: OrientationCorridor,
}

fn is_default_orientation_corridor(v: &OrientationCorridor) -> bool {
    *v == OrientationCorridor::default()
}

/// The default of `options.cl_tolerance` (m).
pub const DEFAULT_CL_TOLERANCE: f64 = 1.5e-4;

fn is_default_cl_tolerance(v: &f64) -> bool {
    *v == DEFAULT_CL_TOLERANCE
}

fn is_default_feed_law(v: &FeedMode) -> bool {
    *v == FeedMode::default()
}

impl Default for CutOptions {
    fn default() -> Self {
        Self {
            control_points: 0,
            max_iterations: 10,
            gfd: GfdGrid::default(),
            weights: Weights::default(),
            rto_indices: Vec::new(),
            rto_spacing: 0.15,
            rto_angle: 20f64.to_radians(),
            reference_standoff: -0.07,
            clearance: 0.0,
            cl_tolerance: DEFAULT_CL_TOLERANCE,
            feed_law: FeedMode::TimeOptimal,
            rto_constraint: RtoConstraint::Box,
            orientation_corridor: OrientationCorridor::Allowance,
        }
    }
}

fn default_feed_acceleration() -> f64 {
    8.0
}
fn default_feed_jerk() -> f64 {
    80.0
}

/// A cut request (planner form).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CutRequest {
    /// Echoed in the plan.
    #[serde(default)]
    pub request_id: String,
    /// CL points in the workpiece frame (m).
    pub points: Vec<[f64; 3]>,
    /// Unit tool axes in the workpiece frame, one per CL point (from the
    /// surface towards the head).
    pub axes: Vec<[f64; 3]>,
    /// Feedrate f along the path (m/s), constant outside the ramps.
    pub feedrate: f64,
    /// Path acceleration limit of the feed ramps (m/s²; Table 1: 8).
    #[serde(default = "default_feed_acceleration")]
    pub feed_acceleration: f64,
    /// Path jerk limit of the feed ramps (m/s³; Table 1: 80).
    #[serde(default = "default_feed_jerk")]
    pub feed_jerk: f64,
    /// Controller sample period Δt (s).
    pub sample_period: f64,
    /// Lead angle limit φ_max (rad), in (0, π/2).
    pub max_lead_angle: f64,
    /// Tilt angle limit ϕ_max (rad), in (0, π/2).
    pub max_tilt_angle: f64,
    /// Workpiece mesh: a file path, `file://` URI or `package://kerf/...` URI
    /// (STL, binary or ASCII, or OBJ), in metres, in the workpiece frame.
    pub mesh: String,
    /// Pose of the workpiece frame in the machine frame.
    #[serde(default)]
    pub workpiece_pose: PoseSpec,
    /// Options.
    #[serde(default)]
    pub options: CutOptions,
    /// Time budget of the plan (s), in (0, [`kerf_budget::MAX_BUDGET_SECONDS`]]; 0 = none of the request's own
    /// (a planner node then applies its `plan_timeout`, and a request may only ask for less).
    /// A plan that runs out of it ends with [`PlanError::Interrupted`] (status TIMEOUT).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub time_budget: f64,
    /// Where the trajectory starts (issue 27): `current`, `none`, or a list of joint
    /// positions; left out = current when the planner node has the robot's joint state, else
    /// none. Resolved and framed by the planner-node harness, not by the planner.
    #[serde(default, skip_serializing_if = "kerf_approach::StartSpec::is_default")]
    pub start: kerf_approach::StartSpec,
}

fn is_default_rto_constraint(v: &RtoConstraint) -> bool {
    *v == RtoConstraint::default()
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// A request after validation, in the machine frame.
#[derive(Debug, Clone)]
pub struct ValidatedRequest {
    /// CL points in the machine frame (m).
    pub points: Vec<Vector3<f64>>,
    /// Unit tool axes in the machine frame.
    pub axes: Vec<Vector3<f64>>,
    /// Cumulative arc length at each CL point (m), starting at 0.
    pub arc_length: Vec<f64>,
    /// Normalized arc length u_i = s_i / σ (eq. 1).
    pub u: Vec<f64>,
    /// Total path length σ (m).
    pub sigma: f64,
    /// Workpiece pose in the machine frame.
    pub workpiece_pose: Isometry3<f64>,
    /// The request's own time budget (`time_budget`; `None` for 0).
    pub time_budget: Option<std::time::Duration>,
}

fn finite(field: &str, v: f64) -> Result<f64, PlanError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(PlanError::invalid(
            field,
            format!("{v} is not a finite number"),
        ))
    }
}

fn positive(field: &str, v: f64) -> Result<f64, PlanError> {
    finite(field, v)?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(PlanError::invalid(field, format!("{v} must be > 0")))
    }
}

impl CutRequest {
    /// Parses a YAML (or JSON) request document.
    ///
    /// JSON is nearly a subset of YAML; where YAML refuses a JSON document (a `\u` escape of a
    /// UTF-16 surrogate pair, e.g. `"\ud83d\ude00"`), the text is read as JSON.
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] (field `request`) with the YAML parser's message (unknown
    /// or missing field, wrong type, with line and column), or for a document nested deeper
    /// than `kerf_robot::document::MAX_DEPTH` (checked before parsing).
    pub fn from_yaml(text: &str) -> Result<Self, PlanError> {
        // Nesting is checked before parsing: YAML parsing is quadratic in it.
        kerf_robot::document::from_yaml_or_json(text).map_err(|e| PlanError::invalid("request", e))
    }

    /// The number of trajectory samples the plan will have (one every `sample_period` over the
    /// feed profile's duration, both ends included), from the path length and the feed
    /// profile alone, before any planning.
    ///
    /// # Returns
    /// `None` when a field it needs is invalid ([`Self::validate`] names it).
    pub fn sample_count(&self) -> Option<usize> {
        let sigma: f64 = self
            .points
            .windows(2)
            .map(|w| {
                let d: f64 = (0..3).map(|k| (w[1][k] - w[0][k]).powi(2)).sum();
                d.sqrt()
            })
            .sum();
        if !(sigma.is_finite() && self.sample_period.is_finite() && self.sample_period > 0.0) {
            return None;
        }
        let law =
            TimeLaw::new(sigma, self.feedrate, self.feed_acceleration, self.feed_jerk).ok()?;
        let samples = (law.duration() / self.sample_period).ceil() + 1.0;
        (samples.is_finite() && samples < usize::MAX as f64).then_some(samples as usize)
    }

    /// Checks every field and transforms the path into the machine frame.
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] naming the field (with index) for:
    /// different numbers of points and axes, fewer than two points, NaN or
    /// infinite values, zero or non-unit axes, repeated points, non-positive
    /// feedrate / sample period / ramp limits, angle limits outside
    /// (0, π/2), bad options.
    pub fn validate(&self) -> Result<ValidatedRequest, PlanError> {
        let n = self.points.len();
        if n != self.axes.len() {
            return Err(PlanError::invalid(
                "axes",
                format!(
                    "{} axes for {} CL points: one unit axis per point is required",
                    self.axes.len(),
                    n
                ),
            ));
        }
        if n < 2 {
            return Err(PlanError::invalid(
                "points",
                format!("{n} CL point(s): at least 2 are required"),
            ));
        }
        positive("feedrate", self.feedrate)?;
        positive("feed_acceleration", self.feed_acceleration)?;
        positive("feed_jerk", self.feed_jerk)?;
        positive("sample_period", self.sample_period)?;
        let time_budget = kerf_budget::limit_from_seconds(self.time_budget)
            .map_err(|e| PlanError::invalid("time_budget", e))?;
        for (name, v) in [
            ("max_lead_angle", self.max_lead_angle),
            ("max_tilt_angle", self.max_tilt_angle),
        ] {
            positive(name, v)?;
            if v >= std::f64::consts::FRAC_PI_2 {
                return Err(PlanError::invalid(
                    name,
                    format!("{v} rad must be below π/2"),
                ));
            }
        }
        if self.mesh.trim().is_empty() {
            return Err(PlanError::invalid(
                "mesh",
                "empty: a workpiece mesh is required",
            ));
        }
        let pose = self.workpiece_pose.isometry()?;
        self.validate_options(n)?;

        let mut points = Vec::with_capacity(n);
        let mut axes = Vec::with_capacity(n);
        for (i, (p, a)) in self.points.iter().zip(&self.axes).enumerate() {
            if p.iter().any(|v| !v.is_finite()) {
                return Err(PlanError::invalid(
                    format!("points[{i}]"),
                    format!("{p:?} is not finite"),
                ));
            }
            if a.iter().any(|v| !v.is_finite()) {
                return Err(PlanError::invalid(
                    format!("axes[{i}]"),
                    format!("{a:?} is not finite"),
                ));
            }
            let a = Vector3::new(a[0], a[1], a[2]);
            let norm = a.norm();
            if norm == 0.0 {
                return Err(PlanError::invalid(
                    format!("axes[{i}]"),
                    "zero vector: the tool axis must be a unit vector",
                ));
            }
            if (norm - 1.0).abs() > AXIS_NORM_TOLERANCE {
                return Err(PlanError::invalid(
                    format!("axes[{i}]"),
                    format!("norm {norm:.9} is not 1 (tolerance {AXIS_NORM_TOLERANCE:e})"),
                ));
            }
            points.push((pose * nalgebra::Point3::new(p[0], p[1], p[2])).coords);
            axes.push(pose.rotation * (a / norm));
        }
        let mut arc_length = Vec::with_capacity(n);
        arc_length.push(0.0);
        for i in 1..n {
            let d = (points[i] - points[i - 1]).norm();
            if !(arc_length[i - 1] + d).is_finite() {
                // Finite coordinates near f64::MAX overflow in the pose or the lengths.
                return Err(PlanError::invalid(
                    format!("points[{i}]"),
                    format!("the path length to this point overflows (segment of {d} m): coordinates too large"),
                ));
            }
            if d < MIN_SEGMENT_LENGTH {
                return Err(PlanError::invalid(
                    format!("points[{i}]"),
                    format!(
                        "repeats points[{}] (segment length {d:e} m < {MIN_SEGMENT_LENGTH:e} m)",
                        i - 1
                    ),
                ));
            }
            let s = arc_length[i - 1] + d;
            if s <= arc_length[i - 1] {
                // A segment below the rounding of a huge path length leaves it unchanged.
                return Err(PlanError::invalid(
                    format!("points[{i}]"),
                    format!(
                        "the segment of {d:e} m does not lengthen the path of {:e} m so far \
                         (f64 rounding): coordinates too large",
                        arc_length[i - 1]
                    ),
                ));
            }
            arc_length.push(s);
        }
        let sigma = arc_length[n - 1];
        let mut u: Vec<f64> = arc_length.iter().map(|s| s / sigma).collect();
        u[n - 1] = 1.0;
        Ok(ValidatedRequest {
            points,
            axes,
            arc_length,
            u,
            sigma,
            workpiece_pose: pose,
            time_budget,
        })
    }

    fn validate_options(&self, n: usize) -> Result<(), PlanError> {
        let o = &self.options;
        if o.control_points != 0 && (o.control_points < 6 || o.control_points > n) {
            return Err(PlanError::invalid(
                "options.control_points",
                format!(
                    "{} must be 0 (automatic) or in [6, {n}] (the CL count is seed 001's choice)",
                    o.control_points
                ),
            ));
        }
        if o.max_iterations == 0 {
            return Err(PlanError::invalid("options.max_iterations", "must be ≥ 1"));
        }
        let g = &o.gfd;
        for (name, steps) in [("q4_steps", g.q4_steps), ("q5_steps", g.q5_steps)] {
            if steps == 0 || steps % 2 == 0 || steps > 101 {
                return Err(PlanError::invalid(
                    format!("options.gfd.{name}"),
                    format!("{steps} must be odd, in [1, 101]"),
                ));
            }
        }
        if g.q6_steps == 0 || g.q6_steps > 101 {
            return Err(PlanError::invalid(
                "options.gfd.q6_steps",
                format!("{} must be in [1, 101]", g.q6_steps),
            ));
        }
        // Every candidate of a GFD costs a kinematics and a collision query; a grid of
        // 101 × 101 × 101 was still planning after 10 min (issue 11, row 7).
        let candidates = g.q4_steps * g.q5_steps * g.q6_steps;
        if candidates > MAX_GFD_CANDIDATES {
            return Err(PlanError::invalid(
                "options.gfd",
                format!(
                    "q4_steps × q5_steps × q6_steps = {} × {} × {} = {candidates} candidates per \
                     GFD, over the limit of {MAX_GFD_CANDIDATES}",
                    g.q4_steps, g.q5_steps, g.q6_steps
                ),
            ));
        }
        for (name, v) in [
            ("q4_half_range", g.q4_half_range),
            ("q5_half_range", g.q5_half_range),
        ] {
            finite(&format!("options.gfd.{name}"), v)?;
            if !(0.0..=std::f64::consts::PI).contains(&v) {
                return Err(PlanError::invalid(
                    format!("options.gfd.{name}"),
                    format!("{v} must be in [0, π]"),
                ));
            }
        }
        let w = &o.weights;
        for (name, v) in [
            ("k1", w.k1),
            ("k2", w.k2),
            ("k4", w.k4),
            ("k5", w.k5),
            ("k6", w.k6),
        ] {
            finite(&format!("options.weights.{name}"), v)?;
            if v < 0.0 {
                return Err(PlanError::invalid(
                    format!("options.weights.{name}"),
                    format!("{v} must be ≥ 0"),
                ));
            }
        }
        if !o.rto_indices.is_empty() {
            let r = &o.rto_indices;
            if r[0] != 0 || *r.last().unwrap_or(&0) != n - 1 || r.windows(2).any(|w| w[1] <= w[0]) {
                return Err(PlanError::invalid(
                    "options.rto_indices",
                    format!(
                        "must be strictly increasing from 0 to {} (got {r:?})",
                        n - 1
                    ),
                ));
            }
        }
        positive("options.rto_spacing", o.rto_spacing)?;
        positive("options.rto_angle", o.rto_angle)?;
        finite("options.reference_standoff", o.reference_standoff)?;
        finite("options.clearance", o.clearance)?;
        if o.clearance < 0.0 {
            return Err(PlanError::invalid("options.clearance", "must be ≥ 0"));
        }
        positive("options.cl_tolerance", o.cl_tolerance)?;
        Ok(())
    }
}
