//! [`frame`]: a process framed by its approach and its retract, the whole of "every plan starts
//! where the robot is" for one planner answer (issue 27, item 1).
//!
//! ```text
//! start ──approach (direct, or via a safe pose; clearance c)──▶ pre
//!       ──lead-in along the tool axis (process contact left out; lead clearance)──▶ first
//!       ══ process (unchanged) ══▶ last
//!       ──lead-out along the tool axis (process contact left out)──▶ post
//!       [──retract to the safe pose (clearance c)──▶ safe pose]
//! ```
//!
//! `pre` is the first process configuration backed off `lead_distance` along the tool axis,
//! `post` the last one backed off `retract_distance`. The process's first and last points are
//! in working contact with the part (a laser nozzle 0.84 mm from the sheet, a milling cutter in
//! the stock), so no move ending there can keep the approach's clearance: the lead-in and
//! lead-out are checked against the world with the process contact left out
//! ([`Surroundings::clearance`] with `process = true`) and keep the lead clearance, at most half
//! the process's own clearance at its ends. Every other move keeps the full clearance against
//! everything. Each move is certified by conservative advancement ([`crate::ClearanceCheck`]).

use crate::{
    ApproachError, ApproachPlanner, ApproachSettings, CheckedMove, Clearance, ClosestSample,
    JointLimit, Route, Sample, Stitched, Timeline, WaypointMove,
};

/// What a robot's surroundings tell the framing: exact distances and the tool axis.
///
/// Implemented by each planner for its robot and world (the laser head against the workpiece
/// mesh, the milling robot's links and tool against the cell objects).
pub trait Surroundings: Send + Sync {
    /// The exact signed distance (m) from the robot at `q` to the nearest obstacle, and its
    /// name ([`Clearance`]). With `process`, the tool's working contact with the workpiece
    /// (the pairs the process itself brings into contact) is left out: the lead-in and
    /// lead-out are checked so.
    fn clearance(&self, q: &[f64], process: bool) -> Clearance;

    /// Per joint: a bound (m per rad, or m per m) on how far any point of the robot that
    /// [`Self::clearance`] measures moves per unit of that joint.
    fn lipschitz(&self) -> Vec<f64>;

    /// The configuration with the tool `distance` m further back along its axis, away from
    /// the part, at the same tool orientation.
    ///
    /// # Errors
    /// An [`ApproachError`] when no such configuration exists (out of limits, no IK).
    fn back_off(&self, q: &[f64], distance: f64) -> Result<Vec<f64>, ApproachError>;
}

/// One of the framing's moves, named in errors.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Start → backed-off first process point (direct or via a safe pose).
    Approach,
    /// Backed-off first process point → first process point, along the tool axis.
    LeadIn,
    /// Last process point → backed off along the tool axis.
    LeadOut,
    /// Backed-off last process point → the retract safe pose.
    Retract,
}

impl std::fmt::Display for Stage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Stage::Approach => "approach",
            Stage::LeadIn => "lead-in along the tool axis",
            Stage::LeadOut => "lead-out along the tool axis",
            Stage::Retract => "retract to the safe pose",
        })
    }
}

/// Default approach clearance (m).
pub const DEFAULT_CLEARANCE: f64 = 0.01;
/// Default distance (m) along the tool axis over which the lead-in reaches the first point.
pub const DEFAULT_LEAD_DISTANCE: f64 = 0.03;
/// Default clearance (m) of the lead-in and lead-out (process contact left out); it is lowered
/// to half the process's own clearance at its first and last points when that is smaller.
pub const DEFAULT_LEAD_CLEARANCE: f64 = 0.0005;
/// Default retract distance (m) along the tool axis.
pub const DEFAULT_RETRACT_DISTANCE: f64 = 0.05;

