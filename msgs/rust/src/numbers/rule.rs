//! [`Rule`]: what one numeric field of a request accepts, and [`Section`]: the rules of a
//! message (or of a nested message under a path prefix).

use super::{format_value, Number};

/// One end of a rule's range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Bound {
    /// The value itself is allowed (`[` or `]`).
    Closed(f64),
    /// The value itself is not allowed (`(` or `)`).
    Open(f64),
}

impl Bound {
    fn value(self) -> f64 {
        match self {
            Bound::Closed(v) | Bound::Open(v) => v,
        }
    }
}

/// The rule of one numeric field (or of every field a pattern matches): finite, inside a
/// range with its unit, optionally a special value with a meaning (`0 = default`,
/// `-1 = no tolerance`), optionally "not denormal" (for a value the planner divides by), and
/// optionally only when a `bool` flag of the message says the field applies.
///
/// Integer fields use the same rule: their value is compared as `f64` (exact for every
/// integer type a ROS message has up to 2^53, which every bound here is below).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rule {
    /// The field pattern: field names joined by `.`, `[]` for any index of an array, and a
    /// final `*` for any one field name, e.g. `points[].*`, `workpiece_pose.orientation.w`.
    pub field: &'static str,
    /// Lower end of the range.
    pub lo: Bound,
    /// Upper end of the range.
    pub hi: Bound,
    /// The unit of the value (`m`, `m/s`, `rad`, `s`, `ns`, `rpm`, `-`, …).
    pub unit: &'static str,
    /// Values accepted outside the range, each with its meaning (`0 = default`).
    pub special: &'static [(f64, &'static str)],
    /// Whether a nonzero value below `f64::MIN_POSITIVE` in magnitude (denormal) is refused
    /// even inside the range: the value divides somewhere.
    pub divides: bool,
    /// The `bool` field (its full pattern, e.g. `has_process`) that says whether this field
    /// applies. When that flag is false the field is only checked finite: the `.msg` says a
    /// finite value there is ignored.
    pub when: Option<&'static str>,
}

impl Rule {
    /// A rule for `field`: finite and inside `lo`…`hi` in `unit`.
    pub const fn new(field: &'static str, lo: Bound, hi: Bound, unit: &'static str) -> Rule {
        Rule {
            field,
            lo,
            hi,
            unit,
            special: &[],
            divides: false,
            when: None,
        }
    }

    /// A rule for `field`: finite and in the closed range `[lo, hi]` in `unit`.
    pub const fn closed(field: &'static str, lo: f64, hi: f64, unit: &'static str) -> Rule {
        Rule::new(field, Bound::Closed(lo), Bound::Closed(hi), unit)
    }

    /// This rule, also accepting the values of `special` (each with its meaning).
    pub const fn or(self, special: &'static [(f64, &'static str)]) -> Rule {
        Rule { special, ..self }
    }

    /// This rule, refusing denormal values (the field divides).
    pub const fn divides(self) -> Rule {
        Rule {
            divides: true,
            ..self
        }
    }

    /// This rule, applied in full only when the `bool` field `flag` is true.
    pub const fn when(self, flag: &'static str) -> Rule {
        Rule {
            when: Some(flag),
            ..self
        }
    }

    /// Whether `value` is accepted, the flag of [`Rule::when`] being `applies`.
    ///
    /// # Errors
    /// The rule's text (what the value must be) when it is not accepted.
    pub fn check(&self, value: Number, applies: bool) -> Result<(), String> {
        let v = value.as_f64();
        if !v.is_finite() {
            return Err("must be finite".to_string());
        }
        if !applies {
            return Ok(());
        }
        if self.special.iter().any(|(s, _)| *s == v) {
            return Ok(());
        }
        if self.divides && v != 0.0 && v.abs() < f64::MIN_POSITIVE {
            return Err(format!(
                "must not be denormal (|x| < {:e}): the value divides; {}",
                f64::MIN_POSITIVE,
                self.describe()
            ));
        }
        let above = match self.lo {
            Bound::Closed(lo) => v >= lo,
            Bound::Open(lo) => v > lo,
        };
        let below = match self.hi {
            Bound::Closed(hi) => v <= hi,
            Bound::Open(hi) => v < hi,
        };
        if above && below {
            Ok(())
        } else {
            Err(self.describe())
        }
    }

    /// The rule as text, e.g. `must be in (0, 10] m/s, or 0 = default 8 m/s^2`.
    pub fn describe(&self) -> String {
        let open = if matches!(self.lo, Bound::Closed(_)) {
            '['
        } else {
            '('
        };
        let close = if matches!(self.hi, Bound::Closed(_)) {
            ']'
        } else {
            ')'
        };
        let mut text = format!(
            "must be in {open}{}, {}{close} {}",
            bound_text(self.lo.value()),
            bound_text(self.hi.value()),
            self.unit
        );
        for (value, meaning) in self.special {
            text.push_str(&format!(", or {} = {meaning}", bound_text(*value)));
        }
        if let Some(flag) = self.when {
            text.push_str(&format!(" (when {flag} is true; else only finite)"));
        }
        text
    }

    /// Whether this rule's pattern matches the normalized field key `key` (field names joined
    /// by `.`, `[]` for indices).
    pub fn matches(&self, key: &str) -> bool {
        pattern_matches(self.field, key)
    }
}

/// A bound as text: whole numbers in full (`2147483647`, `100000`), others short.
fn bound_text(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e16 {
        format!("{}", v as i64)
    } else {
        format_value(v)
    }
}

/// Whether `pattern` (with an optional final `*` for any one field name) matches `key`.
pub(crate) fn pattern_matches(pattern: &str, key: &str) -> bool {
    match pattern.strip_suffix('*') {
        None => pattern == key,
        Some(prefix) => key
            .strip_prefix(prefix)
            .is_some_and(|rest| !rest.is_empty() && !rest.contains(['.', '['])),
    }
}

/// The rules of a message, or of a message nested under `prefix` (e.g. `trajectory.` for the
/// `JointTrajectory` inside a goal).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Section {
    /// Prepended to every rule's field (and flag) of this section; empty at the top level.
    pub prefix: &'static str,
    /// The rules.
    pub rules: &'static [Rule],
}

impl Section {
    /// The rule of `key` in this section, if one matches.
    pub fn rule(&self, key: &str) -> Option<&'static Rule> {
        let rest = key.strip_prefix(self.prefix)?;
        self.rules.iter().find(|r| r.matches(rest))
    }
}

/// The rule of `key` among `sections` (the first that matches).
pub fn find_rule(sections: &[Section], key: &str) -> Option<(&'static str, &'static Rule)> {
    sections
        .iter()
        .find_map(|s| s.rule(key).map(|r| (s.prefix, r)))
}
