//! The ROS 2 command-line conventions, so launch files work unchanged.
//!
//! `exe [args] --ros-args [-r|--remap [node:]from:=to] [-p|--param name:=value]
//! [--params-file FILE] [--log-level LEVEL] [--enable|--disable-rosout-logs]
//! [--enable|--disable-stdout-logs] [--] [args]`. Several `--ros-args` sections may appear;
//! `--` or a new non-ROS argument after `--` closes a section, as in rcl.

use std::path::PathBuf;

use crate::{names::Remap, params::ParamValue, Params, RosError};

/// Severity threshold of the node's logger (`--log-level`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum LogLevel {
    /// Everything.
    Debug,
    /// Normal operation (the default).
    Info,
    /// Something unexpected, the node continues.
    Warn,
    /// A request failed.
    Error,
    /// The node cannot continue.
    Fatal,
}

impl LogLevel {
    fn parse(s: &str) -> Option<Self> {
        Some(match s.to_ascii_lowercase().as_str() {
            "debug" => Self::Debug,
            "info" => Self::Info,
            "warn" | "warning" => Self::Warn,
            "error" => Self::Error,
            "fatal" => Self::Fatal,
            _ => return None,
        })
    }
}

/// Where a parameter came from, kept in command-line order (later ones override earlier ones).
#[derive(Debug, Clone, PartialEq)]
pub enum ParamSource {
    /// `--params-file FILE`.
    File(PathBuf),
    /// `-p name:=value`.
    Inline(String, ParamValue),
}

/// The parsed ROS arguments of a process, plus its other arguments.
#[derive(Debug, Clone, PartialEq)]
pub struct RosArgs {
    /// Remap rules in order, including `__ns` and `__node`.
    pub remaps: Vec<Remap>,
    /// Parameter sources in order.
    pub params: Vec<ParamSource>,
    /// `--log-level`, if given.
    pub log_level: Option<LogLevel>,
    /// Whether logs go to `/rosout` (default true).
    pub rosout_logs: bool,
    /// Whether logs go to stderr (default true).
    pub stdout_logs: bool,
    /// Arguments that are not ROS arguments, in order.
    pub other: Vec<String>,
}

impl Default for RosArgs {
    fn default() -> Self {
        Self {
            remaps: Vec::new(),
            params: Vec::new(),
            log_level: None,
            rosout_logs: true,
            stdout_logs: true,
            other: Vec::new(),
        }
    }
}

impl RosArgs {
    /// Parses a full argument list (without the program name).
    ///
    /// # Returns
    /// The ROS arguments, or an error naming the first argument that is not understood.
    /// Unknown flags inside `--ros-args` are errors rather than being ignored.
    pub fn parse<I, S>(args: I) -> Result<Self, RosError>
    where
        I: IntoIterator<Item = S>,
        S: Into<String>,
    {
        let mut out = Self::default();
        let mut it = args.into_iter().map(Into::into);
        let mut in_ros = false;
        while let Some(arg) = it.next() {
            if arg == "--ros-args" {
                in_ros = true;
                continue;
            }
            if !in_ros {
                out.other.push(arg);
                continue;
            }
            let mut value = |flag: &str| {
                it.next().ok_or_else(|| RosError::Args {
                    arg: flag.to_string(),
                    reason: "missing value".into(),
                })
            };
            match arg.as_str() {
                "--" => in_ros = false,
                "-r" | "--remap" => out.remaps.push(Remap::parse(&value(&arg)?)?),
                "-p" | "--param" => {
                    let rule = value(&arg)?;
                    let (name, text) = rule.split_once(":=").ok_or_else(|| RosError::Args {
                        arg: rule.clone(),
                        reason: "a parameter has the form name:=value".into(),
                    })?;
                    if name.is_empty() {
                        return Err(RosError::Args {
                            arg: rule.clone(),
                            reason: "empty parameter name".into(),
                        });
                    }
                    out.params.push(ParamSource::Inline(
                        name.to_string(),
                        ParamValue::parse(name, text)?,
                    ));
                }
                "--params-file" => out.params.push(ParamSource::File(value(&arg)?.into())),
                "--log-level" => {
                    let v = value(&arg)?;
                    // `--log-level name:=level` sets one logger; kerf nodes have one logger each.
                    let level = v.rsplit(":=").next().unwrap_or(&v);
                    out.log_level = Some(LogLevel::parse(level).ok_or_else(|| RosError::Args {
                        arg: v.clone(),
                        reason: "log level must be debug, info, warn, error or fatal".into(),
                    })?);
                }
                "--enable-rosout-logs" => out.rosout_logs = true,
                "--disable-rosout-logs" => out.rosout_logs = false,
                "--enable-stdout-logs" => out.stdout_logs = true,
                "--disable-stdout-logs" => out.stdout_logs = false,
                // rcl also accepts these; they have no effect on a kerf node.
                "--enable-external-lib-logs" | "--disable-external-lib-logs" => {}
                other => {
                    return Err(RosError::Args {
                        arg: other.to_string(),
                        reason: "not a ROS argument kerf understands (-r, -p, --params-file, \
                                 --log-level, --enable/--disable-rosout-logs, \
                                 --enable/--disable-stdout-logs)"
                            .into(),
                    })
                }
            }
        }
        Ok(out)
    }

