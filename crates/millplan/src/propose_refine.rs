//! Propose and refine (issue 28, item 4: "a policy that proposes and a short
//! lookahead search that refines"): a proposer (e.g. the trained DDPG policy's
//! plan) gives the redundancy angle g per segment, and a depth-limited search
//! chooses the spindle speed Ω and the feed f per segment under the chatter
//! constraint, with |μ|max evaluated DIRECTLY (seed 004 section 2,
//! `kerf_chatter::indicator::chatter_indicator`; no cache, so it plans any
//! valid path).
//!
//! # Rule ([`refine_with_g`])
//!
//! * g: segment t takes `g_schedule[t]` as it is (the proposal; the search
//!   never moves g). The cell state of segment t is the one at
//!   g = `g_schedule[t]` with IK nearest the previous segment's joints, as
//!   [`crate::plan`] and [`crate::greedy`] do; a schedule that is infeasible
//!   at some segment (IK, joint limit) is an error, not repaired.
//! * Segment 0 is the initial state (Ω0, f0) at `g_schedule[0]`, which must
//!   equal g0 (every plan starts at the initial state), whatever its |μ|max.
//! * Moves: at segment t ≥ 1, from the previous (Ω, f), the nine moves of
//!   −1/0/+1 step bounds (ΔΩ = `max_spindle_step_rpm`, Δf = `max_feed_step`
//!   of the cell's [`kerf_mill::StateLimits`], seed 004 section 3, Table 1 /
//!   eq. 11 with the inertia filter left out: the search moves at the step
//!   bound, as [`crate::greedy`]), clipped to the state ranges, the feed to
//!   at least max(f_min, [`crate::env::EnvConfig`]'s default `min_feed`),
//!   exact duplicates removed, in greedy's order: highest feed first, then
//!   highest Ω. A state is stable when its |μ|max < 1 (NaN is not).
//! * Choice with lookahead L ≥ 0: each stable move m at t is scored by its
//!   best continuation over the next L segments (t+1 … min(t+L, N−1)): a
//!   depth-limited search over the nine moves per segment that expands only
//!   stable states (unstable ones are pruned). A continuation is ranked by
//!   (1) how many of those segments it stays stable on, then (2) the sum of
//!   its feeds over the window t … t+L (m's feed included: machining time is
//!   Σ l_i / f_i, so the highest feeds are the time-greedy objective), then
//!   (3) the sum of its Ω (higher Ω first: the paper's Fig. 4, higher feeds
//!   need a higher Ω to stay stable). Sums within 1e-12 relative are ties;
//!   an exact tie keeps the earlier move in greedy's order. The best-ranked
//!   move is taken, and the search starts again at t+1 (receding horizon:
//!   only the first move of the best continuation is kept).
//! * L = 0 is greedy's rule exactly: the first stable move in the order
//!   highest feed, then highest Ω ([`crate::greedy::solve_within`] with the
//!   schedule's g).
//! * When no move at t is stable, the one with the smallest |μ|max is taken
//!   (the first in greedy's order among equals) and the plan chatters there,
//!   as greedy's (reported by the plan's evaluation, never hidden).
//!
//! # What it is NOT
//!
//! Nothing here is trained or learned: the search is a fixed rule over the
//! step-bound lattice, and its only input from a policy is the g schedule.
//! It does not move g, does not look at the time of the EXECUTED trajectory
//! (that slows where the wrist must, [`crate::timing`]; the objective is the
//! planned Σ f over the window), keeps no margin below |μ|max = 1 at segment
//! midpoints (the executed chatter judge, [`crate::chatter_judge`], also
//! checks the samples between them), and is no global optimum (the DP of
//! [`crate::dp`] is): a window of L + 1 segments cannot see a narrowing of
//! the stable set further ahead.
//!
//! # Cost
//!
//! |μ|max is memoized per (segment, Ω, f) (keys rounded to 1e-6 rpm and
//! 1e-12 m/s, so the same lattice point reached by different move orders is
//! evaluated once). The states reachable from segment t's state in k moves
//! form at most a (2k+1)² lattice, so a step evaluates at most about
//! (2L+3)² new states at its deepest segment, fewer where the ranges clip
//! or unstable states are pruned: about 100–300 direct evaluations (≈ 1 ms
//! each) per 100-segment path for L = 0, a few thousand for L = 2. The
//! search itself visits up to 9^(L+1) leaves per step (memo lookups). The
//! budget is checked before every evaluation.