/// How a process is framed ([`FrameSettings::builder`]).
#[derive(Debug, Clone, PartialEq)]
pub struct FrameSettings {
    clearance: f64,
    control_period: f64,
    safe_poses: Vec<Vec<f64>>,
    max_duration: f64,
    lead_distance: f64,
    lead_clearance: f64,
    retract_distance: f64,
    retract_safe_pose: Option<Vec<f64>>,
}

impl Default for FrameSettings {
    /// The defaults of [`FrameSettings::builder`].
    fn default() -> Self {
        Self {
            clearance: DEFAULT_CLEARANCE,
            control_period: crate::settings::DEFAULT_CONTROL_PERIOD,
            safe_poses: Vec::new(),
            max_duration: crate::settings::DEFAULT_MAX_DURATION,
            lead_distance: DEFAULT_LEAD_DISTANCE,
            lead_clearance: DEFAULT_LEAD_CLEARANCE,
            retract_distance: DEFAULT_RETRACT_DISTANCE,
            retract_safe_pose: None,
        }
    }
}

impl FrameSettings {
    /// A builder with the defaults ([`DEFAULT_CLEARANCE`], [`DEFAULT_LEAD_DISTANCE`],
    /// [`DEFAULT_LEAD_CLEARANCE`], [`DEFAULT_RETRACT_DISTANCE`], the approach crate's control
    /// period and longest move, no safe pose).
    pub fn builder() -> FrameSettingsBuilder {
        FrameSettingsBuilder::default()
    }

    /// Clearance (m) of the approach and of the retract to the safe pose.
    pub fn clearance(&self) -> f64 {
        self.clearance
    }

    /// Control period (s): moves last whole periods and are sampled at it.
    pub fn control_period(&self) -> f64 {
        self.control_period
    }

    /// Safe poses the approach may pass through when the direct move is not clear.
    pub fn safe_poses(&self) -> &[Vec<f64>] {
        &self.safe_poses
    }

    /// Longest single move (s).
    pub fn max_duration(&self) -> f64 {
        self.max_duration
    }

    /// Lead-in distance (m) along the tool axis.
    pub fn lead_distance(&self) -> f64 {
        self.lead_distance
    }

    /// Largest clearance (m) the lead-in and lead-out keep.
    pub fn lead_clearance(&self) -> f64 {
        self.lead_clearance
    }

    /// Retract distance (m) along the tool axis.
    pub fn retract_distance(&self) -> f64 {
        self.retract_distance
    }

    /// The safe pose the retract ends at after the lead-out, if any.
    pub fn retract_safe_pose(&self) -> Option<&[f64]> {
        self.retract_safe_pose.as_deref()
    }

    /// Checks every configuration of the settings against the robot's position limits.
    ///
    /// # Errors
    /// [`ApproachError::OutOfLimits`] (and the other configuration errors) naming the safe
    /// pose: a safe pose the robot cannot reach.
    pub fn check_reach(&self, limits: &[JointLimit]) -> Result<(), ApproachError> {
        for (i, pose) in self.safe_poses.iter().enumerate() {
            crate::limits::check_configuration(crate::Role::SafePose(i), pose, limits)?;
        }
        if let Some(pose) = &self.retract_safe_pose {
            crate::limits::check_configuration(crate::Role::RetractTarget(0), pose, limits)?;
        }
        Ok(())
    }
}

/// Builder of [`FrameSettings`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FrameSettingsBuilder {
    clearance: Option<f64>,
    control_period: Option<f64>,
    safe_poses: Vec<Vec<f64>>,
    max_duration: Option<f64>,
    lead_distance: Option<f64>,
    lead_clearance: Option<f64>,
    retract_distance: Option<f64>,
    retract_safe_pose: Option<Vec<f64>>,
}

