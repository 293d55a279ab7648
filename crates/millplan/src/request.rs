//! The milling planner's request (issue 5 section 4): the schema of the
//! node's YAML text topic and of `kerf plan mill --request FILE`, with its
//! validation (issue 5 section 5, "bad input").
//!
//! # Schema (YAML or JSON; unknown fields are refused)
//!
//! ```yaml
//! request_id: job-17
//! points: [[1.4, -0.3, 1.7], [1.6, -0.1, 1.7], [1.8, 0.1, 1.7], [2.1, 0.3, 1.7]]  # m, coplanar
//! segments: 100            # optional, default: the cell's (100)
//! process:                 # optional, all fields when given
//!   {teeth: 2, tool_radius: 0.04, axial_depth: 0.003, kt: 6.44e8, kn: 2.37e8,
//!    entry_angle: 2.356194490192345, exit_angle: 3.141592653589793}   # m, N/m^2, rad
//! limits:                  # optional, each field optional (the cell's otherwise)
//!   spindle_rpm: [2000, 4000]
//!   feed: [0.0, 0.06]                 # m/s
//!   redundancy_angle: [-3.14, 3.14]   # rad
//!   step_bounds: {spindle_rpm: 20, feed: 0.001, redundancy_angle: 0.2}
//! initial: {spindle_rpm: 2000, feed: 0.04, g: 0.0}   # optional, each field optional
//! planner: best            # best | ddpg | fixed_g | dp | naive | greedy | greedy_best_g (default best)
//! policy_file: crates/millplan/policies/ddpg.safetensors   # optional
//! allow_chatter: false     # optional: answer a plan that chatters as executed (status CHATTER)
//! entry: run_in            # optional: run_in (default) | in_material
//! ```
//!
//! The path is machined from the +z side ([`REQUEST_UP`], tool pointing
//! down into a horizontal plane), as in the default cell file; the
//! request does not change the robot, the TCP, the dynamics model or the
//! chatter settings of the cell.

use std::f64::consts::PI;
use std::path::Path;

use kerf_chatter::{ChatterError, MillingProcess};
use kerf_mill::{MillingPath, PathSpec, StateLimits};
use serde::{Deserialize, Serialize};

use crate::error::MillPlanError;

/// The side the tool comes from for a request's path (the plane normal is
/// oriented towards it and the tool approaches against it).
pub const REQUEST_UP: [f64; 3] = [0.0, 0.0, 1.0];

/// Largest number of path points a request may give.
pub const MAX_POINTS: usize = 10_000;
/// Largest number of segments a request may ask for (the planners and the
/// direct evaluation of a plan scale linearly with it).
pub const MAX_SEGMENTS: usize = 10_000;

/// Largest |coordinate| of a path point (m): far beyond any robot's reach (the IRB 6660 reaches
/// 3.1 m), small enough that the path's spline and arc length stay well conditioned.
pub const MAX_COORDINATE: f64 = 1000.0;

/// Default initial spindle speed \[rpm\] (seed 004's IVP Ω0).
pub const DEFAULT_INITIAL_RPM: f64 = 2000.0;
/// Default initial feed [m/s] (seed 004's IVP f0).
pub const DEFAULT_INITIAL_FEED: f64 = 0.04;
/// Default initial redundancy angle \[rad\] (seed 004's IVP g0).
pub const DEFAULT_INITIAL_G: f64 = 0.0;

/// Which planner answers a request.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PlannerKind {
    /// Greedy rollout of a DDPG policy with the redundancy angle free.
    Ddpg,
    /// Greedy rollout of a DDPG policy trained with g fixed at g0 (the
    /// paper's ablation).
    FixedG,
    /// The dynamic-programming optimum ([`crate::dp`]) with the executed timing in its loop
    /// ([`crate::dp_executed`]): the best plan as executed among the DP's rounds.
    Dp,
    /// Constant spindle speed and feed ([`crate::naive`]).
    Naive,
    /// The greedy ramp from the initial state at the step bounds, g held at
    /// the initial g ([`crate::greedy::solve_within`]).
    Greedy,
    /// The greedy ramp with the best fixed g, reached from the initial g at
    /// the step bound ([`crate::greedy::best_fixed_g_within`]).
    GreedyBestG,
    /// The fastest plan as executed among [`PlannerKind::BEST_CANDIDATES`] that is
    /// chatter-free at every executed sample and keeps 1/K at or above
    /// [`crate::planner::BEST_MIN_CONDITION_INDICATOR`] (or the request's minimum) along the
    /// trajectory (issue 28, item 3): the default.
    Best,
}

