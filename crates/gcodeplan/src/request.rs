//! [`GcodeRequest`]: a G-code plan request as a document (the `gcode_planner` node's text
//! topic, `kerf plan gcode`), checked and turned into the machine and settings to plan with.
//!
//! ```yaml
//! request_id: job-1
//! machine: laser-cutter        # or irb6660; default laser-cutter
//! program: "G21 G90\nM3\nG1 X20 F3000\nG1 Y20\nM5\n"   # or program_uri: /path/part.ngc
//! tolerance: 1.0e-4            # m, default 1e-4
//! ```
//!
//! The keys are the `kerf_msgs/msg/GcodeRequest` field names (`program_uri`, `has_limits`,
//! `max_feed`, …, `has_placement`, `start_positions`); the earlier names of this form are
//! kept (`program_file` for `program_uri`, `limits: {…}` for the flat limit fields, `origin` as
//! a list): [`RequestText`].
//!
//! Optional: `method` (`kerf`, `kerf-curvature`, `icr`, `ccr`, `nurbs`, `drls-net`), `feed_method` (`near-optimal`,
//! `constant-intervals`), `limits` (any of `max_feed`, `tangential_acceleration`,
//! `tangential_jerk`, `normal_acceleration`, `normal_jerk`, `chord_error`, `contour_error`,
//! each replacing the machine's default), `rapid_feed`, `origin` (the program's zero in the
//! machine's base frame), `redundancy_angle` (IRB 6660 only), `standoff_axis` (laser cutter
//! only), `time_budget`. Unknown fields are refused; every value given is checked, even one
//! that does not apply to the request's machine ([`GcodeRequest::check_numbers`], ranges in
//! [`RANGES`]).
//!
//! A `program_uri` (`program_file`) is read as a stream: a regular file of at most [`MAX_PROGRAM_BYTES`]
//! (a FIFO, device, socket or directory is refused before it is opened:
//! [`kerf_robot::file::open_regular`]).

use std::io::BufRead;
use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::error::GcodePlanError;
use crate::settings::PlanSettings;

/// The machines a program can be planned for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MachineKind {
    /// The laser cutter of seed 001 over a flat sheet ([`crate::LaserSheet`]).
    LaserCutter,
    /// The IRB 6660 of seed 004 on its milling plane ([`crate::MillingPlane`]).
    Irb6660,
}

impl MachineKind {
    /// The name in requests (`laser-cutter`, `irb6660`).
    pub fn name(self) -> &'static str {
        match self {
            MachineKind::LaserCutter => "laser-cutter",
            MachineKind::Irb6660 => "irb6660",
        }
    }

    /// Parses a name; empty is the laser cutter.
    ///
    /// # Errors
    /// [`GcodePlanError::InvalidSetting`] naming `machine` and the names known.
    pub fn parse(name: &str) -> Result<Self, GcodePlanError> {
        match name {
            "" | "laser-cutter" | "laser_cutter" => Ok(MachineKind::LaserCutter),
            "irb6660" => Ok(MachineKind::Irb6660),
            other => Err(GcodePlanError::InvalidRequest {
                field: format!("machine '{other}'"),
                reason: "unknown; use laser-cutter or irb6660".to_string(),
            }),
        }
    }

    /// The machine's default settings.
    pub fn default_settings(self) -> PlanSettings {
        match self {
            MachineKind::LaserCutter => PlanSettings::laser_cutter(),
            MachineKind::Irb6660 => PlanSettings::irb6660(),
        }
    }
}

/// The corner smoothing methods: kerf's quintic (its shape of least jerk norm; `kerf-curvature`:
/// of least κ_max), the baselines ICR (Zhao, Zhu and Ding 2013), CCR (Xu and Sun 2018) and seed
/// 003's NURBS corner by PSO ([`kerf_toolpath::CornerMethod`]), and seed 003's learned NURBS
/// corner with the swarm as its fallback (`drls-net`, [`crate::network`]).
pub const METHODS: &[&str] = &["kerf", "kerf-curvature", "icr", "ccr", "nurbs", "drls-net"];

/// The learned corner method's name ([`crate::PlanSettings::learned_corners`]).
pub const DRLS_NET: &str = "drls-net";

/// The feed planners ([`kerf_toolpath::FeedMethod`]).
pub const FEED_METHODS: &[&str] = &["near-optimal", "constant-intervals"];

/// The corner method named `name` (empty: kerf); for `drls-net`, its fallback (the NURBS
/// swarm: the method is [`crate::PlanSettings::learned_corners`]).
///
/// # Errors
/// [`GcodePlanError::InvalidSetting`] naming the method and the ones known.
pub fn corner_method(name: &str) -> Result<kerf_toolpath::CornerMethod, GcodePlanError> {
    use kerf_toolpath::{CornerMethod, NurbsSettings};
    match name {
        "" | "kerf" => Ok(CornerMethod::Kerf),
        "kerf-curvature" => Ok(CornerMethod::KerfCurvature),
        "icr" => Ok(CornerMethod::Icr),
        "ccr" => Ok(CornerMethod::Ccr),
        "nurbs" | DRLS_NET => Ok(CornerMethod::Nurbs(NurbsSettings::default())),
        other => Err(GcodePlanError::InvalidRequest {
            field: format!("method '{other}'"),
            reason: format!("unknown; use one of {}", METHODS.join(", ")),
        }),
    }
}

