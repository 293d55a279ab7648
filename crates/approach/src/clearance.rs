//! What the caller's collision world answers ([`Clearance`]) and what a check reports: the
//! closest sample of a clear move ([`ClosestSample`]) or where a move is not clear
//! ([`Violation`]).

use std::fmt;

use crate::Route;

/// The answer of the caller's clearance function at one configuration.
///
/// `distance` is the exact signed distance (m) from the robot to the nearest obstacle:
/// positive when apart, negative (penetration depth) or 0 when touching. A lower bound of the
/// true distance is also safe (the check only gets more conservative); an over-estimate is
/// not. parry's `query::distance`, which answers 0 for intersecting shapes, is fine: only
/// `distance ≥ clearance > 0` passes. `+inf` means no obstacle at all; NaN is refused
/// ([`crate::ApproachError::InvalidClearance`]).
///
/// The function must leave out the contacts the process allows (the tool against the
/// workpiece within its standoff or engagement), or a process point would never be clear.
#[derive(Debug, Clone, PartialEq)]
pub struct Clearance {
    /// Signed distance to the nearest obstacle (m).
    pub distance: f64,
    /// Name of that obstacle (a scene object, the workpiece, a robot link pair...).
    pub obstacle: String,
}

impl Clearance {
    /// A clearance of `distance` metres to `obstacle`.
    pub fn new(distance: f64, obstacle: impl Into<String>) -> Self {
        Self {
            distance,
            obstacle: obstacle.into(),
        }
    }
}

/// The configuration of a move that came closest to an obstacle, among every configuration
/// the check evaluated (the control-period samples and the refinement points between them).
#[derive(Debug, Clone, PartialEq)]
pub struct ClosestSample {
    /// Distance there (m).
    pub distance: f64,
    /// The nearest obstacle there.
    pub obstacle: String,
    /// Time from the start of the move (s).
    pub time: f64,
    /// The configuration.
    pub configuration: Vec<f64>,
}

/// Why a move failed its clearance check.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ViolationKind {
    /// An evaluated configuration is closer than the clearance.
    TooClose,
    /// Every evaluated configuration is clear, but the conservative-advancement bound could
    /// not prove the motion between two of them clear within the refinement budget: the
    /// motion passes within half the swept distance of the clearance.
    Uncertified,
}

/// Where a move is not clear: the route, the obstacle, the time, the configuration and the
/// distance.
#[derive(Debug, Clone, PartialEq)]
pub struct Violation {
    /// The move that failed.
    pub route: Route,
    /// What failed.
    pub kind: ViolationKind,
    /// The nearest obstacle at `configuration`.
    pub obstacle: String,
    /// Time from the start of the move (s).
    pub time: f64,
    /// The configuration.
    pub configuration: Vec<f64>,
    /// Its distance to `obstacle` (m).
    pub distance: f64,
    /// The distance it needed (m): the clearance for [`ViolationKind::TooClose`], the
    /// clearance plus half the swept distance to the neighbouring configuration for
    /// [`ViolationKind::Uncertified`].
    pub required: f64,
}

impl fmt::Display for Violation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let what = match self.kind {
            ViolationKind::TooClose => "comes within",
            ViolationKind::Uncertified => "cannot be certified clear near",
        };
        write!(
            f,
            "{} {what} {:.6} m of '{}' at t = {:.4} s, q = {:?} (needs {:.6} m)",
            self.route, self.distance, self.obstacle, self.time, self.configuration, self.required
        )
    }
}