impl PlannerKind {
    /// Every planner, in the order of the comparison table.
    pub const ALL: [PlannerKind; 7] = [
        Self::Ddpg,
        Self::FixedG,
        Self::Dp,
        Self::Naive,
        Self::Greedy,
        Self::GreedyBestG,
        Self::Best,
    ];

    /// The planners [`PlannerKind::Best`] chooses among: every planner but `dp`, whose grid
    /// search costs seconds to minutes on a new path (its cache is built per path) and whose
    /// plans are slower as executed on every path measured (`BENCHMARKS.md`, "Milling: no
    /// chattering plan as SUCCESS"). `greedy_best_g` runs only where `greedy` has no
    /// chatter-free plan.
    pub const BEST_CANDIDATES: [PlannerKind; 5] = [
        Self::Ddpg,
        Self::FixedG,
        Self::Naive,
        Self::Greedy,
        Self::GreedyBestG,
    ];

    /// The name used in requests (`ddpg`, `fixed_g`, `dp`, `naive`,
    /// `greedy`, `greedy_best_g`).
    pub fn name(&self) -> &'static str {
        match self {
            Self::Ddpg => "ddpg",
            Self::FixedG => "fixed_g",
            Self::Dp => "dp",
            Self::Naive => "naive",
            Self::Greedy => "greedy",
            Self::GreedyBestG => "greedy_best_g",
            Self::Best => "best",
        }
    }

    /// Parses a request's `planner` field.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] naming `planner` and the accepted
    /// names.
    pub fn parse(name: &str) -> Result<Self, MillPlanError> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == name)
            .ok_or_else(|| MillPlanError::InvalidConfig {
                name: "planner".to_string(),
                reason: format!(
                    "unknown planner `{name}`: must be best, ddpg, fixed_g, dp, naive, greedy \
                     or greedy_best_g"
                ),
            })
    }
}

/// The milling process of a request (all fields required when the section
/// is given).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RequestProcess {
    /// Number of teeth.
    pub teeth: usize,
    /// Tool radius \[m\].
    pub tool_radius: f64,
    /// Axial depth of cut \[m\].
    pub axial_depth: f64,
    /// Tangential cutting coefficient K_t [N/m²].
    pub kt: f64,
    /// Normal cutting coefficient K_n [N/m²].
    pub kn: f64,
    /// Entry immersion angle \[rad\].
    pub entry_angle: f64,
    /// Exit immersion angle \[rad\].
    pub exit_angle: f64,
}

impl RequestProcess {
    /// As a `kerf_chatter` process.
    pub fn to_process(&self) -> MillingProcess {
        MillingProcess {
            teeth: self.teeth,
            radius: self.tool_radius,
            axial_depth: self.axial_depth,
            kt: self.kt,
            kn: self.kn,
            entry_angle: self.entry_angle,
            exit_angle: self.exit_angle,
        }
    }
}

/// Per-step bounds of a request (each optional: the cell's otherwise).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RequestStepBounds {
    /// |ΔΩ| per segment \[rpm\].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spindle_rpm: Option<f64>,
    /// |Δf| per segment [m/s].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub feed: Option<f64>,
    /// |Δg| per segment \[rad\].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub redundancy_angle: Option<f64>,
}

/// State ranges and step bounds of a request (each optional).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RequestLimits {
    /// Spindle speed [min, max] \[rpm\].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spindle_rpm: Option<[f64; 2]>,
    /// Feed [min, max] [m/s].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub feed: Option<[f64; 2]>,
    /// Redundancy angle [min, max] \[rad\].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub redundancy_angle: Option<[f64; 2]>,
    /// Per-step bounds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step_bounds: Option<RequestStepBounds>,
}

