//! One validation of request numbers (issue 33, item 1): every numeric field of every request
//! message kerf accepts has a declared [`Rule`] (finite; inside a stated range with its unit;
//! not denormal where it divides; special values such as `0 = default` named), and
//! [`NumberFields::check_numbers`] checks a message against them.
//!
//! The fields are not listed by hand where they are checked: a serde serializer ([`leaves`],
//! [`check`]) visits every numeric leaf of a message with its path (`points[3].x`), so a field
//! added to a message later cannot be forgotten. A leaf without a declared rule is still
//! checked finite at run time, and the unit tests of this module fail for it.
//!
//! The rules live next to each message's definition, one file per request:
//! [`cut`] (`kerf_msgs/msg/CutRequest`), [`mill`] (`MillRequest`), [`gcode`] (`GcodeRequest`),
//! [`trajectory`] (`trajectory_msgs/JointTrajectory`, the
//! `control_msgs/action/FollowJointTrajectory` goal, `kerf_msgs/srv/ValidateTrajectory`),
//! [`reference`] (`kerf_msgs/msg/ReferencePoint`, the executor's streaming points).
//! The planner libraries keep their own validation (it knows the semantics: min < max, unit
//! axes, odd grid sizes, …); these rules never accept a value the library refuses for a plain
//! range reason, and refuse it earlier, with the message's field name.
//!
//! Text forms of requests (YAML documents of other shapes) are checked by the same rules with
//! [`check_value`], naming the message's field.
//!
//! # Performance
//! One pass over the message, no allocation per leaf (the path is formatted only for an
//! error; each field's rule is looked up once per key, not per leaf): 0.61–0.89 s for a
//! 10⁶-point, 6-joint `JointTrajectory` with positions, velocities and times (1.4·10⁷ leaves),
//! measured on the 2-core build machine at load average 6
//! (`cargo test --release -p kerf_msgs --lib numbers_speed -- --ignored --nocapture`). The
//! executor runs it on its prepare worker, never on the control thread.

pub mod cut;
pub mod gcode;
pub mod mill;
pub mod probe;
pub mod reference;
mod rule;
pub mod trajectory;
mod walk;

pub use rule::{find_rule, Bound, Rule, Section};
pub use walk::{check, check_value, leaves, Leaf};

/// A numeric field outside its declared rule.
///
/// Displayed as ``field `points[3].x` = NaN: must be finite``: the field path exactly as in
/// the `.msg` (nested fields joined by `.`, array indices in brackets), the value, the rule.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("field `{field}` = {value}: {rule}")]
pub struct NumberError {
    /// The field path, e.g. `points[3].x` or `trajectory.points[0].positions[2]`.
    pub field: String,
    /// The value as received (`NaN`, `inf`, `1e308`, `4294967295`).
    pub value: String,
    /// What the field must be, e.g. `must be finite`, `must be in (0, 10] m/s`.
    pub rule: String,
}

/// A message whose numeric fields are checked against declared rules.
pub trait NumberFields {
    /// Checks every numeric field (nested messages and arrays included) against its rule.
    ///
    /// # Errors
    /// The first field (in declaration order) outside its rule, as a [`NumberError`].
    ///
    /// # Performance
    /// Linear in the number of numeric leaves; no allocation per leaf.
    fn check_numbers(&self) -> Result<(), NumberError>;
}

/// The declared rules of a message type.
pub trait NumberRules {
    /// The rules, by field pattern (see [`Rule::field`]).
    const SECTIONS: &'static [Section];
}

/// Implements [`NumberFields`] and [`NumberRules`] for a message from its sections.
macro_rules! declare_rules {
    ($ty:ty, $sections:expr) => {
        impl $crate::numbers::NumberRules for $ty {
            const SECTIONS: &'static [$crate::numbers::Section] = $sections;
        }
        impl $crate::numbers::NumberFields for $ty {
            fn check_numbers(&self) -> Result<(), $crate::numbers::NumberError> {
                $crate::numbers::check(self, <$ty as $crate::numbers::NumberRules>::SECTIONS)
            }
        }
    };
}
pub(crate) use declare_rules;

// `std_msgs/String` has no numeric field: every sample passes (the planner harness's text
// request and test services take it as their request message).
declare_rules!(crate::std_msgs::StringMsg, &[]);

/// A numeric leaf's value, with the range of its type for integers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Number {
    /// A `float64` (or `float32`) field.
    Float(f64),
    /// An integer field and the extremes of its type.
    Int {
        /// The value.
        value: i128,
        /// The type's minimum (`i32::MIN`, `0`, …).
        min: i128,
        /// The type's maximum.
        max: i128,
    },
}

impl Number {
    /// The value as `f64` (exact for integers up to 2^53).
    pub fn as_f64(self) -> f64 {
        match self {
            Number::Float(v) => v,
            Number::Int { value, .. } => value as f64,
        }
    }
}

impl std::fmt::Display for Number {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Number::Float(v) => f.write_str(&format_value(*v)),
            Number::Int { value, .. } => write!(f, "{value}"),
        }
    }
}

/// A float for a message: `NaN`, `inf`, `-0`, plain between 1e-4 and 1e7, else in exponent
/// form (`1e308`, `5e-324`), never 300 digits.
pub fn format_value(v: f64) -> String {
    if v.is_nan() {
        "NaN".to_string()
    } else if v.is_infinite() {
        if v > 0.0 { "inf" } else { "-inf" }.to_string()
    } else if v == 0.0 {
        if v.is_sign_negative() { "-0" } else { "0" }.to_string()
    } else if (1e-4..1e7).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

#[cfg(test)]
mod tests;
