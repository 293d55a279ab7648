//! RPRO, kerf's reading of the Reference Points Realization Optimization
//! controller of seed 002 (section 2.A; its details are in the paper's
//! reference [6], which the seed does not include).
//!
//! # What the seed says
//! Every period of 2 ms the controller decides whether the axis
//! accelerates, decelerates or keeps its motion (eq. 1: the decision is the
//! jerk), checks "a certain number of forward steps" before it decides, and
//! aims for the fewest periods while passing each reference point within
//! the target precision (0.01 mm, Table 1).
//!
//! # kerf's reading
//! * **Decisions** are the jerk `+J`, `0`, `−J` held over the period,
//!   stepped exactly on the lattice of [`crate::lattice`].
//! * **Passing a point** means a sample lies within the precision of it
//!   (its window, [`crate::course`]); the run ends at rest inside the last
//!   point's window (a machine stops on its last point). The axis never
//!   moves backward.
//! * **Fewest periods**: of accelerate, keep, decelerate, the controller
//!   takes the first whose next state is *viable*. Seed 002 Fig. 3 shows
//!   this bang-bang character ("pursued the highest possible acceleration,
//!   only to later reduce it just as sharply").
//! * **Viable** (the look-ahead): a state is viable for target `i` at depth
//!   `d` when one of the *tails* from it passes the windows of
//!   `i, …, i + d`, each by a tail that tracks one velocity level
//!   ([`crate::tracker`]), and then falls back: it slows to a level no
//!   faster than the crawl velocity (one at which no window can be stepped
//!   over) before the window of `i + d + 1`, and at that level comes to
//!   rest inside the last point's window. For the last point a tail must
//!   come to rest inside its window: it tracks its level and stops
//!   ([`crate::tracker::stop`]) at a sample from which the stop ends in
//!   the window.
//!
//! The velocity levels are geometric from the crawl velocity to the limit
//! ([`RproSettings::levels`]), then halve below the crawl down to the
//! lattice's smallest (a last point closer than the crawl's stopping
//! distance needs a slower approach), plus 0 for the last point.
//!
//! # The guarantee
//! A viable state has a viable successor: the first action of its witness
//! tail. After a window is left behind, the witness's fallback is itself a
//! tail at its level for the next window, and its continuation is the same
//! fallback, so the witness extends by one point. (A first version fell
//! back to the crawl for the next window only, assuming a crawl can always
//! stop on the last point; 20 of the 1200 Table 1 processes of 15 points
//! broke that, where the last point is closer than the crawl's stop.) Hence from rest at
//! the start, if the start is viable, RPRO passes every point and stops on
//! the last one; [`crate::error::StepError::NoViableAction`] would mean a
//! defect, and the tests run it over the whole Table 1 grid.
//!
//! # Choices the paper leaves open
//! * The look-ahead depth ([`RproSettings::lookahead_points`], default 1)
//!   and the number of velocity levels (default 24) trade planning time
//!   against steps (BENCHMARKS "Reference-point stepping").
//! * The decision order makes RPRO greedy: it is not a time-optimal
//!   search, as the Ruckig reference shows.

use std::collections::HashMap;

use crate::{
    course::Course,
    error::StepError,
    lattice::{Action, State},
    run::{Controller, Decision},
    tracker::{stop, track},
};

/// Settings of [`Rpro`] (builder style).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RproSettings {
    /// Points passed at a chosen velocity level before the crawl (≥ 0).
    pub lookahead_points: usize,
    /// Number of velocity levels between the crawl velocity and the limit
    /// (≥ 2).
    pub levels: usize,
}

impl Default for RproSettings {
    fn default() -> Self {
        Self {
            lookahead_points: 1,
            levels: 24,
        }
    }
}

impl RproSettings {
    /// Sets [`RproSettings::lookahead_points`].
    pub fn lookahead_points(mut self, points: usize) -> Self {
        self.lookahead_points = points;
        self
    }

    /// Sets [`RproSettings::levels`].
    pub fn levels(mut self, levels: usize) -> Self {
        self.levels = levels;
        self
    }