impl RequestLimits {
    /// `base` with the fields this request gives replaced.
    pub fn apply(&self, base: &StateLimits) -> StateLimits {
        let steps = self.step_bounds.unwrap_or_default();
        StateLimits {
            spindle_rpm: self.spindle_rpm.unwrap_or(base.spindle_rpm),
            feed: self.feed.unwrap_or(base.feed),
            redundancy_angle: self.redundancy_angle.unwrap_or(base.redundancy_angle),
            max_feed_step: steps.feed.unwrap_or(base.max_feed_step),
            max_spindle_step_rpm: steps.spindle_rpm.unwrap_or(base.max_spindle_step_rpm),
            max_redundancy_step: steps.redundancy_angle.unwrap_or(base.max_redundancy_step),
        }
    }
}

/// The initial state (each field optional: seed 004's IVP otherwise).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RequestInitial {
    /// Ω0 \[rpm\] (default 2000).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spindle_rpm: Option<f64>,
    /// f0 [m/s] (default 0.04).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub feed: Option<f64>,
    /// g0 \[rad\] (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub g: Option<f64>,
}

/// Tolerances of the executed plan (issue 13, items 1 and 2), each optional.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RequestTolerances {
    /// Largest distance of the executed tool tip from the path and from the milling plane
    /// \[m\], in (0, [`MAX_PATH_TOLERANCE`]] (the planner's, 5e-5 m by default, when absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub path_tolerance: Option<f64>,
    /// Smallest condition indicator 1/K (seed 004 eq. 14) allowed at every point of the
    /// executed trajectory, in [0, 1); 0 or absent: no minimum. A plan below it is refused
    /// ([`MillPlanError::IllConditioned`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_condition_indicator: Option<f64>,
}

/// Largest path tolerance a request may ask for \[m\]: the executed path is measured by a
/// closest-point search that assumes the tool within a millimetre of the path.
pub const MAX_PATH_TOLERANCE: f64 = 1e-3;

/// A milling planning request (module documentation).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MillRequest {
    /// Caller's identifier, echoed in the answer.
    #[serde(default)]
    pub request_id: String,
    /// The coplanar path points \[m\], base frame, interpolated by a cubic
    /// B-spline (seed 004 section 4).
    pub points: Vec<[f64; 3]>,
    /// Number of equal-arc-length segments (the cell's when absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub segments: Option<usize>,
    /// Milling process (the cell's when absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub process: Option<RequestProcess>,
    /// State ranges and step bounds (the cell's when absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limits: Option<RequestLimits>,
    /// Initial state (seed 004's IVP when absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial: Option<RequestInitial>,
    /// `best` (the default), `ddpg`, `fixed_g`, `dp`, `naive`, `greedy` or `greedy_best_g`.
    #[serde(default = "default_planner")]
    pub planner: String,
    /// Answer a plan that chatters as executed (status CHATTER, with its trajectory) instead
    /// of refusing it (issue 28, item 1). kerf never sends such a plan to the robot on its own.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub allow_chatter: bool,
    /// Where the tool enters the material ([`crate::timing::Entry`]): `run_in` (absent: the
    /// path is the cut in the material and the tool enters it at feed from a straight run-in)
    /// or `in_material` (the ramps from and to rest on the path).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub entry: Option<String>,
    /// The policy file of `ddpg`/`fixed_g`: a path (relative paths: to the working
    /// directory), a local `file://` URI or `package://kerf/<path>`
    /// ([`crate::policy::resolve_policy_file`]); the planner's default policy when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub policy_file: Option<String>,
    /// Time budget of the plan (s), in (0, [`kerf_budget::MAX_BUDGET_SECONDS`]]; absent or 0 =
    /// none of the request's own (a planner node then applies its `plan_timeout`, and a
    /// request may only ask for less). A plan that runs out of it ends with
    /// [`MillPlanError::Interrupted`] (status TIMEOUT).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_budget: Option<f64>,
    /// Tolerances of the executed plan (the planner's when absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerances: Option<RequestTolerances>,
    /// Where the trajectory starts (issue 27): `current`, `none`, or a list of joint
    /// positions; left out = current when the planner node has the robot's joint state, else
    /// none. Resolved and framed by the planner-node harness, not by the planner.
    #[serde(default, skip_serializing_if = "kerf_approach::StartSpec::is_default")]
    pub start: kerf_approach::StartSpec,
}

