//! `launch_scripts/cut_request_msg.py` (the README's `ros2 topic pub` helper) turns each
//! committed case file into a `kerf_msgs/msg/CutRequest` that the planner node reads back as
//! exactly the request of the file.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::{path::Path, process::Command};

use kerf_mjto::CutRequest;
use kerf_msgs::msg;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

#[test]
fn case_files_become_equivalent_cut_request_messages() {
    for case in ["case1.yaml", "case2.yaml"] {
        let path = Path::new(ROOT).join("crates/mjto/cases").join(case);
        let out = Command::new("python3")
            .arg(Path::new(ROOT).join("launch_scripts/cut_request_msg.py"))
            .arg(&path)
            .output()
            .expect("python3 runs");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let message: msg::CutRequest =
            serde_json::from_slice(&out.stdout).expect("the output is a CutRequest message");
        let from_msg = kerf_mjto_planner::convert::request_from_msg(&message).expect("converts");
        let file = CutRequest::from_yaml(&std::fs::read_to_string(&path).unwrap()).unwrap();
        assert_eq!(from_msg, file, "{case}");
    }
}

#[test]
fn changed_weights_are_refused() {
    let path = Path::new(ROOT).join("crates/mjto/cases/case1.yaml");
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.contains("    k2: 0.5\n"));
    let dir = std::env::temp_dir().join(format!("kerf-msg-script-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let changed = dir.join("weights.yaml");
    std::fs::write(&changed, text.replace("    k2: 0.5\n", "    k2: 0.7\n")).unwrap();
    let out = Command::new("python3")
        .arg(Path::new(ROOT).join("launch_scripts/cut_request_msg.py"))
        .arg(&changed)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("weights"));
    let _ = std::fs::remove_dir_all(dir);
}

/// Issue 27: a file's `start` (current, none or joint positions) becomes the message's start
/// and start_positions, which the node reads back as the file's start.
#[test]
fn the_start_of_a_file_becomes_the_messages() {
    let path = Path::new(ROOT).join("crates/mjto/cases/case1.yaml");
    let text = std::fs::read_to_string(path).unwrap();
    let dir = std::env::temp_dir().join(format!("kerf-msg-start-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (start, word, positions) in [
        ("current", "current", vec![]),
        ("none", "none", vec![]),
        (
            "[0.8, 0.7, 1.5, 0, 0, -0.05]",
            "given",
            vec![0.8, 0.7, 1.5, 0.0, 0.0, -0.05],
        ),
    ] {
        let file = dir.join("started.yaml");
        std::fs::write(&file, format!("{text}\nstart: {start}\n")).unwrap();
        let out = Command::new("python3")
            .arg(Path::new(ROOT).join("launch_scripts/cut_request_msg.py"))
            .arg(&file)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let message: msg::CutRequest = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(
            (message.start.as_str(), message.start_positions.clone()),
            (word, positions)
        );
        let from_msg = kerf_mjto_planner::convert::request_from_msg(&message).unwrap();
        let read = CutRequest::from_yaml(&std::fs::read_to_string(&file).unwrap()).unwrap();
        assert_eq!(from_msg.start, read.start, "{start}");
    }
    let file = dir.join("bad.yaml");
    std::fs::write(&file, format!("{text}\nstart: home\n")).unwrap();
    let out = Command::new("python3")
        .arg(Path::new(ROOT).join("launch_scripts/cut_request_msg.py"))
        .arg(&file)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("start"));
    let _ = std::fs::remove_dir_all(dir);
}
