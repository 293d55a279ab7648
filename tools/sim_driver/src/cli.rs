//! The command line: every argument parsed and checked into a [`Config`].

use clap::{error::ErrorKind, CommandFactory, Parser, ValueEnum};

use crate::faults::{parse_scheduled, ScheduledFault};

/// Most joints the driver accepts.
pub const MAX_JOINTS: usize = 64;
/// Largest magnitude of an initial position (joint units).
pub const MAX_POSITION: f64 = 1e6;
/// Largest state rate (Hz).
pub const MAX_RATE: f64 = 2000.0;
/// Largest transport delay (s).
pub const MAX_DELAY: f64 = 1.0;
/// Largest noise standard deviation (joint units).
pub const MAX_NOISE: f64 = 0.01;

/// The message type of `<ns>/commands`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum CommandType {
    /// `std_msgs/msg/Float64MultiArray`, one position per joint in `--joints` order.
    #[value(name = "float64_multi_array")]
    Float64MultiArray,
    /// `sensor_msgs/msg/JointState`, names and positions in any order.
    #[value(name = "joint_state")]
    JointState,
}

#[derive(Debug, Parser)]
#[command(
    name = "sim_driver",
    version,
    about = "A simulated robot driver: position commands, FollowJointTrajectory, joint states \
             with delay, noise and injected faults (--help for the whole interface)",
    after_long_help = include_str!("help.md")
)]
struct Args {
    /// Comma-separated joint names (1 to 64, unique).
    #[arg(long, value_name = "NAMES", required = true, value_delimiter = ',', value_parser = parse_joint)]
    joints: Vec<String>,
    /// Start position, one value per joint, comma-separated.
    #[arg(
        long,
        value_name = "VALUES",
        required = true,
        value_delimiter = ',',
        value_parser = parse_value,
        allow_hyphen_values = true
    )]
    initial: Vec<f64>,
    /// Namespace of every topic and the action.
    #[arg(long, value_name = "NS", default_value = "/driver", value_parser = parse_namespace)]
    namespace: String,
    /// State publishing and integration rate, Hz, in (0, 2000].
    #[arg(long, value_name = "HZ", default_value = "250", value_parser = parse_rate, allow_hyphen_values = true)]
    rate: f64,
    /// Transport delay of the measured state behind the command, s, in [0, 1].
    #[arg(long, value_name = "S", default_value = "0.008", value_parser = parse_delay, allow_hyphen_values = true)]
    delay: f64,
    /// Standard deviation of the Gaussian measurement noise (joint units), in [0, 0.01].
    #[arg(long, value_name = "SD", default_value = "0", value_parser = parse_noise, allow_hyphen_values = true)]
    noise: f64,
    /// Seed of the noise generator.
    #[arg(
        long,
        value_name = "N",
        default_value = "1",
        allow_hyphen_values = true
    )]
    seed: u64,
    /// Message type of the commands topic (NS/commands).
    #[arg(
        long,
        value_name = "TYPE",
        value_enum,
        default_value = "float64_multi_array"
    )]
    command_type: CommandType,
    /// A scheduled fault, SECONDS:FAULT after the first command or goal (repeatable).
    #[arg(long = "fault", value_name = "SECONDS:FAULT", value_parser = parse_scheduled, allow_hyphen_values = true)]
    faults: Vec<ScheduledFault>,
}

/// The checked configuration of one driver.
#[derive(Debug, Clone, PartialEq)]
pub struct Config {
    /// Joint names, the order of commands and states.
    pub joints: Vec<String>,
    /// Start position, one per joint.
    pub initial: Vec<f64>,
    /// Namespace (`/` or `/a/b`).
    pub namespace: String,
    /// State rate, Hz.
    pub rate: f64,
    /// Transport delay, s.
    pub delay: f64,
    /// Noise standard deviation, joint units.
    pub noise: f64,
    /// Noise seed.
    pub seed: u64,
    /// Message type of the command topic.
    pub command_type: CommandType,
    /// Scheduled faults, in the order given.
    pub faults: Vec<ScheduledFault>,
}

impl Config {
    /// The absolute name of `leaf` under the namespace, e.g. `/driver/commands`.
    pub fn topic(&self, leaf: &str) -> String {
        if self.namespace == "/" {
            format!("/{leaf}")
        } else {
            format!("{}/{leaf}", self.namespace)
        }
    }
}

/// Parses the process's arguments.
///
/// # Errors
/// A clap error (its `exit()` prints it and exits with code 2; 0 for `--help`).
pub fn parse() -> Result<Config, clap::Error> {
    parse_from(std::env::args_os())
}

/// Parses `args` (the first is the program name).
///
/// # Errors
/// As [`parse`].
pub fn parse_from<I, T>(args: I) -> Result<Config, clap::Error>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let a = Args::try_parse_from(args)?;
    let invalid = |msg: String| Args::command().error(ErrorKind::ValueValidation, msg);
    if a.joints.is_empty() || a.joints.len() > MAX_JOINTS {
        return Err(invalid(format!(
            "--joints: {} names given; between 1 and {MAX_JOINTS} are needed",
            a.joints.len()
        )));
    }
    for (i, name) in a.joints.iter().enumerate() {
        if a.joints[..i].contains(name) {
            return Err(invalid(format!("--joints: '{name}' is given twice")));
        }
    }
    if a.initial.len() != a.joints.len() {
        return Err(invalid(format!(
            "--initial: {} values for {} joints (--joints); give one per joint",
            a.initial.len(),
            a.joints.len()
        )));
    }
    Ok(Config {
        joints: a.joints,
        initial: a.initial,
        namespace: a.namespace,
        rate: a.rate,
        delay: a.delay,
        noise: a.noise,
        seed: a.seed,
        command_type: a.command_type,
        faults: a.faults,
    })
}

