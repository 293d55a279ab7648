//! The text form of requests: YAML and JSON of the `kerf_millplan::MillRequest` schema; errors
//! keep the request id and planner so the answer can carry them.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_milling_planner::{convert, text};
use kerf_msgs::msg;

#[test]
fn yaml_and_json_parse() {
    let r = text::parse_request(
        "request_id: t1\npoints: [[1.4, -0.3, 1.7], [2.1, 0.3, 1.7]]\nplanner: naive\n\
         limits: {feed: [0.01, 0.05]}\ninitial: {feed: 0.02}\n",
    )
    .unwrap();
    assert_eq!(r.request_id, "t1");
    assert_eq!(r.points, vec![[1.4, -0.3, 1.7], [2.1, 0.3, 1.7]]);
    assert_eq!(r.planner, "naive");
    assert_eq!(r.limits.unwrap().feed, Some([0.01, 0.05]));
    assert_eq!(r.initial_state(), [2000.0, 0.02, 0.0]);
    r.validate().unwrap();
    // JSON is YAML; the planner defaults to best (issue 28).
    let r = text::parse_request(r#"{"points": [[1.4, -0.3, 1.7], [2.1, 0.3, 1.7]]}"#).unwrap();
    assert_eq!((r.request_id.as_str(), r.planner.as_str()), ("", "best"));
}

#[test]
fn errors_keep_id_and_planner() {
    let e = text::parse_request("request_id: bad-1\nplanner: dp\npoints: [[0, 0, 0]]\nspeed: 3\n")
        .unwrap_err();
    assert_eq!((e.request_id.as_str(), e.planner.as_str()), ("bad-1", "dp"));
    assert!(e.to_string().contains("unknown field `speed`"), "{e}");
    let m = convert::error_to_msg(&e.request_id, &e.planner, &e.error);
    assert_eq!(m.status, msg::MillPlan::INVALID_REQUEST);
    assert_eq!((m.request_id.as_str(), m.planner.as_str()), ("bad-1", "dp"));

    let e = text::parse_request("request_id: no-points\n").unwrap_err();
    assert_eq!(e.request_id, "no-points");
    assert!(e.to_string().contains("missing field `points`"), "{e}");
    let e = text::parse_request("points: [[0, 0").unwrap_err();
    assert_eq!(e.request_id, "");
    for empty in ["", "  \n"] {
        let e = text::parse_request(empty).unwrap_err();
        assert!(e.to_string().contains("the text is empty"), "{e}");
    }
}

#[test]
fn nan_in_text_is_refused_naming_the_message_field() {
    // Issue 33: the text's numbers are checked by the rules of the message's fields.
    let e = text::parse_request("points: [[1.4, -0.3, 1.7], [2.1, .nan, 1.7]]\n")
        .unwrap_err()
        .to_string();
    assert!(e.contains("points[1].y") && e.contains("finite"), "{e}");
    let e = text::parse_request(
        "points: [[1.4, -0.3, 1.7], [2.1, 0.3, 1.7]]\nlimits: {spindle_rpm: [2000, .inf]}\n",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("spindle_max_rpm"), "{e}");
}
