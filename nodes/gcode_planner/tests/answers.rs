//! Issue 30, the reader's small gaps as the node answers them: `error_line` set for every error
//! of a program line (item 2), the text form's message field names with the earlier names as
//! aliases (item 3), and the tool events' `tool_on` key that YAML 1.1 readers read as text
//! (item 4).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_budget::Budget;
use kerf_gcode_planner::{convert, text, GcodeService};
use kerf_gcodeplan::{
    plan_program, GcodePlanError, GcodeRequest, LaserSheet, MachineBase, MachineKind, PlanSettings,
};
use kerf_msgs::msg::{GcodePlan, GcodeToolEvent};
use kerf_ros::planner::{answer_text, PlanningService};

fn service() -> GcodeService {
    GcodeService::new(MachineBase::load(MachineKind::LaserCutter).unwrap()).unwrap()
}

/// The node's answer to a text request holding `program`.
fn answer(service: &GcodeService, program: &str) -> GcodePlan {
    let request = GcodeRequest {
        request_id: "bad".into(),
        program: Some(program.into()),
        ..GcodeRequest::default()
    };
    service.plan(request, &Budget::unlimited())
}

/// Item 2: every bad program of the table is answered with its error line: the lexer's, the
/// interpreter's, an arc's, a motion out of reach.
#[test]
fn every_program_error_names_its_line_in_error_line() {
    let service = service();
    // (program, the offending line, status)
    let table: &[(&str, u32, u8)] = &[
        // Lexer.
        ("G1 X1 F600\nG1 X2 (unclosed\n", 2, GcodePlan::PROGRAM_ERROR),
        ("G1 X1 F600\n\nG1 X#1\n", 3, GcodePlan::PROGRAM_ERROR),
        ("G21\nO100 sub\n", 2, GcodePlan::PROGRAM_ERROR),
        ("G1 X1 F600\nG1 X2 $\n", 2, GcodePlan::PROGRAM_ERROR),
        ("G1 X1 F600\nG1 X\n", 2, GcodePlan::PROGRAM_ERROR),
        ("G1 X1 F600\nG1 X1e999999\n", 2, GcodePlan::PROGRAM_ERROR),
        ("G21\n% text\n", 2, GcodePlan::PROGRAM_ERROR),
        ("G1 X1 F600\nG1 N5 X2\n", 2, GcodePlan::PROGRAM_ERROR),
        // Interpreter.
        ("G21\nG93 G1 X1 F1\n", 2, GcodePlan::PROGRAM_ERROR),
        ("G1 X1 F600\nG0 G1 X2\n", 2, GcodePlan::PROGRAM_ERROR),
        ("G1 X1 F600\nG1 X2 Y1 X3\n", 2, GcodePlan::PROGRAM_ERROR),
        ("G21\nG90\nG1 X1\n", 3, GcodePlan::PROGRAM_ERROR),
        ("G21\nX1\n", 2, GcodePlan::PROGRAM_ERROR),
        ("G1 X1 F600\nG4 P-1\n", 2, GcodePlan::PROGRAM_ERROR),
        ("G1 X1 F600\nG4\n", 2, GcodePlan::PROGRAM_ERROR),
        ("G1 X1 F600\nG1 X2 I1\n", 2, GcodePlan::PROGRAM_ERROR),
        ("G1 X1 F-1\n", 1, GcodePlan::PROGRAM_ERROR),
        ("G1 X1 F600\nG1.5 X2\n", 2, GcodePlan::PROGRAM_ERROR),
        ("G1 X1 F600\nM6\n", 2, GcodePlan::PROGRAM_ERROR),
        // Arcs.
        (
            "G1 X10 F600\nG3 X0 Y10 I0 J5\n",
            2,
            GcodePlan::PROGRAM_ERROR,
        ),
        ("G1 X10 F600\nG2 X0 Y0\n", 2, GcodePlan::PROGRAM_ERROR),
        ("G1 X10 F600\nG2 X0 Y0 R0\n", 2, GcodePlan::PROGRAM_ERROR),
        ("G1 X10 F600\nG2 X30 Y0 R1\n", 2, GcodePlan::PROGRAM_ERROR),
        (
            "G1 X10 F600\nG2 X0 Y0 I-5 P0\n",
            2,
            GcodePlan::PROGRAM_ERROR,
        ),
        // A motion out of reach.
        (
            "G21 G90\nG1 X100 F1000\nG1 X1500\n",
            3,
            GcodePlan::UNREACHABLE,
        ),
    ];
    for (program, line, status) in table {
        let a = answer(&service, program);
        assert_eq!(
            (a.status, a.error_line),
            (*status, *line),
            "{program:?}: {}",
            a.message
        );
        assert!(
            a.message.contains(&format!("line {line}")),
            "{program:?}: {}",
            a.message
        );
    }
    // Not a program line's: 0.
    let a = answer(&service, "G21\n(nothing moves)\n");
    assert_eq!((a.status, a.error_line), (GcodePlan::PROGRAM_ERROR, 0));
}