use std::collections::HashMap;

use kerf_budget::Budget;
use kerf_chatter::indicator::chatter_indicator;
use kerf_chatter::MillingProcess;
use kerf_mill::{CellState, MillCell, StateLimits};

use crate::env::PhysicalState;
use crate::error::MillPlanError;
use crate::greedy::{feed_floor, step_moves};

/// Relative tolerance of the sums that rank continuations.
const TIE: f64 = 1e-12;

/// A refined plan with its search figures ([`refine_with_g_report`]).
#[derive(Debug, Clone, PartialEq)]
pub struct RefineResult {
    /// One state per segment, in order, the first the initial state.
    pub states: Vec<PhysicalState>,
    /// |μ|max per segment (direct, at the chosen state).
    pub spectral_radii: Vec<f64>,
    /// |μ|max < 1 at every segment's state as planned (midpoints only).
    pub chatter_free: bool,
    /// Direct indicator evaluations made (distinct memo entries).
    pub evaluations: usize,
}

/// The ranking of a continuation: (stable segments after the move, Σ f,
/// Σ Ω) over the window.
#[derive(Debug, Clone, Copy)]
struct Score {
    depth: usize,
    feed_sum: f64,
    rpm_sum: f64,
}

impl Score {
    /// Whether `self` ranks strictly above `other`.
    fn beats(&self, other: &Score) -> bool {
        if self.depth != other.depth {
            return self.depth > other.depth;
        }
        let above = |a: f64, b: f64| a > b + TIE * a.abs().max(b.abs()).max(1.0);
        if above(self.feed_sum, other.feed_sum) {
            return true;
        }
        if above(other.feed_sum, self.feed_sum) {
            return false;
        }
        above(self.rpm_sum, other.rpm_sum)
    }
}

/// Whether |μ|max `m` is stable (< 1; NaN is not).
fn stable(m: f64) -> bool {
    m < 1.0
}

/// The search state: the cell states, the memo and the limits.
struct Search<'a> {
    cell: &'a MillCell,
    process: MillingProcess,
    cell_states: Vec<CellState>,
    lim: StateLimits,
    feed_floor: f64,
    memo: HashMap<(usize, i64, i64), f64>,
    budget: &'a Budget,
}

impl Search<'_> {
    /// |μ|max at segment `t`, (`rpm`, `feed`), memoized.
    fn mu(&mut self, t: usize, rpm: f64, feed: f64) -> Result<f64, MillPlanError> {
        let key = (t, (rpm * 1e6).round() as i64, (feed * 1e12).round() as i64);
        if let Some(m) = self.memo.get(&key) {
            return Ok(*m);
        }
        self.budget.check("the propose-and-refine search")?;
        let cs = &self.cell_states[t];
        let m = chatter_indicator(
            &cs.modal,
            &self.process,
            rpm,
            feed,
            self.cell.indicator_settings(),
        )?
        .spectral_radius;
        self.memo.insert(key, m);
        Ok(m)
    }

    /// The moves from (`rpm`, `feed`) in greedy's order (module
    /// documentation).
    fn moves(&self, rpm: f64, feed: f64) -> Vec<(f64, f64)> {
        step_moves(&self.lim, self.feed_floor, rpm, feed)
    }

    /// The best continuation from the stable state (`rpm`, `feed`) at
    /// segment `t - 1` over segments `t` … `t + depth - 1` (those before
    /// the path's end): its stable segments, Σ f and Σ Ω (of those
    /// segments only).
    fn continuation(
        &mut self,
        t: usize,
        rpm: f64,
        feed: f64,
        depth: usize,
    ) -> Result<Score, MillPlanError> {
        let mut best = Score {
            depth: 0,
            feed_sum: 0.0,
            rpm_sum: 0.0,
        };
        if depth == 0 || t >= self.cell_states.len() {
            return Ok(best);
        }
        for (r, f) in self.moves(rpm, feed) {
            let m = self.mu(t, r, f)?;
            if !stable(m) {
                continue;
            }
            let rest = self.continuation(t + 1, r, f, depth - 1)?;
            let score = Score {
                depth: rest.depth + 1,
                feed_sum: rest.feed_sum + f,
                rpm_sum: rest.rpm_sum + r,
            };
            if score.beats(&best) {
                best = score;
            }
        }
        Ok(best)
    }
}

