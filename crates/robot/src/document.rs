//! [`nesting_depth`]: how deeply a YAML or JSON document nests, found by one linear scan
//! before any parser sees it. YAML parsers take time quadratic in the nesting depth (200 KB
//! of `[` nested 10⁵ deep took 31 s), so kerf refuses documents nested deeper than
//! [`MAX_DEPTH`] before parsing them ([`check_depth`]: the YAML parser's own events, stopped as
//! soon as they nest too deep; the scan for JSON that YAML cannot read).

/// Deepest nesting kerf accepts in a request document. kerf's requests nest three levels
/// (`points: [[x, y, z], …]`, `process: {…}`); 32 leaves room for any hand-written layout.
pub const MAX_DEPTH: usize = 32;

/// An upper bound of the nesting depth of a JSON document, or of a YAML document whose quotes
/// all start quoted scalars (exact or one more; [`check_depth`] reads YAML with YAML's parser): on
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

/// Checks a document against [`MAX_DEPTH`] before it is parsed, by the events of the YAML
/// parser (libyaml, serde_yaml_ng's), read only until they nest deeper than the limit: they are
/// exact where a scan cannot tell YAML's quotes apart (`it's` is a plain scalar, not the start
/// of a quoted one; brackets in a block scalar are text), and stopping them at the limit keeps
/// their cost linear. Text that YAML cannot read (JSON with a surrogate pair escape) is checked
/// by [`nesting_depth`], exact for JSON.
///
/// # Returns
/// The reason it is refused ("nested N levels deep, over the limit of 32"), or `Ok`.
pub fn check_depth(text: &str) -> Result<(), String> {
    let scanned = || {
        let depth = nesting_depth(text);
        (depth > MAX_DEPTH).then(|| {
            format!("the document is nested {depth} levels deep, over the limit of {MAX_DEPTH}")
        })
    };
    match yaml_depth(text) {
        YamlDepth::Within => Ok(()),
        YamlDepth::TooDeep { line } => Err(scanned().unwrap_or_else(|| {
            format!(
                "the document is nested more than {MAX_DEPTH} levels deep at line {line}, over \
                 the limit of {MAX_DEPTH}"
            )
        })),
        YamlDepth::Unreadable => scanned().map_or(Ok(()), Err),
    }
}

/// What libyaml's events say of a document's depth.
enum YamlDepth {
    /// Read to the end, at most [`MAX_DEPTH`] levels deep.
    Within,
    /// Deeper than [`MAX_DEPTH`] at this line (1-based); read no further.
    TooDeep { line: u64 },
    /// A syntax error before either (the parser that reads the document reports it, or the
    /// text is JSON that YAML cannot read).
    Unreadable,
}

/// Frees a libyaml parser (boxed: libyaml keeps a pointer to it) when dropped.
struct YamlParser(Box<std::mem::MaybeUninit<unsafe_libyaml::yaml_parser_t>>);

impl Drop for YamlParser {
    fn drop(&mut self) {
        // SAFETY: only built after `yaml_parser_initialize` succeeded on this box.
        unsafe { unsafe_libyaml::yaml_parser_delete(self.0.as_mut_ptr()) }
    }
}

