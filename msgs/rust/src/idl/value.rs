//! Literal values of constants and defaults, parsed as
//! `rosidl_adapter.parser.parse_value_string` and `parse_primitive_value_string` do.

use super::types::{Array, BaseType, FieldType, Primitive, Value};

/// Parses a constant value or a non-array default of type `base`.
/// On failure returns a sentence saying what is wrong.
pub(crate) fn parse_scalar(base: &BaseType, text: &str) -> Result<Value, String> {
    match base {
        BaseType::Primitive(Primitive::Bool) => match text.to_ascii_lowercase().as_str() {
            "true" | "1" => Ok(Value::Bool(true)),
            "false" | "0" => Ok(Value::Bool(false)),
            _ => Err(format!(
                "bool value `{text}` must be either 'true' / '1' or 'false' / '0'"
            )),
        },
        BaseType::Primitive(p @ (Primitive::Float32 | Primitive::Float64)) => {
            parse_float(text).map(Value::Float).ok_or_else(|| {
                format!(
                    "{} value `{text}` must be a floating point number using '.' as the separator",
                    p.name()
                )
            })
        }
        BaseType::Primitive(p) => {
            let (min, max) = p
                .integer_range()
                .ok_or_else(|| format!("internal: {} has no integer range", p.name()))?;
            match parse_int(text) {
                Some(v) if (min..=max).contains(&v) => Ok(Value::Int(v)),
                _ => Err(format!(
                    "{} value `{text}` must be a valid integer value >= {min} and <= {max}",
                    p.name()
                )),
            }
        }
        BaseType::String { upper_bound, .. } => {
            let s = unquote(text)?;
            if let Some(max) = upper_bound {
                let len = s.chars().count();
                if len > *max {
                    return Err(format!(
                        "string value `{s}` has {len} characters, more than the maximum of {max}"
                    ));
                }
            }
            Ok(Value::String(s))
        }
        BaseType::Message { package, name } => Err(format!(
            "a field of message type {package}/{name} cannot have a default value"
        )),
    }
}

/// Parses the default value of a field of type `field_type`.
pub(crate) fn parse_default(field_type: &FieldType, text: &str) -> Result<Value, String> {
    if field_type.array == Array::No {
        return parse_scalar(&field_type.base, text);
    }
    if matches!(field_type.base, BaseType::Message { .. }) {
        return parse_scalar(&field_type.base, text);
    }
    let inner = text
        .strip_prefix('[')
        .and_then(|t| t.strip_suffix(']'))
        .ok_or_else(|| format!("array value `{text}` must start with '[' and end with ']'"))?;
    let elements: Vec<String> = if matches!(field_type.base, BaseType::String { .. }) {
        split_string_array(inner)?
    } else if inner.is_empty() {
        Vec::new()
    } else {
        inner.split(',').map(|e| e.trim().to_owned()).collect()
    };
    match field_type.array {
        Array::Fixed(n) if elements.len() != n => {
            return Err(format!(
                "array value `{text}` must have exactly {n} elements, not {}",
                elements.len()
            ))
        }
        Array::Bounded(n) if elements.len() > n => {
            return Err(format!(
                "array value `{text}` must have not more than {n} elements, not {}",
                elements.len()
            ))
        }
        _ => {}
    }
    elements
        .iter()
        .enumerate()
        .map(|(i, e)| {
            parse_scalar(&field_type.base, e.trim())
                .map_err(|why| format!("element {i} of array value `{text}`: {why}"))
        })
        .collect::<Result<Vec<_>, _>>()
        .map(Value::Array)
}

/// Python `float(text)`: decimal or exponent notation, `inf`, `infinity`,
/// `nan`, optional sign, surrounding whitespace, single `_` between digits.
fn parse_float(text: &str) -> Option<f64> {
    let t = remove_digit_underscores(text.trim())?;
    t.parse::<f64>().ok()
}

/// Python `int(text)`, then `int(text, 0)`: decimal with optional sign, or
/// `0x` / `0o` / `0b` prefixed, single `_` between digits.
fn parse_int(text: &str) -> Option<i128> {
    let t = text.trim();
    let (negative, body) = match t.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, t.strip_prefix('+').unwrap_or(t)),
    };
    let lower = body.to_ascii_lowercase();
    let (radix, digits) = if let Some(d) = lower.strip_prefix("0x") {
        (16, d.strip_prefix('_').unwrap_or(d))
    } else if let Some(d) = lower.strip_prefix("0o") {
        (8, d.strip_prefix('_').unwrap_or(d))
    } else if let Some(d) = lower.strip_prefix("0b") {
        (2, d.strip_prefix('_').unwrap_or(d))
    } else {
        (10, lower.as_str())
    };
    let digits = remove_digit_underscores(digits)?;
    if digits.is_empty() || !digits.chars().all(|c| c.is_digit(radix)) {
        return None;
    }
    let magnitude = i128::from_str_radix(&digits, radix).ok()?;
    Some(if negative { -magnitude } else { magnitude })
}

/// Removes underscores that stand between two alphanumerics, as Python number
/// literals allow; `None` if any other underscore is present.
fn remove_digit_underscores(text: &str) -> Option<String> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    for (i, &c) in chars.iter().enumerate() {
        if c == '_' {
            let before = i.checked_sub(1).and_then(|j| chars.get(j));
            let after = chars.get(i + 1);
            match (before, after) {
                (Some(b), Some(a)) if b.is_ascii_alphanumeric() && a.is_ascii_alphanumeric() => {}
                _ => return None,
            }
        } else {
            out.push(c);
        }
    }
    Some(out)
}