/// Item 2 with the planner's own limits: the line limit (its first line beyond), an arc that
/// needs more chords than points allowed, an arc with no tolerance left for its chords.
#[test]
fn the_planners_limits_name_their_line_in_error_line() {
    let laser = LaserSheet::default_sheet().unwrap();
    let request = GcodeRequest::default();
    let cases: [(&str, PlanSettings, u32); 4] = [
        (
            "G1 X1 F600\nG1 X2\nG1 X3\nG1 X4\n",
            PlanSettings::laser_cutter().with_max_lines(3),
            4,
        ),
        (
            "G1 X1 F600\n(a)\n(b)\n(c)\n(d)\n",
            PlanSettings::laser_cutter().with_max_lines(3),
            4,
        ),
        (
            "G1 X1 F600\nG2 X1 Y0 I100000 J0\n",
            PlanSettings::laser_cutter().with_max_points(100),
            2,
        ),
        (
            "G1 X10 F600\nG1 Y1\nG3 X0 Y10 R10\n",
            PlanSettings {
                approximation_share: 0.0,
                ..PlanSettings::laser_cutter()
            },
            3,
        ),
    ];
    for (program, settings, line) in cases {
        let e =
            plan_program(program.as_bytes(), &laser, &settings, &Budget::unlimited()).unwrap_err();
        let m = convert::error_to_msg(&request, "laser-cutter", &e);
        assert_eq!(m.error_line, line, "{program:?}: {e}");
        assert_eq!(m.status, GcodePlan::INVALID_REQUEST, "{program:?}: {e}");
        assert!(m.message.contains(&format!("line {line}")), "{}", m.message);
    }
    // Errors of no program line keep 0.
    for e in [
        GcodePlanError::TooManyPoints { max: 5 },
        GcodePlanError::Empty {
            reason: "none".into(),
        },
    ] {
        assert_eq!(convert::error_line(&e), 0);
    }
}

/// Item 3: the message's field names and the earlier names give the same request; an unknown
/// key is still refused.
#[test]
fn text_requests_take_the_message_names_and_the_earlier_ones() {
    let pairs: [(&str, &str); 4] = [
        (
            "request_id: a\nprogram_uri: /tmp/part.ngc\n",
            "request_id: a\nprogram_file: /tmp/part.ngc\n",
        ),
        (
            "program: \"G1 X1 F600\"\nhas_limits: true\nmax_feed: 0.1\nnormal_jerk: 50.0\n",
            "program: \"G1 X1 F600\"\nlimits: {max_feed: 0.1, normal_jerk: 50.0}\n",
        ),
        (
            "program: \"G1 X1 F600\"\nhas_placement: true\norigin: {x: 0.3, y: 0.2, z: 0.5}\n\
             standoff_axis: -0.05\n",
            "program: \"G1 X1 F600\"\norigin: [0.3, 0.2, 0.5]\nstandoff_axis: -0.05\n",
        ),
        (
            "program: \"G1 X1 F600\"\nstart: given\nstart_positions: [0.1, 0.2, 0.3]\n",
            "program: \"G1 X1 F600\"\nstart: [0.1, 0.2, 0.3]\n",
        ),
    ];
    for (message_names, earlier_names) in pairs {
        let a = text::parse_request(message_names).unwrap_or_else(|e| panic!("{}", e.error));
        let b = text::parse_request(earlier_names).unwrap_or_else(|e| panic!("{}", e.error));
        assert_eq!(a, b, "{message_names:?} vs {earlier_names:?}");
    }
    // The JSON form of a message (every field, flags false: their groups not given) reads.
    let json = serde_json_text();
    let r = text::parse_request(&json).unwrap_or_else(|e| panic!("{}", e.error));
    assert_eq!(r.program.as_deref(), Some("G1 X1 F600"));
    assert_eq!(r.limits, None);
    assert_eq!(r.origin, None);
    // Unknown keys are refused, as before (an origin with a fourth coordinate as not a
    // point).
    for (bad, says) in [
        (
            "program: \"G1 X1 F600\"\nprogram_path: x\n",
            "unknown field",
        ),
        (
            "program: \"G1 X1 F600\"\nlimits: {max_speed: 1.0}\n",
            "unknown field",
        ),
        ("program: \"G1 X1 F600\"\non: true\n", "unknown field"),
        (
            "program: \"G1 X1 F600\"\norigin: {x: 0.3, y: 0.2, z: 0.5, w: 1}\n",
            "origin as",
        ),
    ] {
        let e = text::parse_request(bad).unwrap_err();
        assert!(e.error.to_string().contains(says), "{bad:?}: {}", e.error);
    }
}

