//! A milling plan: per segment Ω, f, g with the model's values evaluated
//! DIRECTLY (never from the cache), and the totals of the comparison table
//! of issue 5 (machining time, chatter-free, max |μ|max, min condition
//! indicator, total reward).
//!
//! * Machining time `Σ_i l_i / f_i` (seed 004 section 3: uniform arc-length
//!   segments traversed at feed f_i).
//! * Total reward `Σ_i r_i` over ALL segments, r of seed 004 eq. 12 — the
//!   environment's r(s_0) plus its step rewards ([`crate::env`]).
//! * Joints: IK nearest the previous segment's joints (branch continuity),
//!   the first segment nearest the cell's reference joints — as the
//!   environment.
//! * Threads: the N direct |μ|max evaluations (the cost) run on up to
//!   [`default_eval_threads`] threads ([`Plan::evaluate_with_threads`]);
//!   the plan is bit for bit the sequential one (`tests/plan_eval.rs`).

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use kerf_chatter::indicator::chatter_indicator;
use kerf_mill::{CellState, MillCell};

use crate::env::PhysicalState;
use crate::error::MillPlanError;
use crate::reward::{step_reward, RewardParts, RewardWeights};

/// One planned segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentPlan {
    /// Segment index.
    pub segment: usize,
    /// Spindle speed \[rpm\].
    pub rpm: f64,
    /// Feed [m/s].
    pub feed: f64,
    /// Redundancy angle \[rad\].
    pub g: f64,
    /// |μ|max, evaluated directly.
    pub spectral_radius: f64,
    /// Condition number K (eq. 14).
    pub condition_number: f64,
    /// Condition indicator 1/K.
    pub condition_indicator: f64,
    /// Joint vector \[rad\].
    pub joints: [f64; 6],
    /// Segment time l/f \[s\].
    pub time: f64,
    /// Reward and its parts (eq. 12).
    pub reward: RewardParts,
}

/// A whole plan and its totals.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// Planner name (for the comparison table).
    pub planner: String,
    /// One entry per path segment, in order.
    pub segments: Vec<SegmentPlan>,
    /// Machining time Σ l_i/f_i \[s\].
    pub total_time: f64,
    /// Every segment has |μ|max < 1.
    pub chatter_free: bool,
    /// Largest |μ|max.
    pub max_spectral_radius: f64,
    /// Smallest condition indicator 1/K.
    pub min_condition_indicator: f64,
    /// Σ r_i over all segments.
    pub total_reward: f64,
}

/// One row of [`comparison_table`].
#[derive(Debug, Clone, PartialEq)]
pub struct ComparisonRow {
    /// Planner name.
    pub planner: String,
    /// Machining time \[s\].
    pub total_time: f64,
    /// Chatter-free.
    pub chatter_free: bool,
    /// Largest |μ|max.
    pub max_spectral_radius: f64,
    /// Smallest 1/K.
    pub min_condition_indicator: f64,
    /// Total reward.
    pub total_reward: f64,
}

impl Plan {
    /// Evaluates a state sequence directly (module documentation), on up to
    /// [`default_eval_threads`] threads ([`Plan::evaluate_with_threads`]).
    ///
    /// # Arguments
    /// * `cell` — the milling cell; `weights` — reward weights;
    /// * `states` — one state per segment, segments 0, 1, …, N − 1 in order;
    /// * `planner` — a name for the tables.
    ///
    /// # Returns
    /// The plan; bit for bit the same for every thread count.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] for a wrong length or segment order;
    /// [`MillPlanError::InvalidParameter`] for a zero, negative or NaN feed,
    /// or Ω, g outside the cell's ranges; [`MillPlanError::Mill`] for an
    /// infeasible state (unreachable, joint limit: a plan must be
    /// feasible); chatter-model errors. With several bad segments, the
    /// error of the first one (as a sequential evaluation).
    ///
    /// # Performance
    /// N direct indicator evaluations, about 1.2–1.3 ms each in release:
    /// about 0.13 s for N = 100 on one thread; with 2 threads on the 2-core
    /// machine see [`crate::planner`] (`benches/plan_latency.rs`).
    pub fn evaluate(
        cell: &MillCell,
        weights: &RewardWeights,
        states: &[PhysicalState],
        planner: &str,
    ) -> Result<Self, MillPlanError> {
        Self::evaluate_with_threads(cell, weights, states, planner, default_eval_threads())
    }

