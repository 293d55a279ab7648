//! Node parameters from `-p name:=value` and `--params-file`, with typed, checked access.
//!
//! Values are parsed as YAML, as `rcl` does. Parameter files have the ROS 2 layout
//! `<node key>: {ros__parameters: {...}}`; nested maps flatten to dotted names
//! (`constraints: {goal_time: 1.0}` → `constraints.goal_time`). A node key matches when it is
//! `/**`, the node's fully qualified name (with or without the leading slash), `/**/<node>`,
//! or the node's base name.

use std::collections::BTreeMap;

use serde_yaml_ng::Value;

use crate::RosError;

/// A ROS 2 parameter value (the types of `rcl_interfaces/msg/ParameterType`, less byte arrays).
#[derive(Debug, Clone, PartialEq)]
pub enum ParamValue {
    /// `bool`
    Bool(bool),
    /// `int64`
    Integer(i64),
    /// `float64`
    Double(f64),
    /// `string`
    String(String),
    /// `bool[]`
    BoolArray(Vec<bool>),
    /// `int64[]`
    IntegerArray(Vec<i64>),
    /// `float64[]`
    DoubleArray(Vec<f64>),
    /// `string[]`
    StringArray(Vec<String>),
}

impl ParamValue {
    /// Converts a YAML scalar or homogeneous sequence, as rcl's YAML parameter parser does.
    pub fn from_yaml(name: &str, v: &Value) -> Result<Self, RosError> {
        let bad = |reason: String| RosError::Param {
            name: name.into(),
            reason,
        };
        Ok(match v {
            Value::Bool(b) => Self::Bool(*b),
            Value::Number(n) => match n.as_i64() {
                Some(i) => Self::Integer(i),
                None => Self::Double(
                    n.as_f64()
                        .ok_or_else(|| bad(format!("number {n} out of range")))?,
                ),
            },
            Value::String(s) => Self::String(s.clone()),
            Value::Sequence(items) => {
                if items.is_empty() {
                    return Err(bad(
                        "empty arrays have no type; give at least one element".into()
                    ));
                }
                if items.iter().all(|i| matches!(i, Value::Bool(_))) {
                    Self::BoolArray(items.iter().filter_map(Value::as_bool).collect())
                } else if items.iter().all(|i| i.as_i64().is_some()) {
                    Self::IntegerArray(items.iter().filter_map(Value::as_i64).collect())
                } else if items.iter().all(|i| i.as_f64().is_some()) {
                    Self::DoubleArray(items.iter().filter_map(Value::as_f64).collect())
                } else if items.iter().all(|i| i.as_str().is_some()) {
                    Self::StringArray(
                        items
                            .iter()
                            .filter_map(|i| i.as_str().map(String::from))
                            .collect(),
                    )
                } else {
                    return Err(bad(
                        "arrays must hold one type: bool, integer, double or string".into(),
                    ));
                }
            }
            Value::Null => return Err(bad("no value given".into())),
            other => return Err(bad(format!("unsupported value {other:?}"))),
        })
    }

    /// Parses the right-hand side of `-p name:=value` (YAML, like rcl).
    pub fn parse(name: &str, text: &str) -> Result<Self, RosError> {
        let v: Value = serde_yaml_ng::from_str(text).map_err(|e| RosError::Param {
            name: name.into(),
            reason: format!("cannot parse {text:?} as a YAML value: {e}"),
        })?;
        Self::from_yaml(name, &v)
    }

    fn type_name(&self) -> &'static str {
        match self {
            Self::Bool(_) => "bool",
            Self::Integer(_) => "integer",
            Self::Double(_) => "double",
            Self::String(_) => "string",
            Self::BoolArray(_) => "bool array",
            Self::IntegerArray(_) => "integer array",
            Self::DoubleArray(_) => "double array",
            Self::StringArray(_) => "string array",
        }
    }

    /// Converts to ros2-client's parameter value (so `ros2 param get` shows it).
    pub fn to_ros(&self) -> ros2_client::ParameterValue {
        use ros2_client::ParameterValue as P;
        match self.clone() {
            Self::Bool(b) => P::Boolean(b),
            Self::Integer(i) => P::Integer(i),
            Self::Double(d) => P::Double(d),
            Self::String(s) => P::String(s),
            Self::BoolArray(v) => P::BooleanArray(v),
            Self::IntegerArray(v) => P::IntegerArray(v),
            Self::DoubleArray(v) => P::DoubleArray(v),
            Self::StringArray(v) => P::StringArray(v),
        }
    }
}

/// The parameters of one node, by flattened name.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Params {
    values: BTreeMap<String, ParamValue>,
}

