//! Request documents: JSON is read as JSON where YAML cannot read it (`\u` escapes of
//! characters outside the Basic Multilingual Plane are UTF-16 surrogate pairs in JSON, which
//! YAML refuses), and YAML flow style keeps working.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_mjto::CutRequest;

const JSON: &str = r#"{
  "request_id": "slot \ud83d\ude00 \u00e9\u4e2d",
  "points": [[0.6, 0.2, 0.1], [0.7, 0.2, 0.1]],
  "axes": [[0, 0, 1], [0, 0, 1]],
  "feedrate": 0.3,
  "sample_period": 0.004,
  "max_lead_angle": 0.1,
  "max_tilt_angle": 0.1,
  "mesh": "m.stl"
}"#;

#[test]
fn json_with_unicode_escapes_parses() {
    let r = CutRequest::from_yaml(JSON).expect("JSON request");
    assert_eq!(r.request_id, "slot \u{1F600} \u{e9}\u{4e2d}");
    assert_eq!(r.points.len(), 2);
}

#[test]
fn yaml_flow_style_and_errors_still_come_from_yaml() {
    let flow = "{request_id: flow-1, points: [[0.6, 0.2, 0.1], [0.7, 0.2, 0.1]], \
                axes: [[0, 0, 1], [0, 0, 1]], feedrate: 0.3, sample_period: 0.004, \
                max_lead_angle: 0.1, max_tilt_angle: 0.1, mesh: m.stl}";
    assert_eq!(CutRequest::from_yaml(flow).unwrap().request_id, "flow-1");
    // Neither YAML nor JSON: the YAML parser's message (with its position).
    let e = CutRequest::from_yaml("{request_id: [")
        .unwrap_err()
        .to_string();
    assert!(e.contains("request"), "{e}");
    // JSON with an unknown field: refused, naming it.
    let e = CutRequest::from_yaml(&JSON.replace("\"feedrate\"", "\"feed_rate\""))
        .unwrap_err()
        .to_string();
    assert!(e.contains("feed_rate"), "{e}");
}

/// Issue 11, row 8: a document nested 10^5 levels deep (200 KB) is refused before it is parsed
/// (YAML parsing took 31 s, quadratic in the depth), naming the depth and the limit.
#[test]
fn deep_nesting_is_refused_before_parsing() {
    let deep = format!("request_id: deep\npoints: {}\n", "[".repeat(100_000));
    let e = CutRequest::from_yaml(&deep).unwrap_err().to_string();
    assert!(
        e.contains("levels deep") && e.contains("limit of 32"),
        "{e}"
    );
}

/// Issue 11, row 7: a GFD grid of 101 × 101 × 101 (each dimension allowed alone) is refused
/// before planning, naming the fields, the product and the limit.
#[test]
fn gfd_grids_are_bounded_as_a_product() {
    let mut r = CutRequest::from_yaml(JSON).unwrap();
    r.options.gfd.q4_steps = 101;
    r.options.gfd.q5_steps = 101;
    r.options.gfd.q6_steps = 101;
    let e = r.validate().unwrap_err().to_string();
    assert!(
        e.contains("options.gfd") && e.contains("1030301 candidates") && e.contains("10000"),
        "{e}"
    );
    // The default grid and one at the limit's scale are accepted.
    r.options.gfd.q4_steps = 21;
    r.options.gfd.q5_steps = 21;
    r.options.gfd.q6_steps = 21;
    assert!(r.validate().is_ok());
}

/// Found by fuzzing (issue 11, item 7; fuzz/corpus/cut_text/overflow-*.txt): finite
/// coordinates near f64::MAX, alone or moved by the workpiece pose, gave an infinite or NaN
/// path length that validation accepted, and a short segment after a huge one left the path
/// length unchanged (repeated arc-length parameters). They are refused, naming the point.
#[test]
fn path_lengths_that_overflow_are_refused() {
    let mut r = CutRequest::from_yaml(JSON).unwrap();
    r.points = vec![[1e308, -1e308, 0.0], [-1e308, 1e308, 0.0]];
    let e = r.validate().unwrap_err().to_string();
    assert!(
        e.contains("points[1]") && e.contains("coordinates too large"),
        "{e}"
    );
    // Each point is fine, the pose moves them out of range.
    r.points = vec![[1e308, 0.0, 0.0], [1.7e308, 0.0, 0.0]];
    r.workpiece_pose.position = [1e308, 0.0, 0.0];
    let e = r.validate().unwrap_err().to_string();
    assert!(
        e.contains("points[1]") && e.contains("coordinates too large"),
        "{e}"
    );
    // A short segment after a huge one is lost in the rounding of the path length.
    r.workpiece_pose.position = [0.0; 3];
    r.points = vec![[0.6, 1.8e20, 0.0], [0.6, 0.2, 0.1], [0.7, 0.2, 0.1]];
    r.axes = vec![[0.0, 0.0, 1.0]; 3];
    let e = r.validate().unwrap_err().to_string();
    assert!(
        e.contains("points[2]") && e.contains("coordinates too large"),
        "{e}"
    );
    // Large but representable lengths are not refused here (the machine's reach is checked
    // by the planner).
    r.points = vec![[1e100, 0.0, 0.0], [2e100, 0.0, 0.0]];
    r.axes = vec![[0.0, 0.0, 1.0]; 2];
    let v = r.validate().unwrap();
    assert!(v.sigma.is_finite() && v.sigma > 0.0);
}
