//! The text form of requests and answers, for users without the `kerf_msgs` package.
//!
//! `~/mill_request_text` (`std_msgs/String`) carries a YAML (or JSON) document of the
//! [`kerf_millplan::MillRequest`] schema — the request file of `kerf plan mill` — e.g.
//!
//! ```yaml
//! request_id: job-17
//! points: [[1.4, -0.3, 1.7], [1.6, -0.1, 1.7], [1.8, 0.1, 1.7], [2.1, 0.3, 1.7]]
//! planner: naive
//! ```
//!
//! Optional: `segments`, `process` (all seven fields), `limits` (each of `spindle_rpm`,
//! `feed`, `redundancy_angle` as `[min, max]` and `step_bounds`), `initial` (`spindle_rpm`,
//! `feed`, `g`), `planner` (`ddpg` default, `fixed_g`, `dp`, `naive`) and `policy_file`.
//! Unknown fields are refused. Every number is checked against the declared rule of its
//! `kerf_msgs/msg/MillRequest` field ([`kerf_msgs::numbers`]: finite, range, not denormal
//! where it divides), named as in the message (`limits.spindle_rpm: [a, b]` are
//! `spindle_min_rpm` and `spindle_max_rpm`); the planner's validation checks the rest
//! (min < max, coplanar points, …). Unlike the message form, a `policy_file` given for
//! `dp` or `naive` is ignored, as in `kerf plan mill`.
//!
//! `~/mill_plan_text` carries each `MillPlan` answer as YAML ([`plan_text`]).

use kerf_millplan::{MillPlanError, MillRequest};
use kerf_msgs::msg;
use kerf_ros::planner::yaml_field;

/// A text request that could not be turned into a [`MillRequest`]: its request id and
/// planner when the text names them, and the error ([`MillPlanError::InvalidConfig`] naming
/// `request` with the parser's message, line and column).
pub type TextRequestError = kerf_ros::planner::TextRequestError<MillPlanError>;

/// Parses a text request.
///
/// # Errors
/// [`TextRequestError`] with the request id and planner when the text names them: an empty
/// text, YAML syntax errors, unknown or missing fields, wrong types.
pub fn parse_request(text: &str) -> Result<MillRequest, TextRequestError> {
    if text.trim().is_empty() {
        return Err(TextRequestError {
            request_id: String::new(),
            planner: String::new(),
            error: Box::new(MillPlanError::InvalidConfig {
                name: "request".to_string(),
                reason: "the text is empty; send a YAML MillRequest such as \
                         `{points: [[1.4, -0.3, 1.7], [2.1, 0.3, 1.7]], planner: naive}`"
                    .to_string(),
            }),
        });
    }
    MillRequest::from_yaml_str(text)
        .and_then(|r| crate::convert::check_text_numbers(&r).map(|()| r))
        .map_err(|error| TextRequestError {
            request_id: yaml_field(text, "request_id"),
            planner: yaml_field(text, "planner"),
            error: Box::new(error),
        })
}

/// The YAML text of a `MillPlan` message, as published on `~/mill_plan_text` (serde's YAML of
/// the message: every field, in `.msg` order): [`kerf_ros::planner::answer_text`].
pub fn plan_text(plan: &msg::MillPlan) -> String {
    kerf_ros::planner::answer_text(plan)
}
