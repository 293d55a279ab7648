//! Parsing of message, service and action definitions; mirrors
//! `rosidl_adapter.parser.parse_message_string`, `parse_service_string` and
//! `parse_action_string`.

use super::names::{
    is_valid_constant_name, is_valid_field_name, is_valid_message_name, is_valid_package_name,
};
use super::types::{
    Array, BaseType, Constant, Field, FieldType, InterfaceSpec, MessageSpec, Primitive,
};
use super::value::{parse_default, parse_scalar};
use crate::{Error, InterfaceKind};

/// Separator line between the parts of services and actions.
const SEPARATOR: &str = "---";

/// Parses the text of an interface file of the given kind. `file` names it in
/// error messages; `package` and `name` are the package and the file stem.
///
/// # Errors
/// [`Error::Idl`] for an invalid line, [`Error::IdlSeparators`] for a wrong
/// number of `---` lines.
pub fn parse_interface(
    kind: InterfaceKind,
    package: &str,
    name: &str,
    text: &str,
    file: &str,
) -> Result<InterfaceSpec, Error> {
    match kind {
        InterfaceKind::Msg => parse_message(package, name, text, file).map(|m| InterfaceSpec {
            kind,
            package: package.to_owned(),
            name: name.to_owned(),
            parts: vec![m],
        }),
        InterfaceKind::Srv => parse_service(package, name, text, file),
        InterfaceKind::Action => parse_action(package, name, text, file),
    }
}

/// Parses a `.msg` file's text into the message `package/name`.
///
/// # Errors
/// [`Error::Idl`] naming the line and what is wrong with it.
pub fn parse_message(
    package: &str,
    name: &str,
    text: &str,
    file: &str,
) -> Result<MessageSpec, Error> {
    check_names(package, name, file)?;
    let lines: Vec<&str> = text.lines().collect();
    parse_lines(package, name, &lines, 0, file)
}

/// Checks the package and interface names of a file.
fn check_names(package: &str, name: &str, file: &str) -> Result<(), Error> {
    let whole = |reason: String| Error::Idl {
        file: file.to_owned(),
        line: 0,
        text: String::new(),
        reason,
    };
    if !is_valid_package_name(package) {
        return Err(whole(format!(
            "package name `{package}` is invalid: it must match ^[a-z][a-z0-9_]*$ \
             without `__` or a trailing `_`"
        )));
    }
    if !is_valid_message_name(name) {
        return Err(whole(format!(
            "interface name `{name}` is invalid: it must match ^[A-Z][A-Za-z0-9]*$"
        )));
    }
    Ok(())
}

/// Parses a `.srv` file's text: parts `<name>_Request` and `<name>_Response`.
///
/// # Errors
/// [`Error::IdlSeparators`] unless there is exactly one `---` line;
/// [`Error::Idl`] for an invalid line.
pub fn parse_service(
    package: &str,
    name: &str,
    text: &str,
    file: &str,
) -> Result<InterfaceSpec, Error> {
    let parts = parse_parts(
        package,
        name,
        text,
        file,
        InterfaceKind::Srv,
        &["_Request", "_Response"],
    )?;
    Ok(InterfaceSpec {
        kind: InterfaceKind::Srv,
        package: package.to_owned(),
        name: name.to_owned(),
        parts,
    })
}

/// Parses a `.action` file's text: parts `<name>_Goal`, `<name>_Result` and
/// `<name>_Feedback`.
///
/// # Errors
/// [`Error::IdlSeparators`] unless there are exactly two `---` lines;
/// [`Error::Idl`] for an invalid line.
pub fn parse_action(
    package: &str,
    name: &str,
    text: &str,
    file: &str,
) -> Result<InterfaceSpec, Error> {
    let parts = parse_parts(
        package,
        name,
        text,
        file,
        InterfaceKind::Action,
        &["_Goal", "_Result", "_Feedback"],
    )?;
    Ok(InterfaceSpec {
        kind: InterfaceKind::Action,
        package: package.to_owned(),
        name: name.to_owned(),
        parts,
    })
}

