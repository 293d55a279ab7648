//! Issue 33, item 1: every numeric field of a `CutRequest`, set to NaN, ±inf, ±0, 5e-324,
//! ±1e308 and the integer extremes, through `check_numbers` and the service's
//! `request_from_msg`, and through the text path (the line format) with the same value: never
//! a panic, and every value outside the field's declared rule refused naming the field.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_mjto::error::status;
use kerf_mjto::LaserMachine;
use kerf_mjto_planner::CutService;
use kerf_msgs::geometry_msgs::{Point, Pose, Quaternion, Vector3};
use kerf_msgs::msg::CutRequest;
use kerf_msgs::numbers::probe::{expected, probe_values, with_value};
use kerf_msgs::numbers::{leaves, NumberFields};
use kerf_ros::planner::PlanningService;

/// A valid request with every array non-empty and every flag set: the two-point cut of the
/// allowed-roots test on the shipped B-pillar mesh.
fn request() -> CutRequest {
    CutRequest {
        request_id: "numbers".into(),
        points: vec![
            Point {
                x: 0.6,
                y: 0.2,
                z: 0.1,
            },
            Point {
                x: 0.7,
                y: 0.2,
                z: 0.1,
            },
        ],
        axes: vec![
            Vector3 {
                x: 0.0,
                y: 0.0,
                z: 1.0
            };
            2
        ],
        feedrate: 0.3,
        feed_acceleration: 8.0,
        feed_jerk: 80.0,
        sample_period: 0.01,
        max_lead_angle: 0.1,
        max_tilt_angle: 0.1,
        mesh: "package://kerf/urdf/meshes/bpillar.obj".into(),
        workpiece_pose: Pose {
            position: Point {
                x: 0.0,
                y: 0.0,
                z: 0.0,
            },
            orientation: Quaternion::IDENTITY,
        },
        max_iterations: 10,
        gfd_q4_steps: 13,
        gfd_q5_steps: 9,
        gfd_q6_steps: 5,
        gfd_q4_half_range: 0.35,
        gfd_q5_half_range: 0.3,
        rto_indices: vec![0, 1],
        rto_spacing: 0.15,
        rto_angle: 0.35,
        has_reference_standoff: true,
        reference_standoff: -0.07,
        clearance: 0.0,
        cl_tolerance: 1.5e-4,
        time_budget: 10.0,
        ..Default::default()
    }
}

/// The message in the line format of `~/cut_request_text` (every field it has a key for).
fn line_text(m: &CutRequest) -> String {
    let p = &m.workpiece_pose;
    let mut t = format!(
        "request_id: {}\nmesh: {}\nfeedrate: {}\nfeed_acceleration: {}\nfeed_jerk: {}\n\
         sample_period: {}\nmax_lead_angle: {}\nmax_tilt_angle: {}\n\
         workpiece_pose: {} {} {} {} {} {} {}\ncontrol_points: {}\nmax_iterations: {}\n\
         gfd_q4_steps: {}\ngfd_q5_steps: {}\ngfd_q6_steps: {}\ngfd_q4_half_range: {}\n\
         gfd_q5_half_range: {}\nrto_spacing: {}\nrto_angle: {}\nreference_standoff: {}\n\
         clearance: {}\ncl_tolerance: {}\ntime_budget: {}\n",
        m.request_id,
        m.mesh,
        m.feedrate,
        m.feed_acceleration,
        m.feed_jerk,
        m.sample_period,
        m.max_lead_angle,
        m.max_tilt_angle,
        p.position.x,
        p.position.y,
        p.position.z,
        p.orientation.x,
        p.orientation.y,
        p.orientation.z,
        p.orientation.w,
        m.control_points,
        m.max_iterations,
        m.gfd_q4_steps,
        m.gfd_q5_steps,
        m.gfd_q6_steps,
        m.gfd_q4_half_range,
        m.gfd_q5_half_range,
        m.rto_spacing,
        m.rto_angle,
        m.reference_standoff,
        m.clearance,
        m.cl_tolerance,
        m.time_budget,
    );
    let indices: Vec<String> = m.rto_indices.iter().map(|i| i.to_string()).collect();
    t.push_str(&format!("rto_indices: {}\n", indices.join(" ")));
    for (p, a) in m.points.iter().zip(&m.axes) {
        t.push_str(&format!(
            "{} {} {} {} {} {}\n",
            p.x, p.y, p.z, a.x, a.y, a.z
        ));
    }
    t
}

#[test]
fn every_numeric_field_is_refused_by_its_rule_on_both_paths() {
    let service = CutService::new(LaserMachine::default_machine().unwrap(), String::new()).unwrap();
    let example = request();
    assert_eq!(example.check_numbers(), Ok(()));
    assert!(service.request_from_msg(&example).is_ok());
    assert!(service.request_from_text(&line_text(&example)).is_ok());
    let mut refused = 0;
    for leaf in leaves(&example) {
        for value in probe_values(leaf.value) {
            let m = with_value(&example, &leaf.path, value).unwrap();
            let checked = m.check_numbers();
            // The harness calls check_numbers, then request_from_msg: the conversion is run
            // on every value anyway, and must not panic.
            let _ = service.request_from_msg(&m);
            let text = service.request_from_text(&line_text(&m));
            match expected::<CutRequest>(&leaf.key, value) {
                Ok(()) => assert_eq!(checked, Ok(()), "{} = {value}", leaf.path),
                Err(_) => {
                    refused += 1;
                    let e = checked.expect_err(&leaf.path);
                    assert_eq!(e.field, leaf.path);
                    let answer = text.expect_err(&format!("text {} = {value}", leaf.path));
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
fn yaml_text_numbers_are_refused_by_the_message_field() {
    let service = CutService::new(LaserMachine::default_machine().unwrap(), String::new()).unwrap();
    let base = "request_id: y\npoints: [[0.6, 0.2, 0.1], [0.7, 0.2, 0.1]]\n\
                axes: [[0, 0, 1], [0, 0, 1]]\nfeedrate: 0.3\nsample_period: 0.01\n\
                max_lead_angle: 0.1\nmax_tilt_angle: 0.1\n\
                mesh: package://kerf/urdf/meshes/bpillar.obj\n";
    assert!(service.request_from_text(base).is_ok());
    let cases = [
        ("points: [[0.6, 0.2, 0.1], [0.7, .nan, 0.1]]", "points[1].y"),
        ("sample_period: 1.0e-300", "sample_period"),
        ("time_budget: .inf", "time_budget"),
        ("options: {gfd: {q4_steps: 4294967297}}", "gfd_q4_steps"),
        ("options: {cl_tolerance: 5.0e-324}", "cl_tolerance"),
        (
            "workpiece_pose: {position: [0, 0, 1.0e308], orientation: [0, 0, 0, 1]}",
            "workpiece_pose.position.z",
        ),
    ];
    for (line, field) in cases {
        let key = line.split(':').next().unwrap();
        let text: String = base
            .lines()
            .filter(|l| !l.starts_with(&format!("{key}:")))
            .chain([line])
            .collect::<Vec<_>>()
            .join("\n");
        let answer = service.request_from_text(&text).unwrap_err();
        assert_eq!(answer.status, status::INVALID_REQUEST, "{}", answer.message);
        assert!(answer.message.contains(field), "{line}: {}", answer.message);
    }
}

#[test]
fn the_message_rule_of_time_budget_is_the_budget_crate_s() {
    assert_eq!(
        kerf_msgs::numbers::cut::MAX_TIME_BUDGET,
        kerf_budget::MAX_BUDGET_SECONDS
    );
}
