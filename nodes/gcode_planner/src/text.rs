//! The text form of requests and answers, for users without the `kerf_msgs` package.
//!
//! `~/gcode_request_text` (`std_msgs/String`) carries a YAML (or JSON) document of the
//! [`kerf_gcodeplan::GcodeRequest`] schema — the request file of `kerf plan gcode` — e.g.
//!
//! ```yaml
//! request_id: part-7
//! program: "G21 G90\nM3\nG1 X20 Y0 F3000\nG1 X20 Y20\nG1 X0 Y20\nG1 X0 Y0\nM5\nM30\n"
//! tolerance: 1.0e-4
//! ```
//!
//! Its keys are the message's field names (`program_uri`, `has_limits`, `max_feed`, …,
//! `has_placement`, `start_positions`); the earlier names (`program_file`, `limits: {…}`,
//! `origin: [x, y, z]`, `start: [q…]`) are still read, and an unknown key is refused
//! ([`kerf_gcodeplan::request::RequestText`]).
//!
//! Every number is checked against the declared rule of its `kerf_msgs/msg/GcodeRequest`
//! field ([`kerf_msgs::numbers`]), named as in the message
//! ([`crate::convert::check_text_numbers`]).
//!
//! `~/gcode_plan_text` carries each `GcodePlan` answer as YAML.

use kerf_gcodeplan::{GcodePlanError, GcodeRequest};
use kerf_ros::planner::yaml_field;

/// A text request that could not be read, with its request id when the text names one.
pub type TextRequestError = kerf_ros::planner::TextRequestError<GcodePlanError>;

/// Parses a text request.
///
/// # Errors
/// [`TextRequestError`]: an empty text, YAML syntax errors, unknown fields, wrong types.
pub fn parse_request(text: &str) -> Result<GcodeRequest, TextRequestError> {
    if text.trim().is_empty() {
        return Err(TextRequestError {
            request_id: String::new(),
            planner: String::new(),
            error: Box::new(GcodePlanError::InvalidRequest {
                field: "request".to_string(),
                reason: "the text is empty; send a YAML GcodeRequest such as \
                         `{program: \"G1 X10 F600\"}`"
                    .to_string(),
            }),
        });
    }
    GcodeRequest::from_yaml_str(text)
        .and_then(|r| crate::convert::check_text_numbers(&r).map(|()| r))
        .map_err(|error| TextRequestError {
            request_id: yaml_field(text, "request_id"),
            planner: yaml_field(text, "method"),
            error: Box::new(error),
        })
}