fn default_planner() -> String {
    PlannerKind::Best.name().to_string()
}

impl Default for MillRequest {
    /// The seed 004 path (the default cell's points), no overrides, planner
    /// `ddpg`.
    fn default() -> Self {
        Self {
            start: Default::default(),
            request_id: String::new(),
            points: PathSpec::default().points,
            segments: None,
            process: None,
            limits: None,
            initial: None,
            planner: default_planner(),
            allow_chatter: false,
            entry: None,
            policy_file: None,
            time_budget: None,
            tolerances: None,
        }
    }
}

fn check_finite(name: &str, v: f64) -> Result<(), MillPlanError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(MillPlanError::InvalidParameter {
            name: name.to_string(),
            value: v,
            reason: "must be finite (NaN and infinities are refused)".to_string(),
        })
    }
}

fn check_range(name: &str, r: [f64; 2], lo: f64, hi: f64) -> Result<(), MillPlanError> {
    for (i, v) in r.iter().enumerate() {
        check_finite(&format!("{name}[{i}]"), *v)?;
    }
    if r[0] > r[1] {
        return Err(MillPlanError::InvalidParameter {
            name: format!("{name}[0]"),
            value: r[0],
            reason: format!("min > max ({name}[1] = {})", r[1]),
        });
    }
    if r[0] == r[1] {
        return Err(MillPlanError::InvalidParameter {
            name: format!("{name}[1]"),
            value: r[1],
            reason: "must be > min (an empty range)".to_string(),
        });
    }
    if r[0] < lo {
        return Err(MillPlanError::InvalidParameter {
            name: format!("{name}[0]"),
            value: r[0],
            reason: format!("must be >= {lo}"),
        });
    }
    if r[1] > hi {
        return Err(MillPlanError::InvalidParameter {
            name: format!("{name}[1]"),
            value: r[1],
            reason: format!("must be <= {hi}"),
        });
    }
    Ok(())
}

fn check_step(name: &str, v: Option<f64>) -> Result<(), MillPlanError> {
    match v {
        Some(v) if !(v.is_finite() && v > 0.0) => Err(MillPlanError::InvalidParameter {
            name: name.to_string(),
            value: v,
            reason: "step bounds must be finite and > 0".to_string(),
        }),
        _ => Ok(()),
    }
}

impl MillRequest {
    /// Parses YAML (or JSON) text.
    ///
    /// JSON is nearly a subset of YAML; where YAML refuses a JSON document
    /// (a `\u` escape of a UTF-16 surrogate pair, e.g. `"\ud83d\ude00"`),
    /// the text is read as JSON.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] naming `request` with the YAML
    /// parser's message (unknown or missing field, wrong type, with line and
    /// column), or for a document nested deeper than
    /// `kerf_robot::document::MAX_DEPTH` (checked before parsing: YAML parsing
    /// is quadratic in the depth).
    pub fn from_yaml_str(text: &str) -> Result<Self, MillPlanError> {
        kerf_robot::document::from_yaml_or_json(text).map_err(|reason| {
            MillPlanError::InvalidConfig {
                name: "request".to_string(),
                reason,
            }
        })
    }

    /// Parses JSON text.
    ///
    /// # Errors
    /// As [`MillRequest::from_yaml_str`].
    pub fn from_json_str(text: &str) -> Result<Self, MillPlanError> {
        check_depth(text)?;
        serde_json::from_str(text).map_err(|e| MillPlanError::InvalidConfig {
            name: "request".to_string(),
            reason: e.to_string(),
        })
    }

