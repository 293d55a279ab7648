//! The rules of `kerf_msgs/msg/CutRequest` (msgs/msg/CutRequest.msg): the ranges of the `.msg`
//! comments and of `kerf_mjto::CutRequest::validate`, with a physically sensible bound where
//! either states none (documented in the `.msg`).

use std::f64::consts::{FRAC_PI_2, PI};

use super::{declare_rules, Bound, Rule, Section};
use crate::msg::CutRequest;

/// "0 = default".
const DEFAULT: &[(f64, &str)] = &[(0.0, "default")];

/// The rules of every numeric field of `CutRequest`.
pub const RULES: &[Rule] = &[
    // A cell is metres across; 1 km is far beyond any and keeps arc lengths well conditioned.
    Rule::closed("points[].*", -1000.0, 1000.0, "m"),
    // Unit axes: |component| <= 1 within the norm tolerance 1e-6.
    Rule::closed("axes[].*", -1.000_001, 1.000_001, "-"),
    Rule::new("feedrate", Bound::Open(0.0), Bound::Closed(10.0), "m/s").divides(),
    Rule::new(
        "feed_acceleration",
        Bound::Open(0.0),
        Bound::Closed(1000.0),
        "m/s^2",
    )
    .or(&[(0.0, "default 8 m/s^2")])
    .divides(),
    Rule::new("feed_jerk", Bound::Open(0.0), Bound::Closed(1e5), "m/s^3")
        .or(&[(0.0, "default 80 m/s^3")])
        .divides(),
    // 10 us to 1 s: every controller's period; a smaller one only multiplies the samples.
    Rule::closed("sample_period", 1e-5, 1.0, "s").divides(),
    Rule::new(
        "max_lead_angle",
        Bound::Open(0.0),
        Bound::Open(FRAC_PI_2),
        "rad",
    )
    .divides(),
    Rule::new(
        "max_tilt_angle",
        Bound::Open(0.0),
        Bound::Open(FRAC_PI_2),
        "rad",
    )
    .divides(),
    Rule::closed("workpiece_pose.position.*", -1000.0, 1000.0, "m"),
    // A unit quaternion within the planner's norm tolerance 1e-3.
    Rule::closed("workpiece_pose.orientation.*", -1.001, 1.001, "-"),
    Rule::closed("control_points", 6.0, 100_000.0, "-").or(&[(0.0, "automatic")]),
    Rule::closed("max_iterations", 1.0, 1000.0, "-").or(&[(0.0, "default 10")]),
    Rule::closed("gfd_q4_steps", 1.0, 101.0, "-").or(DEFAULT),
    Rule::closed("gfd_q5_steps", 1.0, 101.0, "-").or(DEFAULT),
    Rule::closed("gfd_q6_steps", 1.0, 101.0, "-").or(DEFAULT),
    Rule::new(
        "gfd_q4_half_range",
        Bound::Open(0.0),
        Bound::Closed(PI),
        "rad",
    )
    .or(DEFAULT),
    Rule::new(
        "gfd_q5_half_range",
        Bound::Open(0.0),
        Bound::Closed(PI),
        "rad",
    )
    .or(DEFAULT),
    Rule::closed("rto_indices[]", 0.0, 10_000_000.0, "-"),
    Rule::new("rto_spacing", Bound::Open(0.0), Bound::Closed(1000.0), "m")
        .or(&[(0.0, "default 0.15 m")])
        .divides(),
    Rule::new("rto_angle", Bound::Open(0.0), Bound::Closed(PI), "rad")
        .or(&[(0.0, "default 20 degrees")])
        .divides(),
    Rule::closed("reference_standoff", -1.0, 1.0, "m").when("has_reference_standoff"),
    Rule::closed("clearance", 0.0, 1.0, "m"),
    Rule::closed("cl_tolerance", 1e-7, 0.01, "m")
        .or(&[(0.0, "default 0.00015 m")])
        .divides(),
    Rule::closed("time_budget", 1e-6, MAX_TIME_BUDGET, "s").or(&[(0.0, "the node's plan_timeout")]),
    // Joint positions; each is checked against its joint's limits when the start is resolved.
    Rule::closed("start_positions[]", -1000.0, 1000.0, "rad or m"),
];

/// Largest time budget of a request (s): `kerf_budget::MAX_BUDGET_SECONDS`, one day (kerf_msgs
/// does not depend on kerf_budget; the planner nodes' tests check that the two are equal).
pub const MAX_TIME_BUDGET: f64 = 86_400.0;

declare_rules!(
    CutRequest,
    &[Section {
        prefix: "",
        rules: RULES
    }]
);