impl FrameSettingsBuilder {
    /// Approach clearance (m), > 0.
    pub fn clearance(mut self, metres: f64) -> Self {
        self.clearance = Some(metres);
        self
    }
    /// Control period (s), > 0.
    pub fn control_period(mut self, seconds: f64) -> Self {
        self.control_period = Some(seconds);
        self
    }
    /// Safe poses of the approach, tried in order.
    pub fn safe_poses(mut self, poses: Vec<Vec<f64>>) -> Self {
        self.safe_poses = poses;
        self
    }
    /// Longest single move (s), > 0.
    pub fn max_duration(mut self, seconds: f64) -> Self {
        self.max_duration = Some(seconds);
        self
    }
    /// Lead-in distance (m), > 0.
    pub fn lead_distance(mut self, metres: f64) -> Self {
        self.lead_distance = Some(metres);
        self
    }
    /// Largest lead clearance (m), > 0.
    pub fn lead_clearance(mut self, metres: f64) -> Self {
        self.lead_clearance = Some(metres);
        self
    }
    /// Retract distance (m) along the tool axis, > 0.
    pub fn retract_distance(mut self, metres: f64) -> Self {
        self.retract_distance = Some(metres);
        self
    }
    /// Safe pose the retract ends at (after the lead-out).
    pub fn retract_safe_pose(mut self, pose: Option<Vec<f64>>) -> Self {
        self.retract_safe_pose = pose;
        self
    }

    /// Validates and builds.
    ///
    /// # Errors
    /// [`ApproachError::InvalidSetting`] naming the field: a number not finite and > 0, a
    /// pose value not finite.
    pub fn build(self) -> Result<FrameSettings, ApproachError> {
        let d = crate::settings::DEFAULT_CONTROL_PERIOD;
        let settings = FrameSettings {
            clearance: positive("clearance", self.clearance.unwrap_or(DEFAULT_CLEARANCE))?,
            control_period: positive("control_period", self.control_period.unwrap_or(d))?,
            max_duration: positive(
                "max_duration",
                self.max_duration
                    .unwrap_or(crate::settings::DEFAULT_MAX_DURATION),
            )?,
            lead_distance: positive(
                "lead_distance",
                self.lead_distance.unwrap_or(DEFAULT_LEAD_DISTANCE),
            )?,
            lead_clearance: positive(
                "lead_clearance",
                self.lead_clearance.unwrap_or(DEFAULT_LEAD_CLEARANCE),
            )?,
            retract_distance: positive(
                "retract_distance",
                self.retract_distance.unwrap_or(DEFAULT_RETRACT_DISTANCE),
            )?,
            safe_poses: self.safe_poses,
            retract_safe_pose: self.retract_safe_pose,
        };
        let poses = settings
            .safe_poses
            .iter()
            .enumerate()
            .map(|(i, p)| (format!("safe_poses[{i}]"), p))
            .chain(
                settings
                    .retract_safe_pose
                    .iter()
                    .map(|p| ("retract_safe_pose".to_string(), p)),
            );
        for (name, pose) in poses {
            if let Some((j, &v)) = pose.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                return Err(ApproachError::InvalidSetting {
                    field: format!("{name}[{j}]"),
                    value: v,
                    requirement: "must be finite",
                });
            }
        }
        Ok(settings)
    }
}

fn positive(field: &str, value: f64) -> Result<f64, ApproachError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(ApproachError::InvalidSetting {
            field: field.to_string(),
            value,
            requirement: "must be finite and > 0",
        })
    }
}

/// A framed process: the stitched timeline and what each move did.
#[derive(Debug, Clone, PartialEq)]
pub struct Framed {
    /// Approach, process and retract samples, and the process's time marks.
    pub timeline: Timeline,
    /// The approach's route (direct, or via safe pose `i`: the configured safe poses first,
    /// then the points of [`AUTO_VIA_DISTANCES`] on the tool axis above the first point).
    pub approach_route: Route,
    /// With a route via an automatic tool-axis point: its distance (m) above the first point.
    pub auto_via: Option<f64>,
    /// Length (m, the first three joints' displacement) of the lead-in actually used.
    pub lead_in_distance: f64,
    /// Length (m) of the lead-out actually used.
    pub lead_out_distance: f64,
    /// Whether the retract ends at the retract safe pose (else at the tool-axis back-off).
    pub retract_to_safe_pose: bool,
    /// Closest configuration of the approach (full clearance).
    pub approach_closest: ClosestSample,
    /// Closest configuration of the lead-in and lead-out (process contact left out).
    pub lead_closest: ClosestSample,
    /// The lead clearance used (m).
    pub lead_clearance: f64,
}

