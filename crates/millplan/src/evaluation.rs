//! The evaluation of a plan's states ([`crate::plan::Plan::evaluate`] and
//! its variants): the state checks, the direct |μ|max of every segment on
//! up to [`default_eval_threads`] threads (the plan bit for bit the
//! sequential one), and, with an indicator cache, its values where they
//! apply.

use kerf_budget::Budget;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use kerf_chatter::indicator::chatter_indicator;
use kerf_chatter::Modal2;
use kerf_mill::{CellState, MillCell};

use crate::cache::{is_infeasible, IndicatorCache};
use crate::env::PhysicalState;
use crate::error::MillPlanError;
use crate::plan::{Plan, SegmentInput, SegmentPlan};
use crate::provenance::{IndicatorProvenance, IndicatorSource};
use crate::reward::{step_reward, RewardWeights};

/// The checks every evaluation starts with: at least one thread, valid
/// weights, one state per segment. Returns the segment count.
fn check_inputs(
    cell: &MillCell,
    weights: &RewardWeights,
    states: &[PhysicalState],
    planner: &str,
    threads: usize,
) -> Result<usize, MillPlanError> {
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
    Ok(n)
}

/// The evaluation of [`Plan::evaluate_with_threads`] and, with a cache,
/// [`Plan::evaluate_cached`].
pub(crate) fn evaluate_impl(
    cell: &MillCell,
    weights: &RewardWeights,
    states: &[PhysicalState],
    planner: &str,
    threads: usize,
    cache: Option<&IndicatorCache>,
    budget: &Budget,
) -> Result<(Plan, IndicatorProvenance), MillPlanError> {
    check_inputs(cell, weights, states, planner, threads)?;
    let (cell_states, first_error) = cell_states_in_order(cell, states, planner, budget)?;
    // Step 2: cached values where the cache applies, the rest directly.
    let k = cell_states.len();
    let cached = match cache {
        Some(c) => cached_values(cell, states, &cell_states, c)?,
        None => vec![None; k],
    };
    let direct: Vec<usize> = (0..k).filter(|i| cached[*i].is_none()).collect();
    let direct_mus = spectral_radii(cell, states, &cell_states, &direct, threads, budget);
    assemble(
        cell,
        weights,
        states,
        planner,
        &cell_states,
        first_error,
        &cached,
        direct_mus,
        cache,
    )
}

