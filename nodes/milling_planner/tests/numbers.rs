//! Issue 33, item 1: every numeric field of a `MillRequest`, set to NaN, ±inf, ±0, 5e-324,
//! ±1e308 and the integer extremes, through `check_numbers` and the service's
//! `request_from_msg`, and through the YAML text path with the same value: never a panic, and
//! every value outside the field's declared rule refused naming the field.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_milling_planner::{convert, DefaultPolicies, MillService};
use kerf_millplan::{status, MillPlanner};
use kerf_msgs::geometry_msgs::Point;
use kerf_msgs::msg::MillRequest;
use kerf_msgs::numbers::probe::{expected, probe_values, with_value};
use kerf_msgs::numbers::{leaves, NumberFields};
use kerf_ros::planner::PlanningService;

/// A valid request with every group given (the cell's values of seed 004 Table 1), planner
/// naive (no policy file).
fn request() -> MillRequest {
    MillRequest {
        request_id: "numbers".into(),
        points: vec![
            Point {
                x: 1.4,
                y: -0.3,
                z: 1.7,
            },
            Point {
                x: 2.1,
                y: 0.3,
                z: 1.7,
            },
        ],
        segments: 10,
        has_process: true,
        teeth: 2,
        tool_radius: 0.04,
        axial_depth: 0.003,
        kt: 6.44e8,
        kn: 2.37e8,
        entry_angle: 0.75 * std::f64::consts::PI,
        exit_angle: std::f64::consts::PI,
        has_limits: true,
        spindle_min_rpm: 2000.0,
        spindle_max_rpm: 4000.0,
        feed_min: 0.0,
        feed_max: 0.06,
        g_min: -3.0,
        g_max: 3.0,
        max_spindle_step_rpm: 20.0,
        max_feed_step: 1e-3,
        max_g_step: 0.2,
        has_initial_state: true,
        initial_spindle_rpm: 2000.0,
        initial_feed: 0.04,
        initial_g: 0.0,
        planner: MillRequest::PLANNER_NAIVE.into(),
        time_budget: 10.0,
        has_tolerances: true,
        path_tolerance: 5e-5,
        min_condition_indicator: 0.01,
        ..Default::default()
    }
}

fn service() -> MillService {
    let policies = DefaultPolicies {
        ddpg: "/nonexistent/ddpg.safetensors".into(),
        fixed_g: "/nonexistent/fixed_g.safetensors".into(),
    };
    MillService::new(
        MillPlanner::with_default_cell().unwrap(),
        policies,
        String::new(),
    )
    .unwrap()
}

/// The message's YAML text form (the planner form of the same values).
fn yaml_text(m: &MillRequest) -> Option<String> {
    convert::request_from_msg(m).ok()?.to_yaml_string().ok()
}

#[test]
fn every_numeric_field_is_refused_by_its_rule_on_both_paths() {
    let service = service();
    let example = request();
    assert_eq!(example.check_numbers(), Ok(()));
    assert!(service.request_from_msg(&example).is_ok());
    let example_text = yaml_text(&example).unwrap();
    assert!(service.request_from_text(&example_text).is_ok());
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
            match expected::<MillRequest>(&leaf.key, value) {
                Ok(()) => assert_eq!(checked, Ok(()), "{} = {value}", leaf.path),
                Err(_) => {
                    refused += 1;
                    assert_eq!(checked.expect_err(&leaf.path).field, leaf.path);
                    // The text form carries every value of the message (all groups given).
                    let answer = answer
                        .expect("text form")
                        .expect_err(&format!("text {} = {value}", leaf.path));
                    assert_eq!(answer.status, status::INVALID_REQUEST, "{}", answer.message);
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
    assert!(refused > 100, "{refused}");
}

#[test]
fn the_issue_s_spindle_speed_is_refused_naming_the_field() {
    let service = service();
    let mut m = request();
    m.spindle_max_rpm = 1e308;
    let e = m.check_numbers().unwrap_err();
    assert_eq!(e.field, "spindle_max_rpm");
    let answer = service
        .request_from_text(
            "request_id: s\nplanner: naive\npoints: [[1.4, -0.3, 1.7], [2.1, 0.3, 1.7]]\n\
             limits: {spindle_rpm: [2000, 1.0e308]}\n",
        )
        .unwrap_err();
    assert_eq!(answer.status, status::INVALID_REQUEST);
    assert!(
        answer.message.contains("spindle_max_rpm"),
        "{}",
        answer.message
    );
}
