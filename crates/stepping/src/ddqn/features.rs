//! The network's input (seed 002 section 3): "normalized current spindle
//! velocity, normalized current spindle acceleration and normalized distance
//! to the next reference point", normalized by "the maximum allowed spindle
//! velocity, the maximum allowed spindle acceleration and the largest
//! distance between adjacent reference points".
//!
//! One function, [`features`], used by training and by the agent alike.

use crate::{course::Course, run::Decision};

use super::net::INPUTS;

/// `[v/V, a/A, d/d_max]` at `decision`: velocity over the velocity limit,
/// acceleration over the acceleration limit, and the signed distance from
/// the current position to the next target (`decision.target`,
/// [`Course::distance_to`]; negative once the axis is past the point but
/// still inside its window) over the course's largest gap
/// ([`Course::max_gap`]).
///
/// # Performance
/// O(1).
pub fn features(course: &Course, decision: &Decision) -> [f32; INPUTS] {
    let lat = &course.lattice;
    let s = decision.state;
    let v = lat.velocity(s) / lat.limits.velocity;
    let a = lat.acceleration(s) / lat.limits.acceleration;
    let d = course.distance_to(decision.target, s.q) / course.max_gap;
    [v as f32, a as f32, d as f32]
}