/// [`evaluate_impl`] with direct |μ|max (no cache), running `alongside` on
/// its own thread while the |μ|max are evaluated (the planner's step 7:
/// the executed trajectory and the re-evaluation of the segments it slows
/// read the segments' Ω, f, g and cell states, never their |μ|max).
///
/// Threads (`threads`, at most [`MAX_EVAL_THREADS`]): with 1, the evaluation
/// and then `alongside`, on the calling thread. With k ≥ 2, `alongside` runs
/// on a thread of its own that then takes evaluations from the same queue
/// as the calling thread and k − 2 helpers (the queue of
/// [`spectral_radii`]: indices handed out in increasing order, no new one
/// after an error), so that k threads stay busy until the last |μ|max.
///
/// `known`: a [`Prefetch`] that evaluated |μ|max of states while the planner
/// produced them; its values for the longest prefix of `states` it saw
/// unchanged are used as they are (the same function of the same inputs:
/// the cell states of a prefix depend on that prefix only), the rest is
/// evaluated here.
///
/// `alongside` gets the segments as [`SegmentInput`]s once step 1 (the
/// sequential chain of cell states) has succeeded for every segment; when it
/// has not, the evaluation fails anyway (with the error of the sequential
/// evaluation) and `alongside` is not run. The plan and its provenance are
/// those of [`evaluate_impl`] with no cache, bit for bit (the same
/// functions of the same inputs; the threads only change when each value is
/// computed).
///
/// # Returns
/// The plan, its provenance, `alongside`'s result (`None` only when it was
/// not run) and the wall time \[s\] from the call until the plan's |μ|max
/// were all known (the evaluation's share of the overlapped time).
///
/// # Errors
/// As [`evaluate_impl`]; `alongside`'s own errors are its result's.
#[allow(clippy::too_many_arguments)]
pub(crate) fn evaluate_direct_alongside<T: Send>(
    cell: &MillCell,
    weights: &RewardWeights,
    states: &[PhysicalState],
    planner: &str,
    threads: usize,
    budget: &Budget,
    known: Option<Prefetch>,
    alongside: impl FnOnce(&[SegmentInput]) -> T + Send,
) -> Result<(Plan, IndicatorProvenance, Option<T>, f64), MillPlanError> {
    let start = std::time::Instant::now();
    let n = check_inputs(cell, weights, states, planner, threads)?;
    let (cell_states, first_error) = cell_states_in_order(cell, states, planner, budget)?;
    let k = cell_states.len();
    let cached = vec![None; k];
    // |μ|max the prefetch already has for a prefix of these very states.
    let known = known.map(|p| p.finish(states)).unwrap_or_default();
    let direct: Vec<usize> = (known.len().min(k)..k).collect();
    let complete = first_error.is_none() && k == n;
    let (direct_mus, beside, evaluated) = if complete {
        let inputs: Vec<SegmentInput> = states
            .iter()
            .zip(&cell_states)
            .map(|(s, cs)| SegmentInput {
                segment: s.segment,
                rpm: s.rpm,
                feed: s.feed,
                g: s.g,
                joints: cs.joints,
            })
            .collect();
        let workers = threads.clamp(1, MAX_EVAL_THREADS);
        if workers == 1 {
            // One thread: the evaluation, then `alongside` (sequential).
            let mus = spectral_radii(cell, states, &cell_states, &direct, 1, budget);
            let evaluated = start.elapsed().as_secs_f64();
            (mus, Some(alongside(&inputs)), evaluated)
        } else {
            // `alongside` runs on a thread of its own, which then joins the
            // evaluation of what is left; the calling thread and `workers − 2`
            // helpers evaluate from the start. The closure is taken by whichever
            // thread runs it (that thread, or this one when it could not start).
            let eval = |j: usize| {
                budget.check("the chatter indicator")?;
                spectral_radius(cell, &states[direct[j]], &cell_states[direct[j]])
            };
            let queue = Queue::new(&eval, direct.len());
            // At least the time step 5's own work (cell states, prefetch) took.
            let queued = start.elapsed().as_secs_f64();
            let task = std::sync::Mutex::new(Some(alongside));
            let run = || {
                let f = task.lock().unwrap_or_else(|e| e.into_inner()).take();
                f.map(|f| f(&inputs))
            };
            // Each worker's results and when its last evaluation ended (0 for none).
            let work = || {
                let done = queue.work();
                let at = if done.is_empty() {
                    0.0
                } else {
                    start.elapsed().as_secs_f64()
                };
                (done, at)
            };
            std::thread::scope(|scope| {
                let chain = std::thread::Builder::new()
                    .name("plan-trajectory".to_string())
                    .spawn_scoped(scope, || {
                        let beside = run();
                        (beside, work())
                    })
                    .ok();
                let helpers: Vec<_> = (2..workers)
                    .filter_map(|k| {
                        std::thread::Builder::new()
                            .name(format!("plan-eval-{k}"))
                            .spawn_scoped(scope, work)
                            .ok()
                    })
                    .collect();
                let (mut all, at) = work();
                let mut evaluated = at.max(queued);
                for h in helpers {
                    match h.join() {
                        Ok((done, at)) => {
                            all.extend(done);
                            evaluated = evaluated.max(at);
                        }
                        Err(panic) => std::panic::resume_unwind(panic),
                    }
                }
                let beside = match chain {
                    Some(h) => match h.join() {
                        Ok((beside, (done, at))) => {
                            all.extend(done);
                            evaluated = evaluated.max(at);
                            beside
                        }
                        Err(panic) => std::panic::resume_unwind(panic),
                    },
                    None => run(),
                };
                (queue.results(all, &direct), beside, evaluated)
            })
        }
    } else {
        let mus = spectral_radii(cell, states, &cell_states, &direct, threads, budget);
        (mus, None, start.elapsed().as_secs_f64())
    };
    // In segment order: the known prefix, then the direct values (which stop
    // after their first error, as a sequential evaluation would).
    let mus: Vec<Result<f64, MillPlanError>> = known
        .into_iter()
        .take(k)
        .map(Ok)
        .chain(direct_mus)
        .collect();
    let (plan, provenance) = assemble(
        cell,
        weights,
        states,
        planner,
        &cell_states,
        first_error,
        &cached,
        mus,
        None,
    )?;
    Ok((plan, provenance, beside, evaluated))
}

