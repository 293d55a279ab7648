//! Issue 33, item 1: every numeric field of a `GcodeRequest`, set to NaN, ±inf, ±0, 5e-324,
//! ±1e308, through `check_numbers` and the service's `request_from_msg`, and through the YAML
//! text path with the same value, for both machines: never a panic, and every value outside
//! the field's declared rule refused naming the field. The probe's cases (a denormal
//! `max_feed`, a NaN or infinite `time_budget`, a NaN `redundancy_angle` on the laser cutter)
//! are refused before planning.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_gcode_planner::{convert, GcodeService};
use kerf_gcodeplan::{MachineBase, MachineKind};
use kerf_msgs::geometry_msgs::Point;
use kerf_msgs::msg::{GcodePlan, GcodeRequest};
use kerf_msgs::numbers::probe::{expected, probe_values, with_value};
use kerf_msgs::numbers::{leaves, NumberFields};
use kerf_ros::planner::PlanningService;

/// A valid request for `machine` with every group given (the machine's defaults).
fn request(machine: MachineKind) -> GcodeRequest {
    let laser = machine == MachineKind::LaserCutter;
    GcodeRequest {
        request_id: "numbers".into(),
        machine: machine.name().into(),
        program: "G21 G90\nG1 X10 F600\nG1 Y10\n".into(),
        tolerance: 1e-4,
        has_limits: true,
        max_feed: if laser { 0.16 } else { 0.06 },
        tangential_acceleration: if laser { 8.0 } else { 0.8 },
        tangential_jerk: if laser { 80.0 } else { 20.0 },
        normal_acceleration: if laser { 8.0 } else { 0.99 },
        normal_jerk: if laser { 80.0 } else { 29.0 },
        chord_error: 1e-5,
        contour_error: 5e-5,
        rapid_feed: 0.1,
        has_placement: true,
        origin: if laser {
            Point {
                x: 0.3,
                y: 0.3,
                z: 0.5,
            }
        } else {
            Point {
                x: 1.4,
                y: -0.3,
                z: 1.7,
            }
        },
        redundancy_angle: 0.0,
        standoff_axis: -0.08,
        time_budget: 10.0,
        ..Default::default()
    }
}

/// A float as YAML (`.nan`, `.inf`, `-.inf`, else Rust's shortest round-trip form).
fn yaml_float(v: f64) -> String {
    if v.is_nan() {
        ".nan".into()
    } else if v.is_infinite() {
        if v > 0.0 { ".inf" } else { "-.inf" }.into()
    } else {
        format!("{v:?}")
    }
}

/// The planner form of a request as the YAML text of `~/gcode_request_text`.
fn yaml(r: &kerf_gcodeplan::GcodeRequest) -> String {
    let mut t = format!("request_id: {}\nmachine: {}\n", r.request_id, r.machine);
    if let Some(p) = &r.program {
        t.push_str(&format!("program: {p:?}\n"));
    }
    let mut num = |name: &str, v: Option<f64>| {
        if let Some(v) = v {
            t.push_str(&format!("{name}: {}\n", yaml_float(v)));
        }
    };
    num("tolerance", r.tolerance);
    num("rapid_feed", r.rapid_feed);
    num("redundancy_angle", r.redundancy_angle);
    num("standoff_axis", r.standoff_axis);
    num("time_budget", r.time_budget);
    if let Some(o) = r.origin {
        let o: Vec<String> = o.iter().map(|v| yaml_float(*v)).collect();
        t.push_str(&format!("origin: [{}]\n", o.join(", ")));
    }
    if let Some(l) = &r.limits {
        t.push_str("limits:\n");
        for (name, v) in [
            ("max_feed", l.max_feed),
            ("tangential_acceleration", l.tangential_acceleration),
            ("tangential_jerk", l.tangential_jerk),
            ("normal_acceleration", l.normal_acceleration),
            ("normal_jerk", l.normal_jerk),
            ("chord_error", l.chord_error),
            ("contour_error", l.contour_error),
        ] {
            if let Some(v) = v {
                t.push_str(&format!("  {name}: {}\n", yaml_float(v)));
            }
        }
    }
    t
}

