//! Text requests of `~/cut_request_text` (`std_msgs/String`) and the text form of plans.
//!
//! A text request is either
//!
//! * **YAML (or JSON)**: the request file schema of `kerf plan cut`
//!   ([`kerf_mjto::CutRequest`]: `points: [[x, y, z], …]`, `axes`, `feedrate`, …, `options`).
//!   A text is read as YAML when its first non-blank character is `{` or one of its lines
//!   starts with `points:`.
//! * **the line format**, otherwise: one CL point per line as six numbers `x y z i j k` (the
//!   point in m and the unit tool axis, workpiece frame; separated by spaces, tabs or commas),
//!   plus `key: value` lines for the parameters. The keys are the scalar fields of
//!   `kerf_msgs/msg/CutRequest`, with the same units and the same "0 = default" rules:
//!   `request_id`, `feedrate`, `feed_acceleration`, `feed_jerk`, `sample_period`,
//!   `max_lead_angle`, `max_tilt_angle`, `mesh`, `workpiece_pose` (seven numbers
//!   `x y z qx qy qz qw`), `control_points`, `max_iterations`, `gfd_q4_steps`, `gfd_q5_steps`,
//!   `gfd_q6_steps`, `gfd_q4_half_range`, `gfd_q5_half_range`, `rto_indices` (integers
//!   separated by spaces or commas), `rto_spacing`, `rto_angle`, `reference_standoff` (giving
//!   it sets `has_reference_standoff`), `clearance`, `rto_constraint` (`box` or `equality`),
//!   `orientation_corridor` (`allowance` or `none`), `time_budget`, `start` (`current`,
//!   `given` or `none`) and `start_positions` (numbers separated by spaces or commas, with
//!   `start: given`). `feedrate`, `sample_period`,
//!   `max_lead_angle`, `max_tilt_angle` and `mesh` are required; every key may appear once.
//!   Blank lines and lines starting with `#` are ignored (comments are whole lines: a value
//!   is never cut at `#`); points keep their order even when key lines come between them.
//!
//! ```text
//! # slot 3: three CL points, axis tilting towards +y
//! request_id: slot-3
//! feedrate: 0.3333
//! sample_period: 0.004
//! max_lead_angle: 0.087
//! max_tilt_angle: 0.087
//! mesh: package://kerf/meshes/plate.stl
//! 0.10 0.20 0.30  0 0 1
//! 0.15 0.20 0.30  0 0.6 0.8
//! 0.20 0.20 0.30  0 0 1
//! ```
//!
//! Any other line is refused with its line number. Every number of either form is checked
//! against the declared rule of its `kerf_msgs/msg/CutRequest` field ([`kerf_msgs::numbers`]:
//! finite, range, not denormal where it divides), named as in the message (`points[2].y`,
//! `gfd_q4_steps` for the YAML's `options.gfd.q4_steps`), like a message's; the values' meaning
//! (unit axes, increasing indices, …) is checked by [`kerf_mjto::CutRequest::validate`].

use kerf_mjto::{CutRequest, PlanError};
use kerf_msgs::{
    geometry_msgs::{Point, Pose, Quaternion, Vector3},
    msg,
};

use kerf_ros::planner::yaml_field;

use kerf_msgs::numbers::{check_value, Number, NumberRules};

use crate::convert::{check_numbers, number_error, request_from_msg};

/// A text request that could not be turned into a [`CutRequest`] (its `planner` is always
/// empty: cut requests have none).
pub type TextRequestError = kerf_ros::planner::TextRequestError<PlanError>;

/// Whether `text` is read as YAML/JSON (else as the line format); see the module docs.
pub fn is_yaml(text: &str) -> bool {
    text.trim_start().starts_with('{') || text.lines().any(|l| l.starts_with("points:"))
}