/// The feed method named `name` (empty: near-optimal).
///
/// # Errors
/// [`GcodePlanError::InvalidSetting`] naming the method and the ones known.
pub fn feed_method(name: &str) -> Result<kerf_toolpath::FeedMethod, GcodePlanError> {
    use kerf_toolpath::FeedMethod;
    match name {
        "" | "near-optimal" => Ok(FeedMethod::NearOptimal),
        "constant-intervals" => Ok(FeedMethod::ConstantIntervals),
        other => Err(GcodePlanError::InvalidRequest {
            field: format!("feed_method '{other}'"),
            reason: format!("unknown; use one of {}", FEED_METHODS.join(", ")),
        }),
    }
}

/// The largest program file read (bytes): 256 MiB, about 10⁷ lines of dense G01 code (a
/// program of 10⁶ lines is about 30 MB). A larger file is refused before it is read.
pub const MAX_PROGRAM_BYTES: u64 = 256 << 20;

/// The range of a request's number: its field (as in requests, with its unit), and the
/// smallest and largest values accepted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// The field, what it is and its unit, e.g. `limits.max_feed (max feed) [m/s]`.
    pub field: &'static str,
    /// The smallest value accepted.
    pub min: f64,
    /// The largest value accepted.
    pub max: f64,
}

impl Range {
    /// Checks `value`: finite and within \[min, max\] (so never denormal: every `min` of a
    /// positive quantity is far above 2.2·10⁻³⁰⁸).
    ///
    /// # Errors
    /// [`GcodePlanError::InvalidRequest`] naming the field, the value and the range.
    pub fn check(&self, value: f64) -> Result<(), GcodePlanError> {
        if value >= self.min && value <= self.max {
            return Ok(());
        }
        let (min, max) = (self.min, self.max);
        let reason = if self.min > 0.0 && !(value.is_finite() && value > 0.0) {
            format!("{value:e} must be finite and > 0, in [{min:e}, {max:e}]")
        } else if !value.is_finite() {
            format!("{value:e} must be finite, in [{min:e}, {max:e}]")
        } else {
            format!("{value:e} is outside [{min:e}, {max:e}]")
        };
        Err(GcodePlanError::InvalidRequest {
            field: self.field.to_string(),
            reason,
        })
    }
}

/// δ \[m\]: 0.1 µm to 10 mm.
pub const TOLERANCE: Range = Range {
    field: "tolerance [m]",
    min: 1e-7,
    max: 1e-2,
};

/// The ranges of a request's path limits and rapid feed (SI): what a real cell can mean. A
/// feed of 10⁻³⁰⁰ m/s is not a feed: it would make a trajectory of 10³⁰⁰ s.
pub const RANGES: [Range; 8] = [
    Range {
        field: "limits.max_feed (max feed) [m/s]",
        min: 1e-5,
        max: 10.0,
    },
    Range {
        field: "limits.tangential_acceleration (tangential acceleration) [m/s^2]",
        min: 1e-3,
        max: 1e3,
    },
    Range {
        field: "limits.tangential_jerk (tangential jerk) [m/s^3]",
        min: 1e-2,
        max: 1e5,
    },
    Range {
        field: "limits.normal_acceleration (normal acceleration) [m/s^2]",
        min: 1e-3,
        max: 1e3,
    },
    Range {
        field: "limits.normal_jerk (normal jerk) [m/s^3]",
        min: 1e-2,
        max: 1e5,
    },
    Range {
        field: "limits.chord_error (chord error) [m]",
        min: 1e-9,
        max: 1e-2,
    },
    Range {
        field: "limits.contour_error (contour error) [m]",
        min: 1e-9,
        max: 1e-2,
    },
    Range {
        field: "rapid_feed (G0 speed) [m/s]",
        min: 1e-5,
        max: 10.0,
    },
];

/// The program's zero, each coordinate \[m\]: within 100 m of the base.
pub const ORIGIN: Range = Range {
    field: "origin [m]",
    min: -100.0,
    max: 100.0,
};

/// The IRB 6660's redundancy angle g \[rad\]: one turn either way.
pub const REDUNDANCY_ANGLE: Range = Range {
    field: "redundancy_angle [rad]",
    min: -std::f64::consts::TAU,
    max: std::f64::consts::TAU,
};

