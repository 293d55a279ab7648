//! The numbers targets (issue 33, item 8): request messages whose numbers are drawn against
//! their declared rules, hostile ones included ([`crate::gen`]: NaN, ±∞, ±0, 5e-324, ±1e308,
//! 2³¹ and `u32::MAX`, bounds and the floats just past them, `has_*` groups off with
//! non-finite values), through `kerf_msgs::numbers::NumberFields::check_numbers` and the
//! node's conversion.
//!
//! The property of every target here ([`check_rules`]): `check_numbers` accepts exactly the
//! messages whose every numeric leaf lies within its declared rule, as this module reads the
//! rule from its fields (independently of `Rule::check` and of the walk's flag lookup), and a
//! refusal names the first leaf outside it. So an accepted message has only finite numbers,
//! none subnormal where its rule divides and applies. The conversion (which a node reaches only
//! for a message `check_numbers` accepted: the planner harness checks the numbers first) must
//! not panic either way, and where both accept, the planner library's own checks agree.

use arbitrary::Unstructured;
use kerf_msgs::numbers::{leaves, probe, Bound, Leaf, Number, NumberFields, NumberRules, Rule};
use serde::Serialize;

use crate::gen;
use crate::targets::{cut_msg_of, mill_msg_of};

// ---------------------------------------------------------------------------------------------
// The rules, read independently
// ---------------------------------------------------------------------------------------------

/// Whether `v` is on the allowed side of the lower bound `lo`.
fn above(lo: Bound, v: f64) -> bool {
    match lo {
        Bound::Closed(b) => v >= b,
        Bound::Open(b) => v > b,
    }
}

/// Whether `v` is on the allowed side of the upper bound `hi`.
fn below(hi: Bound, v: f64) -> bool {
    match hi {
        Bound::Closed(b) => v <= b,
        Bound::Open(b) => v < b,
    }
}

/// Whether `rule` (none: the value only has to be finite) accepts `value`, the field applying
/// when `applies`: always finite; then, when it applies, one of the rule's special values, or
/// inside its range and, for a field that divides, not subnormal.
fn allowed(rule: Option<&Rule>, value: Number, applies: bool) -> bool {
    let v = value.as_f64();
    if !v.is_finite() {
        return false;
    }
    let Some(rule) = rule else { return true };
    if !applies || rule.special.iter().any(|(s, _)| *s == v) {
        return true;
    }
    !(rule.divides && v.is_subnormal()) && above(rule.lo, v) && below(rule.hi, v)
}

/// The declared rules of a message of type `T` as this module reads them: each leaf's rule
/// (looked up once per key) and whether it applies (its `has_*` flag, read from the message
/// written as JSON, once, when a rule first needs it).
struct Rules<'m, T> {
    message: &'m T,
    /// The rules of the keys seen so far.
    seen: Vec<(String, Option<&'static Rule>)>,
    /// The message as JSON (its flags), once a rule with a flag is met.
    json: Option<serde_json::Value>,
}

impl<'m, T: NumberRules + Serialize> Rules<'m, T> {
    /// The rules of `message`, nothing looked up yet.
    fn new(message: &'m T) -> Self {
        Self {
            message,
            seen: Vec::new(),
            json: None,
        }
    }

    /// The declared rule of the normalized key `key`.
    fn rule(&mut self, key: &str) -> Option<&'static Rule> {
        if let Some((_, r)) = self.seen.iter().rev().find(|(k, _)| k == key) {
            return *r;
        }
        let r = probe::rule_of::<T>(key);
        self.seen.push((key.to_string(), r));
        r
    }

    /// Whether the top-level `bool` field `flag` is true (a field that is absent is taken as
    /// applying, as the rules say).
    fn flag(&mut self, flag: &str) -> bool {
        let message = self.message;
        self.json
            .get_or_insert_with(|| serde_json::to_value(message).unwrap_or(serde_json::Value::Null))
            .get(flag)
            .and_then(serde_json::Value::as_bool)
            .unwrap_or(true)
    }

    /// The rule of `leaf` and whether it applies (it has no flag, or its flag is set).
    fn of(&mut self, leaf: &Leaf) -> (Option<&'static Rule>, bool) {
        let rule = self.rule(&leaf.key);
        let applies = rule.and_then(|r| r.when).is_none_or(|f| self.flag(f));
        (rule, applies)
    }
}

