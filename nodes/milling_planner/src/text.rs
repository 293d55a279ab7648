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
//! Unknown fields are refused; NaN (`.nan`) and infinities are refused by the planner's
//! validation, which names the field. Unlike the message form, a `policy_file` given for
//! `dp` or `naive` is ignored, as in `kerf plan mill`.
//!
//! `~/mill_plan_text` carries each `MillPlan` answer as YAML ([`plan_text`]).

use kerf_millplan::{MillPlanError, MillRequest};
use kerf_msgs::msg;

/// A text request that could not be turned into a [`MillRequest`].
#[derive(Debug)]
pub struct TextRequestError {
    /// The request id if the text names one (empty otherwise), so the answer can carry it.
    pub request_id: String,
    /// The `planner` field if the text names one (empty otherwise).
    pub planner: String,
    /// What is wrong ([`MillPlanError::InvalidConfig`] naming `request` with the parser's
    /// message, line and column); boxed to keep the `Result` small.
    pub error: Box<MillPlanError>,
}

impl std::fmt::Display for TextRequestError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.error.fmt(f)
    }
}

impl std::error::Error for TextRequestError {}

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
    MillRequest::from_yaml_str(text).map_err(|error| TextRequestError {
        request_id: yaml_string(text, "request_id"),
        planner: yaml_string(text, "planner"),
        error: Box::new(error),
    })
}

/// The string value of the top-level `key` of a YAML document that may not parse as a
/// request (empty if none).
fn yaml_string(text: &str, key: &str) -> String {
    serde_yaml_ng::from_str::<serde_yaml_ng::Value>(text)
        .ok()
        .and_then(|v| v.get(key).and_then(|r| r.as_str()).map(String::from))
        .unwrap_or_default()
}

/// The YAML text of a `MillPlan` message, as published on `~/mill_plan_text` (serde's YAML of
/// the message: every field, in `.msg` order).
pub fn plan_text(plan: &msg::MillPlan) -> String {
    serde_yaml_ng::to_string(plan).unwrap_or_else(|e| {
        // Only reachable if serde_yaml_ng refused a value; keep the essentials readable.
        format!(
            "request_id: {:?}\nstatus: {}\nmessage: {:?}\n# full plan not rendered: {e}\n",
            plan.request_id, plan.status, plan.message
        )
    })
}