/// The laser cutter's standoff axis q6 \[m\] (its joint limits are checked when the sheet is
/// placed): within 10 m.
pub const STANDOFF_AXIS: Range = Range {
    field: "standoff_axis [m]",
    min: -10.0,
    max: 10.0,
};

/// Path limits that replace the machine's defaults (SI units).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LimitOverrides {
    /// Largest cutting feed \[m/s\].
    pub max_feed: Option<f64>,
    /// Tangential acceleration \[m/s²\].
    pub tangential_acceleration: Option<f64>,
    /// Tangential jerk \[m/s³\].
    pub tangential_jerk: Option<f64>,
    /// Normal acceleration \[m/s²\] (seed 003 eq. 19).
    pub normal_acceleration: Option<f64>,
    /// Normal jerk \[m/s³\] (seed 003 eq. 21).
    pub normal_jerk: Option<f64>,
    /// Chord error per interpolation period \[m\] (seed 003 eq. 15–16).
    pub chord_error: Option<f64>,
    /// Servo contour error \[m\] (seed 003 eq. 17).
    pub contour_error: Option<f64>,
}

/// A request (module documentation). Written with the message's field names (`program_uri`);
/// read from text through [`RequestText`]: the
/// `kerf_msgs/msg/GcodeRequest` field names and the earlier names of this form.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(try_from = "RequestText")]
pub struct GcodeRequest {
    /// Any text; echoed in the answer.
    #[serde(default)]
    pub request_id: String,
    /// `laser-cutter` (default) or `irb6660`.
    #[serde(default)]
    pub machine: String,
    /// The program text (exactly one of `program` and `program_file`).
    #[serde(default)]
    pub program: Option<String>,
    /// A program file: a path, a local `file://` URI or `package://kerf/<path>`
    /// ([`kerf_robot::file::resolve_uri`]).
    #[serde(rename = "program_uri")]
    pub program_file: Option<String>,
    /// δ \[m\], default 1e-4.
    #[serde(default)]
    pub tolerance: Option<f64>,
    /// Corner smoothing method ([`METHODS`]), default `kerf`.
    #[serde(default)]
    pub method: Option<String>,
    /// Feed planner ([`FEED_METHODS`]), default `near-optimal`.
    #[serde(default)]
    pub feed_method: Option<String>,
    /// Path limits (as text: `limits: {max_feed: …}`, or the message's flat fields
    /// `max_feed`, … with an optional `has_limits: true`).
    #[serde(default)]
    pub limits: Option<LimitOverrides>,
    /// G0 speed \[m/s\].
    #[serde(default)]
    pub rapid_feed: Option<f64>,
    /// The program's zero in the machine's base frame \[m\].
    #[serde(default)]
    pub origin: Option<[f64; 3]>,
    /// The IRB 6660's redundancy angle g \[rad\] (default 0).
    #[serde(default)]
    pub redundancy_angle: Option<f64>,
    /// The laser cutter's standoff axis q6 \[m\].
    #[serde(default)]
    pub standoff_axis: Option<f64>,
    /// The plan's time budget \[s\]; none = the node's.
    #[serde(default)]
    pub time_budget: Option<f64>,
    /// Where the trajectory starts (issue 27): `current`, `none`, or a list of joint
    /// positions; left out = current when the planner node has the robot's joint state, else
    /// none. Resolved and framed by the planner-node harness, not by the planner.
    #[serde(default, skip_serializing_if = "kerf_approach::StartSpec::is_default")]
    pub start: kerf_approach::StartSpec,
}