/// A message-shaped text request: the fields a YAML dump of `kerf_msgs/msg/GcodeRequest`
/// holds that the text form reads with their meaning (the groups' flags false).
fn serde_json_text() -> String {
    r#"{"request_id": "m", "machine": "laser-cutter", "program": "G1 X1 F600",
        "method": "kerf", "feed_method": "near-optimal", "has_limits": false,
        "rapid_feed": 0.1, "has_placement": false, "start": "none"}"#
        .to_string()
}

/// Item 4: the answer's tool events are written `tool_on`, a key YAML 1.1 readers take for
/// text; kerf's reader takes it, and still takes the earlier `on`.
#[test]
fn tool_events_are_written_tool_on_and_read_either_way() {
    let plan = GcodePlan {
        request_id: "events".into(),
        tool_events: vec![
            GcodeToolEvent {
                time: 0.5,
                tool_on: true,
                line: 2,
            },
            GcodeToolEvent {
                time: 1.5,
                tool_on: false,
                line: 5,
            },
        ],
        ..GcodePlan::default()
    };
    let text = answer_text(&plan);
    // YAML 1.1's booleans (yes/no/on/off/y/n/true/false, any case): no key of the answer is one.
    let yaml11_bool = |key: &str| {
        ["y", "yes", "n", "no", "true", "false", "on", "off"]
            .contains(&key.to_ascii_lowercase().as_str())
    };
    for line in text.lines() {
        let body = line.trim_start().trim_start_matches("- ");
        if let Some((key, _)) = body.split_once(':') {
            assert!(!yaml11_bool(key.trim()), "key {key:?} in\n{text}");
        }
    }
    assert!(text.contains("tool_on: true"), "{text}");
    let back: GcodePlan = kerf_robot::document::from_yaml_or_json(&text).unwrap();
    assert_eq!(back, plan);
    // The earlier key still reads.
    let earlier = text.replace("tool_on:", "on:");
    assert_ne!(earlier, text);
    let back: GcodePlan = kerf_robot::document::from_yaml_or_json(&earlier).unwrap();
    assert_eq!(back.tool_events, plan.tool_events);
}

/// Issue 30, item 3: a `drls-net` request is planned by the learned corner, and the answer
/// counts the corners that fell back to the swarm (here the 178.85° corner outside the trained
/// distribution) and says why among its warnings.
#[test]
fn a_drls_net_answer_counts_its_fallbacks() {
    let service = service();
    let request = GcodeRequest {
        request_id: "drls".into(),
        method: Some(kerf_msgs::msg::GcodeRequest::METHOD_DRLS_NET.into()),
        program: Some(
            "G21 G90\nM3\nG1 X20 F3000\nG1 X20 Y15\nG1 X0 Y15\nG1 X20 Y15.4\nM5\n".into(),
        ),
        ..GcodeRequest::default()
    };
    let answer = service.plan(request, &Budget::unlimited());
    assert_eq!(answer.status, GcodePlan::SUCCESS, "{}", answer.message);
    assert_eq!(answer.method, "drls-net");
    assert_eq!(answer.corners, 3);
    assert_eq!(answer.corner_fallbacks, 1, "{:?}", answer.warnings);
    assert!(
        answer
            .warnings
            .iter()
            .any(|w| w.contains("1 of 3 corners fell back") && w.contains("turning angle")),
        "{:?}",
        answer.warnings
    );
    assert!(answer.max_corner_deviation <= answer.tolerance);
}
