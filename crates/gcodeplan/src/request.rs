//! [`GcodeRequest`]: a G-code plan request as a document (the `gcode_planner` node's text
//! topic, `kerf plan gcode`), checked and turned into the machine and settings to plan with.
//!
//! ```yaml
//! request_id: job-1
//! machine: laser-cutter        # or irb6660; default laser-cutter
//! program: "G21 G90\nM3\nG1 X20 F3000\nG1 Y20\nM5\n"   # or program_file: /path/part.ngc
//! tolerance: 1.0e-4            # m, default 1e-4
//! ```
//!
//! Optional: `method` (`kerf`, `kerf-curvature`, `icr`, `ccr`, `nurbs`), `feed_method` (`near-optimal`,
//! `constant-intervals`), `limits` (any of `max_feed`, `tangential_acceleration`,
//! `tangential_jerk`, `normal_acceleration`, `normal_jerk`, `chord_error`, `contour_error`,
//! each replacing the machine's default), `rapid_feed`, `origin` (the program's zero in the
//! machine's base frame), `redundancy_angle` (IRB 6660 only), `standoff_axis` (laser cutter
//! only), `time_budget`. Unknown fields are refused; every value given is checked, even one
//! that does not apply to the request's machine ([`GcodeRequest::check_numbers`], ranges in
//! [`RANGES`]).
//!
//! A `program_file` is read as a stream: a regular file of at most [`MAX_PROGRAM_BYTES`]
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
/// 003's NURBS corner by PSO ([`kerf_toolpath::CornerMethod`]).
pub const METHODS: &[&str] = &["kerf", "kerf-curvature", "icr", "ccr", "nurbs"];

/// The feed planners ([`kerf_toolpath::FeedMethod`]).
pub const FEED_METHODS: &[&str] = &["near-optimal", "constant-intervals"];

/// The corner method named `name` (empty: kerf).
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
        "nurbs" => Ok(CornerMethod::Nurbs(NurbsSettings::default())),
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

/// A request (module documentation).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
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
    #[serde(default)]
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
    /// Path limits.
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
        s.corner_method = corner_method(self.method.as_deref().unwrap_or(""))?;
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