/// A request document as read (YAML or JSON): every field of `kerf_msgs/msg/GcodeRequest` by
/// its message name, and the earlier names of the text form as aliases (`program_file` for
/// `program_uri`), checked into a [`GcodeRequest`] ([`GcodeRequest::try_from`]). Unknown keys
/// are refused.
///
/// Beyond the names, the text keeps its own meaning of a value: a key left out is "not given"
/// (a 0 is a value, checked against its range, where the message reads 0 as "not given"). The
/// message's groups are accepted both ways: the path limits as `limits: {max_feed: …}` or as
/// the flat `max_feed`, `tangential_acceleration`, … (`has_limits` optional; `false` with a
/// limit given, or `true` with none, is refused), the placement as `origin`,
/// `redundancy_angle`, `standoff_axis` (`has_placement` likewise), `origin` as `[x, y, z]` or
/// `{x: …, y: …, z: …}` (a `geometry_msgs/Point`), and the start as `start: current | none |
/// [q…]` or the message's pair `start: given` with `start_positions: [q…]`.
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RequestText {
    /// `request_id`.
    #[serde(default)]
    pub request_id: String,
    /// `machine`.
    #[serde(default)]
    pub machine: String,
    /// `program`.
    #[serde(default)]
    pub program: Option<String>,
    /// `program_uri` (alias `program_file`).
    #[serde(default, alias = "program_file")]
    pub program_uri: Option<String>,
    /// `tolerance` \[m\].
    #[serde(default)]
    pub tolerance: Option<f64>,
    /// `method`.
    #[serde(default)]
    pub method: Option<String>,
    /// `feed_method`.
    #[serde(default)]
    pub feed_method: Option<String>,
    /// `has_limits`: whether the path limits are given.
    #[serde(default)]
    pub has_limits: Option<bool>,
    /// `limits`: the path limits as one map (the text form's own name).
    #[serde(default)]
    pub limits: Option<LimitOverrides>,
    /// `max_feed` \[m/s\].
    #[serde(default)]
    pub max_feed: Option<f64>,
    /// `tangential_acceleration` \[m/s²\].
    #[serde(default)]
    pub tangential_acceleration: Option<f64>,
    /// `tangential_jerk` \[m/s³\].
    #[serde(default)]
    pub tangential_jerk: Option<f64>,
    /// `normal_acceleration` \[m/s²\].
    #[serde(default)]
    pub normal_acceleration: Option<f64>,
    /// `normal_jerk` \[m/s³\].
    #[serde(default)]
    pub normal_jerk: Option<f64>,
    /// `chord_error` \[m\].
    #[serde(default)]
    pub chord_error: Option<f64>,
    /// `contour_error` \[m\].
    #[serde(default)]
    pub contour_error: Option<f64>,
    /// `rapid_feed` \[m/s\].
    #[serde(default)]
    pub rapid_feed: Option<f64>,
    /// `has_placement`: whether the placement is given.
    #[serde(default)]
    pub has_placement: Option<bool>,
    /// `origin` \[m\].
    #[serde(default)]
    pub origin: Option<OriginText>,
    /// `redundancy_angle` \[rad\].
    #[serde(default)]
    pub redundancy_angle: Option<f64>,
    /// `standoff_axis` \[m\].
    #[serde(default)]
    pub standoff_axis: Option<f64>,
    /// `time_budget` \[s\].
    #[serde(default)]
    pub time_budget: Option<f64>,
    /// `start`.
    #[serde(default)]
    pub start: Option<StartText>,
    /// `start_positions` (with `start: given`).
    #[serde(default)]
    pub start_positions: Option<Vec<f64>>,
}

/// The program's zero as text: `[x, y, z]` or a `geometry_msgs/Point` `{x, y, z}` \[m\].
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(untagged, expecting = "origin as [x, y, z] or {x: …, y: …, z: …} (m)")]
pub enum OriginText {
    /// `[x, y, z]`.
    List([f64; 3]),
    /// `{x: …, y: …, z: …}`.
    Point(PointText),
}

/// A `geometry_msgs/Point` \[m\]: every coordinate given.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointText {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

/// The `start` field as text: a word (`current`, `none`, `given`, or empty) or a list of joint
/// positions.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(
    untagged,
    expecting = "start as \"current\", \"none\", \"given\" (with start_positions) or a list of joint positions"
)]
pub enum StartText {
    /// A word.
    Word(String),
    /// Joint positions.
    Positions(Vec<f64>),
}

impl TryFrom<RequestText> for GcodeRequest {
    type Error = String;

    /// The request a document asks for.
    ///
    /// # Errors
    /// A sentence naming the fields for limits given both as `limits` and as the flat fields,
    /// a `has_limits` or `has_placement` that contradicts the fields given, or a start that
    /// is not one of the forms above.
    fn try_from(t: RequestText) -> Result<Self, String> {
        let flat = LimitOverrides {
            max_feed: t.max_feed,
            tangential_acceleration: t.tangential_acceleration,
            tangential_jerk: t.tangential_jerk,
            normal_acceleration: t.normal_acceleration,
            normal_jerk: t.normal_jerk,
            chord_error: t.chord_error,
            contour_error: t.contour_error,
        };
        let any_flat = flat != LimitOverrides::default();
        if t.limits.is_some() && any_flat {
            return Err(
                "the path limits are given both as limits and as the message's fields \
                        (max_feed, tangential_acceleration, …): give one form"
                    .to_string(),
            );
        }
        let limits = t.limits.or(any_flat.then_some(flat));
        match (t.has_limits, limits.is_some()) {
            (Some(false), true) => {
                return Err(
                    "has_limits is false but path limits are given: set has_limits: \
                            true or leave the limits out"
                        .to_string(),
                )
            }
            (Some(true), false) => {
                return Err("has_limits is true but no path limit is given (max_feed, \
                            tangential_acceleration, …)"
                    .to_string())
            }
            _ => {}
        }
        let origin = t.origin.map(|o| match o {
            OriginText::List(p) => p,
            OriginText::Point(p) => [p.x, p.y, p.z],
        });
        let placed = origin.is_some() || t.redundancy_angle.is_some() || t.standoff_axis.is_some();
        match (t.has_placement, placed) {
            (Some(false), true) => {
                return Err("has_placement is false but origin, redundancy_angle or \
                            standoff_axis is given: set has_placement: true or leave them out"
                    .to_string())
            }
            (Some(true), false) => {
                return Err(
                    "has_placement is true but neither origin, redundancy_angle nor \
                            standoff_axis is given"
                        .to_string(),
                )
            }
            _ => {}
        }
        let start = match (t.start, t.start_positions) {
            (None, None) => kerf_approach::StartSpec::Default,
            (None, Some(q)) => kerf_approach::StartSpec::from_fields("", &q)?,
            (Some(StartText::Word(w)), q) => {
                kerf_approach::StartSpec::from_fields(&w, q.as_deref().unwrap_or(&[]))?
            }
            (Some(StartText::Positions(_)), Some(_)) => {
                return Err(
                    "start is a list of joint positions and start_positions is given: \
                            give the positions once (start: [q…], or start: given with \
                            start_positions)"
                        .to_string(),
                )
            }
            (Some(StartText::Positions(q)), None) if q.is_empty() => {
                return Err("start is an empty list: give one position per joint".to_string())
            }
            (Some(StartText::Positions(q)), None) => kerf_approach::StartSpec::Given(q),
        };
        Ok(GcodeRequest {
            request_id: t.request_id,
            machine: t.machine,
            program: t.program,
            program_file: t.program_uri,
            tolerance: t.tolerance,
            method: t.method,
            feed_method: t.feed_method,
            limits,
            rapid_feed: t.rapid_feed,
            origin,
            redundancy_angle: t.redundancy_angle,
            standoff_axis: t.standoff_axis,
            time_budget: t.time_budget,
            start,
        })
    }
}