    /// # Errors
    /// [`StepError::InvalidParameter`] for fewer than 2 levels, more than
    /// 1000, or a look-ahead beyond 8 points.
    pub fn validate(&self) -> Result<(), StepError> {
        if !(2..=1000).contains(&self.levels) {
            return Err(StepError::InvalidParameter {
                name: "velocity levels".to_string(),
                value: self.levels as f64,
                reason: "must be in 2..=1000".to_string(),
            });
        }
        if self.lookahead_points > 8 {
            return Err(StepError::InvalidParameter {
                name: "look-ahead points".to_string(),
                value: self.lookahead_points as f64,
                reason: "must be at most 8 (the search grows as levels^points)".to_string(),
            });
        }
        Ok(())
    }
}

/// The RPRO controller on one course.
#[derive(Debug, Clone)]
pub struct Rpro {
    settings: RproSettings,
    /// Velocity levels, fastest first (even, crawl included).
    levels: Vec<i64>,
    /// The tracker's stop (Δq) from an (n, m) pair.
    stops: HashMap<(i64, i64), i64>,
    /// Tail evaluations of the last decision (for the cost figures).
    pub tails: usize,
}

/// Periods any single tail may take before it is abandoned (a tail at a
/// level > 0 passes its window long before: this only bounds bad input).
const TAIL_CAP: usize = 10_000_000;

impl Rpro {
    /// RPRO for `course` with `settings`.
    ///
    /// # Errors
    /// [`RproSettings::validate`].
    pub fn new(course: &Course, settings: RproSettings) -> Result<Self, StepError> {
        settings.validate()?;
        let lo = course.crawl as f64;
        let hi = course.lattice.max_n as f64;
        let mut levels: Vec<i64> = (0..settings.levels)
            .map(|k| {
                let f = k as f64 / (settings.levels - 1) as f64;
                let n = (lo * (hi / lo).powf(f)).round() as i64;
                (n & !1).clamp(course.crawl, course.lattice.max_n)
            })
            .collect();
        // The ladder below the crawl (crawl/2, crawl/4, … ≥ 2): slow enough to stop on a last
        // point closer than the crawl's stopping distance.
        let mut below = course.crawl / 2;
        while below >= 2 {
            levels.push(below & !1);
            below /= 2;
        }
        levels.sort_unstable_by(|a, b| b.cmp(a));
        levels.dedup();
        Ok(Self {
            settings,
            levels,
            stops: HashMap::new(),
            tails: 0,
        })
    }

    /// The velocity levels, fastest first.
    pub fn levels(&self) -> &[i64] {
        &self.levels
    }

    /// Whether `action` at `decision` leads to a viable state.
    pub fn allows(&mut self, course: &Course, decision: &Decision, action: Action) -> bool {
        let u = action.sign();
        let x = decision.state;
        if !course.lattice.allows(x, u) {
            return false;
        }
        let y = x.step(u);
        let (lo, hi) = course.windows[decision.target];
        let seen = decision.seen || (lo <= x.q && x.q <= hi);
        let mut target = decision.target;
        if y.q > hi {
            if !seen || target + 1 >= course.targets() {
                return false;
            }
            target += 1;
            if y.q > course.windows[target].1 {
                return false;
            }
        }
        self.viable(course, y, target, self.settings.lookahead_points)
    }

    /// Whether state `x` is viable for target `i` at depth `depth` (module
    /// documentation).
    pub fn viable(&mut self, course: &Course, x: State, i: usize, depth: usize) -> bool {
        let last = i + 1 == course.targets();
        for k in 0..self.levels.len() + usize::from(last) {
            let level = self.levels.get(k).copied().unwrap_or(0);
            if self.tail(course, x, i, level, depth) {
                return true;
            }
        }
        false
    }

    /// The tracker's stop Δq from `s` (memoized by velocity and
    /// acceleration).
    fn stop_dq(&mut self, course: &Course, s: State) -> Option<i64> {
        if let Some(dq) = self.stops.get(&(s.n, s.m)) {
            return Some(*dq);
        }
        let lat = &course.lattice;
        let cap = (2 * lat.max_m + lat.max_n / lat.max_m.max(1) + 16) as usize;
        let (dq, _) = stop(lat, s, cap)?;
        self.stops.insert((s.n, s.m), dq);
        Some(dq)
    }

