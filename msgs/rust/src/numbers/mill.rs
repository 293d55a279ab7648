//! The rules of `kerf_msgs/msg/MillRequest` (msgs/msg/MillRequest.msg): the ranges of the
//! `.msg` comments, of `kerf_millplan::MillRequest::validate` and of the cell's state limits,
//! with a physically sensible bound where none is stated (documented in the `.msg`).

use std::f64::consts::PI;

use super::cut::MAX_TIME_BUDGET;
use super::{declare_rules, Bound, Rule, Section};
use crate::msg::MillRequest;

/// Fastest spindle a request may ask for (rpm): above any milling spindle (high-speed
/// spindles reach 60 000 rpm).
pub const MAX_SPINDLE_RPM: f64 = 100_000.0;

/// Fastest feed a request may ask for (m/s): 600 m/min, above any robot's milling feed.
pub const MAX_FEED: f64 = 10.0;

/// The rules of every numeric field of `MillRequest`.
pub const RULES: &[Rule] = &[
    // kerf_millplan::request::MAX_COORDINATE.
    Rule::closed("points[].*", -1000.0, 1000.0, "m"),
    Rule::closed("segments", 1.0, 10_000.0, "-").or(&[(0.0, "the cell's 100")]),
    // kerf_chatter::MAX_TEETH.
    Rule::closed("teeth", 1.0, 100.0, "-").when("has_process"),
    Rule::closed("tool_radius", 1e-4, 1.0, "m")
        .divides()
        .when("has_process"),
    Rule::closed("axial_depth", 1e-6, 0.1, "m")
        .divides()
        .when("has_process"),
    Rule::closed("kt", 0.0, 1e11, "N/m^2").when("has_process"),
    Rule::closed("kn", 0.0, 1e11, "N/m^2").when("has_process"),
    Rule::closed("entry_angle", 0.0, PI, "rad").when("has_process"),
    Rule::closed("exit_angle", 0.0, PI, "rad").when("has_process"),
    Rule::new(
        "spindle_min_rpm",
        Bound::Open(0.0),
        Bound::Closed(MAX_SPINDLE_RPM),
        "rpm",
    )
    .divides()
    .when("has_limits"),
    Rule::new(
        "spindle_max_rpm",
        Bound::Open(0.0),
        Bound::Closed(MAX_SPINDLE_RPM),
        "rpm",
    )
    .divides()
    .when("has_limits"),
    Rule::closed("feed_min", 0.0, MAX_FEED, "m/s").when("has_limits"),
    Rule::new("feed_max", Bound::Open(0.0), Bound::Closed(MAX_FEED), "m/s")
        .divides()
        .when("has_limits"),
    Rule::closed("g_min", -PI, PI, "rad").when("has_limits"),
    Rule::closed("g_max", -PI, PI, "rad").when("has_limits"),
    // Steps small enough to make a grid axis of 10^8 nodes are refused: they only grow the
    // planners' grids.
    Rule::closed("max_spindle_step_rpm", 1e-3, MAX_SPINDLE_RPM, "rpm")
        .divides()
        .when("has_limits"),
    Rule::closed("max_feed_step", 1e-7, MAX_FEED, "m/s")
        .divides()
        .when("has_limits"),
    Rule::closed("max_g_step", 1e-6, 2.0 * PI, "rad")
        .divides()
        .when("has_limits"),
    Rule::new(
        "initial_spindle_rpm",
        Bound::Open(0.0),
        Bound::Closed(MAX_SPINDLE_RPM),
        "rpm",
    )
    .when("has_initial_state"),
    Rule::new(
        "initial_feed",
        Bound::Open(0.0),
        Bound::Closed(MAX_FEED),
        "m/s",
    )
    .divides()
    .when("has_initial_state"),
    Rule::closed("initial_g", -PI, PI, "rad").when("has_initial_state"),
    Rule::closed("time_budget", 1e-6, MAX_TIME_BUDGET, "s").or(&[(0.0, "the node's plan_timeout")]),
    // Joint positions; each is checked against its joint's limits when the start is resolved.
    Rule::closed("start_positions[]", -1000.0, 1000.0, "rad or m"),
    Rule::closed("path_tolerance", 1e-9, 1e-3, "m")
        .divides()
        .when("has_tolerances"),
    Rule::new(
        "min_condition_indicator",
        Bound::Closed(0.0),
        Bound::Open(1.0),
        "-",
    )
    .when("has_tolerances"),
];

declare_rules!(
    MillRequest,
    &[Section {
        prefix: "",
        rules: RULES
    }]
);