/// Where the program comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum ProgramSource {
    /// The text itself.
    Text(String),
    /// A file.
    File(PathBuf),
}

impl GcodeRequest {
    /// Parses YAML (or JSON) text.
    ///
    /// # Errors
    /// [`GcodePlanError::InvalidSetting`] naming `request` with the parser's message.
    pub fn from_yaml_str(text: &str) -> Result<Self, GcodePlanError> {
        kerf_robot::document::from_yaml_or_json(text).map_err(|reason| {
            GcodePlanError::InvalidRequest {
                field: "request".to_string(),
                reason,
            }
        })
    }

    /// The machine.
    ///
    /// # Errors
    /// As [`MachineKind::parse`].
    pub fn machine_kind(&self) -> Result<MachineKind, GcodePlanError> {
        MachineKind::parse(&self.machine)
    }

    /// The program's source: a file is resolved by [`kerf_robot::file::resolve_uri`] (a path,
    /// a local `file://` URI or `package://kerf/<path>`).
    ///
    /// # Errors
    /// [`GcodePlanError::InvalidRequest`] for both or neither given, an empty one, or a
    /// reference that does not resolve (another URI scheme or host, a malformed `file://` or
    /// `package://` URI), naming it.
    pub fn source(&self) -> Result<ProgramSource, GcodePlanError> {
        let bad = |reason: String| GcodePlanError::InvalidRequest {
            field: "program".to_string(),
            reason,
        };
        match (&self.program, &self.program_file) {
            (Some(_), Some(_)) => Err(bad("give program or program_file, not both".to_string())),
            (None, None) => Err(bad("give program (text) or program_file".to_string())),
            (Some(text), None) => {
                if text.trim().is_empty() {
                    Err(bad("the program text is empty".to_string()))
                } else {
                    Ok(ProgramSource::Text(text.clone()))
                }
            }
            (None, Some(file)) => {
                if file.trim().is_empty() {
                    return Err(bad("program_file is empty".to_string()));
                }
                kerf_robot::file::resolve_uri(file)
                    .map(ProgramSource::File)
                    .map_err(|e| bad(e.to_string()))
            }
        }
    }

    /// The time budget, when the request asks for one.
    ///
    /// # Errors
    /// [`GcodePlanError::InvalidRequest`] naming `time_budget [s]` for a budget that is
    /// negative, not finite or over a day ([`kerf_budget::limit_from_seconds`]).
    pub fn time_limit(&self) -> Result<Option<std::time::Duration>, GcodePlanError> {
        match self.time_budget {
            None => Ok(None),
            Some(s) => kerf_budget::limit_from_seconds(s).map_err(|reason| {
                GcodePlanError::InvalidRequest {
                    field: "time_budget [s]".to_string(),
                    reason,
                }
            }),
        }
    }