/// Parses a text request in either form.
///
/// # Errors
/// [`TextRequestError`] with the request id when the text names one: YAML syntax or schema
/// errors (field `request`), line-format errors (field `line N`), a zero quaternion.
pub fn parse_request(text: &str) -> Result<CutRequest, TextRequestError> {
    if is_yaml(text) {
        CutRequest::from_yaml(text)
            .and_then(|r| check_yaml_numbers(&r).map(|()| r))
            .map_err(|error| TextRequestError {
                request_id: yaml_field(text, "request_id"),
                planner: String::new(),
                error: Box::new(error),
            })
    } else {
        parse_lines(text)
            .and_then(|m| check_numbers(&m).and_then(|()| request_from_msg(&m)))
            .map_err(|error| TextRequestError {
                request_id: line_request_id(text),
                planner: String::new(),
                error: Box::new(error),
            })
    }
}

/// Checks every number of a YAML request against the rule of its `CutRequest` message field,
/// named as in the message. The YAML's `options.weights` have no message field: the planner's
/// validation checks them (finite, >= 0).
///
/// # Errors
/// [`PlanError::InvalidRequest`] naming the first field outside its rule.
pub fn check_yaml_numbers(r: &CutRequest) -> Result<(), PlanError> {
    let rules = <msg::CutRequest as NumberRules>::SECTIONS;
    let float = |path: &str, v: f64| check_value(rules, path, Number::Float(v));
    let count = |path: &str, v: usize| {
        let value = i128::try_from(v).unwrap_or(i128::MAX);
        let max = i128::from(u32::MAX);
        check_value(rules, path, Number::Int { value, min: 0, max })
    };
    let xyz = ["x", "y", "z"];
    let run = || -> Result<(), kerf_msgs::numbers::NumberError> {
        for (name, list) in [("points", &r.points), ("axes", &r.axes)] {
            for (i, p) in list.iter().enumerate() {
                for (c, v) in xyz.iter().zip(p) {
                    float(&format!("{name}[{i}].{c}"), *v)?;
                }
            }
        }
        float("feedrate", r.feedrate)?;
        float("feed_acceleration", r.feed_acceleration)?;
        float("feed_jerk", r.feed_jerk)?;
        float("sample_period", r.sample_period)?;
        float("max_lead_angle", r.max_lead_angle)?;
        float("max_tilt_angle", r.max_tilt_angle)?;
        for (c, v) in xyz.iter().zip(&r.workpiece_pose.position) {
            float(&format!("workpiece_pose.position.{c}"), *v)?;
        }
        for (c, v) in ["x", "y", "z", "w"]
            .iter()
            .zip(&r.workpiece_pose.orientation)
        {
            float(&format!("workpiece_pose.orientation.{c}"), *v)?;
        }
        let o = &r.options;
        count("control_points", o.control_points)?;
        count("max_iterations", o.max_iterations)?;
        count("gfd_q4_steps", o.gfd.q4_steps)?;
        count("gfd_q5_steps", o.gfd.q5_steps)?;
        count("gfd_q6_steps", o.gfd.q6_steps)?;
        float("gfd_q4_half_range", o.gfd.q4_half_range)?;
        float("gfd_q5_half_range", o.gfd.q5_half_range)?;
        for (i, v) in o.rto_indices.iter().enumerate() {
            count(&format!("rto_indices[{i}]"), *v)?;
        }
        float("rto_spacing", o.rto_spacing)?;
        float("rto_angle", o.rto_angle)?;
        float("reference_standoff", o.reference_standoff)?;
        float("clearance", o.clearance)?;
        float("cl_tolerance", o.cl_tolerance)?;
        float("time_budget", r.time_budget)
    };
    run().map_err(number_error)
}

/// `request_id` of a line-format text (empty if none).
fn line_request_id(text: &str) -> String {
    text.lines()
        .filter_map(|l| l.trim().split_once(':'))
        .find(|(k, _)| k.trim() == "request_id")
        .map(|(_, v)| v.trim().to_string())
        .unwrap_or_default()
}

