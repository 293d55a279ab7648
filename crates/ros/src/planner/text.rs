//! What the text request topics of every planner node share: the error of a text request
//! that cannot be read, and the fields it can still name.

/// Largest text request read (4 MiB, about 60 000 CL points in the line format; what DDS
/// delivers promptly, [`super::MAX_ANSWER_BYTES`]); a larger one is answered INVALID_REQUEST
/// before any parsing.
pub const MAX_TEXT_REQUEST_BYTES: usize = super::MAX_ANSWER_BYTES;

/// Checks the size of a text request before it is parsed.
///
/// # Returns
/// The reason it is refused, naming the size and the limit, or `Ok`.
pub fn check_text_size(text: &str) -> Result<(), String> {
    if text.len() > MAX_TEXT_REQUEST_BYTES {
        return Err(format!(
            "the text request is {} bytes, over the limit of {MAX_TEXT_REQUEST_BYTES} bytes",
            text.len()
        ));
    }
    Ok(())
}

/// A text request that could not be turned into a request.
#[derive(Debug)]
pub struct TextRequestError<E> {
    /// The request id if the text names one (empty otherwise), so the answer can carry it.
    pub request_id: String,
    /// The `planner` field if the text names one (empty otherwise, and for services whose
    /// requests have none).
    pub planner: String,
    /// What is wrong (the service's error, naming the field or line); boxed to keep the
    /// `Result` small.
    pub error: Box<E>,
}

impl<E: std::fmt::Display> std::fmt::Display for TextRequestError<E> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.error.fmt(f)
    }
}

impl<E: std::fmt::Debug + std::fmt::Display> std::error::Error for TextRequestError<E> {}

/// The string value of the top-level `key` of a YAML (or JSON) document that may not parse
/// as a request (empty if the text is no YAML or JSON mapping or the key is no string).
pub fn yaml_field(text: &str, key: &str) -> String {
    if text.len() > MAX_TEXT_REQUEST_BYTES {
        // Not parsed at all: the request is refused for its size anyway.
        return String::new();
    }
    // Too deep a document is not parsed either (kerf_robot::document::check_depth).
    kerf_robot::document::from_yaml_or_json::<serde_yaml_ng::Value>(text)
        .ok()
        .and_then(|v| v.get(key).and_then(|r| r.as_str()).map(String::from))
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::yaml_field;

    #[test]
    fn fields_of_yaml_and_of_json_yaml_cannot_read() {
        assert_eq!(yaml_field("{request_id: a-1, x: [", "request_id"), "");
        assert_eq!(yaml_field("request_id: a-1\nx: 1\n", "request_id"), "a-1");
        let json = r#"{"request_id": "b \ud83d\ude00", "points": 3}"#;
        assert_eq!(yaml_field(json, "request_id"), "b \u{1F600}");
        assert_eq!(yaml_field(json, "points"), "");
        // Too deep to be parsed at all (YAML parsing is quadratic in the depth).
        let deep = format!("request_id: x\nd: {}\n", "[".repeat(100_000));
        assert_eq!(yaml_field(&deep, "request_id"), "");
    }

    #[test]
    fn text_requests_have_a_size_limit() {
        assert!(super::check_text_size("request_id: a\n").is_ok());
        let big = "#".repeat(super::MAX_TEXT_REQUEST_BYTES + 1);
        let e = super::check_text_size(&big).unwrap_err();
        assert!(e.contains("over the limit of 4194304 bytes"), "{e}");
    }
}