/// Splits `text` at its `---` lines (compared before trimming, as rosidl does)
/// and parses each part as the message `<name><suffix>`.
fn parse_parts(
    package: &str,
    name: &str,
    text: &str,
    file: &str,
    kind: InterfaceKind,
    suffixes: &[&str],
) -> Result<Vec<MessageSpec>, Error> {
    check_names(package, name, file)?;
    let lines: Vec<&str> = text.lines().collect();
    let separators: Vec<usize> = lines
        .iter()
        .enumerate()
        .filter(|(_, l)| **l == SEPARATOR)
        .map(|(i, _)| i)
        .collect();
    if separators.len() + 1 != suffixes.len() {
        return Err(Error::IdlSeparators {
            file: file.to_owned(),
            kind: kind.as_str(),
            expected: suffixes.len() - 1,
            found: separators.len(),
        });
    }
    let mut parts = Vec::with_capacity(suffixes.len());
    let mut start = 0;
    for (i, suffix) in suffixes.iter().enumerate() {
        let end = separators.get(i).copied().unwrap_or(lines.len());
        let part_name = format!("{name}{suffix}");
        parts.push(parse_lines(
            package,
            &part_name,
            &lines[start..end],
            start,
            file,
        )?);
        start = end + 1;
    }
    Ok(parts)
}

/// Parses the lines of one message; `first_line` is the 0-based index of
/// `lines[0]` in the file, for error messages.
fn parse_lines(
    package: &str,
    name: &str,
    lines: &[&str],
    first_line: usize,
    file: &str,
) -> Result<MessageSpec, Error> {
    let mut spec = MessageSpec {
        package: package.to_owned(),
        name: name.to_owned(),
        fields: Vec::new(),
        constants: Vec::new(),
    };
    for (offset, raw) in lines.iter().enumerate() {
        let error = |reason: String| Error::Idl {
            file: file.to_owned(),
            line: first_line + offset + 1,
            text: (*raw).to_owned(),
            reason,
        };
        let expanded = raw.replace('\t', " ");
        let code = match expanded.find('#') {
            Some(i) => &expanded[..i],
            None => expanded.as_str(),
        };
        let code = code.trim_end();
        if code.is_empty() {
            continue;
        }
        let (type_text, rest) = code.split_once(' ').unwrap_or((code, ""));
        let rest = rest.trim_start();
        if type_text.is_empty() {
            return Err(error(
                "a definition line must not start with whitespace".into(),
            ));
        }
        if rest.is_empty() {
            return Err(error(format!(
                "`{type_text}` is not followed by a name: expected `TYPE NAME [DEFAULT]` \
                 or `TYPE NAME=VALUE`"
            )));
        }
        if let Some((constant_name, value_text)) = rest.split_once('=') {
            let constant =
                parse_constant(type_text, constant_name.trim_end(), value_text.trim_start())
                    .map_err(error)?;
            if spec.constants.iter().any(|c| c.name == constant.name) {
                return Err(error(format!(
                    "constant `{}` is defined twice",
                    constant.name
                )));
            }
            spec.constants.push(constant);
        } else {
            let (field_name, default_text) = rest.split_once(' ').unwrap_or((rest, ""));
            let default_text = default_text.trim_start();
            let field = parse_field(package, type_text, field_name, default_text).map_err(error)?;
            if spec.fields.iter().any(|f| f.name == field.name) {
                return Err(error(format!("field `{}` is defined twice", field.name)));
            }
            spec.fields.push(field);
        }
    }
    Ok(spec)
}

/// Parses `TYPE NAME=VALUE`.
fn parse_constant(type_text: &str, name: &str, value_text: &str) -> Result<Constant, String> {
    let constant_type = match type_text {
        "string" => BaseType::String {
            wide: false,
            upper_bound: None,
        },
        "wstring" => BaseType::String {
            wide: true,
            upper_bound: None,
        },
        other => match Primitive::from_name(other) {
            Some(p) => BaseType::Primitive(p),
            None => {
                return Err(format!(
                    "constant type `{type_text}` must be a primitive type \
                     (bool, byte, char, float32, float64, [u]int8..64, string, wstring)"
                ))
            }
        },
    };
    if !is_valid_constant_name(name) {
        return Err(format!(
            "constant name `{name}` is invalid: it must match ^[A-Z]([A-Z0-9_]?[A-Z0-9]+)*$"
        ));
    }
    let value = parse_scalar(&constant_type, value_text)
        .map_err(|why| format!("constant `{name}`: {why}"))?;
    Ok(Constant {
        name: name.to_owned(),
        constant_type,
        value,
    })
}