fn line_err(line: usize, reason: impl Into<String>) -> PlanError {
    PlanError::invalid(format!("line {line}"), reason)
}

/// Numbers of a value or data line, or `None` if one token is not a number.
fn numbers(s: &str) -> Option<Vec<f64>> {
    s.split(|c: char| c.is_whitespace() || c == ',')
        .filter(|t| !t.is_empty())
        .map(|t| t.parse::<f64>().ok())
        .collect()
}

fn number(line: usize, key: &str, value: &str) -> Result<f64, PlanError> {
    value
        .parse::<f64>()
        .map_err(|_| line_err(line, format!("{key}: {} is not a number", excerpt(value))))
}

fn count(line: usize, key: &str, value: &str) -> Result<u32, PlanError> {
    value.parse::<u32>().map_err(|_| {
        line_err(
            line,
            format!("{key}: {} is not a non-negative integer", excerpt(value)),
        )
    })
}

/// Longest quotation of request text in an error message (characters).
const EXCERPT_CHARS: usize = 60;

/// `text` quoted for an error message: whole when short, else its first [`EXCERPT_CHARS`]
/// characters and its length (an error never echoes a whole 4 MiB line back).
fn excerpt(text: &str) -> String {
    if text.chars().count() <= EXCERPT_CHARS {
        return format!("{text:?}");
    }
    let head: String = text.chars().take(EXCERPT_CHARS).collect();
    format!("{head:?}… ({} bytes)", text.len())
}

