//! The greedy ramp baseline (issue 13, item 3): from the request's initial
//! state (seed 004's IVP by default: Ω0 = 2000 rpm, f0 = 0.04 m/s, g0 = 0),
//! ramp the feed and the spindle speed at the step bounds toward the
//! fastest stable setting, one segment at a time, with |μ|max evaluated
//! DIRECTLY (the state-dependent chatter indicator of seed 004 section 2,
//! `kerf_chatter::indicator::chatter_indicator`; no cache, so it plans any
//! valid path).
//!
//! # Rule ([`solve_within`])
//!
//! * Segment 0 is the initial state (Ω0, f0, g0), whatever its |μ|max.
//! * At segment t ≥ 1, from the previous (Ω, f), the candidates are the
//!   nine moves of −1/0/+1 step bounds (ΔΩ = `max_spindle_step_rpm`,
//!   Δf = `max_feed_step` of the request's limits, seed 004 Table 1 /
//!   eq. 11), clipped to the state ranges (the feed to at least
//!   max(f_min, [`crate::env::EnvConfig`]'s default `min_feed`, 0.01 m/s)),
//!   in the order: highest feed first, then highest spindle speed. The
//!   first candidate with |μ|max < 1 at segment t (the cell state at g_t,
//!   IK nearest the previous segment's joints, as [`crate::plan`]) is
//!   taken: the ramp toward the fastest feed and speed that is stable
//!   here. When no candidate is stable, the one with the smallest |μ|max
//!   is taken and the plan chatters there (reported, never hidden).
//! * g: the schedule g_t is g0 moved toward a target g* by at most
//!   `max_redundancy_step` per segment, then held. The planner kind
//!   `greedy` uses g* = g0 (the request's initial g; 0 = the paper's fixed-g
//!   setting), so g never moves.
//!
//! Machining time is Σ l_i / f_i (seed 004 section 3), so the highest
//! stable feed is the time-greedy choice; Ω does not enter the time and is
//! raised only as the ramp's second priority.
//!
//! # Best fixed g ([`best_fixed_g_within`], planner kind `greedy_best_g`)
//!
//! The same ramp for every target g* = g0 + k · Δg inside the g range
//! (Δg = `max_redundancy_step`, at most [`MAX_G_CANDIDATES`] candidates:
//! the spacing is widened when the range holds more) whose g schedule is
//! feasible (IK, joint limits) on every segment; the chosen one is
//! chatter-free first (as planned), then has the shortest time AS EXECUTED
//! (the duration of its trajectory from rest to rest,
//! [`crate::timing::time_scale`] with the planner's trajectory settings:
//! a g move costs time where the wrist must slow down, which the planned
//! Σ l/f does not show — measured on the default request: g* = 0.4 rad
//! ties with g = 0 as planned, 16.18 s, and takes 18.43 s as executed),
//! then the smallest max |μ|max, then the smallest |g* − g0|. g moves from
//! g0 to g* at the step bound over the first |g* − g0| / Δg segments (the
//! plan starts at the initial state, as every planner), then stays fixed.
//! A candidate whose trajectory cannot be built is not chosen.
//! The candidates are planned on the planner's evaluation threads; the
//! choice does not depend on the thread count.
//!
//! # Cost
//!
//! One indicator evaluation per segment while the first candidate is
//! stable, up to nine where none is: about 100–300 direct evaluations
//! (≈ 1 ms each) for `greedy`, that times the feasible candidates (about
//! 20 on the default cell) for `greedy_best_g`. The budget is checked
//! before every evaluation.

use std::sync::Mutex;

use kerf_budget::Budget;
use kerf_chatter::indicator::chatter_indicator;
use kerf_mill::{MillCell, StateLimits};

use crate::cache::is_infeasible;
use crate::env::{EnvConfig, PhysicalState};
use crate::error::MillPlanError;
use crate::plan::{Plan, SegmentPlan};
use crate::reward::RewardParts;
use crate::timing::{joint_limits, time_scale, JointLimit, TrajectorySettings};

/// Largest number of target g* tried by [`best_fixed_g_within`].
pub const MAX_G_CANDIDATES: usize = 64;