impl Params {
    /// The parameters node `name` (namespace `/`) reads from `--ros-args -p a:=1 -p b:=x …`,
    /// as parsed from a command line, with unknown names refused: what a node's `run` would
    /// see, for checking a node's configuration without starting it.
    ///
    /// # Arguments
    /// * `name` — the node's name.
    /// * `known` — the parameter names the node reads.
    /// * `assignments` — `name:=value` strings.
    ///
    /// # Errors
    /// As [`crate::RosArgs::parse`] and [`Params::reject_unknown`].
    pub fn from_assignments(
        name: &str,
        known: &[&str],
        assignments: &[&str],
    ) -> Result<Self, RosError> {
        let mut words = vec!["--ros-args".to_string()];
        for a in assignments {
            words.push("-p".into());
            words.push(a.to_string());
        }
        let args = crate::RosArgs::parse(words)?;
        let params = args.params_for(&format!("/{name}"), name)?;
        params.reject_unknown(known)?;
        Ok(params)
    }

    /// Sets (or overrides) one parameter.
    pub fn set(&mut self, name: &str, value: ParamValue) {
        self.values.insert(name.to_string(), value);
    }

    /// All parameters, sorted by name.
    pub fn iter(&self) -> impl Iterator<Item = (&String, &ParamValue)> {
        self.values.iter()
    }

    /// The raw value, if set.
    pub fn get(&self, name: &str) -> Option<&ParamValue> {
        self.values.get(name)
    }

    /// Parameters whose names the node does not know: a typo in a launch file should fail loudly.
    ///
    /// # Returns
    /// Error naming the first unknown parameter and listing the known ones.
    pub fn reject_unknown(&self, known: &[&str]) -> Result<(), RosError> {
        for name in self.values.keys() {
            let is_known = known
                .iter()
                .any(|k| k == name || (k.ends_with(".*") && name.starts_with(&k[..k.len() - 1])));
            if !is_known && name != "use_sim_time" {
                return Err(RosError::Param {
                    name: name.clone(),
                    reason: format!("unknown parameter; this node accepts: {}", known.join(", ")),
                });
            }
        }
        Ok(())
    }

    fn wrong_type(name: &str, want: &str, got: &ParamValue) -> RosError {
        RosError::Param {
            name: name.into(),
            reason: format!("expected {want}, got {} {got:?}", got.type_name()),
        }
    }

    /// A finite double; an integer is accepted and converted (YAML `1` for `1.0`).
    pub fn f64(&self, name: &str) -> Result<Option<f64>, RosError> {
        let v = match self.get(name) {
            None => return Ok(None),
            Some(ParamValue::Double(d)) => *d,
            Some(ParamValue::Integer(i)) => *i as f64,
            Some(other) => return Err(Self::wrong_type(name, "double", other)),
        };
        if !v.is_finite() {
            return Err(RosError::Param {
                name: name.into(),
                reason: format!("must be finite, got {v}"),
            });
        }
        Ok(Some(v))
    }

    /// A finite double, or `default` when unset.
    pub fn f64_or(&self, name: &str, default: f64) -> Result<f64, RosError> {
        Ok(self.f64(name)?.unwrap_or(default))
    }

    /// An integer, or `default` when unset.
    pub fn i64_or(&self, name: &str, default: i64) -> Result<i64, RosError> {
        match self.get(name) {
            None => Ok(default),
            Some(ParamValue::Integer(i)) => Ok(*i),
            Some(other) => Err(Self::wrong_type(name, "integer", other)),
        }
    }

    /// A boolean, or `default` when unset.
    pub fn bool_or(&self, name: &str, default: bool) -> Result<bool, RosError> {
        match self.get(name) {
            None => Ok(default),
            Some(ParamValue::Bool(b)) => Ok(*b),
            Some(other) => Err(Self::wrong_type(name, "bool", other)),
        }
    }

    /// A string, if set.
    pub fn string(&self, name: &str) -> Result<Option<String>, RosError> {
        match self.get(name) {
            None => Ok(None),
            Some(ParamValue::String(s)) => Ok(Some(s.clone())),
            Some(other) => Err(Self::wrong_type(name, "string", other)),
        }
    }

    /// A string that must be set.
    pub fn required_string(&self, name: &str) -> Result<String, RosError> {
        self.string(name)?.ok_or_else(|| RosError::Param {
            name: name.into(),
            reason: "required, but not set".into(),
        })
    }

    /// An array of finite doubles (integers accepted), if set.
    pub fn f64_array(&self, name: &str) -> Result<Option<Vec<f64>>, RosError> {
        let v = match self.get(name) {
            None => return Ok(None),
            Some(ParamValue::DoubleArray(v)) => v.clone(),
            Some(ParamValue::IntegerArray(v)) => v.iter().map(|i| *i as f64).collect(),
            Some(other) => return Err(Self::wrong_type(name, "double array", other)),
        };
        if let Some(bad) = v.iter().find(|x| !x.is_finite()) {
            return Err(RosError::Param {
                name: name.into(),
                reason: format!("must be finite, got {bad}"),
            });
        }
        Ok(Some(v))
    }