/// Parses the line format into a `CutRequest` message (defaults are applied later, by
/// [`request_from_msg`], exactly as for a message).
///
/// # Errors
/// [`PlanError::InvalidRequest`] naming the line: a line that is neither six numbers nor
/// `key: value`, an unknown or repeated key, a value that is not a number (or not a
/// non-negative integer for counts), a `workpiece_pose` without seven numbers, a missing
/// required key (field `request`).
pub fn parse_lines(text: &str) -> Result<msg::CutRequest, PlanError> {
    let mut m = msg::CutRequest::default();
    let mut seen: Vec<&str> = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let n = i + 1;
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        if let Some(v) = numbers(line).filter(|v| v.len() == 6) {
            m.points.push(Point {
                x: v[0],
                y: v[1],
                z: v[2],
            });
            m.axes.push(Vector3 {
                x: v[3],
                y: v[4],
                z: v[5],
            });
            continue;
        }
        let Some((key, value)) = line.split_once(':') else {
            return Err(line_err(
                n,
                format!(
                    "{} is neither a CL point `x y z i j k` (six numbers) nor `key: value`",
                    excerpt(line)
                ),
            ));
        };
        let (key, value) = (key.trim(), value.trim());
        if seen.contains(&key) {
            return Err(line_err(n, format!("{key} is given twice")));
        }
        match key {
            "request_id" => m.request_id = value.to_string(),
            "rto_constraint" => m.rto_constraint = value.to_string(),
            "orientation_corridor" => m.orientation_corridor = value.to_string(),
            "mesh" => m.mesh = value.to_string(),
            "feed_law" => m.feed_law = value.to_string(),
            "start" => m.start = value.to_string(),
            "start_positions" => {
                let list = value.trim_start_matches('[').trim_end_matches(']');
                m.start_positions = list
                    .split(|c: char| c.is_whitespace() || c == ',')
                    .filter(|t| !t.is_empty())
                    .map(|t| number(n, key, t))
                    .collect::<Result<_, _>>()?;
            }
            "feedrate" => m.feedrate = number(n, key, value)?,
            "feed_acceleration" => m.feed_acceleration = number(n, key, value)?,
            "feed_jerk" => m.feed_jerk = number(n, key, value)?,
            "sample_period" => m.sample_period = number(n, key, value)?,
            "max_lead_angle" => m.max_lead_angle = number(n, key, value)?,
            "max_tilt_angle" => m.max_tilt_angle = number(n, key, value)?,
            "gfd_q4_half_range" => m.gfd_q4_half_range = number(n, key, value)?,
            "gfd_q5_half_range" => m.gfd_q5_half_range = number(n, key, value)?,
            "rto_spacing" => m.rto_spacing = number(n, key, value)?,
            "rto_angle" => m.rto_angle = number(n, key, value)?,
            "clearance" => m.clearance = number(n, key, value)?,
            "cl_tolerance" => m.cl_tolerance = number(n, key, value)?,
            "time_budget" => m.time_budget = number(n, key, value)?,
            "reference_standoff" => {
                m.reference_standoff = number(n, key, value)?;
                m.has_reference_standoff = true;
            }
            "control_points" => m.control_points = count(n, key, value)?,
            "max_iterations" => m.max_iterations = count(n, key, value)?,
            "gfd_q4_steps" => m.gfd_q4_steps = count(n, key, value)?,
            "gfd_q5_steps" => m.gfd_q5_steps = count(n, key, value)?,
            "gfd_q6_steps" => m.gfd_q6_steps = count(n, key, value)?,
            "rto_indices" => {
                m.rto_indices = value
                    .split(|c: char| c.is_whitespace() || c == ',')
                    .filter(|t| !t.is_empty())
                    .map(|t| count(n, key, t))
                    .collect::<Result<_, _>>()?;
            }
            "workpiece_pose" => {
                let v = numbers(value).filter(|v| v.len() == 7).ok_or_else(|| {
                    line_err(
                        n,
                        format!(
                            "workpiece_pose: {} is not seven numbers x y z qx qy qz qw",
                            excerpt(value)
                        ),
                    )
                })?;
                m.workpiece_pose = Pose {
                    position: Point {
                        x: v[0],
                        y: v[1],
                        z: v[2],
                    },
                    orientation: Quaternion {
                        x: v[3],
                        y: v[4],
                        z: v[5],
                        w: v[6],
                    },
                };
            }
            other => {
                return Err(line_err(
                    n,
                    format!(
                        "unknown key {}; the keys are the scalar fields of \
                         kerf_msgs/msg/CutRequest (request_id, feedrate, sample_period, \
                         max_lead_angle, max_tilt_angle, mesh, ...)",
                        excerpt(other)
                    ),
                ))
            }
        }
        // `key` borrows `text`, which outlives `seen`.
        seen.push(key);
    }
    let missing: Vec<&str> = [
        "feedrate",
        "sample_period",
        "max_lead_angle",
        "max_tilt_angle",
        "mesh",
    ]
    .into_iter()
    .filter(|k| !seen.contains(k))
    .collect();
    if !missing.is_empty() {
        return Err(PlanError::invalid(
            "request",
            format!("missing key(s): {}", missing.join(", ")),
        ));
    }
    Ok(m)
}

/// The YAML text of a `CutPlan` message, as published on `~/cut_plan_text` (the same document
/// `kerf echo /mjto_planner/cut_plan` prints): [`kerf_ros::planner::answer_text`].
pub fn plan_text(plan: &msg::CutPlan) -> String {
    kerf_ros::planner::answer_text(plan)
}

#[cfg(test)]
mod tests {
    use super::*;
    use kerf_mjto::error::status;

    const LINES: &str = "\
# a two-segment slot
request_id: slot-3
feedrate: 0.3333
sample_period: 0.004
max_lead_angle: 0.087
max_tilt_angle: 0.087
mesh: package://kerf/meshes/plate.stl
0.10 0.20 0.30  0 0 1
0.15 0.20 0.30  0 0.6 0.8

0.20 0.20 0.30\t0 0 1
reference_standoff: 0
rto_indices: 0, 2
workpiece_pose: 1 2 3 0 0 0 1
feed_law: constant
";