/// The first of `leaves` (in declaration order) outside its declared rule.
fn first_refused<'l, T: NumberRules + Serialize>(
    leaves: &'l [Leaf],
    rules: &mut Rules<T>,
) -> Option<&'l Leaf> {
    leaves.iter().find(|leaf| {
        let (rule, applies) = rules.of(leaf);
        !allowed(rule, leaf.value, applies)
    })
}

/// Every float leaf of an accepted message is finite, and not subnormal where its rule
/// divides and applies (the property issue 33 asks for, checked on its own).
fn assert_accepted_numbers<T: NumberRules + Serialize>(leaves: &[Leaf], rules: &mut Rules<T>) {
    for leaf in leaves {
        let Number::Float(v) = leaf.value else {
            continue;
        };
        assert!(
            v.is_finite(),
            "check_numbers accepted `{}` = {v}",
            leaf.path
        );
        let (rule, applies) = rules.of(leaf);
        assert!(
            !(rule.is_some_and(|r| r.divides) && applies && v.is_subnormal()),
            "check_numbers accepted the subnormal `{}` = {v:e}, which divides",
            leaf.path
        );
    }
}

/// `check_numbers` of `m` agrees with its declared rules leaf by leaf (module documentation):
/// it accepts exactly when no leaf is outside its rule, and a refusal names the first such
/// leaf and displays without panicking. Returns whether `m` was accepted.
pub fn check_rules<T: NumberFields + NumberRules + Serialize>(m: &T) -> bool {
    let verdict = m.check_numbers();
    let all = leaves(m);
    let mut rules = Rules::new(m);
    match (&verdict, first_refused(&all, &mut rules)) {
        (Ok(()), None) => assert_accepted_numbers(&all, &mut rules),
        (Ok(()), Some(leaf)) => panic!(
            "check_numbers accepted `{}` = {}, outside its rule",
            leaf.path, leaf.value
        ),
        (Err(e), None) => panic!("check_numbers refused a message within its rules: {e}"),
        (Err(e), Some(leaf)) => assert!(
            e.field == leaf.path,
            "check_numbers named `{}`, but the first leaf outside its rule is `{}` = {}",
            e.field,
            leaf.path,
            leaf.value
        ),
    }
    if let Err(e) = &verdict {
        drop(e.to_string());
    }
    verdict.is_ok()
}

// ---------------------------------------------------------------------------------------------
// Targets
// ---------------------------------------------------------------------------------------------

/// A `CutRequest` message with hostile numbers ([`gen::cut_request_numbers`]): `check_numbers`
/// agrees with the rules ([`check_rules`]); the node's error for a refused one displays; the
/// conversion and validation never panic, whatever `check_numbers` said, and a validated path
/// is finite (`cut_msg`'s properties).
pub fn cut_numbers(data: &[u8]) {
    let mut u = Unstructured::new(data);
    let Ok(m) = gen::cut_request_numbers(&mut u) else {
        return;
    };
    check_rules(&m);
    if let Err(e) = kerf_mjto_planner::convert::check_numbers(&m) {
        drop(e.to_string());
    }
    cut_msg_of(&m);
}

/// Most segments of a message `mill_numbers` validates: `MillRequest::validate` builds the
/// path with the request's own segments, 17 ms for 1 000 and 0.17–0.7 s for 10 000 in the
/// test build, so a message with more (up to `MAX_SEGMENTS`) is only converted; `mill_msg`
/// validates those.
const VALIDATED_SEGMENTS: u32 = 200;

