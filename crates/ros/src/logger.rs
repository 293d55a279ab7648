//! Node logging to stderr (ROS 2 console format) and to `/rosout`.

use std::sync::Arc;

use ros2_client::{
    builtin_interfaces::Time, log::LogLevel as RosLevel, NodeLoggingHandle, RosoutRaw,
};

use crate::LogLevel;

struct Inner {
    name: String,
    rosout: Option<NodeLoggingHandle>,
    level: LogLevel,
    stderr: bool,
}

/// A cheap, clonable logger for one node; usable from any thread.
#[derive(Clone)]
pub struct Logger {
    inner: Arc<Inner>,
}

impl Logger {
    /// A logger named `name` (ROS logger names use dots: `cell.executor`).
    pub fn new(
        name: &str,
        rosout: Option<NodeLoggingHandle>,
        level: LogLevel,
        stderr: bool,
    ) -> Self {
        Self {
            inner: Arc::new(Inner {
                name: name.to_string(),
                rosout,
                level,
                stderr,
            }),
        }
    }

    /// A logger that writes only to stderr (for tools and tests).
    pub fn stderr_only(name: &str) -> Self {
        Self::new(name, None, LogLevel::Info, true)
    }

    /// Logs `msg` at `level` if it passes the threshold.
    pub fn log(&self, level: LogLevel, msg: &str) {
        let i = &self.inner;
        if level < i.level {
            return;
        }
        let stamp = Time::now();
        if i.stderr {
            let ns = stamp.to_nanos();
            let tag = match level {
                LogLevel::Debug => "DEBUG",
                LogLevel::Info => "INFO",
                LogLevel::Warn => "WARN",
                LogLevel::Error => "ERROR",
                LogLevel::Fatal => "FATAL",
            };
            eprintln!(
                "[{tag}] [{}.{:09}] [{}]: {msg}",
                ns.div_euclid(1_000_000_000),
                ns.rem_euclid(1_000_000_000),
                i.name
            );
        }
        if let Some(h) = &i.rosout {
            let l = match level {
                LogLevel::Debug => RosLevel::Debug,
                LogLevel::Info => RosLevel::Info,
                LogLevel::Warn => RosLevel::Warn,
                LogLevel::Error => RosLevel::Error,
                LogLevel::Fatal => RosLevel::Fatal,
            };
            h.rosout_raw(stamp, l, &i.name, msg, file!(), "", line!());
        }
    }

    /// Logs at debug level.
    pub fn debug(&self, msg: &str) {
        self.log(LogLevel::Debug, msg)
    }
    /// Logs at info level.
    pub fn info(&self, msg: &str) {
        self.log(LogLevel::Info, msg)
    }
    /// Logs at warn level.
    pub fn warn(&self, msg: &str) {
        self.log(LogLevel::Warn, msg)
    }
    /// Logs at error level.
    pub fn error(&self, msg: &str) {
        self.log(LogLevel::Error, msg)
    }
}