    /// [`Plan::evaluate`] on at most `threads` threads (the calling thread
    /// included; 1 = sequential).
    ///
    /// # Steps
    /// 1. In segment order: the state checks and the cell state (IK nearest
    ///    the previous segment's joints — a sequential chain, cheap), up to
    ///    the first failing segment.
    /// 2. The |μ|max of those segments: the expensive part, handed out in
    ///    segment order to `min(threads, N, MAX_EVAL_THREADS)` workers
    ///    (the calling thread and scoped helper threads); each value goes
    ///    to its segment's slot, so the result does not depend on the
    ///    thread count or the scheduling (every evaluation is a pure
    ///    function of its segment's inputs). After an error no new
    ///    segments are started; every segment before it still finishes.
    /// 3. In segment order: rewards, times, totals; the first error in
    ///    segment order wins — the same error as a sequential evaluation.
    ///
    /// # Arguments
    /// As [`Plan::evaluate`], and `threads` ≥ 1. A helper thread that the
    /// OS refuses to start is not an error: the others do its work.
    ///
    /// # Returns
    /// The plan (identical for every `threads`).
    ///
    /// # Errors
    /// As [`Plan::evaluate`]; [`MillPlanError::InvalidParameter`] for
    /// `threads` = 0.
    ///
    /// # Performance
    /// About (N × 1.25 ms) / min(threads, free cores) in release.
    pub fn evaluate_with_threads(
        cell: &MillCell,
        weights: &RewardWeights,
        states: &[PhysicalState],
        planner: &str,
        threads: usize,
    ) -> Result<Self, MillPlanError> {
        if threads == 0 {
            return Err(MillPlanError::InvalidParameter {
                name: "evaluation threads".to_string(),
                value: 0.0,
                reason: "must be >= 1".to_string(),
            });
        }
        weights.validate()?;
        let n = cell.path().segments().len();
        if states.len() != n {
            return Err(MillPlanError::InvalidConfig {
                name: format!("plan `{planner}`"),
                reason: format!("{} states for {n} segments", states.len()),
            });
        }
        let lim = cell.state_limits();
        // Step 1: checks and cell states, in order, up to the first error.
        let mut cell_states: Vec<CellState> = Vec::with_capacity(n);
        let mut first_error: Option<MillPlanError> = None;
        let mut reference: Option<[f64; 6]> = None;
        for (i, s) in states.iter().enumerate() {
            match check_state(cell, i, s, planner)
                .and_then(|()| Ok(cell.evaluate(i, s.g, reference.as_ref())?))
            {
                Ok(cs) => {
                    reference = Some(cs.joints);
                    cell_states.push(cs);
                }
                Err(e) => {
                    first_error = Some(e);
                    break;
                }
            }
        }
        // Step 2: |μ|max of the segments 0..cell_states.len().
        let mus = spectral_radii(cell, states, &cell_states, threads);
        // Step 3: in order; a |μ| error at segment j precedes a step-1
        // error at a later segment (sequential order).
        let mut segments = Vec::with_capacity(n);
        for (i, (cs, mu)) in cell_states.iter().zip(mus).enumerate() {
            let s = &states[i];
            let mu = mu?;
            let reward = step_reward(weights, cs.condition_number, s.feed, lim.feed[1], mu)?;
            let length = cell.path().segment(i)?.length;
            segments.push(SegmentPlan {
                segment: i,
                rpm: s.rpm,
                feed: s.feed,
                g: s.g,
                spectral_radius: mu,
                condition_number: cs.condition_number,
                condition_indicator: cs.condition_indicator,
                joints: cs.joints,
                time: length / s.feed,
                reward,
            });
        }
        if let Some(e) = first_error {
            return Err(e);
        }
        let max_mu = segments
            .iter()
            .map(|s| s.spectral_radius)
            .fold(0.0, f64::max);
        Ok(Self {
            planner: planner.to_string(),
            total_time: segments.iter().map(|s| s.time).sum(),
            chatter_free: segments.iter().all(|s| s.spectral_radius < 1.0),
            max_spectral_radius: max_mu,
            min_condition_indicator: segments
                .iter()
                .map(|s| s.condition_indicator)
                .fold(f64::INFINITY, f64::min),
            total_reward: segments.iter().map(|s| s.reward.total).sum(),
            segments,
        })
    }

    /// The plan's row of the comparison table.
    pub fn row(&self) -> ComparisonRow {
        ComparisonRow {
            planner: self.planner.clone(),
            total_time: self.total_time,
            chatter_free: self.chatter_free,
            max_spectral_radius: self.max_spectral_radius,
            min_condition_indicator: self.min_condition_indicator,
            total_reward: self.total_reward,
        }
    }

    /// The state sequence of the plan.
    pub fn states(&self) -> Vec<PhysicalState> {
        self.segments
            .iter()
            .map(|s| PhysicalState {
                segment: s.segment,
                rpm: s.rpm,
                feed: s.feed,
                g: s.g,
            })
            .collect()
    }
}

/// Largest number of threads [`Plan::evaluate`] uses, whatever the
/// machine reports (a cap for a node serving several requests at once).
pub const MAX_EVAL_THREADS: usize = 8;

/// The thread count of [`Plan::evaluate`]:
/// [`std::thread::available_parallelism`] (1 when unknown), at most
/// [`MAX_EVAL_THREADS`].
///
/// # Returns
/// A number in 1..=[`MAX_EVAL_THREADS`].
pub fn default_eval_threads() -> usize {
    std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
        .clamp(1, MAX_EVAL_THREADS)
}