/// A greedy ramp plan.
#[derive(Debug, Clone, PartialEq)]
pub struct GreedyResult {
    /// One state per segment, the first the initial state.
    pub states: Vec<PhysicalState>,
    /// The held redundancy angle g* \[rad\].
    pub g: f64,
    /// |μ|max < 1 at every segment (direct evaluation at the planned
    /// feeds).
    pub chatter_free: bool,
    /// Largest |μ|max over the segments.
    pub max_spectral_radius: f64,
    /// Machining time Σ l_i / f_i \[s\] as planned.
    pub machining_time: f64,
    /// Duration of the trajectory from rest to rest \[s\] (only computed
    /// by [`best_fixed_g_within`], to rank the candidates).
    pub executed_time: Option<f64>,
    /// The plan's cell states (joints, K, 1/K) per segment.
    pub cell_states: Vec<([f64; 6], f64, f64)>,
    /// |μ|max per segment (direct, at the planned state).
    pub spectral_radii: Vec<f64>,
    /// Indicator evaluations made (this plan; for
    /// [`best_fixed_g_within`], every candidate's).
    pub evaluations: usize,
    /// Targets g* planned ([`best_fixed_g_within`]; 1 for [`solve_within`]).
    pub candidates: usize,
}

/// `x` moved toward `target` by at most `step`.
fn toward(x: f64, target: f64, step: f64) -> f64 {
    if (target - x).abs() <= step {
        target
    } else {
        x + step * (target - x).signum()
    }
}

/// Distinct values of `v` in order (exact duplicates removed).
fn distinct(v: [f64; 3]) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::with_capacity(3);
    for x in v {
        if !out.contains(&x) {
            out.push(x);
        }
    }
    out
}

/// The lowest feed a ramp moves to: the feed range's lower end, at least
/// [`EnvConfig`]'s default `min_feed` (module documentation).
pub(crate) fn feed_floor(lim: &StateLimits) -> f64 {
    lim.feed[0]
        .max(EnvConfig::default().min_feed)
        .min(lim.feed[1])
}

/// The moves of −1/0/+1 step bounds of Ω and f from (`rpm`, `feed`), clipped to the state
/// ranges (the feed to at least `floor`), exact duplicates removed, in the ramp's order:
/// highest feed first, then highest spindle speed (module documentation). Returns (Ω, f)
/// pairs.
pub(crate) fn step_moves(lim: &StateLimits, floor: f64, rpm: f64, feed: f64) -> Vec<(f64, f64)> {
    let feeds = distinct([
        (feed + lim.max_feed_step).min(lim.feed[1]),
        feed,
        (feed - lim.max_feed_step).max(floor).min(feed),
    ]);
    let rpms = distinct([
        (rpm + lim.max_spindle_step_rpm).min(lim.spindle_rpm[1]),
        rpm,
        (rpm - lim.max_spindle_step_rpm).max(lim.spindle_rpm[0]),
    ]);
    feeds
        .iter()
        .flat_map(|&f| rpms.iter().map(move |&r| (r, f)))
        .collect()
}

