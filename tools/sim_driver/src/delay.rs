//! The transport delay between the commanded and the measured position.

use std::collections::VecDeque;

/// Most commands kept in flight; beyond it the oldest are forgotten (only a flood of commands
/// faster than 10⁵ per delay reaches it).
const MAX_IN_FLIGHT: usize = 100_000;

/// Commands with the time they were given; the output is the one given `delay` ago.
#[derive(Debug, Clone)]
pub struct DelayLine {
    delay: f64,
    /// (time, position), oldest first; the first entry is the current output once its time
    /// is `delay` past.
    entries: VecDeque<(f64, Vec<f64>)>,
}

impl DelayLine {
    /// A line of `delay` seconds whose output is `initial` until the first command is due.
    pub fn new(delay: f64, initial: Vec<f64>) -> Self {
        Self {
            delay,
            entries: VecDeque::from([(f64::NEG_INFINITY, initial)]),
        }
    }

    /// Commands `position` at time `t` (driver time, s; not earlier than the last command).
    pub fn push(&mut self, t: f64, position: Vec<f64>) {
        if self.entries.len() >= MAX_IN_FLIGHT {
            self.entries.pop_front();
        }
        self.entries.push_back((t, position));
    }

    /// The newest command (the commanded position now).
    pub fn head(&self) -> &[f64] {
        self.entries.back().map_or(&[][..], |(_, p)| p.as_slice())
    }

    /// The command as it was `delay` before `now`; forgets the commands older than it.
    pub fn output(&mut self, now: f64) -> &[f64] {
        let due = now - self.delay;
        while self.entries.len() >= 2 && self.entries[1].0 <= due {
            self.entries.pop_front();
        }
        self.entries.front().map_or(&[][..], |(_, p)| p.as_slice())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn output_follows_the_commands_late() {
        let mut d = DelayLine::new(0.1, vec![1.0]);
        assert_eq!(d.output(0.0), [1.0]);
        d.push(0.0, vec![2.0]);
        d.push(0.05, vec![3.0]);
        assert_eq!(d.head(), [3.0]);
        assert_eq!(d.output(0.099), [1.0]);
        assert_eq!(d.output(0.1), [2.0]);
        assert_eq!(d.output(0.149), [2.0]);
        assert_eq!(d.output(0.1501), [3.0]);
        assert_eq!(d.output(10.0), [3.0]);
        let mut zero = DelayLine::new(0.0, vec![0.0]);
        zero.push(1.0, vec![5.0]);
        assert_eq!(zero.output(1.0), [5.0]);
    }
}