/// The help text's long form (for tests of the documentation).
#[cfg(test)]
pub fn long_help() -> String {
    Args::command().render_long_help().to_string()
}

/// One joint name of `--joints` (clap splits the list at commas).
fn parse_joint(n: &str) -> Result<String, String> {
    if n.is_empty() {
        Err("empty joint name".to_string())
    } else if n.chars().any(|c| c.is_whitespace() || c.is_control()) {
        Err(format!(
            "joint name '{n}' contains a space or control character"
        ))
    } else {
        Ok(n.to_string())
    }
}

/// One finite value of `--initial`, at most [`MAX_POSITION`] in magnitude.
fn parse_value(v: &str) -> Result<f64, String> {
    let x: f64 = v
        .trim()
        .parse()
        .map_err(|_| format!("'{v}' is not a number"))?;
    if !x.is_finite() || x.abs() > MAX_POSITION {
        return Err(format!(
            "{v} must be finite and at most {MAX_POSITION} in magnitude"
        ));
    }
    Ok(x)
}

/// A finite number in `[lo, hi]` (or `(lo, hi]` when `open_low`).
fn number_in(s: &str, lo: f64, hi: f64, open_low: bool, unit: &str) -> Result<f64, String> {
    let x: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("'{s}' is not a number"))?;
    let above = if open_low { x > lo } else { x >= lo };
    if !x.is_finite() || !above || x > hi {
        let open = if open_low { "(" } else { "[" };
        return Err(format!(
            "{s} is out of range: it must be finite and in {open}{lo}, {hi}]{unit}"
        ));
    }
    Ok(x)
}

fn parse_rate(s: &str) -> Result<f64, String> {
    number_in(s, 0.0, MAX_RATE, true, " Hz")
}

fn parse_delay(s: &str) -> Result<f64, String> {
    number_in(s, 0.0, MAX_DELAY, false, " s")
}

fn parse_noise(s: &str) -> Result<f64, String> {
    number_in(s, 0.0, MAX_NOISE, false, " (joint units)")
}

/// `/` or `/tok/tok` where every token is a valid ROS name token.
fn parse_namespace(s: &str) -> Result<String, String> {
    if s == "/" {
        return Ok(s.to_string());
    }
    let Some(rest) = s.strip_prefix('/') else {
        return Err(format!("'{s}' must be absolute (start with '/')"));
    };
    for token in rest.split('/') {
        let mut chars = token.chars();
        let first_ok = chars
            .next()
            .is_some_and(|c| c.is_ascii_alphabetic() || c == '_');
        if !first_ok
            || !chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
            || token.contains("__")
        {
            return Err(format!(
                "'{s}': '{token}' is not a valid ROS name token (a letter or '_', then \
                 letters, digits, single '_'; no empty token or trailing '/')"
            ));
        }
    }
    Ok(s.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(extra: &[&str]) -> Result<Config, clap::Error> {
        let mut args = vec!["sim_driver", "--joints", "a,b", "--initial", "0,-1.5"];
        args.extend_from_slice(extra);
        parse_from(args)
    }

    #[test]
    fn defaults() {
        let c = parse(&[]).unwrap();
        assert_eq!(c.joints, ["a", "b"]);
        assert_eq!(c.initial, [0.0, -1.5]);
        assert_eq!(c.namespace, "/driver");
        assert_eq!((c.rate, c.delay, c.noise, c.seed), (250.0, 0.008, 0.0, 1));
        assert_eq!(c.command_type, CommandType::Float64MultiArray);
        assert!(c.faults.is_empty());
        assert_eq!(c.topic("commands"), "/driver/commands");
    }

    #[test]
    fn bad_numbers_name_their_argument() {
        for (args, needle) in [
            (&["--rate", "0"][..], "--rate"),
            (&["--rate", "2000.5"], "--rate"),
            (&["--rate", "NaN"], "--rate"),
            (&["--delay", "-0.1"], "--delay"),
            (&["--delay", "inf"], "--delay"),
            (&["--noise", "0.02"], "--noise"),
            (&["--seed", "-1"], "--seed"),
            (&["--fault", "x:drop"], "--fault"),
            (&["--fault", "1:explode"], "--fault"),
            (&["--fault", "-1:drop"], "--fault"),
            (&["--namespace", "driver"], "--namespace"),
            (&["--namespace", "/a//b"], "--namespace"),
            (&["--command-type", "twist"], "--command-type"),
        ] {
            let e = parse(args).unwrap_err();
            assert_eq!(e.exit_code(), 2, "{args:?}");
            assert!(e.to_string().contains(needle), "{args:?}: {e}");
        }
        let e = parse_from(["sim_driver", "--joints", "a,b", "--initial", "0"]).unwrap_err();
        assert!(e.to_string().contains("--initial"), "{e}");
        let e = parse_from(["sim_driver", "--joints", "a,a", "--initial", "0,0"]).unwrap_err();
        assert!(e.to_string().contains("twice"), "{e}");
        let e = parse_from(["sim_driver", "--joints", "a", "--initial", "nan"]).unwrap_err();
        assert!(e.to_string().contains("--initial"), "{e}");
    }

    #[test]
    fn root_namespace_and_faults() {
        let c = parse(&[
            "--namespace",
            "/",
            "--fault",
            "0.5:drop",
            "--fault",
            "2:resume",
        ])
        .unwrap();
        assert_eq!(c.topic("joint_states"), "/joint_states");
        assert_eq!(c.faults.len(), 2);
        assert!(long_help().contains("stamp_back"));
    }
}
