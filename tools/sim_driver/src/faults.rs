//! Injected faults: their names, `--fault SECONDS:FAULT` schedules, and when they fall due.

use std::{fmt, str::FromStr};

/// Largest delay of a scheduled fault (s).
pub const MAX_FAULT_DELAY: f64 = 86_400.0;

/// One fault the driver can be told to show (on `<ns>/fault` or with `--fault`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fault {
    /// Stop publishing joint states.
    Drop,
    /// Publish joint states again, and end a freeze.
    Resume,
    /// The next state's stamp is 1 s older than the previous one's.
    StampBack,
    /// The next state has NaN as its first position.
    Nan,
    /// The next state leaves out the last joint.
    FewerJoints,
    /// The measured position stops following the commands until `resume`.
    Freeze,
    /// Reject every new goal.
    RejectGoals,
    /// Accept goals again.
    AcceptGoals,
    /// Exit at once with code 3.
    Die,
}

impl Fault {
    /// Every fault, in the order of the documentation.
    pub const ALL: [Fault; 9] = [
        Fault::Drop,
        Fault::Resume,
        Fault::StampBack,
        Fault::Nan,
        Fault::FewerJoints,
        Fault::Freeze,
        Fault::RejectGoals,
        Fault::AcceptGoals,
        Fault::Die,
    ];

    /// The fault's name on the command line and on `<ns>/fault`.
    pub const fn name(self) -> &'static str {
        match self {
            Fault::Drop => "drop",
            Fault::Resume => "resume",
            Fault::StampBack => "stamp_back",
            Fault::Nan => "nan",
            Fault::FewerJoints => "fewer_joints",
            Fault::Freeze => "freeze",
            Fault::RejectGoals => "reject_goals",
            Fault::AcceptGoals => "accept_goals",
            Fault::Die => "die",
        }
    }
}

impl fmt::Display for Fault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Fault {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let s = s.trim();
        Fault::ALL
            .into_iter()
            .find(|f| f.name() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = Fault::ALL.iter().map(|f| f.name()).collect();
                format!("unknown fault '{s}' (known: {})", names.join(", "))
            })
    }
}

/// A fault of `--fault`, due `after` seconds after the first command or goal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScheduledFault {
    /// Seconds after the first applied command or accepted goal.
    pub after: f64,
    /// What happens then.
    pub fault: Fault,
}

/// Parses `SECONDS:FAULT`, e.g. `0.5:drop`.
///
/// # Errors
/// A message when the form, the number (finite, in [0, [`MAX_FAULT_DELAY`]]) or the fault
/// name is wrong.
pub fn parse_scheduled(s: &str) -> Result<ScheduledFault, String> {
    let Some((secs, name)) = s.split_once(':') else {
        return Err(format!(
            "'{s}' is not of the form SECONDS:FAULT, e.g. 0.5:drop"
        ));
    };
    let after: f64 = secs
        .trim()
        .parse()
        .map_err(|_| format!("'{secs}' in '{s}' is not a number of seconds"))?;
    if !after.is_finite() || !(0.0..=MAX_FAULT_DELAY).contains(&after) {
        return Err(format!(
            "{secs} s in '{s}' must be finite and in [0, {MAX_FAULT_DELAY}]"
        ));
    }
    Ok(ScheduledFault {
        after,
        fault: name.parse()?,
    })
}

/// Scheduled faults and the time they count from.
#[derive(Debug, Clone, Default)]
pub struct Schedule {
    /// Not yet applied, latest first (popped from the back).
    pending: Vec<ScheduledFault>,
    /// When the first command or goal came (driver time, s).
    origin: Option<f64>,
}

impl Schedule {
    /// A schedule of `faults` (any order; equal times keep their order).
    pub fn new(faults: &[ScheduledFault]) -> Self {
        let mut pending = faults.to_vec();
        pending.reverse();
        // Stable: among equal times the earlier given stays nearer the back.
        pending.sort_by(|a, b| b.after.total_cmp(&a.after));
        Self {
            pending,
            origin: None,
        }
    }

    /// Starts the clock at `now` unless it has started.
    pub fn start(&mut self, now: f64) {
        self.origin.get_or_insert(now);
    }

    /// The faults due at `now`, in their order.
    pub fn due(&mut self, now: f64) -> Vec<Fault> {
        let mut out = Vec::new();
        let Some(origin) = self.origin else {
            return out;
        };
        while let Some(next) = self.pending.last() {
            if now - origin < next.after {
                break;
            }
            out.push(next.fault);
            self.pending.pop();
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for f in Fault::ALL {
            assert_eq!(f.name().parse::<Fault>(), Ok(f));
        }
        assert_eq!(" drop\n".parse::<Fault>(), Ok(Fault::Drop));
        assert!("Drop".parse::<Fault>().unwrap_err().contains("known: drop"));
    }

    #[test]
    fn schedules_count_from_the_first_command() {
        let faults = [
            parse_scheduled("1:resume").unwrap(),
            parse_scheduled("0.5:drop").unwrap(),
            parse_scheduled("1:nan").unwrap(),
        ];
        let mut s = Schedule::new(&faults);
        assert!(s.due(100.0).is_empty(), "not started");
        s.start(10.0);
        s.start(11.0);
        assert!(s.due(10.4).is_empty());
        assert_eq!(s.due(10.5), [Fault::Drop]);
        assert_eq!(s.due(12.0), [Fault::Resume, Fault::Nan]);
        assert!(s.due(20.0).is_empty());
    }

    #[test]
    fn bad_schedules() {
        for bad in [
            "drop",
            "x:drop",
            "inf:drop",
            "-0.1:drop",
            "1e9:drop",
            "1:boom",
            ":drop",
        ] {
            assert!(parse_scheduled(bad).is_err(), "{bad}");
        }
    }
}