/// Parses `TYPE NAME [DEFAULT]`; `package` resolves bare message names.
fn parse_field(
    package: &str,
    type_text: &str,
    name: &str,
    default_text: &str,
) -> Result<Field, String> {
    let field_type = parse_type(package, type_text)?;
    if !is_valid_field_name(name) {
        return Err(format!(
            "field name `{name}` is invalid: it must match ^[a-z][a-z0-9_]*$ \
             without `__` or a trailing `_`"
        ));
    }
    let default = if default_text.is_empty() {
        None
    } else {
        Some(
            parse_default(&field_type, default_text)
                .map_err(|why| format!("default of field `{name}`: {why}"))?,
        )
    };
    Ok(Field {
        name: name.to_owned(),
        field_type,
        default,
    })
}

/// Parses a type: `T`, `T[]`, `T[N]`, `T[<=N]` with `T` a primitive,
/// `string<=N`, `pkg/Name` or `Name`.
fn parse_type(package: &str, text: &str) -> Result<FieldType, String> {
    let (element, array) = match text.strip_suffix(']') {
        None => (text, Array::No),
        Some(open) => {
            let index = open
                .rfind('[')
                .ok_or_else(|| format!("type `{text}` ends with ']' but has no '['"))?;
            let size_text = &open[index + 1..];
            let array = if size_text.is_empty() {
                Array::Unbounded
            } else {
                let (bounded, digits) = match size_text.strip_prefix("<=") {
                    Some(d) => (true, d),
                    None => (false, size_text),
                };
                let size = parse_positive(digits).ok_or_else(|| {
                    format!(
                        "the size of array type `{text}` must be an integer > 0, \
                         optionally prefixed with `<=` for an upper bound"
                    )
                })?;
                if bounded {
                    Array::Bounded(size)
                } else {
                    Array::Fixed(size)
                }
            };
            (&open[..index], array)
        }
    };
    Ok(FieldType {
        base: parse_base_type(package, element)?,
        array,
    })
}

/// Parses an element type.
fn parse_base_type(package: &str, text: &str) -> Result<BaseType, String> {
    if let Some(p) = Primitive::from_name(text) {
        return Ok(BaseType::Primitive(p));
    }
    for (prefix, wide) in [("string", false), ("wstring", true)] {
        if text == prefix {
            return Ok(BaseType::String {
                wide,
                upper_bound: None,
            });
        }
        if let Some(bound) = text.strip_prefix(prefix).and_then(|t| t.strip_prefix("<=")) {
            let upper_bound = parse_positive(bound).ok_or_else(|| {
                format!("the upper bound of string type `{text}` must be an integer > 0")
            })?;
            return Ok(BaseType::String {
                wide,
                upper_bound: Some(upper_bound),
            });
        }
    }
    if text == "time" || text == "duration" {
        return Err(format!(
            "`{text}` is a ROS 1 type; use builtin_interfaces/Time or builtin_interfaces/Duration"
        ));
    }
    let (msg_package, msg_name) = match text.split_once('/') {
        Some((p, n)) if !n.contains('/') => (p, n),
        Some(_) => {
            return Err(format!(
                "type `{text}` is not a primitive, `package/Message` or `Message`"
            ))
        }
        None => (package, text),
    };
    if !is_valid_package_name(msg_package) {
        return Err(format!(
            "`{msg_package}` in type `{text}` is an invalid package name: it must match \
             ^[a-z][a-z0-9_]*$ without `__` or a trailing `_`"
        ));
    }
    if !is_valid_message_name(msg_name) {
        return Err(format!(
            "`{msg_name}` in type `{text}` is not a primitive type nor a valid message name \
             (^[A-Z][A-Za-z0-9]*$)"
        ));
    }
    Ok(BaseType::Message {
        package: msg_package.to_owned(),
        name: msg_name.to_owned(),
    })
}