/// Direct |μ|max evaluated on a helper thread while a planner produces its
/// states one by one (the ddpg/fixed_g rollout: the states arrive about
/// every 0.1 ms, an evaluation takes about 0.5 ms, so the core the rollout
/// leaves idle evaluates the first segments before step 5 starts).
///
/// States are [`Prefetch::send`] in segment order; segment 0 starts a new
/// chain (a rollout run again). Each state's cell state is computed as in
/// step 1 of [`evaluate_impl`] (IK nearest the previous state's joints), so
/// a value is step 5's own for the same prefix of states;
/// [`Prefetch::finish`] keeps the values of the longest prefix of the final
/// states that the helper saw bit for bit. A state that fails its checks,
/// its cell state or its indicator ends the chain (step 5 evaluates it and
/// reports its error itself). Dropping a `Prefetch` stops the helper after
/// its current evaluation.
#[derive(Debug)]
pub(crate) struct Prefetch {
    sender: Option<std::sync::mpsc::Sender<PhysicalState>>,
    stop: std::sync::Arc<AtomicBool>,
    helper: Option<std::thread::JoinHandle<Vec<(PhysicalState, f64)>>>,
}

impl Prefetch {
    /// Starts the helper thread for `cell` (`None` when no thread can be
    /// started: step 5 then evaluates everything).
    pub(crate) fn start(cell: std::sync::Arc<MillCell>) -> Option<Self> {
        let (sender, receiver) = std::sync::mpsc::channel::<PhysicalState>();
        let stop = std::sync::Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        let helper = std::thread::Builder::new()
            .name("plan-prefetch".to_string())
            .spawn(move || {
                let mut chain: Vec<(PhysicalState, f64)> = Vec::new();
                let mut reference: Option<[f64; 6]> = None;
                while let Ok(state) = receiver.recv() {
                    if flag.load(Ordering::Acquire) {
                        break;
                    }
                    if state.segment == 0 {
                        chain.clear();
                        reference = None;
                    }
                    if state.segment != chain.len() {
                        // The chain ended at an earlier state; wait for a new one.
                        continue;
                    }
                    let value = check_state(&cell, state.segment, &state, "prefetch")
                        .and_then(|()| {
                            Ok(cell.evaluate(state.segment, state.g, reference.as_ref())?)
                        })
                        .and_then(|cs| Ok((spectral_radius(&cell, &state, &cs)?, cs.joints)));
                    if let Ok((mu, joints)) = value {
                        reference = Some(joints);
                        chain.push((state, mu));
                    }
                }
                chain
            })
            .ok()?;
        Some(Self {
            sender: Some(sender),
            stop,
            helper: Some(helper),
        })
    }

    /// Hands the helper the next state.
    pub(crate) fn send(&self, state: &PhysicalState) {
        if let Some(s) = &self.sender {
            // A helper that has stopped leaves the state to step 5.
            let _ = s.send(*state);
        }
    }

    /// No more states: the helper finishes those it has (until
    /// [`Prefetch::finish`]).
    pub(crate) fn close(&mut self) {
        self.sender = None;
    }

    /// Stops the helper after its current evaluation and returns |μ|max of
    /// the longest prefix of `states` it evaluated from the same states,
    /// bit for bit.
    pub(crate) fn finish(mut self, states: &[PhysicalState]) -> Vec<f64> {
        self.stop.store(true, Ordering::Release);
        self.sender = None;
        let chain = match self.helper.take().map(|h| h.join()) {
            Some(Ok(chain)) => chain,
            Some(Err(panic)) => std::panic::resume_unwind(panic),
            None => Vec::new(),
        };
        let same = |a: &PhysicalState, b: &PhysicalState| {
            a.segment == b.segment
                && a.rpm.to_bits() == b.rpm.to_bits()
                && a.feed.to_bits() == b.feed.to_bits()
                && a.g.to_bits() == b.g.to_bits()
        };
        chain
            .into_iter()
            .zip(states)
            .take_while(|((seen, _), state)| same(seen, state))
            .map(|((_, mu), _)| mu)
            .collect()
    }
}

impl Drop for Prefetch {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
        self.sender = None;
    }
}