/// Removes matching outer quotes (`"` or `'`) and unescapes escaped inner
/// ones; an unescaped inner quote of the same kind is an error.
fn unquote(text: &str) -> Result<String, String> {
    for quote in ['"', '\''] {
        if text.len() >= 2 && text.starts_with(quote) && text.ends_with(quote) {
            let inner = &text[1..text.len() - 1];
            let mut previous = None;
            for c in inner.chars() {
                if c == quote && previous != Some('\\') {
                    return Err(format!(
                        "string value `{text}` has an inner {quote} that is not escaped"
                    ));
                }
                previous = Some(c);
            }
            return Ok(inner.replace(&format!("\\{quote}"), &quote.to_string()));
        }
    }
    Ok(text.to_owned())
}

/// Splits the inside of a string-array default (`a, "b,c", 'd'`) into its
/// elements, as `rosidl_adapter.parser.parse_string_array_value_string` does;
/// quoted elements keep their quotes' content with escaped quotes unescaped.
fn split_string_array(inner: &str) -> Result<Vec<String>, String> {
    let mut rest = inner;
    let mut out = Vec::new();
    while !rest.is_empty() {
        rest = rest.trim_start_matches(' ');
        if rest.starts_with(',') {
            return Err(format!("unexpected ',' at the beginning of `{rest}`"));
        }
        if rest.is_empty() {
            break;
        }
        let quote = rest.chars().next().filter(|c| *c == '"' || *c == '\'');
        if let Some(q) = quote {
            let body = &rest[1..];
            let mut end = None;
            let mut previous = None;
            for (i, c) in body.char_indices() {
                if c == q && previous != Some('\\') {
                    end = Some(i);
                    break;
                }
                previous = Some(c);
            }
            let end = end.ok_or_else(|| format!("string `{rest}` is not closed by a {q}"))?;
            out.push(body[..end].replace(&format!("\\{q}"), &q.to_string()));
            rest = &body[end + 1..];
        } else {
            match rest.find(',') {
                Some(i) => {
                    out.push(rest[..i].to_owned());
                    rest = &rest[i..];
                }
                None => {
                    out.push(rest.to_owned());
                    rest = "";
                }
            }
        }
        rest = rest.trim_start_matches(' ');
        if let Some(after) = rest.strip_prefix(',') {
            rest = after;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ty(base: BaseType, array: Array) -> FieldType {
        FieldType { base, array }
    }

    #[test]
    fn integers_and_ranges() {
        let u8_ = BaseType::Primitive(Primitive::Uint8);
        let i32_ = BaseType::Primitive(Primitive::Int32);
        assert_eq!(parse_scalar(&u8_, "255"), Ok(Value::Int(255)));
        assert_eq!(parse_scalar(&u8_, "0x1F"), Ok(Value::Int(31)));
        assert_eq!(parse_scalar(&i32_, "-5"), Ok(Value::Int(-5)));
        assert_eq!(parse_scalar(&i32_, "1_000"), Ok(Value::Int(1000)));
        let err = parse_scalar(&u8_, "256").unwrap_err();
        assert!(err.contains(">= 0 and <= 255"), "{err}");
        assert!(parse_scalar(&i32_, "1.5").is_err());
        assert!(parse_scalar(&i32_, "").is_err());
        assert!(parse_scalar(&i32_, "_1").is_err());
        let u64_ = BaseType::Primitive(Primitive::Uint64);
        assert_eq!(
            parse_scalar(&u64_, "18446744073709551615"),
            Ok(Value::Int(u64::MAX.into()))
        );
    }

    #[test]
    fn floats_bools_strings() {
        let f = BaseType::Primitive(Primitive::Float64);
        assert_eq!(parse_scalar(&f, "1"), Ok(Value::Float(1.0)));
        assert_eq!(parse_scalar(&f, "-2.5e-3"), Ok(Value::Float(-2.5e-3)));
        assert!(parse_scalar(&f, "1,5").is_err());
        let b = BaseType::Primitive(Primitive::Bool);
        assert_eq!(parse_scalar(&b, "True"), Ok(Value::Bool(true)));
        assert_eq!(parse_scalar(&b, "0"), Ok(Value::Bool(false)));
        assert!(parse_scalar(&b, "yes").is_err());
        let s = BaseType::String {
            wide: false,
            upper_bound: Some(3),
        };
        assert_eq!(parse_scalar(&s, "'ab'"), Ok(Value::String("ab".into())));
        assert_eq!(
            parse_scalar(&s, r#""a\"b""#),
            Ok(Value::String("a\"b".into()))
        );
        assert!(parse_scalar(&s, "abcd").is_err());
        assert!(parse_scalar(&s, r#""a"b""#).is_err());
    }

    #[test]
    fn array_defaults() {
        let f = ty(BaseType::Primitive(Primitive::Float64), Array::Fixed(2));
        assert_eq!(
            parse_default(&f, "[1, 2.5]"),
            Ok(Value::Array(vec![Value::Float(1.0), Value::Float(2.5)]))
        );
        assert!(parse_default(&f, "[1]").unwrap_err().contains("exactly 2"));
        assert!(parse_default(&f, "1, 2").is_err());
        let bounded = ty(BaseType::Primitive(Primitive::Int8), Array::Bounded(1));
        assert!(parse_default(&bounded, "[1, 2]")
            .unwrap_err()
            .contains("not more than 1"));
        let empty = ty(BaseType::Primitive(Primitive::Int8), Array::Unbounded);
        assert_eq!(parse_default(&empty, "[]"), Ok(Value::Array(vec![])));
        let strings = ty(
            BaseType::String {
                wide: false,
                upper_bound: None,
            },
            Array::Unbounded,
        );
        assert_eq!(
            parse_default(&strings, r#"[a, "b,c", 'd']"#),
            Ok(Value::Array(vec![
                Value::String("a".into()),
                Value::String("b,c".into()),
                Value::String("d".into()),
            ]))
        );
    }
}
