//! [`nesting_depth`]: how deeply a YAML or JSON document nests, found by one linear scan
//! before any parser sees it. YAML parsers take time quadratic in the nesting depth (200 KB
//! of `[` nested 10⁵ deep took 31 s), so kerf refuses documents nested deeper than
//! [`MAX_DEPTH`] before parsing them.

/// Deepest nesting kerf accepts in a request document. kerf's requests nest three levels
/// (`points: [[x, y, z], …]`, `process: {…}`); 32 leaves room for any hand-written layout.
pub const MAX_DEPTH: usize = 32;

/// An upper bound of the nesting depth of a YAML (or JSON) document (exact or one more): on
/// each line, the block level (1 for the document's root, plus one per two spaces of
/// indentation, rounded up, plus one per chained `- ` entry) plus the open flow collections
/// (`[`, `{` outside quotes and comments; a flow collection continued on later lines counts
/// from the block level of the line that opened it).
///
/// # Performance
/// O(length), one pass, no allocation.
pub fn nesting_depth(text: &str) -> usize {
    let mut deepest = 0;
    let mut flow = 0usize;
    let mut base = 0usize;
    let (mut single, mut double, mut escaped) = (false, false, false);
    for line in text.lines() {
        if flow == 0 && !single && !double {
            let rest = line.trim_start_matches(' ');
            let indent = line.len() - rest.len();
            let mut dashes = 0;
            let mut r = rest;
            while let Some(next) = r.strip_prefix('-') {
                if !(next.is_empty() || next.starts_with(' ')) {
                    break;
                }
                dashes += 1;
                r = next.trim_start_matches(' ');
            }
            if !rest.is_empty() {
                base = 1 + indent.div_ceil(2) + dashes;
                deepest = deepest.max(base);
            }
        }
        for c in line.chars() {
            if double {
                match (escaped, c) {
                    (true, _) => escaped = false,
                    (false, '\\') => escaped = true,
                    (false, '"') => double = false,
                    _ => {}
                }
                continue;
            }
            if single {
                single = c != '\'';
                continue;
            }
            match c {
                '"' => double = true,
                '\'' => single = true,
                '#' => break,
                '[' | '{' => {
                    flow += 1;
                    deepest = deepest.max(base + flow);
                }
                ']' | '}' => flow = flow.saturating_sub(1),
                _ => {}
            }
        }
    }
    deepest
}

/// Checks a document against [`MAX_DEPTH`] before it is parsed.
///
/// # Returns
/// The reason it is refused ("nested N levels deep, over the limit of 32"), or `Ok`.
pub fn check_depth(text: &str) -> Result<(), String> {
    let depth = nesting_depth(text);
    if depth > MAX_DEPTH {
        return Err(format!(
            "the document is nested {depth} levels deep, over the limit of {MAX_DEPTH}"
        ));
    }
    Ok(())
}

/// Reads a request document: YAML, or JSON where YAML refuses it (JSON is nearly a subset of
/// YAML, but YAML rejects a `\u` escape of a UTF-16 surrogate pair such as `"\ud83d\ude00"`),
/// after [`check_depth`].
///
/// # Returns
/// The value, or the reason: the nesting check's, JSON's own error (with line and column) when
/// the text is a JSON document, else the YAML parser's; at most [`MAX_ERROR_CHARS`]
/// characters (a parser error quotes the offending value, which may be megabytes long).
pub fn from_yaml_or_json<T: serde::de::DeserializeOwned>(text: &str) -> Result<T, String> {
    check_depth(text)?;
    serde_yaml_ng::from_str(text)
        .or_else(|yaml| {
            if serde_json::from_str::<serde_json::Value>(text).is_ok() {
                serde_json::from_str(text).map_err(|e| e.to_string())
            } else {
                Err(yaml.to_string())
            }
        })
        .map_err(cap_error)
}

/// Longest parser error passed on (characters).
pub const MAX_ERROR_CHARS: usize = 400;

/// `error` cut to [`MAX_ERROR_CHARS`] characters, saying so.
fn cap_error(error: String) -> String {
    if error.chars().count() <= MAX_ERROR_CHARS {
        return error;
    }
    let head: String = error.chars().take(MAX_ERROR_CHARS).collect();
    format!("{head}… (parser message cut at {MAX_ERROR_CHARS} characters)")
}

#[cfg(test)]
mod tests {
    use super::{check_depth, nesting_depth};

    #[test]
    fn depth_of_flow_block_and_quoted_text() {
        assert_eq!(nesting_depth("a: 1\n"), 1);
        assert_eq!(nesting_depth("points: [[1, 2, 3], [4, 5, 6]]\n"), 3);
        assert_eq!(nesting_depth("{\"a\": {\"b\": [1]}}"), 4);
        assert_eq!(nesting_depth("a:\n  b:\n    c: 1\n"), 3);
        assert_eq!(nesting_depth("- - - x\n"), 4);
        assert_eq!(nesting_depth("a: [1,\n  [2,\n   [3]]]\n"), 4);
        // Brackets inside strings and comments do not nest.
        assert_eq!(
            nesting_depth("a: '[[[['\nb: \"{{\\\"[[\"\nc: 1 # [[[[\n"),
            1
        );
        let deep = "[".repeat(100_000);
        assert_eq!(nesting_depth(&deep), 100_001);
        assert!(check_depth(&deep).unwrap_err().contains("100001 levels"));
        assert!(check_depth(&"- ".repeat(50)).is_err());
        assert!(check_depth("points: [[1.4, -0.3, 1.7], [2.1, 0.3, 1.7]]\n").is_ok());
    }

    #[test]
    fn parser_errors_never_echo_a_huge_value() {
        #[derive(serde::Deserialize, Debug)]
        #[allow(dead_code)]
        struct R {
            feedrate: f64,
        }
        let text = format!("feedrate: \"{}\"\n", "a".repeat(1 << 20));
        let e = super::from_yaml_or_json::<R>(&text).unwrap_err();
        assert!(
            e.chars().count() < super::MAX_ERROR_CHARS + 60,
            "{} chars",
            e.len()
        );
        assert!(e.ends_with("(parser message cut at 400 characters)"), "{e}");
    }
}