    /// Checks every number the request gives against its range ([`TOLERANCE`], [`RANGES`],
    /// [`ORIGIN`], [`REDUNDANCY_ANGLE`], [`STANDOFF_AXIS`], the time budget), whether or not
    /// it applies to the request's machine: NaN, ±inf, denormal and absurd values are refused
    /// before anything is planned.
    ///
    /// # Errors
    /// [`GcodePlanError::InvalidRequest`] naming the first field out of range.
    pub fn check_numbers(&self) -> Result<(), GcodePlanError> {
        if let Some(t) = self.tolerance {
            TOLERANCE.check(t)?;
        }
        let l = self.limits.unwrap_or_default();
        let given = [
            l.max_feed,
            l.tangential_acceleration,
            l.tangential_jerk,
            l.normal_acceleration,
            l.normal_jerk,
            l.chord_error,
            l.contour_error,
            self.rapid_feed,
        ];
        for (range, value) in RANGES.iter().zip(given) {
            if let Some(v) = value {
                range.check(v)?;
            }
        }
        for v in self.origin.iter().flatten() {
            ORIGIN.check(*v)?;
        }
        if let Some(g) = self.redundancy_angle {
            REDUNDANCY_ANGLE.check(g)?;
        }
        if let Some(q6) = self.standoff_axis {
            STANDOFF_AXIS.check(q6)?;
        }
        self.time_limit()?;
        Ok(())
    }

    /// The settings to plan with: the machine's defaults with the request's values, checked.
    ///
    /// # Errors
    /// [`GcodePlanError::InvalidSetting`] naming the first bad field, an unknown method, or a
    /// field of the other machine.
    pub fn settings(&self) -> Result<PlanSettings, GcodePlanError> {
        self.check_numbers()?;
        let kind = self.machine_kind()?;
        let mut s = kind.default_settings();
        if let Some(t) = self.tolerance {
            s.tolerance = t;
        }
        let method = self.method.as_deref().unwrap_or("");
        s.corner_method = corner_method(method)?;
        s.learned_corners = method == DRLS_NET;
        s.feed_method = feed_method(self.feed_method.as_deref().unwrap_or(""))?;
        if let Some(l) = &self.limits {
            let c = &mut s.limits.curvature;
            set(&mut c.feed, l.max_feed);
            set(
                &mut s.limits.tangential_acceleration,
                l.tangential_acceleration,
            );
            set(&mut s.limits.tangential_jerk, l.tangential_jerk);
            let c = &mut s.limits.curvature;
            set(&mut c.normal_acceleration, l.normal_acceleration);
            set(&mut c.normal_jerk, l.normal_jerk);
            set(&mut c.chord_error, l.chord_error);
            if let (Some(e), Some(servo)) = (l.contour_error, c.servo.as_mut()) {
                servo.contour_error = e;
            }
        }
        if let Some(r) = self.rapid_feed {
            s.rapid_feed = r;
        }
        let other =
            |field: &str, value: f64, machine: MachineKind| GcodePlanError::InvalidSetting {
                name: field.to_string(),
                value,
                reason: format!("applies to the other machine, not {}", machine.name()),
            };
        match kind {
            MachineKind::LaserCutter => {
                if let Some(g) = self.redundancy_angle {
                    return Err(other("redundancy_angle [rad]", g, kind));
                }
            }
            MachineKind::Irb6660 => {
                if let Some(q6) = self.standoff_axis {
                    return Err(other("standoff_axis [m]", q6, kind));
                }
            }
        }
        s.validate()?;
        Ok(s)
    }
}

fn set(field: &mut f64, value: Option<f64>) {
    if let Some(v) = value {
        *field = v;
    }
}

/// A machine loaded once (its URDF, limits and cell), from which each request's machine is
/// placed (its origin, g or standoff).
#[derive(Debug, Clone)]
pub enum MachineBase {
    /// The laser cutter.
    Laser(Box<kerf_mjto::LaserMachine>),
    /// The IRB 6660 milling cell.
    Irb(Box<kerf_mill::MillCell>),
}

impl MachineBase {
    /// Loads the shipped machine of `kind`.
    ///
    /// # Errors
    /// [`GcodePlanError::InvalidSetting`] naming `machine` when its files cannot be loaded.
    pub fn load(kind: MachineKind) -> Result<Self, GcodePlanError> {
        let bad = |reason: String| GcodePlanError::InvalidRequest {
            field: "machine".to_string(),
            reason,
        };
        match kind {
            MachineKind::LaserCutter => kerf_mjto::LaserMachine::default_machine()
                .map(|m| MachineBase::Laser(Box::new(m)))
                .map_err(|e| bad(e.to_string())),
            MachineKind::Irb6660 => kerf_mill::MillCell::default_cell()
                .map(|c| MachineBase::Irb(Box::new(c)))
                .map_err(|e| bad(e.to_string())),
        }
    }

    /// Which machine it is.
    pub fn kind(&self) -> MachineKind {
        match self {
            MachineBase::Laser(_) => MachineKind::LaserCutter,
            MachineBase::Irb(_) => MachineKind::Irb6660,
        }
    }

    /// The robot model.
    pub fn robot(&self) -> &kerf_robot::RobotModel {
        match self {
            MachineBase::Laser(m) => m.robot(),
            MachineBase::Irb(c) => c.robot(),
        }
    }

