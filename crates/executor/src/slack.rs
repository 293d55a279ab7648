//! The relative slack of every limit check, so that trajectories generated exactly at a limit
//! (and then rounded) are not rejected.

use crate::types::JointLimits;

/// Relative slack on every limit check. A velocity `v` passes when
/// `|v| <= max_velocity · (1 + LIMIT_SLACK)`; a position passes when it lies within the
/// limits widened by `LIMIT_SLACK · max(1, |limit|)` joint units.
pub const LIMIT_SLACK: f64 = 1e-9;

/// Whether a position lies within the joint's limits, widened by [`LIMIT_SLACK`].
pub(crate) fn position_ok(p: f64, l: &JointLimits) -> bool {
    let lo = l.min_position - LIMIT_SLACK * l.min_position.abs().max(1.0);
    let hi = l.max_position + LIMIT_SLACK * l.max_position.abs().max(1.0);
    p >= lo && p <= hi
}

/// Whether `|value| <= limit · (1 + LIMIT_SLACK)`.
pub(crate) fn rate_ok(value: f64, limit: f64) -> bool {
    value.abs() <= limit * (1.0 + LIMIT_SLACK)
}