    fn node_rule(&self, key: &str, node: &str) -> Option<&str> {
        self.remaps
            .iter()
            .find(|r| r.from == key && r.applies_to(node))
            .map(|r| r.to.as_str())
    }

    /// The node's base name after `__node:=` (or `__name:=`) remapping of `default`.
    pub fn node_name(&self, default: &str) -> Result<String, RosError> {
        let name = self
            .node_rule("__node", default)
            .or_else(|| self.node_rule("__name", default))
            .unwrap_or(default)
            .to_string();
        crate::names::validate_node_name(&name)?;
        Ok(name)
    }

    /// The node's namespace after `__ns:=`; rules may name the node by its default name.
    pub fn namespace(&self, default_node: &str, default_ns: &str) -> Result<String, RosError> {
        crate::names::normalize_namespace(
            self.node_rule("__ns", default_node).unwrap_or(default_ns),
        )
    }

    /// The parameters of one node: files and `-p` in command-line order.
    pub fn params_for(&self, fqn: &str, base: &str) -> Result<Params, RosError> {
        let mut params = Params::default();
        for src in &self.params {
            match src {
                ParamSource::File(path) => {
                    let shown = path.display().to_string();
                    let text = std::fs::read_to_string(path).map_err(|e| RosError::ParamsFile {
                        path: shown.clone(),
                        reason: e.to_string(),
                    })?;
                    params.merge_file(&shown, &text, fqn, base)?;
                }
                ParamSource::Inline(name, v) => params.set(name, v.clone()),
            }
        }
        Ok(params)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(s: &str) -> Result<RosArgs, RosError> {
        RosArgs::parse(s.split_whitespace())
    }

    #[test]
    fn parses_launch_style_arguments() {
        let a = parse(
            "run --ros-args -r __ns:=/cell -r __node:=exec -r ~/joint_trajectory:=/traj \
             -p control_rate:=100.0 --log-level warn -- extra",
        )
        .unwrap();
        assert_eq!(a.other, vec!["run", "extra"]);
        assert_eq!(a.node_name("trajectory_executor").unwrap(), "exec");
        assert_eq!(a.namespace("trajectory_executor", "/").unwrap(), "/cell");
        assert_eq!(a.log_level, Some(LogLevel::Warn));
        let p = a.params_for("/cell/exec", "exec").unwrap();
        assert_eq!(p.f64("control_rate").unwrap(), Some(100.0));
    }

    #[test]
    fn node_specific_rules_apply_to_their_node_only() {
        let a = parse("--ros-args -r a:__node:=x -r b:__ns:=/y").unwrap();
        assert_eq!(a.node_name("a").unwrap(), "x");
        assert_eq!(a.node_name("b").unwrap(), "b");
        assert_eq!(a.namespace("b", "/").unwrap(), "/y");
        assert_eq!(a.namespace("a", "/").unwrap(), "/");
    }

    #[test]
    fn later_params_override_files() {
        let dir = std::env::temp_dir().join(format!("kerf_ros_args_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("p.yaml");
        std::fs::write(
            &f,
            "/**:\n  ros__parameters:\n    rate: 1.0\n    keep: true\n",
        )
        .unwrap();
        let a = RosArgs::parse([
            "--ros-args".to_string(),
            "--params-file".into(),
            f.display().to_string(),
            "-p".into(),
            "rate:=2.0".into(),
        ])
        .unwrap();
        let p = a.params_for("/n", "n").unwrap();
        assert_eq!(p.f64("rate").unwrap(), Some(2.0));
        assert!(p.bool_or("keep", false).unwrap());
        let missing = RosArgs::parse(["--ros-args", "--params-file", "/nonexistent.yaml"]).unwrap();
        assert!(missing.params_for("/n", "n").is_err());
    }

    #[test]
    fn refuses_malformed_arguments() {
        for bad in [
            "--ros-args -r",
            "--ros-args -p novalue",
            "--ros-args --frobnicate",
            "--ros-args --log-level loud",
            "--ros-args -r __node:=9bad",
        ] {
            let res = parse(bad).and_then(|a| a.node_name("n").map(|_| a));
            assert!(res.is_err(), "{bad} should fail");
        }
    }
}