/// The greedy ramp with g moving from `initial[2]` toward `g_target` at
/// the step bound and then held (module documentation).
///
/// # Arguments
/// * `cell` — the request's cell (path, process, state ranges and step
///   bounds).
/// * `initial` — (Ω0 \[rpm\], f0 [m/s], g0 \[rad\]), inside the ranges.
/// * `g_target` — g* \[rad\], inside the g range.
///
/// # Errors
/// [`MillPlanError::InvalidParameter`] for a NaN or out-of-range input;
/// the cell's [`kerf_mill::MillError`] (status UNREACHABLE) when the g
/// schedule is infeasible at a segment; chatter-model errors;
/// [`MillPlanError::Interrupted`].
pub fn solve_within(
    cell: &MillCell,
    initial: [f64; 3],
    g_target: f64,
    budget: &Budget,
) -> Result<GreedyResult, MillPlanError> {
    let lim = *cell.state_limits();
    let [rpm0, f0, g0] = initial;
    for (name, v, r) in [
        ("greedy initial spindle speed [rpm]", rpm0, lim.spindle_rpm),
        ("greedy initial feed [m/s]", f0, lim.feed),
        ("greedy initial g [rad]", g0, lim.redundancy_angle),
        ("greedy target g [rad]", g_target, lim.redundancy_angle),
    ] {
        if !(v >= r[0] && v <= r[1]) {
            return Err(MillPlanError::InvalidParameter {
                name: name.to_string(),
                value: v,
                reason: format!("must be inside [{}, {}]", r[0], r[1]),
            });
        }
    }
    if f0 <= 0.0 {
        return Err(MillPlanError::InvalidParameter {
            name: "greedy initial feed [m/s]".to_string(),
            value: f0,
            reason: "must be > 0".to_string(),
        });
    }
    let feed_floor = feed_floor(&lim);
    let process = cell.milling_process();
    let settings = cell.indicator_settings();
    let segments = cell.path().segments();
    let n = segments.len();
    let mut states = Vec::with_capacity(n);
    let mut reference: Option<[f64; 6]> = None;
    let (mut rpm, mut feed, mut g) = (rpm0, f0, g0);
    let mut evaluations = 0usize;
    let mut max_mu: f64 = 0.0;
    let mut chatter_free = true;
    let mut cell_states = Vec::with_capacity(n);
    let mut spectral_radii = Vec::with_capacity(n);
    for t in 0..n {
        if t > 0 {
            g = toward(g, g_target, lim.max_redundancy_step);
        }
        let cs = cell.evaluate(t, g, reference.as_ref())?;
        reference = Some(cs.joints);
        cell_states.push((cs.joints, cs.condition_number, cs.condition_indicator));
        let mut mu = |r: f64, f: f64| -> Result<f64, MillPlanError> {
            budget.check("the greedy ramp")?;
            evaluations += 1;
            Ok(chatter_indicator(&cs.modal, &process, r, f, settings)?.spectral_radius)
        };
        let chosen = if t == 0 {
            (rpm, feed, mu(rpm, feed)?)
        } else {
            let mut best: Option<(f64, f64, f64)> = None;
            let mut stable = None;
            for (r, f) in step_moves(&lim, feed_floor, rpm, feed) {
                let m = mu(r, f)?;
                if m < 1.0 {
                    stable = Some((r, f, m));
                    break;
                }
                if best.is_none_or(|b| m < b.2) {
                    best = Some((r, f, m));
                }
            }
            match stable.or(best) {
                Some(c) => c,
                None => (rpm, feed, mu(rpm, feed)?),
            }
        };
        (rpm, feed) = (chosen.0, chosen.1);
        max_mu = max_mu.max(chosen.2);
        spectral_radii.push(chosen.2);
        if chosen.2.is_nan() || chosen.2 >= 1.0 {
            chatter_free = false;
        }
        states.push(PhysicalState {
            segment: t,
            rpm,
            feed,
            g,
        });
    }
    let machining_time = segments
        .iter()
        .zip(&states)
        .map(|(s, x)| s.length / x.feed)
        .sum();
    Ok(GreedyResult {
        states,
        g: g_target,
        chatter_free,
        max_spectral_radius: max_mu,
        machining_time,
        executed_time: None,
        cell_states,
        spectral_radii,
        evaluations,
        candidates: 1,
    })
}

/// Whether the g schedule from `g0` toward `g_target` is feasible at every
/// segment (IK nearest the previous joints, as the plan).
///
/// # Errors
/// Cell-model errors other than infeasibility.
fn schedule_feasible(
    cell: &MillCell,
    g0: f64,
    g_target: f64,
    budget: &Budget,
) -> Result<bool, MillPlanError> {
    let step = cell.state_limits().max_redundancy_step;
    let mut g = g0;
    let mut reference: Option<[f64; 6]> = None;
    for t in 0..cell.path().segments().len() {
        budget.check("the greedy ramp's g candidates")?;
        if t > 0 {
            g = toward(g, g_target, step);
        }
        match cell.evaluate(t, g, reference.as_ref()) {
            Ok(cs) => reference = Some(cs.joints),
            Err(e) if is_infeasible(&e) => return Ok(false),
            Err(e) => return Err(e.into()),
        }
    }
    Ok(true)
}