/// Propose and refine: Ω and f chosen by the lookahead search of the module
/// documentation along the proposed g schedule.
///
/// # Arguments
/// * `cell` — the request's cell (path, process, state ranges and step
///   bounds).
/// * `initial` — (Ω0 \[rpm\], f0 [m/s], g0 \[rad\]), inside the ranges, f0 > 0.
/// * `g_schedule` — g \[rad\] per segment (one per segment of the cell's
///   path, inside the g range, the first equal to g0 within 1e-9 rad),
///   e.g. the DDPG plan's g.
/// * `lookahead` — L, the segments after the current one the search looks
///   at (0 = greedy's rule).
/// * `budget` — checked before every indicator evaluation.
///
/// # Returns
/// One state per segment, in order; `g` equals `g_schedule`.
///
/// # Errors
/// As [`refine_with_g_report`].
pub fn refine_with_g(
    cell: &MillCell,
    initial: [f64; 3],
    g_schedule: &[f64],
    lookahead: usize,
    budget: &Budget,
) -> Result<Vec<PhysicalState>, MillPlanError> {
    refine_with_g_report(cell, initial, g_schedule, lookahead, budget).map(|r| r.states)
}

/// [`refine_with_g`] with the search's figures (|μ|max per segment, the
/// evaluations made).
///
/// # Errors
/// [`MillPlanError::InvalidParameter`] for a NaN or out-of-range input, a
/// schedule of the wrong length or one that does not start at g0; the
/// cell's [`kerf_mill::MillError`] (status UNREACHABLE) when the schedule
/// is infeasible at a segment; chatter-model errors;
/// [`MillPlanError::Interrupted`].
pub fn refine_with_g_report(
    cell: &MillCell,
    initial: [f64; 3],
    g_schedule: &[f64],
    lookahead: usize,
    budget: &Budget,
) -> Result<RefineResult, MillPlanError> {
    let lim = *cell.state_limits();
    let [rpm0, f0, g0] = initial;
    let invalid = |name: &str, value: f64, reason: String| MillPlanError::InvalidParameter {
        name: name.to_string(),
        value,
        reason,
    };
    for (name, v, r) in [
        ("refine initial spindle speed [rpm]", rpm0, lim.spindle_rpm),
        ("refine initial feed [m/s]", f0, lim.feed),
        ("refine initial g [rad]", g0, lim.redundancy_angle),
    ] {
        if !(v >= r[0] && v <= r[1]) {
            return Err(invalid(
                name,
                v,
                format!("must be inside [{}, {}]", r[0], r[1]),
            ));
        }
    }
    if f0 <= 0.0 {
        return Err(invalid(
            "refine initial feed [m/s]",
            f0,
            "must be > 0".to_string(),
        ));
    }
    let n = cell.path().segments().len();
    if g_schedule.len() != n {
        return Err(invalid(
            "refine g schedule length",
            g_schedule.len() as f64,
            format!("must be the path's segment count {n}"),
        ));
    }
    let [g_lo, g_hi] = lim.redundancy_angle;
    if let Some((t, g)) = g_schedule
        .iter()
        .enumerate()
        .find(|(_, g)| !(**g >= g_lo && **g <= g_hi))
    {
        return Err(invalid(
            &format!("refine g schedule[{t}] [rad]"),
            *g,
            format!("must be inside [{g_lo}, {g_hi}]"),
        ));
    }
    if let Some(g) = g_schedule.first() {
        if (g - g0).abs() > 1e-9 {
            return Err(invalid(
                "refine g schedule[0] [rad]",
                *g,
                format!("must be the initial g {g0} (a plan starts at the initial state)"),
            ));
        }
    }
    // The cell states along the schedule (independent of Ω and f).
    let mut cell_states: Vec<CellState> = Vec::with_capacity(n);
    for (t, &g) in g_schedule.iter().enumerate() {
        budget.check("the propose-and-refine search")?;
        let reference = cell_states.last().map(|c| c.joints);
        cell_states.push(cell.evaluate(t, g, reference.as_ref())?);
    }
    let feed_floor = feed_floor(&lim);
    let mut search = Search {
        cell,
        process: cell.milling_process(),
        cell_states,
        lim,
        feed_floor,
        memo: HashMap::new(),
        budget,
    };
    let mut states = Vec::with_capacity(n);
    let mut spectral_radii = Vec::with_capacity(n);
    let (mut rpm, mut feed) = (rpm0, f0);
    for (t, &g) in g_schedule.iter().enumerate() {
        let mu = if t == 0 {
            search.mu(0, rpm, feed)?
        } else {
            // (move, |μ|max, score) of the best stable move, and the least
            // unstable move as the fallback.
            let mut best: Option<((f64, f64), f64, Score)> = None;
            let mut least: Option<((f64, f64), f64)> = None;
            for (r, f) in search.moves(rpm, feed) {
                let m = search.mu(t, r, f)?;
                if !stable(m) {
                    if least.is_none_or(|l| m < l.1 || l.1.is_nan()) {
                        least = Some(((r, f), m));
                    }
                    continue;
                }
                let rest = search.continuation(t + 1, r, f, lookahead)?;
                let score = Score {
                    depth: rest.depth,
                    feed_sum: rest.feed_sum + f,
                    rpm_sum: rest.rpm_sum + r,
                };
                if best.as_ref().is_none_or(|b| score.beats(&b.2)) {
                    best = Some(((r, f), m, score));
                }
            }
            let ((r, f), m) = match (best, least) {
                (Some((x, m, _)), _) | (None, Some((x, m))) => (x, m),
                // Unreachable: there is always at least the hold move.
                (None, None) => ((rpm, feed), search.mu(t, rpm, feed)?),
            };
            (rpm, feed) = (r, f);
            m
        };
        spectral_radii.push(mu);
        states.push(PhysicalState {
            segment: t,
            rpm,
            feed,
            g,
        });
    }
    Ok(RefineResult {
        chatter_free: spectral_radii.iter().all(|m| stable(*m)),
        states,
        spectral_radii,
        evaluations: search.memo.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use kerf_mill::PathSpec;

    fn cell10() -> MillCell {
        MillCell::default_cell()
            .unwrap()
            .with_path(&PathSpec {
                segments: 10,
                ..PathSpec::default()
            })
            .unwrap()
    }

    fn check(cell: &MillCell, initial: [f64; 3], g: &[f64], states: &[PhysicalState]) {
        let lim = cell.state_limits();
        assert_eq!(states.len(), g.len());
        assert_eq!(states[0].rpm, initial[0]);
        assert_eq!(states[0].feed, initial[1]);
        for (t, (x, g)) in states.iter().zip(g).enumerate() {
            assert_eq!(x.segment, t);
            assert_eq!(x.g, *g);
            assert!(x.rpm >= lim.spindle_rpm[0] && x.rpm <= lim.spindle_rpm[1]);
            assert!(x.feed >= lim.feed[0] && x.feed <= lim.feed[1]);
        }
        for w in states.windows(2) {
            assert!((w[1].rpm - w[0].rpm).abs() <= lim.max_spindle_step_rpm * (1.0 + 1e-12));
            assert!((w[1].feed - w[0].feed).abs() <= lim.max_feed_step * (1.0 + 1e-12));
        }
    }

    #[test]
    fn refine_keeps_order_step_bounds_and_schedule() {
        let cell = cell10();
        let initial = [2000.0, 0.04, 0.0];
        let step = cell.state_limits().max_redundancy_step;
        // A schedule that moves g up at the step bound, then holds.
        let g: Vec<f64> = (0..10).map(|t| (t as f64 * step).min(3.0 * step)).collect();
        let budget = Budget::unlimited();
        for lookahead in [0, 2] {
            let states = refine_with_g(&cell, initial, &g, lookahead, &budget).unwrap();
            check(&cell, initial, &g, &states);
        }
    }

    #[test]
    fn lookahead_zero_is_greedy() {
        let cell = cell10();
        let initial = [2000.0, 0.04, 0.0];
        let budget = Budget::unlimited();
        let greedy = crate::greedy::solve_within(&cell, initial, 0.0, &budget).unwrap();
        let states = refine_with_g(&cell, initial, &[0.0; 10], 0, &budget).unwrap();
        assert_eq!(states, greedy.states);
    }

    #[test]
    fn refuses_a_schedule_of_the_wrong_length_or_start() {
        let cell = cell10();
        let budget = Budget::unlimited();
        let initial = [2000.0, 0.04, 0.0];
        assert!(refine_with_g(&cell, initial, &[0.0; 9], 1, &budget).is_err());
        let mut g = [0.0; 10];
        g[0] = 0.1;
        assert!(refine_with_g(&cell, initial, &g, 1, &budget).is_err());
    }
}
