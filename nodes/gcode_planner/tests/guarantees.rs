//! The G-code service's guarantees of issue 33, without DDS (the service's own calls, as the
//! harness makes them): a FIFO, a device or a directory named by `program_uri` is answered
//! INVALID_REQUEST at once, before it is queued and again if it is swapped in before the plan;
//! non-finite numbers are refused naming the field; a heavy program under the budget the
//! harness hands over ends TIMEOUT or RESOURCE_LIMIT naming what grew; and a valid request right
//! after each is planned.
#![allow(clippy::unwrap_used)]

use std::time::{Duration, Instant};

use kerf_budget::{Budget, CancelToken};
use kerf_gcode_planner::GcodeService;
use kerf_gcodeplan::{GcodeRequest, MachineBase, MachineKind};
use kerf_msgs::msg;
use kerf_ros::planner::PlanningService;

fn service() -> GcodeService {
    GcodeService::new(MachineBase::load(MachineKind::LaserCutter).unwrap()).unwrap()
}

fn budget() -> Budget {
    Budget::new(Some(Duration::from_secs(2)), CancelToken::new()).with_memory(Some(256 << 20))
}

/// A valid request plans (the service is still serving).
fn still_plans(s: &GcodeService) {
    let r = s
        .request_from_text("{request_id: ok, program: \"M3\\nG1 X20 F3000\\nG1 Y20\\nM5\\n\"}")
        .unwrap();
    let answer = s.plan(r, &budget());
    assert_eq!(answer.status, msg::GcodePlan::SUCCESS, "{}", answer.message);
}

fn scratch(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("kerf_gcode_node_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn a_fifo_device_or_directory_program_uri_is_answered_at_once() {
    let s = service();
    let d = scratch("fifo");
    let fifo = d.join("part.ngc");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: mkfifo(3) on a NUL-terminated path we own.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    for (path, expect) in [
        (fifo.display().to_string(), "FIFO"),
        ("/dev/zero".to_string(), "not a regular file"),
        (d.display().to_string(), "a directory"),
    ] {
        let started = Instant::now();
        let m = msg::GcodeRequest {
            request_id: "bad-file".into(),
            program_uri: path.clone(),
            ..msg::GcodeRequest::default()
        };
        let answer = *s.request_from_msg(&m).err().unwrap();
        assert!(started.elapsed() < Duration::from_secs(15), "hang guard");
        assert_eq!(answer.status, msg::GcodePlan::INVALID_REQUEST, "{path}");
        assert!(
            answer.message.contains(expect),
            "{path}: {}",
            answer.message
        );
        assert!(answer.message.contains("program_uri"), "{}", answer.message);
        assert_eq!(answer.request_id, "bad-file");
        still_plans(&s);
    }
    // A FIFO swapped in after the request was queued: the plan refuses it without blocking.
    let queued = GcodeRequest {
        request_id: "swapped".into(),
        program_file: Some(fifo.display().to_string()),
        ..GcodeRequest::default()
    };
    let started = Instant::now();
    let answer = s.plan(queued, &budget());
    assert!(started.elapsed() < Duration::from_secs(15), "hang guard");
    assert_eq!(answer.status, msg::GcodePlan::INVALID_REQUEST);
    assert!(answer.message.contains("FIFO"), "{}", answer.message);
    still_plans(&s);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn non_finite_numbers_are_refused_naming_the_field() {
    let s = service();
    for (text, field) in [
        (
            "{program: \"G1 X1 F100\", time_budget: .nan}",
            "time_budget",
        ),
        (
            "{program: \"G1 X1 F100\", time_budget: .inf}",
            "time_budget",
        ),
        (
            "{program: \"G1 X1 F100\", redundancy_angle: .nan}",
            "redundancy_angle",
        ),
        (
            "{program: \"G1 X1 F100\", limits: {max_feed: 5.0e-324}}",
            "max_feed",
        ),
        (
            "{program: \"G1 X1 F100\", limits: {tangential_acceleration: 5.0e-324}}",
            "tangential_acceleration",
        ),
        (
            "{program: \"G1 X1 F100\", limits: {tangential_jerk: 5.0e-324}}",
            "tangential_jerk",
        ),
    ] {
        let answer = *s.request_from_text(text).err().unwrap();
        assert_eq!(answer.status, msg::GcodePlan::INVALID_REQUEST, "{text}");
        assert!(answer.message.contains(field), "{text}: {}", answer.message);
    }
    still_plans(&s);
}

#[test]
fn a_heavy_program_ends_in_a_named_budget_status() {
    let s = service();
    // The 60-byte helix of the probe: more chords than an answer carries, refused as read.
    let helix = "{request_id: helix, program: \"G21 G17\\nG1 X10 F3000\\nG2 X10 Y0 Z-5 I-10 J0 \
                 P10000\\n\"}";
    let answer = s.plan(s.request_from_text(helix).unwrap(), &budget());
    assert_eq!(
        answer.status,
        msg::GcodePlan::INVALID_REQUEST,
        "{}",
        answer.message
    );
    assert!(answer.message.contains("chords"), "{}", answer.message);
    // 10⁵ full circles (5·10⁶ chords) under a 16 MiB memory budget: RESOURCE_LIMIT naming the
    // program's runs.
    let mut circles = String::from("{request_id: circles, program: \"G21 G17\\nG1 X10 F3000\\n");
    for _ in 0..100_000 {
        circles.push_str("G2 X10 Y0 I-5 J0\\n");
    }
    circles.push_str("\"}");
    let small =
        Budget::new(Some(Duration::from_secs(2)), CancelToken::new()).with_memory(Some(16 << 20));
    let started = Instant::now();
    let answer = s.plan(s.request_from_text(&circles).unwrap(), &small);
    assert!(started.elapsed() < Duration::from_secs(15), "hang guard");
    assert_eq!(
        answer.status,
        msg::GcodePlan::RESOURCE_LIMIT,
        "{}",
        answer.message
    );
    assert!(
        answer.message.contains("program runs"),
        "{}",
        answer.message
    );
    // 1 500 NURBS corners under 2 s: TIMEOUT naming the swarm.
    let mut program = String::from("M3\\nF3000\\n");
    for k in 1..=1500u32 {
        program.push_str(&format!("G1 X{} Y{}\\n", k.div_ceil(2), k / 2));
    }
    let text = format!("{{request_id: nurbs, method: nurbs, program: \"{program}\"}}");
    let started = Instant::now();
    let answer = s.plan(s.request_from_text(&text).unwrap(), &budget());
    assert!(started.elapsed() < Duration::from_secs(15), "hang guard");
    assert_eq!(answer.status, msg::GcodePlan::TIMEOUT, "{}", answer.message);
    assert!(answer.message.contains("NURBS"), "{}", answer.message);
    still_plans(&s);
}