/// The target g* candidates: g0 + k · Δg inside the g range (module
/// documentation), g0 first, then by distance to g0.
fn g_candidates(cell: &MillCell, g0: f64) -> Vec<f64> {
    let lim = cell.state_limits();
    let [lo, hi] = lim.redundancy_angle;
    let mut h = lim.max_redundancy_step;
    while ((hi - lo) / h).floor() as usize + 1 > MAX_G_CANDIDATES {
        h *= 2.0;
    }
    let below = ((g0 - lo) / h + 1e-9).floor() as i64;
    let above = ((hi - g0) / h + 1e-9).floor() as i64;
    let mut out: Vec<f64> = (-below..=above).map(|k| g0 + k as f64 * h).collect();
    out.sort_by(|a, b| {
        (a - g0)
            .abs()
            .total_cmp(&(b - g0).abs())
            .then(a.total_cmp(b))
    });
    out
}

/// Every feasible target g* of [`best_fixed_g_within`], each planned by
/// the greedy ramp and timed as executed ([`GreedyResult::executed_time`]),
/// in the order of |g* − g0|.
///
/// # Errors
/// As [`best_fixed_g_within`].
pub fn fixed_g_candidates_within(
    cell: &MillCell,
    initial: [f64; 3],
    threads: usize,
    settings: &TrajectorySettings,
    budget: &Budget,
) -> Result<Vec<GreedyResult>, MillPlanError> {
    let g0 = initial[2];
    let limits = joint_limits(cell)?;
    if !g0.is_finite() {
        return Err(MillPlanError::InvalidParameter {
            name: "greedy initial g [rad]".to_string(),
            value: g0,
            reason: "must be finite".to_string(),
        });
    }
    let mut feasible = Vec::new();
    for g in g_candidates(cell, g0) {
        if schedule_feasible(cell, g0, g, budget)? {
            feasible.push(g);
        }
    }
    if feasible.is_empty() {
        return Err(MillPlanError::Infeasible {
            planner: "greedy_best_g".to_string(),
            reason: "no fixed redundancy angle reachable from the initial g is feasible on every \
                     segment of this path; ddpg, dp and best move g along it"
                .to_string(),
        });
    }
    let slots: Mutex<Vec<Option<Result<GreedyResult, MillPlanError>>>> =
        Mutex::new((0..feasible.len()).map(|_| None).collect());
    let workers = threads
        .clamp(1, crate::plan::MAX_EVAL_THREADS)
        .min(feasible.len());
    let work = |w: usize| {
        for (k, g) in feasible.iter().enumerate() {
            if k % workers != w {
                continue;
            }
            let r = solve_within(cell, initial, *g, budget)
                .and_then(|r| with_executed_time(cell, r, &limits, settings, budget));
            let stop = r.is_err();
            if let Ok(mut s) = slots.lock() {
                if let Some(slot) = s.get_mut(k) {
                    *slot = Some(r);
                }
            }
            if stop {
                break;
            }
        }
    };
    std::thread::scope(|scope| {
        // Workers 1.. on helper threads (one the OS refuses to start is not
        // an error: its candidates are planned below), worker 0 here.
        for w in 1..workers {
            let work = &work;
            let _ = std::thread::Builder::new().spawn_scoped(scope, move || work(w));
        }
        work(0);
    });
    let slots = slots
        .into_inner()
        .map_err(|_| MillPlanError::InvalidConfig {
            name: "planner greedy_best_g".to_string(),
            reason: "a worker thread panicked".to_string(),
        })?;
    // The first error in candidate order wins, before the candidates the
    // workers left after it.
    let mut slots = slots;
    if let Some(k) = slots.iter().position(|s| matches!(s, Some(Err(_)))) {
        if let Some(Some(Err(e))) = slots.get_mut(k).map(Option::take) {
            return Err(e);
        }
    }
    let mut results = Vec::with_capacity(slots.len());
    for (s, g) in slots.into_iter().zip(&feasible) {
        match s {
            Some(Ok(r)) => results.push(r),
            Some(Err(e)) => return Err(e),
            // A worker that did not start: its candidates, here.
            None => results.push(
                solve_within(cell, initial, *g, budget)
                    .and_then(|r| with_executed_time(cell, r, &limits, settings, budget))?,
            ),
        }
    }
    Ok(results)
}