/// Reads libyaml's events of `text` until they end, fail, or nest deeper than [`MAX_DEPTH`].
///
/// # Performance
/// Linear: libyaml's scanner runs at most 1024 characters ahead of the event that stops it.
fn yaml_depth(text: &str) -> YamlDepth {
    use unsafe_libyaml as unsafe_sys;
    let mut boxed = Box::new(std::mem::MaybeUninit::<unsafe_sys::yaml_parser_t>::uninit());
    // SAFETY: libyaml's API as serde_yaml_ng uses it: the parser is initialized in place in a
    // box that does not move, reads `text` (which outlives it), is deleted once (`YamlParser`),
    // and every event it returns is deleted.
    unsafe {
        if unsafe_sys::yaml_parser_initialize(boxed.as_mut_ptr()).fail {
            return YamlDepth::Unreadable;
        }
        let mut parser = YamlParser(boxed);
        let p = parser.0.as_mut_ptr();
        unsafe_sys::yaml_parser_set_encoding(p, unsafe_sys::YAML_UTF8_ENCODING);
        unsafe_sys::yaml_parser_set_input_string(p, text.as_ptr(), text.len() as u64);
        let mut depth = 0usize;
        loop {
            let mut event = std::mem::MaybeUninit::<unsafe_sys::yaml_event_t>::uninit();
            if unsafe_sys::yaml_parser_parse(p, event.as_mut_ptr()).fail {
                return YamlDepth::Unreadable;
            }
            let event = event.as_mut_ptr();
            let (kind, line) = ((*event).type_, (*event).start_mark.line);
            unsafe_sys::yaml_event_delete(event);
            match kind {
                unsafe_sys::YAML_SEQUENCE_START_EVENT | unsafe_sys::YAML_MAPPING_START_EVENT => {
                    depth += 1;
                    if depth > MAX_DEPTH {
                        return YamlDepth::TooDeep { line: line + 1 };
                    }
                }
                unsafe_sys::YAML_SEQUENCE_END_EVENT | unsafe_sys::YAML_MAPPING_END_EVENT => {
                    depth = depth.saturating_sub(1);
                }
                unsafe_sys::YAML_STREAM_END_EVENT => return YamlDepth::Within,
                _ => {}
            }
        }
    }
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
    use super::{check_depth, nesting_depth, MAX_DEPTH};

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

    /// Found by fuzzing (issue 11, item 7; fuzz/corpus/document/plain-quote-deep.yaml): a
    /// quote inside a plain scalar (`it's`) made the scan skip the rest of the document as
    /// quoted, so deep flow nesting after it reached the YAML parser (30 000 levels: 4.6 s in
    /// a debug build, quadratic). libyaml's own events catch it, early and in linear time.
    #[test]
    fn nesting_the_scan_cannot_see_is_refused_by_the_parser_events() {
        let n = 30_000;
        let deep = format!("a: it's\nb: {}{}\n", "[".repeat(n), "]".repeat(n));
        assert_eq!(nesting_depth(&deep), 1);
        // Refused at the 33rd level, without parsing the rest (linear; timings are never
        // asserted in tests).
        let e = check_depth(&deep).unwrap_err();
        assert!(e.contains("more than 32 levels deep at line 2"), "{e}");
        // Other quotes the scan takes for openers: a plain scalar with a quote mid-line,
        // a block scalar, a `#` that starts no comment.
        for text in [
            format!("a: x 'y\nb: {}\n", "[".repeat(40)),
            format!("a: |\n  'x\nb: {}\n", "[".repeat(40)),
            format!("a: [b#c, {}]\n", "[".repeat(40)),
        ] {
            assert!(check_depth(&text).is_err(), "{text}");
        }
        // Brackets the scan counts but YAML reads as text (a block scalar, as serde_yaml_ng
        // writes a multi-line string) do not refuse a document: found by fuzzing too (a request
        // written back as YAML was refused).
        let block = format!("mesh: |-\n  {}\n  x\nb: 1\n", "[".repeat(40));
        assert!(nesting_depth(&block) > MAX_DEPTH);
        assert!(check_depth(&block).is_ok());
        // At the limit, YAML nesting is accepted; JSON that YAML cannot read still gets the scan.
        assert!(check_depth(&format!(
            "a: it's\nb: {}{}\n",
            "[".repeat(31),
            "]".repeat(31)
        ))
        .is_ok());
        assert!(check_depth(&format!(
            "{{\"a\": \"\\ud83d\\ude00\", \"b\": {}1{}}}",
            "[".repeat(40),
            "]".repeat(40)
        ))
        .is_err());
    }
}