/// The message's YAML text form (the planner form of the same values), or `None` when the
/// conversion refuses the message.
fn yaml_text(m: &GcodeRequest) -> Option<String> {
    convert::request_from_msg(m).ok().map(|r| yaml(&r))
}

fn probe(machine: MachineKind) -> usize {
    let service = GcodeService::new(MachineBase::load(machine).unwrap()).unwrap();
    let example = request(machine);
    assert_eq!(example.check_numbers(), Ok(()));
    service.request_from_msg(&example).unwrap();
    let example_text = yaml_text(&example).unwrap();
    service.request_from_text(&example_text).unwrap();
    let mut refused = 0;
    for leaf in leaves(&example) {
        for value in probe_values(leaf.value) {
            let m = with_value(&example, &leaf.path, value).unwrap();
            let checked = m.check_numbers();
            // The harness calls check_numbers, then request_from_msg: the conversion is run
            // on every value anyway, and must not panic.
            let _ = service.request_from_msg(&m);
            let text = yaml_text(&m);
            let answer = text.as_deref().map(|t| service.request_from_text(t));
            match expected::<GcodeRequest>(&leaf.key, value) {
                Ok(()) => assert_eq!(checked, Ok(()), "{} = {value}", leaf.path),
                Err(_) => {
                    refused += 1;
                    assert_eq!(checked.expect_err(&leaf.path).field, leaf.path);
                    // The text form carries the value unless the conversion drops it (a 0
                    // that means "the machine's", the other machine's placement field).
                    if text.as_deref() != Some(example_text.as_str()) {
                        let answer = answer
                            .expect("text form")
                            .expect_err(&format!("text {} = {value}", leaf.path));
                        assert_eq!(
                            answer.status,
                            GcodePlan::INVALID_REQUEST,
                            "{}",
                            answer.message
                        );
                        assert!(
                            answer.message.contains(&leaf.path),
                            "{} = {value}: {}",
                            leaf.path,
                            answer.message
                        );
                    }
                }
            }
        }
    }
    refused
}

#[test]
fn every_numeric_field_is_refused_by_its_rule_on_both_paths() {
    assert!(probe(MachineKind::LaserCutter) > 50);
    assert!(probe(MachineKind::Irb6660) > 50);
}

#[test]
fn the_probe_s_cases_are_refused_before_planning() {
    let service = GcodeService::new(MachineBase::load(MachineKind::LaserCutter).unwrap()).unwrap();
    type Set = fn(&mut GcodeRequest);
    let cases: [(&str, Set); 6] = [
        ("max_feed", |m| m.max_feed = 5e-324),
        ("tangential_acceleration", |m| {
            m.tangential_acceleration = 5e-324
        }),
        ("tangential_jerk", |m| m.tangential_jerk = 5e-324),
        ("time_budget", |m| m.time_budget = f64::NAN),
        ("time_budget", |m| m.time_budget = f64::INFINITY),
        ("redundancy_angle", |m| {
            m.has_placement = false;
            m.redundancy_angle = f64::NAN
        }),
    ];
    for (field, set) in cases {
        let mut m = request(MachineKind::LaserCutter);
        set(&mut m);
        assert_eq!(m.check_numbers().unwrap_err().field, field);
    }
    for (yaml, field) in [
        ("limits: {max_feed: 5.0e-324}", "max_feed"),
        ("time_budget: .nan", "time_budget"),
        ("time_budget: .inf", "time_budget"),
        ("redundancy_angle: .nan", "redundancy_angle"),
    ] {
        let answer = service
            .request_from_text(&format!("program: \"G1 X10 F600\"\n{yaml}\n"))
            .unwrap_err();
        assert_eq!(answer.status, GcodePlan::INVALID_REQUEST);
        assert!(answer.message.contains(field), "{yaml}: {}", answer.message);
    }
}