/// The greedy ramp with the best fixed g (module documentation).
///
/// # Arguments
/// * `cell`, `initial` — as [`solve_within`].
/// * `threads` — candidates planned in parallel (≥ 1; the result does not
///   depend on it).
/// * `settings` — of the trajectory that ranks the candidates (the
///   planner's).
///
/// # Errors
/// [`MillPlanError::Infeasible`] when no target g* is feasible on every
/// segment or none has a trajectory; as [`solve_within`] otherwise.
pub fn best_fixed_g_within(
    cell: &MillCell,
    initial: [f64; 3],
    threads: usize,
    settings: &TrajectorySettings,
    budget: &Budget,
) -> Result<GreedyResult, MillPlanError> {
    let results = fixed_g_candidates_within(cell, initial, threads, settings, budget)?;
    let evaluations = results.iter().map(|r| r.evaluations).sum();
    let candidates = results.len();
    // Chatter-free first, then time, then max |μ|; ties keep the earlier
    // candidate (nearer g0: the candidates are ordered by |g* − g0|).
    let better = |r: &GreedyResult, b: &GreedyResult| {
        if r.chatter_free != b.chatter_free {
            return r.chatter_free;
        }
        let (rt, bt) = (
            r.executed_time.unwrap_or(f64::INFINITY),
            b.executed_time.unwrap_or(f64::INFINITY),
        );
        if rt != bt {
            return rt < bt;
        }
        r.max_spectral_radius < b.max_spectral_radius
    };
    let mut best: Option<GreedyResult> = None;
    for r in results.into_iter().filter(|r| r.executed_time.is_some()) {
        if best.as_ref().is_none_or(|b| better(&r, b)) {
            best = Some(r);
        }
    }
    let mut best = best.ok_or_else(|| MillPlanError::Infeasible {
        planner: "greedy_best_g".to_string(),
        reason: "no candidate's trajectory could be built (time scaling)".to_string(),
    })?;
    best.evaluations = evaluations;
    best.candidates = candidates;
    Ok(best)
}

/// A greedy plan as a [`Plan`] for the time scaling (joints, Ω, f, g, |μ|,
/// K and segment times; the rewards are not computed and are 0).
fn as_plan(cell: &MillCell, r: &GreedyResult) -> Plan {
    let zero = RewardParts {
        operational: 0.0,
        efficiency: 0.0,
        stability: 0.0,
        total: 0.0,
    };
    let segments: Vec<SegmentPlan> = r
        .states
        .iter()
        .zip(&r.cell_states)
        .zip(&r.spectral_radii)
        .zip(cell.path().segments())
        .map(|(((x, (joints, k, ci)), mu), seg)| SegmentPlan {
            segment: x.segment,
            rpm: x.rpm,
            feed: x.feed,
            g: x.g,
            spectral_radius: *mu,
            condition_number: *k,
            condition_indicator: *ci,
            joints: *joints,
            time: seg.length / x.feed,
            reward: zero,
        })
        .collect();
    Plan {
        planner: "greedy_best_g".to_string(),
        total_time: r.machining_time,
        chatter_free: r.chatter_free,
        max_spectral_radius: r.max_spectral_radius,
        min_condition_indicator: segments
            .iter()
            .map(|s| s.condition_indicator)
            .fold(f64::INFINITY, f64::min),
        total_reward: 0.0,
        segments,
    }
}

/// `r` with the duration of its trajectory from rest to rest
/// ([`time_scale`]); `None` when the trajectory cannot be built (the
/// candidate is then not chosen).
///
/// # Errors
/// [`MillPlanError::Interrupted`] (every other error of the time scaling
/// only disqualifies the candidate).
fn with_executed_time(
    cell: &MillCell,
    mut r: GreedyResult,
    limits: &[JointLimit],
    settings: &TrajectorySettings,
    budget: &Budget,
) -> Result<GreedyResult, MillPlanError> {
    r.executed_time = match time_scale(cell, &as_plan(cell, &r), limits, settings, budget) {
        Ok(t) => Some(t.duration()),
        Err(MillPlanError::Interrupted(i)) => return Err(MillPlanError::Interrupted(i)),
        Err(_) => None,
    };
    Ok(r)
}