/// A `MillRequest` message with hostile numbers ([`gen::mill_request_numbers`]):
/// `check_numbers` agrees with the rules ([`check_rules`]); the conversion never panics, nor
/// does validation (of a message of at most [`VALIDATED_SEGMENTS`] segments, or more than
/// `MAX_SEGMENTS`); and a message `check_numbers` accepted converts to a request whose every
/// number passes the same rules again as a text request's numbers are checked
/// (`check_text_numbers`: conversion keeps the numbers it uses).
pub fn mill_numbers(data: &[u8]) {
    use kerf_milling_planner::convert;
    let mut u = Unstructured::new(data);
    let Ok(m) = gen::mill_request_numbers(&mut u) else {
        return;
    };
    let accepted = check_rules(&m);
    if let Err(e) = convert::check_numbers(&m) {
        drop(e.to_string());
    }
    if accepted {
        if let Ok(req) = convert::request_from_msg(&m) {
            if let Err(e) = convert::check_text_numbers(&req) {
                panic!("a message within its rules converts to a request refused as text: {e}");
            }
        }
    }
    let costly = u32::try_from(kerf_millplan::request::MAX_SEGMENTS)
        .is_ok_and(|max| (VALIDATED_SEGMENTS + 1..=max).contains(&m.segments));
    if !costly {
        mill_msg_of(&m);
    }
}

/// A `GcodeRequest` message with hostile numbers ([`gen::gcode_request`]): `check_numbers`
/// agrees with the rules ([`check_rules`]); `kerf_gcode_planner::convert::request_from_msg`
/// and, when it accepts, the request's `settings`, `source` and `time_limit` never panic,
/// and errors become answers without panicking. When `check_numbers` accepted too, the
/// request passes the text request's checks (`check_text_numbers`) and the library's own
/// ranges ([`gcode_library_ranges`]), and accepted settings are positive and finite.
pub fn gcode_msg(data: &[u8]) {
    use kerf_gcode_planner::convert;
    let mut u = Unstructured::new(data);
    let Ok(m) = gen::gcode_request(&mut u) else {
        return;
    };
    let accepted = check_rules(&m);
    if let Err(e) = convert::check_numbers(&m) {
        drop(e.to_string());
    }
    match convert::request_from_msg(&m) {
        Ok(req) => gcode_request_of(&m, &req, accepted),
        Err(e) => drop(convert::error_to_msg(&Default::default(), &m.machine, &e)),
    }
}

/// The planner's view of a converted `GcodeRequest` (see [`gcode_msg`]).
fn gcode_request_of(
    m: &kerf_msgs::msg::GcodeRequest,
    req: &kerf_gcodeplan::GcodeRequest,
    accepted: bool,
) {
    use kerf_gcode_planner::convert;
    let settings = req.settings();
    drop(req.source());
    drop(req.time_limit());
    if accepted {
        if let Err(e) = convert::check_text_numbers(req) {
            panic!("a message within its rules converts to a request refused as text: {e}");
        }
        gcode_library_ranges(req);
    }
    match settings {
        Ok(s) => assert!(
            [s.tolerance, s.rapid_feed, s.limits.curvature.feed]
                .iter()
                .all(|v| v.is_finite() && *v > 0.0),
            "accepted settings with a tolerance {}, rapid feed {} or feed {} not finite and \
             positive",
            s.tolerance,
            s.rapid_feed,
            s.limits.curvature.feed
        ),
        Err(e) => drop(convert::error_to_msg(req, &m.machine, &e)),
    }
}

/// The message's rules are no wider than `kerf_gcodeplan`'s own ranges (`RANGES`, `ORIGIN`,
/// …; `kerf_msgs::numbers` promises it never accepts a value the library refuses for a plain
/// range reason): the converted request of a message `check_numbers` accepted passes
/// `GcodeRequest::check_numbers`.
fn gcode_library_ranges(req: &kerf_gcodeplan::GcodeRequest) {
    if let Err(e) = req.check_numbers() {
        panic!("a message within its rules is refused by the library's ranges: {e}");
    }
}

// ---------------------------------------------------------------------------------------------
// Named seeds
// ---------------------------------------------------------------------------------------------