/// A decimal integer > 0 (surrounding whitespace allowed, as Python `int`).
fn parse_positive(text: &str) -> Option<usize> {
    let t = text.trim();
    let t = t.strip_prefix('+').unwrap_or(t);
    if t.is_empty() || !t.chars().all(|c| c.is_ascii_digit()) {
        return None;
    }
    t.parse::<usize>().ok().filter(|n| *n > 0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::idl::Value;

    fn msg(text: &str) -> Result<MessageSpec, Error> {
        parse_message("pkg", "Test", text, "Test.msg")
    }

    #[test]
    fn fields_constants_comments() {
        assert!(parse_message("Pkg", "Test", "", "x").is_err());
        assert!(parse_message("pkg", "Test_X", "", "x").is_err());
        let m = msg("# file comment\n\
                     uint8 A=1 # comment\n\
                     int32 B = -2\n\
                     string S='x y'\n\
                     \n\
                     std_msgs/Header header\n\
                     Point[] points   # same package\n\
                     float64[3]\txyz [1, 2, 3]\n\
                     string<=5[<=2] names\n\
                     float64 w 1\n")
        .unwrap();
        assert_eq!(
            m.constants
                .iter()
                .map(|c| c.name.as_str())
                .collect::<Vec<_>>(),
            ["A", "B", "S"]
        );
        assert_eq!(m.constants[1].value, Value::Int(-2));
        assert_eq!(m.constants[2].value, Value::String("x y".into()));
        let names: Vec<&str> = m.fields.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(names, ["header", "points", "xyz", "names", "w"]);
        assert_eq!(
            m.fields[1].field_type,
            FieldType {
                base: BaseType::Message {
                    package: "pkg".into(),
                    name: "Point".into()
                },
                array: Array::Unbounded
            }
        );
        assert_eq!(m.fields[2].field_type.array, Array::Fixed(3));
        assert_eq!(
            m.fields[3].field_type,
            FieldType {
                base: BaseType::String {
                    wide: false,
                    upper_bound: Some(5)
                },
                array: Array::Bounded(2)
            }
        );
        assert_eq!(m.fields[4].default, Some(Value::Float(1.0)));
    }

    #[test]
    fn errors_name_line_and_problem() {
        let err = msg("int32 a\nfloat65 b\n").unwrap_err().to_string();
        assert!(
            err.contains("Test.msg:2") && err.contains("float65"),
            "{err}"
        );
        let err = msg("int32 A\n").unwrap_err().to_string();
        assert!(err.contains("field name `A`"), "{err}");
        let err = msg("int32 a\nint32 a\n").unwrap_err().to_string();
        assert!(err.contains("defined twice"), "{err}");
        let err = msg("int32\n").unwrap_err().to_string();
        assert!(err.contains("not followed by a name"), "{err}");
        let err = msg("int8 X=200\n").unwrap_err().to_string();
        assert!(err.contains("<= 127"), "{err}");
        let err = msg("float64[0] x\n").unwrap_err().to_string();
        assert!(err.contains("integer > 0"), "{err}");
        let err = msg("Point[] x=1\n").unwrap_err().to_string();
        assert!(err.contains("must be a primitive"), "{err}");
        let err = msg(" int32 x\n").unwrap_err().to_string();
        assert!(err.contains("whitespace"), "{err}");
        assert!(msg("a/b/C x\n").is_err());
        assert!(msg("time t\n").is_err());
    }

    #[test]
    fn services_and_actions() {
        let s = parse_service("pkg", "Do", "int32 a\n---\nbool ok\n", "Do.srv").unwrap();
        assert_eq!(s.parts.len(), 2);
        assert_eq!(s.parts[0].name, "Do_Request");
        assert_eq!(s.parts[1].name, "Do_Response");
        assert_eq!(s.parts[1].fields[0].name, "ok");
        let a = parse_action("pkg", "Go", "int32 a\n---\n---\nfloat64 f\n", "Go.action").unwrap();
        let names: Vec<&str> = a.parts.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["Go_Goal", "Go_Result", "Go_Feedback"]);
        assert!(a.parts[1].fields.is_empty());
        assert_eq!(
            parse_service("pkg", "Do", "int32 a\n", "Do.srv"),
            Err(Error::IdlSeparators {
                file: "Do.srv".into(),
                kind: "srv",
                expected: 1,
                found: 0
            })
        );
        let err = parse_action("pkg", "Go", "---\nint32 a\n---\nint32 A\n", "Go.action")
            .unwrap_err()
            .to_string();
        assert!(err.contains("Go.action:4"), "{err}");
    }
}