    #[test]
    fn line_format_parses() {
        assert!(!is_yaml(LINES));
        let r = parse_request(LINES).unwrap();
        assert_eq!(r.request_id, "slot-3");
        assert_eq!(
            r.points,
            vec![[0.10, 0.20, 0.30], [0.15, 0.20, 0.30], [0.20, 0.20, 0.30]]
        );
        assert_eq!(r.axes[1], [0.0, 0.6, 0.8]);
        assert_eq!(r.feedrate, 0.3333);
        assert_eq!(r.sample_period, 0.004);
        assert_eq!(r.mesh, "package://kerf/meshes/plate.stl");
        // 0 = default for the ramps, the explicit standoff 0 is kept.
        assert_eq!((r.feed_acceleration, r.feed_jerk), (8.0, 80.0));
        assert_eq!(r.options.reference_standoff, 0.0);
        assert_eq!(r.options.rto_indices, vec![0, 2]);
        assert_eq!(r.workpiece_pose.position, [1.0, 2.0, 3.0]);
        assert_eq!(
            r.options.feed_law,
            kerf_mjto::optimal_feed::FeedMode::Constant
        );
        r.validate().unwrap();
    }

    #[test]
    fn both_forms_take_the_start() {
        use kerf_approach::StartSpec;
        let text = format!("{LINES}start: given\nstart_positions: [0.8, 0.7, 1.5, 0, 0, -0.05]\n");
        let r = parse_request(&text).unwrap();
        assert_eq!(
            r.start,
            StartSpec::Given(vec![0.8, 0.7, 1.5, 0.0, 0.0, -0.05])
        );
        let r = parse_request(&format!("{LINES}start: none\n")).unwrap();
        assert_eq!(r.start, StartSpec::None);
        assert_eq!(parse_request(LINES).unwrap().start, StartSpec::Default);
        let e = parse_request(&format!("{LINES}start: home\n")).unwrap_err();
        assert!(e.to_string().contains("\"home\""), "{e}");
        let e = parse_request(&format!("{LINES}start_positions: 1 2\n")).unwrap_err();
        assert!(
            e.to_string().contains("only read with start \"given\""),
            "{e}"
        );
        let e =
            parse_request(&format!("{LINES}start: given\nstart_positions: 1 nan\n")).unwrap_err();
        assert!(e.to_string().contains("start_positions"), "{e}");
        let yaml =
            "request_id: y1\npoints: [[0, 0, 0], [0.1, 0, 0]]\naxes: [[0, 0, 1], [0, 0, 1]]\n\
                    feedrate: 0.3\nsample_period: 0.01\nmax_lead_angle: 0.1\n\
                    max_tilt_angle: 0.1\nmesh: m.stl\nstart: [0.8, 0.7, 1.5, 0, 0, -0.05]\n";
        assert_eq!(
            parse_request(yaml).unwrap().start,
            StartSpec::Given(vec![0.8, 0.7, 1.5, 0.0, 0.0, -0.05])
        );
        let yaml = yaml.replace("start: [0.8, 0.7, 1.5, 0, 0, -0.05]", "start: current");
        assert_eq!(parse_request(&yaml).unwrap().start, StartSpec::Current);
    }

    #[test]
    fn line_format_takes_the_rto_constraint() {
        let text = format!("{LINES}rto_constraint: equality\n");
        let r = parse_request(&text).unwrap();
        assert_eq!(
            r.options.rto_constraint,
            kerf_mjto::request::RtoConstraint::Equality
        );
        let e = parse_request(&format!("{LINES}rto_constraint: sideways\n")).unwrap_err();
        assert!(e.to_string().contains("rto_constraint"), "{e}");
    }

