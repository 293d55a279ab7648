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

/// How much of a text request over [`MAX_TEXT_REQUEST_BYTES`] is looked at for its
/// `request_id` ([`leading_request_id`]): 64 KiB.
pub const LEADING_BYTES: usize = 64 << 10;

/// The `request_id` a text request gives in its first [`LEADING_BYTES`], read without parsing
/// the document: a top-level YAML line `request_id: VALUE` (plain, or in quotes without
/// escapes; a trailing ` # comment` dropped) or a JSON member `"request_id": "VALUE"` (without
/// escapes). Empty when there is none or its value is not that simple. The answer to a text
/// request refused for its size carries it, so that the sender can match the refusal.
///
/// # Performance
/// One pass over at most [`LEADING_BYTES`] bytes; nothing is allocated but the result.
pub fn leading_request_id(text: &str) -> String {
    let mut end = text.len().min(LEADING_BYTES);
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    let head = &text[..end];
    if head.trim_start().starts_with('{') {
        return json_request_id(head).unwrap_or_default().to_string();
    }
    head.lines()
        .find_map(|line| line.strip_prefix("request_id:"))
        .and_then(yaml_scalar)
        .unwrap_or_default()
        .to_string()
}

/// A YAML plain or quoted scalar without escapes (`a-1`, `"a 1"`, `'a'`), its comment dropped.
fn yaml_scalar(value: &str) -> Option<&str> {
    let v = value.trim();
    for q in ['"', '\''] {
        if let Some(inner) = v.strip_prefix(q) {
            let (inner, _) = inner.split_once(q)?;
            return (!inner.contains('\\')).then_some(inner);
        }
    }
    let v = v.split(" #").next().unwrap_or_default().trim_end();
    let special = v.chars().next().is_none_or(|c| "{[&*!|>%@`#,".contains(c));
    (!special).then_some(v)
}

/// The string value of a JSON member `"request_id": "…"` without escapes.
fn json_request_id(head: &str) -> Option<&str> {
    let at = head.find("\"request_id\"")? + "\"request_id\"".len();
    let rest = head[at..].trim_start().strip_prefix(':')?.trim_start();
    let (value, _) = rest.strip_prefix('"')?.split_once('"')?;
    (!value.contains('\\')).then_some(value)
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
    fn an_over_size_request_still_names_its_id() {
        use super::leading_request_id as id;
        let pad = "#".repeat(super::MAX_TEXT_REQUEST_BYTES);
        assert_eq!(id(&format!("request_id: big-1\n{pad}")), "big-1");
        assert_eq!(id(&format!("# x\nrequest_id: 'big 2'  \n{pad}")), "big 2");
        assert_eq!(id("request_id: a-3 # the third\n"), "a-3");
        assert_eq!(
            id(&format!(
                "{{\"points\": [], \"request_id\": \"j-4\", \"x\": \"{pad}\"}}"
            )),
            "j-4"
        );
        // Not simple, nested, or past the first 64 KiB: none.
        assert_eq!(id("request_id: {a: 1}\n"), "");
        assert_eq!(id("request_id: \"a\\\"b\"\n"), "");
        assert_eq!(id("  request_id: nested\n"), "");
        assert_eq!(id(&format!("{pad}\nrequest_id: late\n")), "");
        assert_eq!(id(""), "");
        // A multi-byte character at the 64 KiB boundary.
        let long = format!("request_id: é-5\n{}", "é".repeat(40_000));
        assert_eq!(id(&long), "é-5");
    }

    #[test]
    fn text_requests_have_a_size_limit() {
        assert!(super::check_text_size("request_id: a\n").is_ok());
        let big = "#".repeat(super::MAX_TEXT_REQUEST_BYTES + 1);
        let e = super::check_text_size(&big).unwrap_err();
        assert!(e.contains("over the limit of 4194304 bytes"), "{e}");
    }
}
