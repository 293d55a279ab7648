//! Which motion a checked move or a clearance violation belongs to.

use std::fmt;

/// The route of a move the planner built and checked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Route {
    /// Straight in joint space from the start to the goal.
    Direct,
    /// Start → safe pose number `i` (0-based) → goal, each leg rest-to-rest.
    ViaSafePose(usize),
    /// From the last process configuration through the retract targets.
    Retract,
}

impl fmt::Display for Route {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Route::Direct => write!(f, "direct move"),
            Route::ViaSafePose(i) => write!(f, "move via safe pose {i}"),
            Route::Retract => write!(f, "retract"),
        }
    }
}
