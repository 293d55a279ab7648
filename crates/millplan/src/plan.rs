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

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use kerf_chatter::indicator::chatter_indicator;
use kerf_chatter::Modal2;
use kerf_mill::{CellState, MillCell};

use crate::cache::{is_infeasible, IndicatorCache};
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
        evaluate_impl(cell, weights, states, planner, threads, None).map(|(plan, _)| plan)
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
    ) -> Result<(Self, IndicatorProvenance), MillPlanError> {
        evaluate_impl(cell, weights, states, planner, threads, Some(cache))
    }

    /// The plan with its totals from `segments` (in order): machining time
    /// Σ time, chatter-free when every |μ|max + `margin(segment)` < 1 (the
    /// margin: a cached value's error bound, 0 for a direct one), largest
    /// |μ|max, smallest 1/K, Σ reward.
    fn from_segments(
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
        self.as_executed_with(cell, weights, feeds, times, threads, cached, None)
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
    ) -> Result<(Self, Vec<usize>), MillPlanError> {
        let n = self.segments.len();
        if feeds.len() != n || times.len() != n {
            return Err(MillPlanError::InvalidConfig {
                name: format!("executed plan `{}`", self.planner),
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
        let changed: Vec<usize> = (0..n)
            .filter(|&i| feeds[i] != self.segments[i].feed)
            .collect();
        let mut states = Vec::with_capacity(changed.len());
        let mut cell_states = Vec::with_capacity(changed.len());
        for &i in &changed {
            let s = &self.segments[i];
            let reference = i.checked_sub(1).map(|p| self.segments[p].joints);
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
        let mut direct_mus =
            spectral_radii(cell, &states, &cell_states, &direct, threads).into_iter();
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

/// Where the |μ|max of a plan's segments comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum IndicatorSource {
    /// Every segment evaluated directly with the chatter model (the
    /// default; about 1.25 ms per segment in release).
    #[default]
    Direct,
    /// The indicator cache's interpolation where it applies, with its
    /// stated error bound reported ([`Plan::evaluate`] stays direct; see
    /// [`crate::planner::MillPlanner::with_indicator_source`]).
    Cache,
}

impl IndicatorSource {
    /// `direct` or `cache`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Direct => "direct",
            Self::Cache => "cache",
        }
    }
}

/// How the |μ|max values of a plan were obtained (part of the planner's
/// answer, [`crate::planner::MillPlanOutput::indicator`]).
#[derive(Debug, Clone, PartialEq)]
pub struct IndicatorProvenance {
    /// The source asked for.
    pub requested: IndicatorSource,
    /// Segments whose |μ|max is the cache's interpolation (ascending);
    /// empty for a direct evaluation.
    pub cached_segments: Vec<usize>,
    /// Segments in the plan.
    pub segments: usize,
    /// The cache's stated bound on |cached − direct| |μ|max when some
    /// segment is cached (the largest that applies: the bound for g on a
    /// g node where every cached g is a node and the cache states one, else
    /// the general bound), else `None`.
    pub error_bound: Option<f64>,
    /// One sentence for the answer's message: how many segments are
    /// cached, the bound, and why the cache was not used where it was not.
    pub note: String,
}

impl IndicatorProvenance {
    /// Every segment evaluated directly, `requested` having been asked for
    /// (`reason`: why the cache was not used, when it was asked for).
    ///
    /// # Arguments
    /// * `requested` — the source asked for; `segments` — plan length;
    /// * `reason` — appended to the note when not empty.
    ///
    /// # Returns
    /// A provenance with no cached segment.
    pub fn direct(requested: IndicatorSource, segments: usize, reason: &str) -> Self {
        let mut note = format!("|mu|max evaluated directly for all {segments} segments");
        if !reason.is_empty() {
            note.push_str(&format!(" ({reason})"));
        }
        Self {
            requested,
            cached_segments: Vec::new(),
            segments,
            error_bound: None,
            note,
        }
    }

    /// Whether every |μ|max of the plan is a direct evaluation.
    pub fn all_direct(&self) -> bool {
        self.cached_segments.is_empty()
    }
}

/// The evaluation of [`Plan::evaluate_with_threads`] and, with a cache,
/// [`Plan::evaluate_cached`].
fn evaluate_impl(
    cell: &MillCell,
    weights: &RewardWeights,
    states: &[PhysicalState],
    planner: &str,
    threads: usize,
    cache: Option<&IndicatorCache>,
) -> Result<(Plan, IndicatorProvenance), MillPlanError> {
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
    // Step 2: cached values where the cache applies, the rest directly.
    let k = cell_states.len();
    let cached = match cache {
        Some(c) => cached_values(cell, states, &cell_states, c)?,
        None => vec![None; k],
    };
    let direct: Vec<usize> = (0..k).filter(|i| cached[*i].is_none()).collect();
    let mut direct_mus = spectral_radii(cell, states, &cell_states, &direct, threads).into_iter();
    let mut mus: Vec<Result<f64, MillPlanError>> = Vec::with_capacity(k);
    for value in &cached {
        match value {
            Some((v, _)) => mus.push(Ok(*v)),
            None => match direct_mus.next() {
                Some(r) => mus.push(r),
                // The direct evaluations stopped at an earlier error.
                None => break,
            },
        }
    }
    // Step 3: in order; a |μ| error at segment j precedes a step-1 error at
    // a later segment (sequential order).
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
    if segments.len() != n {
        // Unreachable: every segment is evaluated when none failed.
        return Err(MillPlanError::InvalidConfig {
            name: format!("plan `{planner}`"),
            reason: format!("{} of {n} segments evaluated", segments.len()),
        });
    }
    let cached_segments: Vec<usize> = (0..n).filter(|i| cached[*i].is_some()).collect();
    let margin = |i: usize| cached[i].map_or(0.0, |(_, b)| b);
    let bound = cached.iter().flatten().map(|(_, b)| *b).reduce(f64::max);
    let plan = Plan::from_segments(planner, segments, margin);
    let provenance = match (cache, bound) {
        (None, _) => IndicatorProvenance::direct(IndicatorSource::Direct, n, ""),
        (Some(c), None) => IndicatorProvenance::direct(
            IndicatorSource::Cache,
            n,
            if c.header().error_bound.is_none() {
                "the indicator cache states no error bound"
            } else {
                "no state is inside the indicator cache's feasible grid with the cache's tool-tip dynamics"
            },
        ),
        (Some(_), Some(b)) => IndicatorProvenance {
            requested: IndicatorSource::Cache,
            note: format!(
                "|mu|max of {} of {n} segments INTERPOLATED from the indicator cache (stated \
                 error bound +/-{b:.3}; chatter-free is claimed only where |mu|max + bound < 1), \
                 {} evaluated directly",
                cached_segments.len(),
                n - cached_segments.len()
            ),
            cached_segments,
            segments: n,
            error_bound: Some(b),
        },
    };
    Ok((plan, provenance))
}

/// Per cell state, the cache's |μ|max and the stated bound that applies
/// to it (the bound for g on a g node when the state's g is a node and
/// the cache states one, else the general bound), when the cache answers
/// on the same IK branch ([`Plan::evaluate_cached`]); all `None` without
/// a stated general bound.
///
/// # Errors
/// A NaN state (refused earlier by [`check_state`]); a cell-model error
/// other than an infeasible state.
fn cached_values(
    cell: &MillCell,
    states: &[PhysicalState],
    cell_states: &[CellState],
    cache: &IndicatorCache,
) -> Result<Vec<Option<(f64, f64)>>, MillPlanError> {
    let k = cell_states.len();
    let valid = |b: &f64| b.is_finite() && *b >= 0.0;
    let header = cache.header();
    let Some(general) = header.error_bound.filter(valid) else {
        return Ok(vec![None; k]);
    };
    let on_nodes = header.error_bound_g_nodes.filter(valid);
    let mut out = Vec::with_capacity(k);
    for (s, cs) in states.iter().zip(cell_states) {
        let Some(v) = cache.try_query(s.segment, s.rpm, s.feed, s.g)? else {
            out.push(None);
            continue;
        };
        // The cache's nodes use the IK nearest the reference joints; the
        // cached |μ| applies when that state has the same tool-tip dynamics
        // (|μ| depends on the cell state only through them; e.g. a wrist
        // flip of the chain keeps them).
        let same_dynamics = match cell.evaluate(s.segment, s.g, None) {
            Ok(r) => same_modal(&r.modal, &cs.modal),
            Err(e) if is_infeasible(&e) => false,
            Err(e) => return Err(e.into()),
        };
        let bound = match on_nodes {
            Some(b) if cache.grid().g.contains(&s.g) => b.min(general),
            _ => general,
        };
        out.push((same_dynamics && v.is_finite()).then_some((v, bound)));
    }
    Ok(out)
}

/// Relative tolerance of [`same_modal`].
const SAME_MODAL_TOLERANCE: f64 = 1e-9;

/// Whether two tool-tip models are equal within [`SAME_MODAL_TOLERANCE`]
/// relative to each matrix's largest entry (a NaN or infinite entry: not
/// equal).
fn same_modal(a: &Modal2, b: &Modal2) -> bool {
    [
        (&a.mass, &b.mass),
        (&a.damping, &b.damping),
        (&a.stiffness, &b.stiffness),
    ]
    .iter()
    .all(|(x, y)| {
        if !(x.iter().chain(y.iter()).all(|v| v.is_finite())) {
            return false;
        }
        let scale = x.amax().max(y.amax());
        let diff = (*x - *y).amax();
        diff <= SAME_MODAL_TOLERANCE * scale
    })
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

/// Step 2 of [`Plan::evaluate_with_threads`]: the direct |μ|max of the
/// segments `indices` (ascending), one result per index in that order.
/// Indices are handed out in increasing order from a shared counter; after
/// the first error no new one starts, so every result before the lowest
/// failing index is computed; the list stops after that error (step 3
/// stops there first).
fn spectral_radii(
    cell: &MillCell,
    states: &[PhysicalState],
    cell_states: &[CellState],
    indices: &[usize],
    threads: usize,
) -> Vec<Result<f64, MillPlanError>> {
    let n = indices.len();
    let eval = |j: usize| spectral_radius(cell, &states[indices[j]], &cell_states[indices[j]]);
    let workers = threads.min(n).clamp(1, MAX_EVAL_THREADS);
    if workers == 1 {
        let mut out = Vec::with_capacity(n);
        for j in 0..n {
            let r = eval(j);
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
            let j = next.fetch_add(1, Ordering::AcqRel);
            if j >= n {
                break;
            }
            let r = eval(j);
            if r.is_err() {
                failed.store(true, Ordering::Release);
            }
            done.push((j, r));
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
        for (j, r) in all {
            slots[j] = Some(r);
        }
    });
    let mut out = Vec::with_capacity(n);
    for (j, slot) in slots.into_iter().enumerate() {
        match slot {
            Some(r) => {
                let failed = r.is_err();
                out.push(r);
                if failed {
                    break;
                }
            }
            None => {
                // Only after a failing index (see above); reported as an
                // error rather than dropped, should that ever not hold.
                out.push(Err(MillPlanError::InvalidConfig {
                    name: format!("plan evaluation of segment {}", indices[j]),
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

#[cfg(test)]
mod tests {
    use super::*;
    use kerf_chatter::Mode;

    #[test]
    fn same_modal_is_a_relative_tolerance_and_refuses_nan() {
        let mode = Mode {
            natural_frequency_hz: 25.0,
            damping_ratio: 0.05,
            modal_mass: 50.0,
        };
        let a = Modal2::from_modes(mode, mode).expect("modal");
        assert!(same_modal(&a, &a));
        let mut b = a;
        b.stiffness[(0, 1)] += 1e-12 * a.stiffness.amax();
        assert!(same_modal(&a, &b));
        b.stiffness[(0, 1)] += 1e-6 * a.stiffness.amax();
        assert!(!same_modal(&a, &b));
        for bad in [f64::NAN, f64::INFINITY] {
            let mut c = a;
            c.mass[(1, 1)] = bad;
            assert!(!same_modal(&a, &c));
            assert!(!same_modal(&c, &c));
        }
    }
}