/// Step 1 of [`evaluate_impl`]: the checks and cell states, in order, up
/// to the first error (returned beside them: a |μ| error at an earlier
/// segment precedes it, step 3).
///
/// # Errors
/// An interrupt of `budget` (checked per segment).
fn cell_states_in_order(
    cell: &MillCell,
    states: &[PhysicalState],
    planner: &str,
    budget: &Budget,
) -> Result<(Vec<CellState>, Option<MillPlanError>), MillPlanError> {
    let mut cell_states: Vec<CellState> = Vec::with_capacity(states.len());
    let mut first_error: Option<MillPlanError> = None;
    let mut reference: Option<[f64; 6]> = None;
    for (i, s) in states.iter().enumerate() {
        budget.check("the plan's cell states")?;
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
    Ok((cell_states, first_error))
}

/// Step 3 of [`evaluate_impl`]: the plan from the cell states, the cached
/// values (`cached`, one per cell state) and the direct |μ|max of the
/// others (`direct_mus`, in segment order, stopping after an error); in
/// segment order, so that a |μ| error at segment j precedes a step-1 error
/// (`first_error`) at a later segment (sequential order).
#[allow(clippy::too_many_arguments)]
fn assemble(
    cell: &MillCell,
    weights: &RewardWeights,
    states: &[PhysicalState],
    planner: &str,
    cell_states: &[CellState],
    first_error: Option<MillPlanError>,
    cached: &[Option<(f64, f64)>],
    direct_mus: Vec<Result<f64, MillPlanError>>,
    cache: Option<&IndicatorCache>,
) -> Result<(Plan, IndicatorProvenance), MillPlanError> {
    let n = cell.path().segments().len();
    let lim = cell.state_limits();
    let k = cell_states.len();
    let mut direct_mus = direct_mus.into_iter();
    let mut mus: Vec<Result<f64, MillPlanError>> = Vec::with_capacity(k);
    for value in cached {
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
pub(crate) fn cached_values(
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
/// stops there first). `budget` is checked before each evaluation: an
/// interrupt is that segment's error.
pub(crate) fn spectral_radii(
    cell: &MillCell,
    states: &[PhysicalState],
    cell_states: &[CellState],
    indices: &[usize],
    threads: usize,
    budget: &Budget,
) -> Vec<Result<f64, MillPlanError>> {
    let n = indices.len();
    let eval = |j: usize| {
        budget.check("the chatter indicator")?;
        spectral_radius(cell, &states[indices[j]], &cell_states[indices[j]])
    };
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
    let queue = Queue::new(&eval, n);
    let all = std::thread::scope(|scope| {
        let helpers: Vec<_> = (1..workers)
            .filter_map(|k| {
                std::thread::Builder::new()
                    .name(format!("plan-eval-{k}"))
                    .spawn_scoped(scope, || queue.work())
                    .ok()
            })
            .collect();
        let mut all = queue.work();
        for h in helpers {
            match h.join() {
                Ok(done) => all.extend(done),
                Err(panic) => std::panic::resume_unwind(panic),
            }
        }
        all
    });
    queue.results(all, indices)
}

/// The shared work of [`spectral_radii`]'s workers: indices 0..n handed out
/// in increasing order from a counter; after the first error no new one
/// starts, so every index below the lowest failing one is evaluated.
struct Queue<'a> {
    eval: &'a (dyn Fn(usize) -> Result<f64, MillPlanError> + Sync),
    n: usize,
    next: AtomicUsize,
    failed: AtomicBool,
}

impl<'a> Queue<'a> {
    fn new(eval: &'a (dyn Fn(usize) -> Result<f64, MillPlanError> + Sync), n: usize) -> Self {
        Self {
            eval,
            n,
            next: AtomicUsize::new(0),
            failed: AtomicBool::new(false),
        }
    }

    /// One worker: evaluates indices until none is left (or one failed).
    fn work(&self) -> Vec<(usize, Result<f64, MillPlanError>)> {
        let mut done = Vec::new();
        while !self.failed.load(Ordering::Acquire) {
            let j = self.next.fetch_add(1, Ordering::AcqRel);
            if j >= self.n {
                break;
            }
            let r = (self.eval)(j);
            if r.is_err() {
                self.failed.store(true, Ordering::Release);
            }
            done.push((j, r));
        }
        done
    }

    /// Every worker's results in index order, stopping after the first
    /// error (`indices`: the segments, for the message of a missing one).
    fn results(
        &self,
        all: Vec<(usize, Result<f64, MillPlanError>)>,
        indices: &[usize],
    ) -> Vec<Result<f64, MillPlanError>> {
        let mut slots: Vec<Option<Result<f64, MillPlanError>>> =
            (0..self.n).map(|_| None).collect();
        for (j, r) in all {
            slots[j] = Some(r);
        }
        let mut out = Vec::with_capacity(self.n);
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