    /// Reads a request file: JSON when the name ends in `.json`, YAML
    /// otherwise.
    ///
    /// # Errors
    /// [`MillPlanError::Io`] when unreadable; the parse errors above.
    pub fn from_file(path: &Path) -> Result<Self, MillPlanError> {
        let text = std::fs::read_to_string(path).map_err(|e| MillPlanError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        if path.extension().is_some_and(|e| e == "json") {
            Self::from_json_str(&text)
        } else {
            Self::from_yaml_str(&text)
        }
    }

    /// The request as YAML.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] if serialization fails.
    pub fn to_yaml_string(&self) -> Result<String, MillPlanError> {
        serde_yaml_ng::to_string(self).map_err(|e| MillPlanError::InvalidConfig {
            name: "request".to_string(),
            reason: e.to_string(),
        })
    }

    /// The planner named by the request.
    ///
    /// # Errors
    /// [`PlannerKind::parse`].
    pub fn planner_kind(&self) -> Result<PlannerKind, MillPlanError> {
        PlannerKind::parse(&self.planner)
    }

    /// The initial state (Ω0 \[rpm\], f0 [m/s], g0 \[rad\]) with the defaults
    /// filled in.
    pub fn initial_state(&self) -> [f64; 3] {
        let i = self.initial.unwrap_or_default();
        [
            i.spindle_rpm.unwrap_or(DEFAULT_INITIAL_RPM),
            i.feed.unwrap_or(DEFAULT_INITIAL_FEED),
            i.g.unwrap_or(DEFAULT_INITIAL_G),
        ]
    }

    /// The path of the request with `default_segments` when it gives none
    /// (tool from [`REQUEST_UP`]).
    pub fn path_spec(&self, default_segments: usize) -> PathSpec {
        PathSpec {
            points: self.points.clone(),
            segments: self.segments.unwrap_or(default_segments),
            approach_from_above: true,
            up: REQUEST_UP,
        }
    }

    /// Checks everything that does not need the cell: at least 2 points,
    /// every number finite, no repeated consecutive points, the points
    /// coplanar (`kerf_mill`'s path validation: the worst point and its
    /// distance), `segments` ≥ 1, the process, every limit with
    /// min < max, step bounds > 0, the planner's name, and the initial
    /// state against the limits the request gives. [`Self::validate_with`]
    /// also checks the initial state against the cell's limits.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidParameter`] / [`MillPlanError::InvalidConfig`]
    /// naming the field and index (e.g. `points[2][1] [m]`,
    /// `limits.feed[0]`); [`MillPlanError::Mill`] with
    /// [`kerf_mill::MillError::NotCoplanar`] for points off a plane.
    ///
    /// # Performance
    /// Builds the spline once with one segment (well under a millisecond
    /// for a few points).
    pub fn validate(&self) -> Result<(), MillPlanError> {
        self.time_limit()?;
        self.check_tolerances()?;
        self.entry()?;
        if self.points.len() < 2 {
            return Err(MillPlanError::InvalidParameter {
                name: "points (count)".to_string(),
                value: self.points.len() as f64,
                reason: "a path needs at least 2 points".to_string(),
            });
        }
        if self.points.len() > MAX_POINTS {
            return Err(MillPlanError::InvalidParameter {
                name: "points (count)".to_string(),
                value: self.points.len() as f64,
                reason: format!("at most {MAX_POINTS} points are accepted"),
            });
        }
        for (i, p) in self.points.iter().enumerate() {
            for (c, v) in p.iter().enumerate() {
                let name = format!("points[{i}][{c}] [m]");
                check_finite(&name, *v)?;
                if v.abs() > MAX_COORDINATE {
                    // Found by fuzzing: 1e20 m ran the path's arc-length refinement through
                    // all its steps before failing (seconds per request).
                    return Err(MillPlanError::InvalidParameter {
                        name,
                        value: *v,
                        reason: format!(
                            "more than {MAX_COORDINATE} m from the robot base: outside any cell"
                        ),
                    });
                }
            }
        }
        for (i, w) in self.points.windows(2).enumerate() {
            let d = ((w[1][0] - w[0][0]).powi(2)
                + (w[1][1] - w[0][1]).powi(2)
                + (w[1][2] - w[0][2]).powi(2))
            .sqrt();
            if d <= kerf_mill::path::REPEAT_TOL {
                return Err(MillPlanError::InvalidParameter {
                    name: format!("points[{}]", i + 1),
                    value: d,
                    reason: format!("repeats points[{i}] (distance shown)"),
                });
            }
        }
        if let Some(n) = self.segments {
            if n == 0 || n > MAX_SEGMENTS {
                return Err(MillPlanError::InvalidParameter {
                    name: "segments".to_string(),
                    value: n as f64,
                    reason: format!("must be in 1..={MAX_SEGMENTS}"),
                });
            }
        }
        // Coplanarity (and everything else of the path) by kerf_mill, on one segment whatever
        // `segments` asks (found by fuzzing: 10 000 segments made validation cost 174 ms).
        MillingPath::new(&PathSpec {
            segments: 1,
            ..self.path_spec(1)
        })?;
        if let Some(p) = &self.process {
            for (name, v) in [
                ("process.tool_radius [m]", p.tool_radius),
                ("process.axial_depth [m]", p.axial_depth),
                ("process.kt [N/m^2]", p.kt),
                ("process.kn [N/m^2]", p.kn),
                ("process.entry_angle [rad]", p.entry_angle),
                ("process.exit_angle [rad]", p.exit_angle),
            ] {
                check_finite(name, v)?;
            }
            p.to_process().validate().map_err(|e| match e {
                ChatterError::InvalidParameter {
                    name,
                    value,
                    reason,
                } => MillPlanError::InvalidParameter {
                    name: format!("process ({name})"),
                    value,
                    reason,
                },
                other => MillPlanError::InvalidConfig {
                    name: "process".to_string(),
                    reason: other.to_string(),
                },
            })?;
        }
        if let Some(l) = &self.limits {
            if let Some(r) = l.spindle_rpm {
                check_range("limits.spindle_rpm [rpm]", r, 0.0, f64::MAX)?;
                if r[0] <= 0.0 {
                    return Err(MillPlanError::InvalidParameter {
                        name: "limits.spindle_rpm [rpm][0]".to_string(),
                        value: r[0],
                        reason: "must be > 0".to_string(),
                    });
                }
            }
            if let Some(r) = l.feed {
                check_range("limits.feed [m/s]", r, 0.0, f64::MAX)?;
            }
            if let Some(r) = l.redundancy_angle {
                check_range("limits.redundancy_angle [rad]", r, -PI - 1e-12, PI + 1e-12)?;
            }
            if let Some(s) = l.step_bounds {
                check_step("limits.step_bounds.spindle_rpm [rpm]", s.spindle_rpm)?;
                check_step("limits.step_bounds.feed [m/s]", s.feed)?;
                check_step(
                    "limits.step_bounds.redundancy_angle [rad]",
                    s.redundancy_angle,
                )?;
            }
        }
        let [rpm, feed, g] = self.initial_state();
        check_finite("initial.spindle_rpm [rpm]", rpm)?;
        check_finite("initial.feed [m/s]", feed)?;
        check_finite("initial.g [rad]", g)?;
        if feed <= 0.0 {
            return Err(MillPlanError::InvalidParameter {
                name: "initial.feed [m/s]".to_string(),
                value: feed,
                reason: "must be > 0 (a zero feed never finishes a segment)".to_string(),
            });
        }
        self.planner_kind()?;
        if let Some(l) = &self.limits {
            self.check_initial(&l.apply(&StateLimits {
                spindle_rpm: [f64::MIN, f64::MAX],
                feed: [f64::MIN, f64::MAX],
                redundancy_angle: [f64::MIN, f64::MAX],
                max_feed_step: 1.0,
                max_spindle_step_rpm: 1.0,
                max_redundancy_step: 1.0,
            }))?;
        }
        Ok(())
    }

    /// [`Self::validate`], then the initial state against the effective
    /// limits (the request's over `cell_limits`), and those limits by the
    /// cell's rules.
    ///
    /// # Errors
    /// As [`Self::validate`]; [`MillPlanError::InvalidParameter`] naming
    /// `initial.<field>` when the initial state is outside the limits.
    pub fn validate_with(&self, cell_limits: &StateLimits) -> Result<(), MillPlanError> {
        self.validate()?;
        let limits = self.effective_limits(cell_limits);
        limits.validate()?;
        self.check_initial(&limits)
    }

    /// The request's own time budget (`None`: absent or 0).
    ///
    /// # Errors
    /// [`MillPlanError::InvalidParameter`] (`time_budget [s]`) for a negative, non-finite or
    /// too large value.
    pub fn time_limit(&self) -> Result<Option<std::time::Duration>, MillPlanError> {
        let seconds = self.time_budget.unwrap_or(0.0);
        kerf_budget::limit_from_seconds(seconds).map_err(|reason| MillPlanError::InvalidParameter {
            name: "time_budget [s]".to_string(),
            value: seconds,
            reason,
        })
    }

    /// The request's entry ([`crate::timing::Entry`]; `run_in` when absent).
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] naming `entry` for an unknown name.
    pub fn entry(&self) -> Result<crate::timing::Entry, MillPlanError> {
        match self.entry.as_deref() {
            None | Some("") => Ok(crate::timing::Entry::default()),
            Some(name) => {
                crate::timing::Entry::from_name(name).ok_or_else(|| MillPlanError::InvalidConfig {
                    name: "entry".to_string(),
                    reason: format!("unknown entry `{name}`: must be run_in or in_material"),
                })
            }
        }
    }