/// Frames a process: the approach from `start`, the process unchanged, the retract.
///
/// # Arguments
/// * `start` – the robot's configuration, at rest.
/// * `process` – the process samples, starting and ending at rest.
/// * `limits` – the robot's joint limits (the order of every configuration).
/// * `world` – distances and the tool axis ([`Surroundings`]).
/// * `settings` – clearances, distances, safe poses.
///
/// # Returns
/// The [`Framed`] process; [`ApproachError::InStage`] naming the move that failed around the
/// crate's errors ([`ApproachError::InCollision`] for a start too close to an obstacle,
/// [`ApproachError::NoApproach`] naming the obstacle, …); [`ApproachError::EmptyProcess`].
///
/// # Performance
/// Dominated by the clearance queries: about one per control period of each move, more where
/// a move passes close to an obstacle ([`crate::ClearanceCheck::check`]).
pub fn frame(
    start: &[f64],
    process: Vec<Sample>,
    limits: &[JointLimit],
    world: &dyn Surroundings,
    settings: &FrameSettings,
) -> Result<Framed, ApproachError> {
    let (first, last) = match (process.first(), process.last()) {
        (Some(f), Some(l)) => (f.q.clone(), l.q.clone()),
        _ => return Err(ApproachError::EmptyProcess),
    };
    let full = |q: &[f64]| world.clearance(q, false);
    let contact = |q: &[f64]| world.clearance(q, true);
    let lipschitz = world.lipschitz();
    let in_stage = |stage: Stage| move |e: ApproachError| e.in_stage(stage);

    // The lead clearance: at most half the process's own at its ends (process contact left
    // out), so that the lead-in can end where the process starts.
    let ends = contact(&first).distance.min(contact(&last).distance);
    let lead_clearance = settings.lead_clearance.min(0.5 * ends);
    if lead_clearance.is_nan() || lead_clearance <= 0.0 {
        let (role, q) = if contact(&first).distance <= contact(&last).distance {
            (crate::Role::Goal, &first)
        } else {
            (crate::Role::RetractStart, &last)
        };
        let c = contact(q);
        return Err(ApproachError::InCollision {
            role,
            obstacle: c.obstacle,
            distance: c.distance,
            clearance: 0.0,
        }
        .in_stage(Stage::LeadIn));
    }
    let approach_settings = |clearance: f64, safe: Vec<Vec<f64>>| {
        ApproachSettings::builder()
            .clearance(clearance)
            .control_period(settings.control_period)
            .lipschitz(lipschitz.clone())
            .safe_poses(safe)
            .max_duration(settings.max_duration)
            .build()
    };
    let lead = ApproachPlanner::new(
        approach_settings(lead_clearance, Vec::new())?,
        limits.to_vec(),
        &contact,
    )?;

    // The lead-in starts, and the retract ends, where the robot keeps the full clearance: the
    // tool-axis distance is doubled (at most LEAD_DOUBLINGS times) until it does, so that the
    // approach can end there and the next plan can start there.
    let pre = clear_back_off(
        world,
        &full,
        &first,
        settings.lead_distance,
        settings.clearance,
    )
    .map_err(in_stage(Stage::LeadIn))?;
    let post = clear_back_off(
        world,
        &full,
        &last,
        settings.retract_distance,
        settings.clearance,
    )
    .map_err(in_stage(Stage::LeadOut))?;
    // Via poses: the configured safe poses, then points on the tool axis farther above the
    // first process point (the "safe pose above the part" of a cell without one configured).
    let mut via = settings.safe_poses.clone();
    for d in AUTO_VIA_DISTANCES {
        if let Ok(q) = world.back_off(&first, d) {
            via.push(q);
        }
    }
    let free = ApproachPlanner::new(
        approach_settings(settings.clearance, via)?,
        limits.to_vec(),
        &full,
    )?;
    let approach = free
        .approach(start, &pre)
        .map_err(in_stage(Stage::Approach))?;
    let lead_in = lead
        .approach(&pre, &first)
        .map_err(in_stage(Stage::LeadIn))?;
    let lead_out = lead
        .retract(&last, &[post.as_slice()])
        .map_err(in_stage(Stage::LeadOut))?;
    let to_safe = match &settings.retract_safe_pose {
        Some(pose) => Some(
            free.retract(&post, &[pose.as_slice()])
                .map_err(in_stage(Stage::Retract))?,
        ),
        None => None,
    };
    let approach_route = approach.route;
    let configured = settings.safe_poses.len();
    let auto_via = match approach.route {
        Route::ViaSafePose(i) if i >= configured => AUTO_VIA_DISTANCES.get(i - configured).copied(),
        _ => None,
    };
    let approach_closest = approach.closest.clone();
    let lead_closest = closer(&lead_in.closest, &lead_out.closest).clone();
    let retract_to_safe_pose = to_safe.is_some();
    let stitched = Stitched {
        approach: joined(&[&approach, &lead_in])?,
        process,
        retract: match &to_safe {
            Some(s) => joined(&[&lead_out, s])?,
            None => lead_out.path,
        },
    };
    Ok(Framed {
        timeline: stitched.timeline(settings.control_period)?,
        approach_route,
        auto_via,
        lead_in_distance: distance_between(&pre, &first),
        lead_out_distance: distance_between(&post, &last),
        retract_to_safe_pose,
        approach_closest,
        lead_closest,
        lead_clearance,
    })
}

