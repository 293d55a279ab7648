//! The rules of the executor's streaming input, `kerf_msgs/msg/ReferencePoint` (the
//! `~/reference_points` topic, issue 29). The stepping core keeps its own checks (joint
//! ranges, repeated points, jumps); these refuse what no robot could mean, with the field's
//! name, before the point reaches it.

use super::{
    declare_rules, trajectory::MAX_NANOSEC, trajectory::MAX_POSITION, Bound, Rule, Section,
};
use crate::msg::ReferencePoint;

/// The rules of a `ReferencePoint`.
pub const REFERENCE_POINT: &[Rule] = &[
    Rule::closed("header.stamp.sec", 0.0, i32::MAX as f64, "s"),
    Rule::closed("header.stamp.nanosec", 0.0, MAX_NANOSEC, "ns"),
    // The id is the sender's: any uint32.
    Rule::closed("id", 0.0, u32::MAX as f64, "-"),
    Rule::closed("positions[]", -MAX_POSITION, MAX_POSITION, "rad or m"),
    // The stepping core divides by it (its lattice windows): (0, 1], not denormal.
    Rule::new(
        "precision",
        Bound::Open(0.0),
        Bound::Closed(1.0),
        "rad or m",
    )
    .divides(),
];

declare_rules!(
    ReferencePoint,
    &[Section {
        prefix: "",
        rules: REFERENCE_POINT
    }]
);
