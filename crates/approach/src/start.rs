//! [`StartSpec`]: where a request asks its trajectory to start (issue 27, item 1).

use serde::{de, Deserialize, Deserializer, Serialize, Serializer};

/// Where a planned trajectory starts.
///
/// In a request message it is the pair `start` (`""`, `"current"`, `"given"`, `"none"`) and
/// `start_positions` ([`StartSpec::from_fields`]); in a YAML request the one field `start`:
/// `current`, `none`, or a list of joint positions (given).
#[derive(Debug, Clone, PartialEq, Default)]
pub enum StartSpec {
    /// Not given: the robot's current state when the node has one, else [`StartSpec::None`].
    #[default]
    Default,
    /// The robot's latest joint state (an error when the node has none).
    Current,
    /// These joint positions (the planner's joint order).
    Given(Vec<f64>),
    /// The process's first point: no approach, no retract.
    None,
}

impl StartSpec {
    /// The start of a request message's `start` and `start_positions` fields.
    ///
    /// # Errors
    /// A message naming the field: an unknown `start`, `"given"` without positions, positions
    /// with another `start`.
    pub fn from_fields(start: &str, positions: &[f64]) -> Result<Self, String> {
        let spec = match start {
            "" => StartSpec::Default,
            "current" => StartSpec::Current,
            "none" => StartSpec::None,
            "given" => {
                if positions.is_empty() {
                    return Err(
                        "start is \"given\" but start_positions is empty: give one position per \
                         joint"
                            .into(),
                    );
                }
                return Ok(StartSpec::Given(positions.to_vec()));
            }
            other => {
                return Err(format!(
                    "start = {other:?}: must be \"\" (current when the robot's joint state is \
                     known, else none), \"current\", \"given\" or \"none\""
                ))
            }
        };
        if !positions.is_empty() {
            return Err(format!(
                "start_positions has {} value(s) but start is {start:?}: positions are only \
                 read with start \"given\"",
                positions.len()
            ));
        }
        Ok(spec)
    }

    /// Whether it is [`StartSpec::Default`] (left out when serialized).
    pub fn is_default(&self) -> bool {
        matches!(self, StartSpec::Default)
    }

    /// The message fields of this start (`start`, `start_positions`).
    pub fn to_fields(&self) -> (String, Vec<f64>) {
        match self {
            StartSpec::Default => (String::new(), Vec::new()),
            StartSpec::Current => ("current".into(), Vec::new()),
            StartSpec::Given(q) => ("given".into(), q.clone()),
            StartSpec::None => ("none".into(), Vec::new()),
        }
    }
}

impl Serialize for StartSpec {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            StartSpec::Default => s.serialize_str(""),
            StartSpec::Current => s.serialize_str("current"),
            StartSpec::None => s.serialize_str("none"),
            StartSpec::Given(q) => q.serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for StartSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl<'de> de::Visitor<'de> for Visitor {
            type Value = StartSpec;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("\"current\", \"none\" or a list of joint positions")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<StartSpec, E> {
                match v {
                    "" => Ok(StartSpec::Default),
                    "current" => Ok(StartSpec::Current),
                    "none" => Ok(StartSpec::None),
                    other => Err(E::custom(format!(
                        "start = {other:?}: must be \"current\", \"none\" or a list of joint \
                         positions"
                    ))),
                }
            }
            fn visit_seq<A: de::SeqAccess<'de>>(self, mut seq: A) -> Result<StartSpec, A::Error> {
                let mut q = Vec::new();
                while let Some(v) = seq.next_element::<f64>()? {
                    q.push(v);
                }
                if q.is_empty() {
                    return Err(de::Error::custom(
                        "start is an empty list: give one position per joint",
                    ));
                }
                Ok(StartSpec::Given(q))
            }
        }
        d.deserialize_any(Visitor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn message_fields_are_read_and_refused_by_name() {
        assert_eq!(StartSpec::from_fields("", &[]), Ok(StartSpec::Default));
        assert_eq!(StartSpec::from_fields("none", &[]), Ok(StartSpec::None));
        assert_eq!(
            StartSpec::from_fields("given", &[0.1, 0.2]),
            Ok(StartSpec::Given(vec![0.1, 0.2]))
        );
        assert!(StartSpec::from_fields("given", &[])
            .unwrap_err()
            .contains("start_positions is empty"));
        assert!(StartSpec::from_fields("current", &[1.0])
            .unwrap_err()
            .contains("only read with start \"given\""));
        assert!(StartSpec::from_fields("home", &[])
            .unwrap_err()
            .contains("\"home\""));
        for s in [
            StartSpec::Default,
            StartSpec::Current,
            StartSpec::None,
            StartSpec::Given(vec![1.0]),
        ] {
            let (a, b) = s.to_fields();
            assert_eq!(StartSpec::from_fields(&a, &b), Ok(s));
        }
    }

    #[test]
    fn yaml_takes_a_word_or_a_list() {
        let read = |t: &str| serde_yaml_ng::from_str::<StartSpec>(t);
        assert_eq!(read("current").unwrap(), StartSpec::Current);
        assert_eq!(read("none").unwrap(), StartSpec::None);
        assert_eq!(read("[0.5, 1]").unwrap(), StartSpec::Given(vec![0.5, 1.0]));
        assert!(read("[]").unwrap_err().to_string().contains("empty list"));
        assert!(read("home").unwrap_err().to_string().contains("\"home\""));
        assert_eq!(
            serde_yaml_ng::to_string(&StartSpec::Given(vec![0.5])).unwrap(),
            "- 0.5\n"
        );
    }
}