/// Whether `check_numbers` refuses `m` naming `field` with the value written `value`.
fn refused<T: NumberFields>(m: &T, field: &str, value: &str) -> bool {
    m.check_numbers()
        .err()
        .is_some_and(|e| e.field == field && e.value == value)
}

/// The `GcodeRequest` the bytes give, if any.
fn gcode(data: &[u8]) -> Option<kerf_msgs::msg::GcodeRequest> {
    gen::gcode_request(&mut Unstructured::new(data)).ok()
}

/// The `CutRequest` the bytes give, if any.
fn cut(data: &[u8]) -> Option<kerf_msgs::msg::CutRequest> {
    gen::cut_request_numbers(&mut Unstructured::new(data)).ok()
}

/// The `MillRequest` the bytes give, if any.
fn mill(data: &[u8]) -> Option<kerf_msgs::msg::MillRequest> {
    gen::mill_request_numbers(&mut Unstructured::new(data)).ok()
}

/// A named seed of a numbers target: the target, the corpus file's name, and what the
/// message its bytes give must be (`kerf-fuzz seeds` searches bytes for it; `tests/fuzz.rs`
/// checks the committed file still gives it).
pub type NamedSeed = (&'static str, &'static str, fn(&[u8]) -> bool);

/// The named seeds of the numbers targets: the hostile values of issue 33 (a denormal
/// `max_feed`, a NaN `time_budget`, a 1e308 rpm, …), each the first field `check_numbers`
/// refuses, and messages it accepts (a group off with a huge value; every group on).
pub const SEEDS: &[NamedSeed] = &[
    ("gcode_msg", "denormal-max-feed", |d| {
        gcode(d).is_some_and(|m| m.has_limits && refused(&m, "max_feed", "5e-324"))
    }),
    ("gcode_msg", "nan-time-budget", |d| {
        gcode(d).is_some_and(|m| refused(&m, "time_budget", "NaN"))
    }),
    ("gcode_msg", "inf-origin-placement-off", |d| {
        gcode(d).is_some_and(|m| !m.has_placement && refused(&m, "origin.x", "inf"))
    }),
    ("gcode_msg", "huge-origin-placement-off", |d| {
        gcode(d)
            .is_some_and(|m| !m.has_placement && m.origin.x == 1e308 && m.check_numbers().is_ok())
    }),
    ("gcode_msg", "accepted-limits-placement", |d| {
        gcode(d).is_some_and(|m| {
            m.has_limits
                && m.has_placement
                && m.check_numbers().is_ok()
                && kerf_gcode_planner::convert::request_from_msg(&m).is_ok()
        })
    }),
    ("cut_numbers", "nan-time-budget", |d| {
        cut(d).is_some_and(|m| refused(&m, "time_budget", "NaN"))
    }),
    ("cut_numbers", "denormal-feedrate", |d| {
        cut(d).is_some_and(|m| refused(&m, "feedrate", "5e-324"))
    }),
    ("cut_numbers", "u32-max-control-points", |d| {
        cut(d).is_some_and(|m| refused(&m, "control_points", "4294967295"))
    }),
    ("cut_numbers", "accepted-standoff-off-1e308", |d| {
        cut(d).is_some_and(|m| {
            !m.has_reference_standoff && m.reference_standoff == 1e308 && m.check_numbers().is_ok()
        })
    }),
    ("mill_numbers", "1e308-rpm", |d| {
        mill(d).is_some_and(|m| m.has_limits && refused(&m, "spindle_max_rpm", "1e308"))
    }),
    ("mill_numbers", "denormal-max-feed-step", |d| {
        mill(d).is_some_and(|m| refused(&m, "max_feed_step", "5e-324"))
    }),
    ("mill_numbers", "nan-kt-process-off", |d| {
        mill(d).is_some_and(|m| !m.has_process && refused(&m, "kt", "NaN"))
    }),
    ("mill_numbers", "accepted-every-group", |d| {
        mill(d).is_some_and(|m| {
            m.has_process
                && m.has_limits
                && m.has_initial_state
                && m.has_tolerances
                && m.points.len() >= 2
                && m.check_numbers().is_ok()
        })
    }),
];