/// The checks of one state of [`Plan::evaluate`]: segment order, Ω, f, g
/// in the cell's ranges (NaN refused), f > 0.
fn check_state(
    cell: &MillCell,
    i: usize,
    s: &PhysicalState,
    planner: &str,
) -> Result<(), MillPlanError> {
    if s.segment != i {
        return Err(MillPlanError::InvalidConfig {
            name: format!("plan `{planner}`"),
            reason: format!("state {i} is for segment {}", s.segment),
        });
    }
    let lim = cell.state_limits();
    for (name, v, lo, hi) in [
        (
            "spindle speed [rpm]",
            s.rpm,
            lim.spindle_rpm[0],
            lim.spindle_rpm[1],
        ),
        ("feed [m/s]", s.feed, lim.feed[0], lim.feed[1]),
        (
            "redundancy angle [rad]",
            s.g,
            lim.redundancy_angle[0],
            lim.redundancy_angle[1],
        ),
    ] {
        if !(v >= lo && v <= hi) {
            return Err(MillPlanError::InvalidParameter {
                name: format!("{name} at segment {i}"),
                value: v,
                reason: format!("must be in [{lo}, {hi}]"),
            });
        }
    }
    if s.feed <= 0.0 {
        return Err(MillPlanError::InvalidParameter {
            name: format!("feed [m/s] at segment {i}"),
            value: s.feed,
            reason: "must be > 0 (the segment time l/f would be infinite)".to_string(),
        });
    }
    Ok(())
}

/// |μ|max of segment `i`: the direct chatter indicator at the segment's
/// cell state, Ω and f.
fn spectral_radius(
    cell: &MillCell,
    state: &PhysicalState,
    cell_state: &CellState,
) -> Result<f64, MillPlanError> {
    Ok(chatter_indicator(
        &cell_state.modal,
        &cell.milling_process(),
        state.rpm,
        state.feed,
        cell.indicator_settings(),
    )?
    .spectral_radius)
}

/// Step 2 of [`Plan::evaluate_with_threads`]: one result per cell state,
/// in segment order. Segments are handed out in increasing order from a
/// shared counter; after the first error no new segment starts, so every
/// slot before the lowest failing segment is filled, and a slot left
/// empty lies after it (step 3 stops at that error first).
fn spectral_radii(
    cell: &MillCell,
    states: &[PhysicalState],
    cell_states: &[CellState],
    threads: usize,
) -> Vec<Result<f64, MillPlanError>> {
    let n = cell_states.len();
    let workers = threads.min(n).clamp(1, MAX_EVAL_THREADS);
    if workers == 1 {
        let mut out = Vec::with_capacity(n);
        for (s, cs) in states.iter().zip(cell_states) {
            let r = spectral_radius(cell, s, cs);
            let failed = r.is_err();
            out.push(r);
            if failed {
                break;
            }
        }
        return out;
    }
    let next = AtomicUsize::new(0);
    let failed = AtomicBool::new(false);
    let work = || {
        let mut done = Vec::new();
        while !failed.load(Ordering::Acquire) {
            let i = next.fetch_add(1, Ordering::AcqRel);
            if i >= n {
                break;
            }
            let r = spectral_radius(cell, &states[i], &cell_states[i]);
            if r.is_err() {
                failed.store(true, Ordering::Release);
            }
            done.push((i, r));
        }
        done
    };
    let mut slots: Vec<Option<Result<f64, MillPlanError>>> = (0..n).map(|_| None).collect();
    std::thread::scope(|scope| {
        let helpers: Vec<_> = (1..workers)
            .filter_map(|k| {
                std::thread::Builder::new()
                    .name(format!("plan-eval-{k}"))
                    .spawn_scoped(scope, work)
                    .ok()
            })
            .collect();
        let mut all = work();
        for h in helpers {
            match h.join() {
                Ok(done) => all.extend(done),
                Err(panic) => std::panic::resume_unwind(panic),
            }
        }
        for (i, r) in all {
            slots[i] = Some(r);
        }
    });
    let mut out = Vec::with_capacity(n);
    for (i, slot) in slots.into_iter().enumerate() {
        match slot {
            Some(r) => {
                let failed = r.is_err();
                out.push(r);
                if failed {
                    break;
                }
            }
            None => {
                // Only after a failing segment (see above); reported as an
                // error rather than dropped, should that ever not hold.
                out.push(Err(MillPlanError::InvalidConfig {
                    name: format!("plan evaluation of segment {i}"),
                    reason: "not evaluated (an earlier segment failed)".to_string(),
                }));
                break;
            }
        }
    }
    out
}

/// The comparison table of issue 5 as Markdown: planner, machining time
/// \[s\], chatter-free (yes/no), max |μ|max, min condition indicator, total
/// reward. A `|` in a planner name is escaped (`\|`) so it stays one cell.
pub fn comparison_table(rows: &[ComparisonRow]) -> String {
    let mut out = String::from(
        "| planner | machining time [s] | chatter-free | max \\|μ\\|max | min 1/K | total reward |\n\
         |---|---:|---|---:|---:|---:|\n",
    );
    for r in rows {
        out.push_str(&format!(
            "| {} | {:.2} | {} | {:.4} | {:.3} | {:.3} |\n",
            r.planner.replace('|', "\\|"),
            r.total_time,
            if r.chatter_free { "yes" } else { "no" },
            r.max_spectral_radius,
            r.min_condition_indicator,
            r.total_reward
        ));
    }
    out
}
