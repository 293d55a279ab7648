//! Which configuration of a plan an error is about.

use std::fmt;

/// The role of a configuration handed to this crate, named in errors.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// The robot's current joint state, where an approach starts.
    Start,
    /// The first point of the process, where an approach ends.
    Goal,
    /// Safe pose number `i` (0-based) of [`crate::ApproachSettings::safe_poses`].
    SafePose(usize),
    /// The last process configuration, where a retract starts.
    RetractStart,
    /// Retract target number `i` (0-based).
    RetractTarget(usize),
    /// Waypoint number `i` (0-based) of a [`crate::JointMove`] or [`crate::WaypointMove`].
    Waypoint(usize),
}

impl fmt::Display for Role {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Role::Start => write!(f, "start configuration"),
            Role::Goal => write!(f, "goal configuration"),
            Role::SafePose(i) => write!(f, "safe pose {i}"),
            Role::RetractStart => write!(f, "retract start configuration"),
            Role::RetractTarget(i) => write!(f, "retract target {i}"),
            Role::Waypoint(i) => write!(f, "waypoint {i}"),
        }
    }
}
