//! The rules of `kerf_msgs/msg/GcodeRequest` (msgs/msg/GcodeRequest.msg): the ranges of the
//! `.msg` comments and of `kerf_gcodeplan`'s settings, with a physically sensible bound where
//! none is stated (documented in the `.msg`). The denormal limits of issue 33 (`max_feed`,
//! `tangential_acceleration`, `tangential_jerk` = 5e-324 grew the node to 17.7 GB) are
//! refused by these ranges.

use std::f64::consts::PI;

use super::cut::MAX_TIME_BUDGET;
use super::{declare_rules, Rule, Section};
use crate::msg::GcodeRequest;

/// The rules of every numeric field of `GcodeRequest`.
pub const RULES: &[Rule] = &[
    Rule::closed("tolerance", 1e-7, 0.01, "m")
        .or(&[(0.0, "default 1e-4 m")])
        .divides(),
    Rule::closed("max_feed", 1e-4, 10.0, "m/s")
        .divides()
        .when("has_limits"),
    Rule::closed("tangential_acceleration", 1e-3, 1000.0, "m/s^2")
        .divides()
        .when("has_limits"),
    Rule::closed("tangential_jerk", 1e-2, 1e5, "m/s^3")
        .divides()
        .when("has_limits"),
    Rule::closed("normal_acceleration", 1e-3, 1000.0, "m/s^2")
        .divides()
        .when("has_limits"),
    Rule::closed("normal_jerk", 1e-2, 1e5, "m/s^3")
        .divides()
        .when("has_limits"),
    Rule::closed("chord_error", 1e-9, 0.01, "m")
        .divides()
        .when("has_limits"),
    Rule::closed("contour_error", 1e-9, 0.01, "m")
        .divides()
        .when("has_limits"),
    Rule::closed("rapid_feed", 1e-4, 10.0, "m/s")
        .or(&[(0.0, "the machine's")])
        .divides(),
    Rule::closed("origin.*", -100.0, 100.0, "m").when("has_placement"),
    Rule::closed("redundancy_angle", -PI, PI, "rad").when("has_placement"),
    Rule::closed("standoff_axis", -0.1, 0.02, "m").when("has_placement"),
    Rule::closed("time_budget", 1e-6, MAX_TIME_BUDGET, "s").or(&[(0.0, "the node's plan_timeout")]),
    // Joint positions; each is checked against its joint's limits when the start is resolved.
    Rule::closed("start_positions[]", -1000.0, 1000.0, "rad or m"),
];

declare_rules!(
    GcodeRequest,
    &[Section {
        prefix: "",
        rules: RULES
    }]
);
