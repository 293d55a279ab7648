//! A milling plan: per segment Ω, f, g with the model's values evaluated
//! DIRECTLY (never from the cache), and the totals of the comparison table
//! of issue 5 (machining time, chatter-free, max |μ|max, min condition
//! indicator, total reward).
//!
//! The one exception is opt-in and reported: a planner set to
//! [`IndicatorSource::Cache`] ([`crate::planner::MillPlanner::with_indicator_source`])
//! takes |μ|max from the indicator cache where it applies, and its answer
//! lists the cached segments and the cache's stated error bound
//! ([`IndicatorProvenance`]); [`Plan::evaluate`] is always direct.
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

use kerf_budget::Budget;
use kerf_mill::{CellState, MillCell};

use crate::cache::IndicatorCache;
use crate::env::PhysicalState;
use crate::error::MillPlanError;
use crate::evaluation::{cached_values, evaluate_impl, spectral_radii};
use crate::reward::{step_reward, RewardParts, RewardWeights};

pub use crate::evaluation::{default_eval_threads, MAX_EVAL_THREADS};
pub use crate::provenance::{IndicatorProvenance, IndicatorSource};

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

impl SegmentPlan {
    /// What the trajectory and the re-evaluation of a plan read of this
    /// segment (neither reads |μ|max nor the reward).
    pub(crate) fn input(&self) -> SegmentInput {
        SegmentInput {
            segment: self.segment,
            rpm: self.rpm,
            feed: self.feed,
            g: self.g,
            joints: self.joints,
        }
    }
}

/// A planned segment before its |μ|max is known: what the executed
/// trajectory ([`crate::timing::time_scale`]) and the re-evaluation of
/// the segments it slows ([`Reevaluation`]) read, so that both can run
/// while the plan's |μ|max are being evaluated
/// ([`crate::evaluation::evaluate_direct_alongside`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SegmentInput {
    /// Segment index.
    pub segment: usize,
    /// Spindle speed \[rpm\].
    pub rpm: f64,
    /// Feed \[m/s\].
    pub feed: f64,
    /// Redundancy angle \[rad\].
    pub g: f64,
    /// Joint vector of the segment's cell state \[rad\].
    pub joints: [f64; 6],
}

/// The first half of [`Plan::as_executed_with`]: the segments whose
/// executed feed differs from the planned one (bit for bit), their cell
/// states (IK nearest the previous segment's planned joints, as
/// [`Plan::evaluate`]: the same inputs, so the same cell states) and
/// their |μ|max at the executed feed (the cache's where it applies, the
/// others direct). It reads no |μ|max of the plan, so it can run before
/// they are known.
#[derive(Debug)]
pub(crate) struct Reevaluation {
    changed: Vec<usize>,
    cell_states: Vec<CellState>,
    cached_now: Vec<Option<(f64, f64)>>,
    direct_mus: Vec<Result<f64, MillPlanError>>,
}

