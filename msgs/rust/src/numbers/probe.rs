//! Probing a request path with hostile numbers (issue 33): the values every numeric leaf is
//! set to in turn, a message with one leaf replaced, and what the declared rule says of it.
//! Used by the tests of kerf_msgs and of every node that takes a request.

use serde::{de::DeserializeOwned, Serialize};
use serde_yaml_ng::Value;

use super::{find_rule, leaves, Number, NumberRules, Rule};

/// The floats every `float64` leaf is probed with: NaN, ±inf, 0, −0, the smallest denormal,
/// ±1e308.
pub const FLOAT_PROBES: [f64; 8] = [
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    0.0,
    -0.0,
    5e-324,
    1e308,
    -1e308,
];

/// The values a leaf is probed with: [`FLOAT_PROBES`] for a float; for an integer its type's
/// minimum and maximum, 0 and 1.
pub fn probe_values(leaf: Number) -> Vec<Number> {
    match leaf {
        Number::Float(_) => FLOAT_PROBES.iter().map(|v| Number::Float(*v)).collect(),
        Number::Int { min, max, .. } => [min, max, 0, 1]
            .into_iter()
            .map(|value| Number::Int { value, min, max })
            .collect(),
    }
}

/// The declared rule of the field `key` (normalized: indices as `[]`) of `T`.
pub fn rule_of<T: NumberRules>(key: &str) -> Option<&'static Rule> {
    find_rule(T::SECTIONS, key).map(|(_, r)| r)
}

/// What the declared rules of `T` say of `value` at `key`, the field applying.
///
/// # Errors
/// The rule's text when refused (a field without a rule: when not finite).
pub fn expected<T: NumberRules>(key: &str, value: Number) -> Result<(), String> {
    match rule_of::<T>(key) {
        Some(rule) => rule.check(value, true),
        None if value.as_f64().is_finite() => Ok(()),
        None => Err("must be finite".to_string()),
    }
}

/// The refusal cases of `msg` over DDS, where each case costs a round trip: every numeric leaf
/// (of an array, only its first and last element) with each probe value ([`probe_values`])
/// its declared rule refuses ([`expected`]), as (path, value).
///
/// # Performance
/// O(leaves²) comparisons of keys: for the small messages a probe starts from.
pub fn refused_cases<T: Serialize + NumberRules>(msg: &T) -> Vec<(String, Number)> {
    let all = leaves(msg);
    let mut cases = Vec::new();
    for (i, leaf) in all.iter().enumerate() {
        let first = all[..i].iter().all(|l| l.key != leaf.key);
        let last = all[i + 1..].iter().all(|l| l.key != leaf.key);
        if !(first || last) {
            continue;
        }
        for v in probe_values(leaf.value) {
            if expected::<T>(&leaf.key, v).is_err() {
                cases.push((leaf.path.clone(), v));
            }
        }
    }
    cases
}

/// `msg` with the numeric leaf at `path` (e.g. `points[1].x`) set to `value`.
///
/// # Errors
/// The path does not name a leaf of `msg`, or the value does not fit the field's type.
pub fn with_value<T: Serialize + DeserializeOwned>(
    msg: &T,
    path: &str,
    value: Number,
) -> Result<T, String> {
    let mut tree = serde_yaml_ng::to_value(msg).map_err(|e| e.to_string())?;
    let mut at = &mut tree;
    for step in steps(path)? {
        at = match step {
            Step::Field(name) => at
                .as_mapping_mut()
                .and_then(|m| m.get_mut(name))
                .ok_or_else(|| format!("{path}: no field {name}"))?,
            Step::Index(i) => at
                .as_sequence_mut()
                .and_then(|s| s.get_mut(i))
                .ok_or_else(|| format!("{path}: no element {i}"))?,
        };
    }
    *at = match value {
        Number::Float(v) => Value::Number(serde_yaml_ng::Number::from(v)),
        Number::Int { value, .. } => match i64::try_from(value) {
            Ok(v) => Value::Number(serde_yaml_ng::Number::from(v)),
            Err(_) => Value::Number(serde_yaml_ng::Number::from(
                u64::try_from(value).map_err(|e| e.to_string())?,
            )),
        },
    };
    serde_yaml_ng::from_value(tree).map_err(|e| format!("{path}: {e}"))
}

enum Step<'a> {
    Field(&'a str),
    Index(usize),
}

fn steps(path: &str) -> Result<Vec<Step<'_>>, String> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let (name, mut rest) = part.split_once('[').map_or((part, ""), |(n, r)| (n, r));
        if !name.is_empty() {
            out.push(Step::Field(name));
        }
        while !rest.is_empty() {
            let (index, after) = rest
                .split_once(']')
                .ok_or_else(|| format!("{path}: unclosed ["))?;
            out.push(Step::Index(
                index.parse().map_err(|_| format!("{path}: bad index"))?,
            ));
            rest = after.strip_prefix('[').unwrap_or(after);
        }
    }
    Ok(out)
}
