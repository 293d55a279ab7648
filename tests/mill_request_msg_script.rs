//! `launch_scripts/mill_request_msg.py` (the `ros2 topic pub` helper of the milling planner)
//! turns request files into `kerf_msgs/msg/MillRequest` messages that the node reads back as
//! the request of the file, and refuses what the message cannot carry (a partial `limits`).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::{path::Path, process::Command};

use kerf_millplan::MillRequest;
use kerf_msgs::msg;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

const FULL: &str = "\
request_id: job-17
points: [[1.4, -0.3, 1.7], [1.6, -0.1, 1.7], [1.8, 0.1, 1.7], [2.1, 0.3, 1.7]]
segments: 50
process:
  {teeth: 3, tool_radius: 0.035, axial_depth: 0.002, kt: 6.44e8, kn: 2.37e8,
   entry_angle: 2.356194490192345, exit_angle: 3.141592653589793}
limits:
  spindle_rpm: [2100, 3900]
  feed: [0.0, 0.05]
  redundancy_angle: [-1.5, 2.0]
  step_bounds: {spindle_rpm: 15, feed: 0.0005, redundancy_angle: 0.1}
initial: {spindle_rpm: 2500, feed: 0.03}
planner: fixed_g
policy_file: /policies/fixed.safetensors
allow_chatter: true
entry: in_material
";

fn script(file: &Path) -> std::process::Output {
    Command::new("python3")
        .arg(Path::new(ROOT).join("launch_scripts/mill_request_msg.py"))
        .arg(file)
        .output()
        .expect("python3 runs")
}

fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "kerf-mill-msg-script-{name}-{}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn request_files_become_equivalent_mill_request_messages() {
    let dir = scratch("good");
    let cases = [
        ("full.yaml", FULL.to_string()),
        (
            "minimal.yaml",
            "points: [[1.4, -0.3, 1.7], [2.1, 0.3, 1.7]]\nplanner: naive\n".to_string(),
        ),
        (
            "default_planner.json",
            r#"{"request_id": "j", "points": [[1.4, -0.3, 1.7], [2.1, 0.3, 1.7]]}"#.to_string(),
        ),
    ];
    for (name, text) in cases {
        let path = dir.join(name);
        std::fs::write(&path, &text).unwrap();
        let out = script(&path);
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let message: msg::MillRequest =
            serde_json::from_slice(&out.stdout).expect("the output is a MillRequest message");
        let from_msg = kerf_milling_planner::convert::request_from_msg(&message).expect("converts");
        let file = MillRequest::from_file(&path).unwrap();
        // The same request: the message carries whole groups, so `initial` is compared by its
        // effective values.
        assert_eq!(from_msg.request_id, file.request_id, "{name}");
        assert_eq!(from_msg.points, file.points, "{name}");
        assert_eq!(from_msg.segments, file.segments, "{name}");
        assert_eq!(from_msg.process, file.process, "{name}");
        assert_eq!(from_msg.limits, file.limits, "{name}");
        assert_eq!(from_msg.initial_state(), file.initial_state(), "{name}");
        assert_eq!(from_msg.initial.is_some(), file.initial.is_some(), "{name}");
        assert_eq!(from_msg.planner, file.planner, "{name}");
        assert_eq!(from_msg.policy_file, file.policy_file, "{name}");
        assert_eq!(from_msg.allow_chatter, file.allow_chatter, "{name}");
        assert_eq!(from_msg.entry().unwrap(), file.entry().unwrap(), "{name}");
        from_msg.validate().unwrap();
    }
    let full: msg::MillRequest =
        serde_json::from_slice(&script(&dir.join("full.yaml")).stdout).unwrap();
    assert_eq!((full.kt, full.teeth, full.segments), (6.44e8, 3, 50));
    assert_eq!(
        (full.initial_spindle_rpm, full.initial_feed, full.initial_g),
        (2500.0, 0.03, 0.0)
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn what_the_message_cannot_carry_is_refused() {
    let dir = scratch("bad");
    let cases = [
        (
            "partial_limits.yaml",
            "points: [[1.4, -0.3, 1.7], [2.1, 0.3, 1.7]]\nlimits: {feed: [0, 0.05]}\n",
            "limits lacks spindle_rpm, redundancy_angle, step_bounds.spindle_rpm",
        ),
        (
            "unknown.yaml",
            "points: [[1.4, -0.3, 1.7], [2.1, 0.3, 1.7]]\nspeed: 3\n",
            "unknown field(s) speed",
        ),
        (
            "entry.yaml",
            "points: [[1.4, -0.3, 1.7], [2.1, 0.3, 1.7]]\nentry: plunge\n",
            "entry: 'plunge' must be run_in or in_material",
        ),
        ("no_points.yaml", "planner: dp\n", "missing field points"),
        (
            "bad_number.yaml",
            "points: [[1.4, -0.3, 1.7], [2.1, fast, 1.7]]\n",
            "points[1]: 'fast' is not a number",
        ),
    ];
    for (name, text, needle) in cases {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        let out = script(&path);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{name}");
        assert!(stderr.contains(needle), "{name}: {stderr}");
    }
    let _ = std::fs::remove_dir_all(dir);
}