impl Reevaluation {
    /// The re-evaluation of the segments `inputs` (the plan's, in order)
    /// at `feeds`, `times` (one per segment, finite and > 0).
    ///
    /// # Errors
    /// As [`Plan::as_executed_with`] before its assembly: wrong lengths,
    /// bad feeds or times, 0 threads, cell-model errors, the cache's
    /// errors. |μ|max errors are kept, per segment, for the assembly.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new(
        cell: &MillCell,
        planner: &str,
        inputs: &[SegmentInput],
        feeds: &[f64],
        times: &[f64],
        threads: usize,
        cache: Option<&IndicatorCache>,
        budget: &Budget,
    ) -> Result<Self, MillPlanError> {
        let n = inputs.len();
        if feeds.len() != n || times.len() != n {
            return Err(MillPlanError::InvalidConfig {
                name: format!("executed plan `{planner}`"),
                reason: format!(
                    "{} feeds and {} times for {n} segments",
                    feeds.len(),
                    times.len()
                ),
            });
        }
        for (i, (f, t)) in feeds.iter().zip(times).enumerate() {
            for (name, v) in [("feed [m/s]", f), ("time [s]", t)] {
                if !(v.is_finite() && *v > 0.0) {
                    return Err(MillPlanError::InvalidParameter {
                        name: format!("executed {name} at segment {i}"),
                        value: *v,
                        reason: "must be finite and > 0".to_string(),
                    });
                }
            }
        }
        if threads == 0 {
            return Err(MillPlanError::InvalidParameter {
                name: "evaluation threads".to_string(),
                value: 0.0,
                reason: "must be >= 1".to_string(),
            });
        }
        let changed: Vec<usize> = (0..n).filter(|&i| feeds[i] != inputs[i].feed).collect();
        let mut states = Vec::with_capacity(changed.len());
        let mut cell_states = Vec::with_capacity(changed.len());
        for &i in &changed {
            budget.check("the executed plan's cell states")?;
            let s = &inputs[i];
            let reference = i.checked_sub(1).map(|p| inputs[p].joints);
            cell_states.push(cell.evaluate(i, s.g, reference.as_ref())?);
            states.push(PhysicalState {
                segment: i,
                rpm: s.rpm,
                feed: feeds[i],
                g: s.g,
            });
        }
        let cached_now = match cache {
            Some(c) => cached_values(cell, &states, &cell_states, c)?,
            None => vec![None; changed.len()],
        };
        let direct: Vec<usize> = (0..changed.len())
            .filter(|j| cached_now[*j].is_none())
            .collect();
        let direct_mus = spectral_radii(cell, &states, &cell_states, &direct, threads, budget);
        Ok(Self {
            changed,
            cell_states,
            cached_now,
            direct_mus,
        })
    }
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
        evaluate_impl(
            cell,
            weights,
            states,
            planner,
            threads,
            None,
            &Budget::unlimited(),
        )
        .map(|(plan, _)| plan)
    }

    /// [`Plan::evaluate_with_threads`] with |μ|max from `cache` where it
    /// applies ([`IndicatorSource::Cache`]): a segment's cached value is
    /// used when the cache has a stated error bound,
    /// [`IndicatorCache::try_query`] answers, and the plan's cell state (IK
    /// nearest the previous segment's joints) has the tool-tip dynamics of
    /// the reference-joint IK state the cache was built with (mass,
    /// damping and stiffness matrices equal within 1e-9 relative: |μ|
    /// depends on the cell state only through them); every other segment
    /// is evaluated directly. A cached segment's bound is the
    /// cache's bound for g on a g node when its g is a node (and the cache
    /// states one), else the general bound. `chatter_free` is then claimed
    /// only when every cached |μ| + its bound < 1 (and every direct
    /// |μ| < 1).
    ///
    /// The caller guarantees that the cache belongs to the cell's model
    /// ([`crate::planner::MillPlanner`] checks the cell fingerprint):
    /// hence crate-private.
    ///
    /// # Errors
    /// As [`Plan::evaluate_with_threads`].
    pub(crate) fn evaluate_cached(
        cell: &MillCell,
        weights: &RewardWeights,
        states: &[PhysicalState],
        planner: &str,
        threads: usize,
        cache: &IndicatorCache,
        budget: &Budget,
    ) -> Result<(Self, IndicatorProvenance), MillPlanError> {
        evaluate_impl(cell, weights, states, planner, threads, Some(cache), budget)
    }

    /// The plan with its totals from `segments` (in order): machining time
    /// Σ time, chatter-free when every |μ|max + `margin(segment)` < 1 (the
    /// margin: a cached value's error bound, 0 for a direct one), largest
    /// |μ|max, smallest 1/K, Σ reward.
    pub(crate) fn from_segments(
        planner: &str,
        segments: Vec<SegmentPlan>,
        margin: impl Fn(usize) -> f64,
    ) -> Self {
        Plan {
            planner: planner.to_string(),
            total_time: segments.iter().map(|s| s.time).sum(),
            chatter_free: segments
                .iter()
                .all(|s| s.spectral_radius + margin(s.segment) < 1.0),
            max_spectral_radius: segments
                .iter()
                .map(|s| s.spectral_radius)
                .fold(0.0, f64::max),
            min_condition_indicator: segments
                .iter()
                .map(|s| s.condition_indicator)
                .fold(f64::INFINITY, f64::min),
            total_reward: segments.iter().map(|s| s.reward.total).sum(),
            segments,
        }
    }

    /// The plan as the robot runs it after [`crate::timing::time_scale`]:
    /// segment i machined in `times[i]` at the feed `feeds[i]`. Segments
    /// whose feed differs from the plan's (bit for bit) get |μ|max, reward
    /// and feed re-evaluated DIRECTLY at the new feed (from the cache only
    /// through the crate's planner in [`IndicatorSource::Cache`] mode) (same Ω, g and cell
    /// state: IK nearest the previous segment's joints, as
    /// [`Plan::evaluate`]); the others keep their values. Every segment's
    /// time is `times[i]` (a start or stop from rest included, so it may
    /// exceed l/f at the two ends).
    ///
    /// # Arguments
    /// * `cell`, `weights` — as the plan was evaluated with;
    /// * `feeds`, `times` — one per segment, finite and > 0;
    /// * `threads` — as [`Plan::evaluate_with_threads`];
    /// * `cached` — the plan's provenance: a cached, unchanged segment keeps
    ///   its error bound in the chatter-free test;
    ///
    /// # Returns
    /// The executed plan.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] for wrong lengths;
    /// [`MillPlanError::InvalidParameter`] for a non-positive or NaN feed or
    /// time; cell-model and chatter-model errors of the re-evaluation. A
    /// feed below the request's minimum is NOT an error: it is what the
    /// robot's limits impose, and is reported by its |μ|max.
    ///
    /// # Performance
    /// One direct indicator evaluation per changed segment, on up to
    /// `threads` threads.
    pub fn as_executed(
        &self,
        cell: &MillCell,
        weights: &RewardWeights,
        feeds: &[f64],
        times: &[f64],
        threads: usize,
        cached: &IndicatorProvenance,
    ) -> Result<Self, MillPlanError> {
        self.as_executed_with(
            cell,
            weights,
            feeds,
            times,
            threads,
            cached,
            None,
            &Budget::unlimited(),
        )
        .map(|(plan, _)| plan)
    }

    /// [`Plan::as_executed`], with `cache` `Some` when the plan was
    /// evaluated with [`IndicatorSource::Cache`]: a changed segment then
    /// takes the cache's value where it applies (as
    /// [`Plan::evaluate_cached`], whose caller guarantees that the cache
    /// belongs to the cell: hence crate-private), with its bound in the
    /// chatter-free test.
    ///
    /// # Returns
    /// The executed plan and its segments whose |μ|max is interpolated from
    /// the cache (ascending; empty without a cache).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn as_executed_with(
        &self,
        cell: &MillCell,
        weights: &RewardWeights,
        feeds: &[f64],
        times: &[f64],
        threads: usize,
        cached: &IndicatorProvenance,
        cache: Option<&IndicatorCache>,
        budget: &Budget,
    ) -> Result<(Self, Vec<usize>), MillPlanError> {
        let inputs: Vec<SegmentInput> = self.segments.iter().map(SegmentPlan::input).collect();
        let reevaluation = Reevaluation::new(
            cell,
            &self.planner,
            &inputs,
            feeds,
            times,
            threads,
            cache,
            budget,
        )?;
        self.with_reevaluation(cell, weights, feeds, times, cached, reevaluation)
    }

    /// The second half of [`Plan::as_executed_with`]: the executed plan from
    /// this plan (same segments, Ω, f, g and joints as the `inputs` the
    /// `reevaluation` was made for) and the re-evaluated |μ|max of its
    /// changed segments, in segment order (the first error in segment order
    /// wins, as in the sequential evaluation).
    pub(crate) fn with_reevaluation(
        &self,
        cell: &MillCell,
        weights: &RewardWeights,
        feeds: &[f64],
        times: &[f64],
        cached: &IndicatorProvenance,
        reevaluation: Reevaluation,
    ) -> Result<(Self, Vec<usize>), MillPlanError> {
        let n = self.segments.len();
        let Reevaluation {
            changed,
            cell_states,
            cached_now,
            direct_mus,
        } = reevaluation;
        if feeds.len() != n
            || times.len() != n
            || changed
                .iter()
                .any(|&i| i >= n || feeds[i] == self.segments[i].feed)
        {
            return Err(MillPlanError::InvalidConfig {
                name: format!("executed plan `{}`", self.planner),
                reason: "the re-evaluation was made for another plan or other feeds".to_string(),
            });
        }
        let mut direct_mus = direct_mus.into_iter();
        let max_feed = cell.state_limits().feed[1];
        let mut segments = self.segments.clone();
        let mut margins = vec![0.0; n];
        for &i in &cached.cached_segments {
            if let Some(m) = margins.get_mut(i) {
                *m = cached.error_bound.unwrap_or(0.0);
            }
        }
        for (j, (&i, cs)) in changed.iter().zip(&cell_states).enumerate() {
            let mu = match cached_now[j] {
                Some((v, bound)) => {
                    margins[i] = bound;
                    v
                }
                None => {
                    margins[i] = 0.0;
                    // The direct evaluations stop after the first error.
                    direct_mus.next().unwrap_or_else(|| {
                        Err(MillPlanError::InvalidConfig {
                            name: format!("executed plan `{}`", self.planner),
                            reason: format!("segment {i} was not evaluated"),
                        })
                    })?
                }
            };
            let seg = &mut segments[i];
            seg.feed = feeds[i];
            seg.spectral_radius = mu;
            seg.reward = step_reward(weights, cs.condition_number, feeds[i], max_feed, mu)?;
        }
        for (seg, t) in segments.iter_mut().zip(times) {
            seg.time = *t;
        }
        let cached_segments: Vec<usize> = (0..n)
            .filter(|&i| {
                margins[i] > 0.0
                    || (cached.cached_segments.binary_search(&i).is_ok()
                        && changed.binary_search(&i).is_err())
            })
            .collect();
        let plan = Self::from_segments(&self.planner, segments, |i| margins[i]);
        Ok((plan, cached_segments))
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