/// How many times the tool-axis distance of the lead-in or lead-out is doubled, at most, to
/// reach a configuration with the full clearance.
pub const LEAD_DOUBLINGS: u32 = 3;

/// Distances (m) along the tool axis above the first process point of the via points the
/// approach tries after the configured safe poses.
pub const AUTO_VIA_DISTANCES: [f64; 2] = [0.15, 0.3];

/// The configuration `distance` back along the tool axis from `q`, doubled up to
/// [`LEAD_DOUBLINGS`] times until it keeps `clearance` by `full`.
fn clear_back_off(
    world: &dyn Surroundings,
    full: &dyn Fn(&[f64]) -> Clearance,
    q: &[f64],
    distance: f64,
    clearance: f64,
) -> Result<Vec<f64>, ApproachError> {
    let mut d = distance;
    let mut last = None;
    for _ in 0..=LEAD_DOUBLINGS {
        let target = world.back_off(q, d)?;
        let c = full(&target);
        if c.distance >= clearance {
            return Ok(target);
        }
        last = Some(c);
        d *= 2.0;
    }
    let c = last.unwrap_or_else(|| Clearance::new(f64::NAN, "?"));
    Err(ApproachError::InCollision {
        role: crate::Role::Waypoint(0),
        obstacle: c.obstacle,
        distance: c.distance,
        clearance,
    })
}

/// Euclidean distance between two configurations' first three joints (the tool translation of
/// a gantry; a size of the move for other robots).
fn distance_between(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .take(3)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt()
}

fn closer<'a>(a: &'a ClosestSample, b: &'a ClosestSample) -> &'a ClosestSample {
    if b.distance < a.distance {
        b
    } else {
        a
    }
}

/// The legs of `moves`, one after the other, as one move.
fn joined(moves: &[&CheckedMove]) -> Result<WaypointMove, ApproachError> {
    WaypointMove::from_legs(
        moves
            .iter()
            .flat_map(|m| m.path.legs().iter().cloned())
            .collect(),
    )
}