    /// The request's path tolerance \[m\], if it gives one.
    pub fn path_tolerance(&self) -> Option<f64> {
        self.tolerances.and_then(|t| t.path_tolerance)
    }

    /// The request's minimum condition indicator, if it asks for one above 0.
    pub fn min_condition_indicator(&self) -> Option<f64> {
        self.tolerances
            .and_then(|t| t.min_condition_indicator)
            .filter(|v| *v > 0.0)
    }

    fn check_tolerances(&self) -> Result<(), MillPlanError> {
        let Some(t) = self.tolerances else {
            return Ok(());
        };
        if let Some(v) = t.path_tolerance {
            if !(v.is_finite() && v > 0.0 && v <= MAX_PATH_TOLERANCE) {
                return Err(MillPlanError::InvalidParameter {
                    name: "tolerances.path_tolerance [m]".to_string(),
                    value: v,
                    reason: format!("must be > 0 and at most {MAX_PATH_TOLERANCE} m"),
                });
            }
        }
        if let Some(v) = t.min_condition_indicator {
            if !(v.is_finite() && (0.0..1.0).contains(&v)) {
                return Err(MillPlanError::InvalidParameter {
                    name: "tolerances.min_condition_indicator".to_string(),
                    value: v,
                    reason: "must be in [0, 1) (1/K of seed 004 eq. 14; 0 = no minimum)"
                        .to_string(),
                });
            }
        }
        Ok(())
    }

    /// The request's limits over `cell_limits`.
    pub fn effective_limits(&self, cell_limits: &StateLimits) -> StateLimits {
        match &self.limits {
            Some(l) => l.apply(cell_limits),
            None => *cell_limits,
        }
    }

    fn check_initial(&self, limits: &StateLimits) -> Result<(), MillPlanError> {
        let [rpm, feed, g] = self.initial_state();
        for (name, v, r) in [
            ("initial.spindle_rpm [rpm]", rpm, limits.spindle_rpm),
            ("initial.feed [m/s]", feed, limits.feed),
            ("initial.g [rad]", g, limits.redundancy_angle),
        ] {
            if !(v >= r[0] && v <= r[1]) {
                return Err(MillPlanError::InvalidParameter {
                    name: name.to_string(),
                    value: v,
                    reason: format!("outside the limits [{}, {}]", r[0], r[1]),
                });
            }
        }
        Ok(())
    }
}

/// The nesting check of request documents, before any parsing.
fn check_depth(text: &str) -> Result<(), MillPlanError> {
    kerf_robot::document::check_depth(text).map_err(|reason| MillPlanError::InvalidConfig {
        name: "request".to_string(),
        reason,
    })
}