    /// The machine placed as `request` asks.
    ///
    /// # Errors
    /// [`GcodePlanError::InvalidSetting`] for a request naming another machine (a node
    /// plans for one), or a bad origin, g or standoff.
    pub fn place(&self, request: &GcodeRequest) -> Result<Box<dyn crate::Machine>, GcodePlanError> {
        let asked = request.machine_kind()?;
        if asked != self.kind() {
            return Err(GcodePlanError::InvalidRequest {
                field: format!("machine '{}'", request.machine),
                reason: format!(
                    "this planner plans for {} (start one with machine {} for the other)",
                    self.kind().name(),
                    asked.name()
                ),
            });
        }
        match self {
            MachineBase::Laser(m) => Ok(Box::new(crate::LaserSheet::new(
                (**m).clone(),
                request
                    .origin
                    .unwrap_or(crate::machine::laser::DEFAULT_SHEET_ORIGIN),
                request
                    .standoff_axis
                    .unwrap_or(crate::machine::laser::DEFAULT_STANDOFF_AXIS),
            )?)),
            MachineBase::Irb(cell) => {
                let origin = match request.origin {
                    Some(o) => o,
                    None => {
                        let p =
                            cell.path()
                                .point(0.0)
                                .map_err(|e| GcodePlanError::InvalidRequest {
                                    field: "machine".to_string(),
                                    reason: e.to_string(),
                                })?;
                        [p.x, p.y, p.z]
                    }
                };
                Ok(Box::new(crate::MillingPlane::new(
                    (**cell).clone(),
                    origin,
                    request.redundancy_angle.unwrap_or(0.0),
                )?))
            }
        }
    }
}

/// Plans a request on `base` (the program read from its text or streamed from its file).
///
/// # Errors
/// The request's own errors ([`GcodeRequest::settings`], [`GcodeRequest::source`],
/// [`MachineBase::place`]), an unreadable file, and [`crate::plan_program`]'s.
pub fn plan_request(
    request: &GcodeRequest,
    base: &MachineBase,
    budget: &kerf_budget::Budget,
) -> Result<crate::GcodePlan, GcodePlanError> {
    plan_request_within(request, base, budget, None)
}

/// [`plan_request`] with at most `max_points` trajectory points (a node's answer size),
/// refused with [`GcodePlanError::TooManyPoints`] as soon as the plan needs more.
///
/// # Errors
/// As [`plan_request`].
pub fn plan_request_within(
    request: &GcodeRequest,
    base: &MachineBase,
    budget: &kerf_budget::Budget,
    max_points: Option<usize>,
) -> Result<crate::GcodePlan, GcodePlanError> {
    let mut settings = request.settings()?;
    if let Some(m) = max_points {
        settings.max_points = settings.max_points.min(m);
    }
    let machine = base.place(request)?;
    match request.source()? {
        ProgramSource::Text(text) => {
            crate::plan_program(text.as_bytes(), machine.as_ref(), &settings, budget)
        }
        ProgramSource::File(path) => {
            crate::plan_program(open_program(&path)?, machine.as_ref(), &settings, budget)
        }
    }
}

/// Opens a program file as a stream: a regular file of at most [`MAX_PROGRAM_BYTES`], refused
/// before it is opened when it is a FIFO, a device, a socket or a directory (opening a FIFO
/// would block), and failing while it is read if it grows past the cap
/// ([`kerf_robot::file::open_regular`]).
///
/// # Errors
/// [`GcodePlanError::InvalidRequest`] naming `program_file` and the path.
pub fn open_program(path: &std::path::Path) -> Result<impl BufRead, GcodePlanError> {
    kerf_robot::file::open_regular(path, MAX_PROGRAM_BYTES).map_err(|reason| {
        GcodePlanError::InvalidRequest {
            field: format!("program_file {}", path.display()),
            reason: format!(
                "{reason} (programs are read from regular files of at most {} bytes)",
                MAX_PROGRAM_BYTES
            ),
        }
    })
}