    #[test]
    fn yaml_parses() {
        let yaml =
            "request_id: y1\npoints: [[0, 0, 0], [0.1, 0, 0]]\naxes: [[0, 0, 1], [0, 0, 1]]\n\
                    feedrate: 0.3\nsample_period: 0.01\nmax_lead_angle: 0.1\n\
                    max_tilt_angle: 0.1\nmesh: m.stl\noptions: {max_iterations: 4}\n";
        assert!(is_yaml(yaml));
        let r = parse_request(yaml).unwrap();
        assert_eq!(r.request_id, "y1");
        assert_eq!(r.points.len(), 2);
        assert_eq!(r.options.max_iterations, 4);
        // JSON is YAML.
        let json = r#"{"request_id": "j", "points": [[0,0,0],[0.1,0,0]], "axes": [[0,0,1],[0,0,1]],
            "feedrate": 0.3, "sample_period": 0.01, "max_lead_angle": 0.1,
            "max_tilt_angle": 0.1, "mesh": "m.stl"}"#;
        assert!(is_yaml(json));
        assert_eq!(parse_request(json).unwrap().request_id, "j");
    }

    #[test]
    fn yaml_errors_keep_the_request_id() {
        let e = parse_request("request_id: bad-1\npoints: [[0, 0, 0]]\nspeed: 3\n").unwrap_err();
        assert_eq!(e.request_id, "bad-1");
        assert_eq!(e.error.status(), status::INVALID_REQUEST);
        assert!(e.to_string().contains("speed"), "{e}");
        let e = parse_request("points: [[0, 0").unwrap_err();
        assert_eq!(e.request_id, "");
    }

    #[test]
    fn line_errors_name_the_line() {
        let cases = [
            ("0 0 0 0 0\n", "line 1", "neither a CL point"),
            ("feedrate: 0.3\nfeedrate: 0.4\n", "line 2", "given twice"),
            ("speed: 3\n", "line 1", "unknown key \"speed\""),
            ("feedrate: fast\n", "line 1", "\"fast\" is not a number"),
            (
                "max_iterations: -2\n",
                "line 1",
                "not a non-negative integer",
            ),
            (
                "rto_indices: 0 x 3\n",
                "line 1",
                "\"x\" is not a non-negative integer",
            ),
            ("workpiece_pose: 0 0 0 1\n", "line 1", "seven numbers"),
            ("feedrate: 0.3 # comment\n", "line 1", "not a number"),
        ];
        for (text, field, reason) in cases {
            let e = parse_lines(text).unwrap_err().to_string();
            assert!(e.contains(field) && e.contains(reason), "{text:?}: {e}");
        }
        let e = parse_lines("request_id: q\n1 2 3 0 0 1\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("feedrate, sample_period, max_lead_angle, max_tilt_angle, mesh"),
            "{e}"
        );
        let e = parse_request("request_id: q7\nwhat\n").unwrap_err();
        assert_eq!(e.request_id, "q7");
    }

    #[test]
    fn non_finite_values_are_refused_naming_the_message_field() {
        let text = LINES.replace("0.15 0.20 0.30", "0.15 NaN 0.30");
        let e = parse_request(&text).unwrap_err();
        assert_eq!(e.request_id, "slot-3");
        let e = e.to_string();
        assert!(e.contains("points[1].y") && e.contains("finite"), "{e}");
        let text = LINES.replace("feedrate: 0.3333", "feedrate: inf");
        let e = parse_request(&text).unwrap_err();
        assert!(e.to_string().contains("feedrate"), "{e}");
    }

    #[test]
    fn zero_quaternion_in_text_is_refused() {
        let text = LINES.replace(
            "workpiece_pose: 1 2 3 0 0 0 1",
            "workpiece_pose: 1 2 3 0 0 0 0",
        );
        let e = parse_request(&text).unwrap_err();
        assert_eq!(e.request_id, "slot-3");
        assert!(e.to_string().contains("zero quaternion"), "{e}");
    }

    #[test]
    fn plan_text_is_the_message_as_yaml() {
        let plan = crate::convert::failure_msg("p1", status::MESH_ERROR, "no such file");
        let text = plan_text(&plan);
        let back: msg::CutPlan = serde_yaml_ng::from_str(&text).unwrap();
        assert_eq!(back, plan);
        assert!(text.contains("status: 2"), "{text}");
    }
}
