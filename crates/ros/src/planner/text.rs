//! What the text request topics of every planner node share: the error of a text request
//! that cannot be read, and the fields it can still name.

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
/// as a request (empty if the text is no YAML mapping or the key is no string).
pub fn yaml_field(text: &str, key: &str) -> String {
    serde_yaml_ng::from_str::<serde_yaml_ng::Value>(text)
        .ok()
        .and_then(|v| v.get(key).and_then(|r| r.as_str()).map(String::from))
        .unwrap_or_default()
}