/// [`plan_request_within`] with the program read from `program` (standard input, a stream
/// the caller capped) instead of the request's own: the request must give neither `program`
/// nor `program_file`.
///
/// # Errors
/// As [`plan_request_within`]; [`GcodePlanError::InvalidRequest`] naming `program` when the
/// request gives one.
pub fn plan_request_reading<R: BufRead>(
    request: &GcodeRequest,
    base: &MachineBase,
    budget: &kerf_budget::Budget,
    max_points: Option<usize>,
    program: R,
) -> Result<crate::GcodePlan, GcodePlanError> {
    if request.program.is_some() || request.program_file.is_some() {
        return Err(GcodePlanError::InvalidRequest {
            field: "program".to_string(),
            reason: "the program is read from the stream given; the request must not name one"
                .to_string(),
        });
    }
    let mut settings = request.settings()?;
    if let Some(m) = max_points {
        settings.max_points = settings.max_points.min(m);
    }
    let machine = base.place(request)?;
    crate::plan_program(program, machine.as_ref(), &settings, budget)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> GcodeRequest {
        GcodeRequest::from_yaml_str(text).unwrap_or_else(|e| panic!("{text:?}: {e}"))
    }

    fn refused(text: &str) -> String {
        match GcodeRequest::from_yaml_str(text) {
            Ok(r) => panic!("{text:?} read as {r:?}"),
            Err(e) => e.to_string(),
        }
    }

    /// Issue 30, item 3: every `GcodeRequest` message field name is read, and the earlier
    /// names give the same request.
    #[test]
    fn the_message_names_and_the_earlier_names_give_the_same_request() {
        let message = read(
            "request_id: r\nmachine: irb6660\nprogram_uri: package://kerf/a.ngc\n\
             tolerance: 2.0e-4\nmethod: icr\nfeed_method: constant-intervals\n\
             has_limits: true\nmax_feed: 0.05\ntangential_acceleration: 0.5\n\
             tangential_jerk: 10.0\nnormal_acceleration: 0.6\nnormal_jerk: 12.0\n\
             chord_error: 1.0e-5\ncontour_error: 4.0e-5\nrapid_feed: 0.1\n\
             has_placement: true\norigin: {x: 1.4, y: -0.3, z: 1.7}\nredundancy_angle: 0.2\n\
             time_budget: 5.0\nstart: given\nstart_positions: [0, 0.1, 0.2, 0, 0.3, 0]\n",
        );
        let earlier = read(
            "request_id: r\nmachine: irb6660\nprogram_file: package://kerf/a.ngc\n\
             tolerance: 2.0e-4\nmethod: icr\nfeed_method: constant-intervals\n\
             limits: {max_feed: 0.05, tangential_acceleration: 0.5, tangential_jerk: 10.0,\n\
             \x20 normal_acceleration: 0.6, normal_jerk: 12.0, chord_error: 1.0e-5,\n\
             \x20 contour_error: 4.0e-5}\nrapid_feed: 0.1\norigin: [1.4, -0.3, 1.7]\n\
             redundancy_angle: 0.2\ntime_budget: 5.0\nstart: [0, 0.1, 0.2, 0, 0.3, 0]\n",
        );
        assert_eq!(message, earlier);
        assert_eq!(
            message.program_file.as_deref(),
            Some("package://kerf/a.ngc")
        );
        assert_eq!(message.limits.and_then(|l| l.normal_jerk), Some(12.0));
        assert_eq!(message.origin, Some([1.4, -0.3, 1.7]));
        assert_eq!(
            message.start,
            kerf_approach::StartSpec::Given(vec![0.0, 0.1, 0.2, 0.0, 0.3, 0.0])
        );
        // JSON, with the message's names.
        let json = read(r#"{"program_uri": "package://kerf/a.ngc", "start": "none"}"#);
        assert_eq!(json.program_file.as_deref(), Some("package://kerf/a.ngc"));
        assert_eq!(json.start, kerf_approach::StartSpec::None);
        // Flags false with nothing of their group: the machine's.
        let r = read("program: G1 X1 F600\nhas_limits: false\nhas_placement: false\n");
        assert_eq!((r.limits, r.origin), (None, None));
    }

    /// An unknown key is refused, as are the two spellings of one field together and flags
    /// that contradict the fields given.
    #[test]
    fn unknown_keys_and_contradictions_are_refused() {
        for (text, says) in [
            (
                "program: G1\nprogram_path: x\n",
                "unknown field `program_path`",
            ),
            (
                "program: G1\nlimits: {max_speed: 1}\n",
                "unknown field `max_speed`",
            ),
            ("program: G1\norigin: {x: 1, y: 2}\n", "origin as [x, y, z]"),
            ("program: G1\norigin: [1, 2]\n", "origin as [x, y, z]"),
            ("program_uri: a\nprogram_file: b\n", "duplicate field"),
            (
                "program: G1\nlimits: {max_feed: 0.1}\nmax_feed: 0.1\n",
                "give one form",
            ),
            (
                "program: G1\nhas_limits: false\nmax_feed: 0.1\n",
                "has_limits is false",
            ),
            ("program: G1\nhas_limits: true\n", "has_limits is true"),
            (
                "program: G1\nhas_placement: false\norigin: [0, 0, 0]\n",
                "has_placement is false",
            ),
            (
                "program: G1\nhas_placement: true\n",
                "has_placement is true",
            ),
            ("program: G1\nstart: given\n", "start_positions is empty"),
            (
                "program: G1\nstart: [1, 2]\nstart_positions: [1, 2]\n",
                "give the positions once",
            ),
            ("program: G1\nstart_positions: [1, 2]\n", "start"),
            ("program: G1\nstart: []\n", "empty list"),
            ("program: G1\nstart: sometimes\n", "sometimes"),
        ] {
            let e = refused(text);
            assert!(e.contains(says), "{text:?}: {e}");
        }
    }
}