    /// Whether the tail tracking `level` from `x` passes target `i` (and,
    /// below depth 0, what follows it).
    fn tail(&mut self, course: &Course, x: State, i: usize, level: i64, depth: usize) -> bool {
        self.tails += 1;
        let lat = course.lattice;
        let (lo, hi) = course.windows[i];
        let last = i + 1 == course.targets();
        let mut y = x;
        for _ in 0..TAIL_CAP {
            let settled = y.m == 0 && y.n == level;
            if last {
                let Some(dq) = self.stop_dq(course, y) else {
                    return false;
                };
                let rest = y.q + dq;
                if lo <= rest && rest <= hi {
                    return true;
                }
                if settled {
                    // Constant speed: the stop's end moves 3·level a period.
                    if level == 0 || rest > hi {
                        return false;
                    }
                    let k = (lo - rest + 3 * level - 1) / (3 * level);
                    return rest + 3 * level * k <= hi;
                }
                if y.q > hi {
                    return false;
                }
            } else {
                if y.q > hi {
                    return false;
                }
                if lo <= y.q && self.after_hit(course, y, i, depth) {
                    return true;
                }
                if settled {
                    if level == 0 {
                        return false;
                    }
                    // Constant speed: try each later sample in the window.
                    let step = 3 * level;
                    let k0 = ((lo - y.q + step - 1) / step).max(1);
                    let mut q = y.q + step * k0;
                    while q <= hi {
                        let s = State { q, n: level, m: 0 };
                        if self.after_hit(course, s, i, depth) {
                            return true;
                        }
                        q += step;
                    }
                    return false;
                }
            }
            y = y.step(track(&lat, y, level));
        }
        false
    }

    /// After a sample `y` in target `i`'s window: the following targets.
    fn after_hit(&mut self, course: &Course, y: State, i: usize, depth: usize) -> bool {
        let j = i + 1;
        if j >= course.targets() {
            // A non-last target is never the last one.
            return false;
        }
        if depth > 0 {
            return self.viable(course, y, j, depth - 1);
        }
        self.crawls_into(course, y, j)
    }

    /// The fallback after a sample `y` of the deepest look-ahead point: a
    /// tail at a level no faster than the crawl that becomes crawl-safe
    /// (it then passes every later window) before it leaves target `j`'s
    /// window, and comes to rest inside the last point's window.
    fn crawls_into(&mut self, course: &Course, y: State, j: usize) -> bool {
        let last = course.targets() - 1;
        let crawl = course.crawl;
        let slow: Vec<i64> = self
            .levels
            .iter()
            .copied()
            .filter(|l| *l <= crawl)
            .collect();
        if j == last {
            return slow
                .iter()
                .chain(std::iter::once(&0))
                .any(|&l| self.tail(course, y, last, l, 0));
        }
        let hi = course.windows[j].1;
        let lat = course.lattice;
        for level in slow {
            let mut s = y;
            let mut safe = false;
            for _ in 0..TAIL_CAP {
                if s.q > hi {
                    break;
                }
                let settle = s.settled_velocity();
                if s.n <= crawl && (0..=crawl).contains(&settle) {
                    safe = true;
                    break;
                }
                s = s.step(track(&lat, s, level));
            }
            if safe && self.tail(course, s, last, level, 0) {
                return true;
            }
        }
        false
    }
}

impl Controller for Rpro {
    fn decide(&mut self, course: &Course, decision: &Decision) -> Result<Action, StepError> {
        self.tails = 0;
        for action in Action::ALL {
            if self.allows(course, decision, action) {
                return Ok(action);
            }
        }
        Err(StepError::NoViableAction {
            step: decision.step,
            point: decision.target + 1,
            reason: format!(
                "state v = {:.6}, a = {:.6} at {:.6}",
                course.lattice.velocity(decision.state),
                course.lattice.acceleration(decision.state),
                course.lattice.position(decision.state)
            ),
        })
    }
}