    /// A string array, if set.
    pub fn string_array(&self, name: &str) -> Result<Option<Vec<String>>, RosError> {
        match self.get(name) {
            None => Ok(None),
            Some(ParamValue::StringArray(v)) => Ok(Some(v.clone())),
            Some(other) => Err(Self::wrong_type(name, "string array", other)),
        }
    }

    /// Merges the `ros__parameters` of every key of a ROS 2 parameters file that matches the node.
    ///
    /// # Arguments
    /// * `yaml` – file contents; `path` – for messages.
    /// * `fqn` – the node's fully qualified name (`/ns/node`); `base` – its base name.
    pub fn merge_file(
        &mut self,
        path: &str,
        yaml: &str,
        fqn: &str,
        base: &str,
    ) -> Result<(), RosError> {
        let file_err = |reason: String| RosError::ParamsFile {
            path: path.into(),
            reason,
        };
        let root: Value = serde_yaml_ng::from_str(yaml).map_err(|e| file_err(e.to_string()))?;
        let Value::Mapping(nodes) = root else {
            return Err(file_err("top level must be a mapping of node names".into()));
        };
        for (key, body) in &nodes {
            let key = key
                .as_str()
                .ok_or_else(|| file_err(format!("node key {key:?} is not a string")))?;
            let k = key.trim_start_matches('/');
            let matches = key == "/**"
                || key == "**"
                || k == fqn.trim_start_matches('/')
                || k == base
                || k.strip_prefix("**/") == Some(base);
            if !matches {
                continue;
            }
            let params = body
                .get("ros__parameters")
                .ok_or_else(|| file_err(format!("node key '{key}' has no 'ros__parameters'")))?;
            self.flatten_into("", params)?;
        }
        Ok(())
    }

    fn flatten_into(&mut self, prefix: &str, v: &Value) -> Result<(), RosError> {
        match v {
            Value::Mapping(m) => {
                for (k, child) in m {
                    let k = match k {
                        Value::String(s) => s.clone(),
                        other => serde_yaml_ng::to_string(other)
                            .map(|s| s.trim().to_string())
                            .unwrap_or_default(),
                    };
                    let name = if prefix.is_empty() {
                        k
                    } else {
                        format!("{prefix}.{k}")
                    };
                    self.flatten_into(&name, child)?;
                }
                Ok(())
            }
            leaf => {
                let value = ParamValue::from_yaml(prefix, leaf)?;
                self.set(prefix, value);
                Ok(())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_values_like_rcl() {
        assert_eq!(
            ParamValue::parse("a", "true").unwrap(),
            ParamValue::Bool(true)
        );
        assert_eq!(ParamValue::parse("a", "3").unwrap(), ParamValue::Integer(3));
        assert_eq!(
            ParamValue::parse("a", "250.0").unwrap(),
            ParamValue::Double(250.0)
        );
        assert_eq!(
            ParamValue::parse("a", "[0.1, 2]").unwrap(),
            ParamValue::DoubleArray(vec![0.1, 2.0])
        );
        assert_eq!(
            ParamValue::parse("a", "urdf/x.urdf").unwrap(),
            ParamValue::String("urdf/x.urdf".into())
        );
        assert!(ParamValue::parse("a", "[1, x]").is_err());
        assert!(ParamValue::parse("a", "[]").is_err());
    }

    #[test]
    fn file_matching_and_flattening() {
        let yaml = r#"
/**:
  ros__parameters:
    control_rate: 100.0
/cell/executor:
  ros__parameters:
    constraints:
      goal_time: 0.5
other:
  ros__parameters:
    control_rate: 1.0
"#;
        let mut p = Params::default();
        p.merge_file("f.yaml", yaml, "/cell/executor", "executor")
            .unwrap();
        assert_eq!(p.f64("control_rate").unwrap(), Some(100.0));
        assert_eq!(p.f64("constraints.goal_time").unwrap(), Some(0.5));
        assert!(p.reject_unknown(&["control_rate", "constraints.*"]).is_ok());
        let err = p.reject_unknown(&["control_rate"]).unwrap_err();
        assert!(err.to_string().contains("constraints.goal_time"), "{err}");
        assert!(Params::default()
            .merge_file("f", "x: {y: 1}", "/n", "n")
            .is_ok());
        assert!(Params::default()
            .merge_file("f", "n: {y: 1}", "/n", "n")
            .is_err());
    }

    #[test]
    fn typed_access_checks_types() {
        let mut p = Params::default();
        p.set("rate", ParamValue::Integer(250));
        p.set("name", ParamValue::Bool(true));
        p.set("nan", ParamValue::Double(f64::NAN));
        assert_eq!(p.f64_or("rate", 1.0).unwrap(), 250.0);
        assert!(p.string("name").is_err());
        assert!(p.f64("nan").is_err());
        assert!(p.required_string("missing").is_err());
        assert_eq!(p.f64_or("missing", 2.0).unwrap(), 2.0);
    }
}
