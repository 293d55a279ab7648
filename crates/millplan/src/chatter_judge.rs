//! Chatter judged on what the robot runs (issue 28, item 1): |μ|max at every control-period
//! sample of the executed trajectory while the tool is in the material, at the executed feed,
//! spindle speed and redundancy angle of that sample.
//!
//! # Why the segments' values are not enough
//! A plan's |μ|max is evaluated per segment at the segment's planned (or executed mean)
//! feed. The robot runs something else: Ω, f and g move smoothly between the segment
//! midpoints ([`crate::timing::ExecutedProfiles`]), the feed falls wherever the joints slow
//! the trajectory, and a start from rest in the material passes every feed from 0. On the
//! default cell |μ| rises as the feed falls (seed 004 Fig. 4/7), so a plan whose segments are
//! all stable can chatter between them or in its ramps.
//!
//! # The samples
//! At every control period t_k = k·T of the trajectory, the tool's state on the time law
//! ([`crate::timing::TimeScaling::path_state`]: arc length s and ṡ = f(s)R(t)/c(s), the law the
//! trajectory's samples were built from; the executed tool tip follows it within the measured
//! path deviation): the sample is in the material when 0 ≤ s ≤ L (the run-in and run-out of
//! [`crate::timing::Entry::RunIn`] are in the air and are not judged). Its state is the
//! segment containing s, Ω(s), the feed ṡ and g(s), and its tool-tip dynamics the segment's
//! cell state at g(s) (IK nearest the previous segment's planned joints, as
//! [`crate::Plan::evaluate`]). A sample at rest (ṡ = 0) cuts nothing and is not judged.
//!
//! # Which samples are evaluated
//! Per segment, consecutive samples with bit-identical states are one state (a cruise at
//! constant Ω, f, g is one evaluation). Over the remaining states of a segment, in order:
//! the first and last are evaluated; a run between two evaluated states is accepted when both
//! are below 1 − [`JUDGE_MARGIN`] and differ by at most [`JUDGE_SPREAD`] (its states are
//! then taken to be below the larger value plus the difference, which is below 1), else it is
//! split at its middle state, down to every state. So every sample near the stability
//! boundary, or where |μ| moves, is evaluated directly; the count is
//! [`ChatterVerdict::evaluations`].
//!
//! # Values already known
//! A state bit-identical to its segment's state in the plan (Ω, f, g; the same cell state,
//! IK nearest the previous segment's joints) takes the plan's |μ|max of that segment when it
//! was evaluated directly ([`Known`]): the same function of the same inputs. A cruise between
//! equal neighbours is such a state.
//!
//! # Undefined samples
//! Where the chatter model has no solution at a sample's feed below the cell's lowest feed
//! (the power-law force's equilibrium as f → 0), the sample counts as chattering
//! ([`JudgedSample::spectral_radius`] = ∞), as an undefined cell of a feed map counts as not
//! stable ([`kerf_chatter::feed_lower_bound`]). A model failure at a feed inside the cell's
//! range is an error.

use kerf_budget::Budget;
use kerf_chatter::chatter_indicator;
use kerf_mill::{CellState, MillCell};

use crate::error::MillPlanError;
use crate::parallel::map_ordered;
use crate::timing::TimeScaling;

/// A run between two evaluated states below 1 − `JUDGE_MARGIN` … (module documentation).
pub const JUDGE_MARGIN: f64 = 0.01;

/// … that differ by at most `JUDGE_SPREAD` is accepted (module documentation).
pub const JUDGE_SPREAD: f64 = 0.01;

/// What the judge knows of one segment of the plan: its joints (the next segment's IK
/// reference) and, when it was evaluated directly, its state and |μ|max.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Known {
    /// The segment's joints \[rad\].
    pub joints: [f64; 6],
    /// (Ω \[rpm\], f \[m/s\], g \[rad\], |μ|max) of the segment, evaluated directly; `None`
    /// when its value is not a direct evaluation (the indicator cache's).
    pub direct: Option<[f64; 4]>,
}

/// One judged sample of the executed trajectory.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JudgedSample {
    /// Time from the trajectory's start \[s\].
    pub time: f64,
    /// Arc length along the path \[m\].
    pub arc_length: f64,
    /// The path segment.
    pub segment: usize,
    /// Spindle speed \[rpm\].
    pub rpm: f64,
    /// Feed \[m/s\].
    pub feed: f64,
    /// Redundancy angle \[rad\].
    pub g: f64,
    /// |μ|max (∞: the model has no solution at this feed).
    pub spectral_radius: f64,
}

/// The verdict on an executed trajectory (module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct ChatterVerdict {
    /// No sample in the material reaches |μ|max ≥ 1.
    pub chatter_free: bool,
    /// The largest |μ|max over the evaluated samples.
    pub max_spectral_radius: f64,
    /// The sample of the largest |μ|max.
    pub worst: Option<JudgedSample>,
    /// The first sample in time with |μ|max ≥ 1.
    pub first_chatter: Option<JudgedSample>,
    /// Per segment, the largest evaluated |μ|max of its samples (0 without samples).
    pub segment_max: Vec<f64>,
    /// Segments with a sample at |μ|max ≥ 1, ascending.
    pub chattering_segments: Vec<usize>,
    /// The lowest feed of a sample in the material, and that sample.
    pub lowest_feed: Option<JudgedSample>,
    /// Samples in the material (every control period from entry to exit).
    pub samples: usize,
    /// Direct evaluations of the chatter indicator.
    pub evaluations: usize,
    /// States whose |μ|max was the plan's own value of the segment ([`Known`]).
    pub reused: usize,
    /// Wall time of the judge \[s\] (its evaluations run on the planner's threads).
    pub seconds: f64,
}

/// A sample's state before its |μ|max is known.
#[derive(Debug, Clone, Copy)]
struct State {
    time: f64,
    s: f64,
    segment: usize,
    rpm: f64,
    feed: f64,
    g: f64,
}

impl State {
    fn same(&self, other: &State) -> bool {
        self.segment == other.segment
            && self.rpm.to_bits() == other.rpm.to_bits()
            && self.feed.to_bits() == other.feed.to_bits()
            && self.g.to_bits() == other.g.to_bits()
    }

    fn judged(&self, spectral_radius: f64) -> JudgedSample {
        JudgedSample {
            time: self.time,
            arc_length: self.s,
            segment: self.segment,
            rpm: self.rpm,
            feed: self.feed,
            g: self.g,
            spectral_radius,
        }
    }
}

/// Judges the executed trajectory `scaling` of a plan with `joints` per segment (module
/// documentation).
///
/// # Arguments
/// * `cell` — the request's cell (path, dynamics, process, limits).
/// * `scaling` — the executed trajectory ([`crate::timing::time_scale`]).
/// * `known` — per segment of the plan: its joints (the IK references) and its directly
///   evaluated state and |μ|max ([`Known`]).
/// * `period` — the executor's control period \[s\], > 0.
/// * `threads` — evaluation threads, ≥ 1.
/// * `budget` — checked before each evaluation.
///
/// # Returns
/// The verdict.
///
/// # Errors
/// [`MillPlanError::InvalidParameter`] for a bad period; cell-model errors; chatter-model
/// errors at a feed inside the cell's range; [`MillPlanError::Interrupted`].
///
/// # Performance
/// One IK and one indicator per evaluated state (0.4–0.7 ms), on `threads` threads; none for
/// a state whose value is known.
pub fn judge(
    cell: &MillCell,
    scaling: &TimeScaling,
    known: &[Known],
    period: f64,
    threads: usize,
    budget: &Budget,
) -> Result<ChatterVerdict, MillPlanError> {
    if !(period.is_finite() && period > 0.0) {
        return Err(MillPlanError::InvalidParameter {
            name: "control period [s]".into(),
            value: period,
            reason: "must be finite and > 0".into(),
        });
    }
    let started = std::time::Instant::now();
    let path = cell.path();
    let length = path.total_length();
    let n = known.len();
    let mut boundaries = Vec::with_capacity(n + 1);
    let mut start = 0.0;
    boundaries.push(start);
    for i in 0..n {
        start += path.segment(i)?.length;
        boundaries.push(start);
    }
    let [g_lo, g_hi] = cell.state_limits().redundancy_angle;
    let duration = scaling.duration();
    let steps = (duration / period).ceil() as usize;
    // The in-material samples, per segment, consecutive identical states merged.
    let mut per_segment: Vec<Vec<State>> = vec![Vec::new(); n];
    let mut samples = 0;
    let mut lowest: Option<State> = None;
    for k in 0..=steps {
        let t = (k as f64 * period).min(duration);
        let p = scaling.path_state(t);
        if !(p.s >= 0.0 && p.s <= length) || p.speed <= 0.0 {
            continue;
        }
        samples += 1;
        let segment = boundaries[1..].partition_point(|b| *b <= p.s).min(n - 1);
        let state = State {
            time: t,
            s: p.s,
            segment,
            rpm: scaling.profiles.rpm.eval(p.s).value,
            feed: p.speed,
            g: scaling.profiles.g.eval(p.s).value.clamp(g_lo, g_hi),
        };
        if lowest.is_none_or(|l| state.feed < l.feed) {
            lowest = Some(state);
        }
        let list = &mut per_segment[segment];
        if !list.last().is_some_and(|last| last.same(&state)) {
            list.push(state);
        }
    }
    // Bisection over each segment's states (module documentation).
    let mut values: Vec<Vec<Option<f64>>> =
        per_segment.iter().map(|l| vec![None; l.len()]).collect();
    let mut intervals: Vec<(usize, usize, usize)> = per_segment
        .iter()
        .enumerate()
        .filter(|(_, l)| !l.is_empty())
        .map(|(i, l)| (i, 0, l.len() - 1))
        .collect();
    let min_feed = cell.state_limits().feed[0];
    let mut evaluations = 0;
    let mut reused = 0;
    while !intervals.is_empty() {
        let mut wanted: Vec<(usize, usize)> = Vec::new();
        for &(i, a, b) in &intervals {
            for j in [a, b] {
                if values[i][j].is_none() && !wanted.contains(&(i, j)) {
                    wanted.push((i, j));
                }
            }
        }
        let results = map_ordered(wanted.len(), threads, "chatter-judge", |w| {
            let (i, j) = wanted[w];
            evaluate(cell, known, &per_segment[i][j], min_feed, budget)
        });
        for ((i, j), r) in wanted.iter().zip(results) {
            let (value, direct) = r?;
            if direct {
                evaluations += 1;
            } else {
                reused += 1;
            }
            values[*i][*j] = Some(value);
        }
        let mut next = Vec::new();
        for (i, a, b) in intervals {
            if b <= a + 1 {
                continue;
            }
            let (va, vb) = (
                values[i][a].unwrap_or(f64::INFINITY),
                values[i][b].unwrap_or(f64::INFINITY),
            );
            let settled = va < 1.0 - JUDGE_MARGIN
                && vb < 1.0 - JUDGE_MARGIN
                && (va - vb).abs() <= JUDGE_SPREAD;
            if !settled {
                let m = (a + b) / 2;
                next.push((i, a, m));
                next.push((i, m, b));
            }
        }
        intervals = next;
    }
    let mut verdict = ChatterVerdict {
        chatter_free: true,
        max_spectral_radius: 0.0,
        worst: None,
        first_chatter: None,
        segment_max: vec![0.0; n],
        chattering_segments: Vec::new(),
        lowest_feed: None,
        samples,
        evaluations,
        reused,
        seconds: 0.0,
    };
    for (i, list) in per_segment.iter().enumerate() {
        for (state, value) in list.iter().zip(&values[i]) {
            let Some(mu) = *value else { continue };
            let judged = state.judged(mu);
            verdict.segment_max[i] = verdict.segment_max[i].max(mu);
            if verdict.worst.is_none() || mu > verdict.max_spectral_radius {
                verdict.max_spectral_radius = mu;
                verdict.worst = Some(judged);
            }
            if mu >= 1.0 {
                verdict.chatter_free = false;
                if verdict.chattering_segments.last() != Some(&i) {
                    verdict.chattering_segments.push(i);
                }
                if verdict.first_chatter.is_none_or(|f| judged.time < f.time) {
                    verdict.first_chatter = Some(judged);
                }
            }
        }
    }
    verdict.lowest_feed = lowest.map(|l| {
        let mu = per_segment[l.segment]
            .iter()
            .zip(&values[l.segment])
            .find(|(s, _)| s.same(&l))
            .and_then(|(_, v)| *v)
            .unwrap_or(f64::NAN);
        l.judged(mu)
    });
    verdict.seconds = started.elapsed().as_secs_f64();
    Ok(verdict)
}

/// |μ|max of one state and whether it was evaluated: the plan's value of the segment when
/// the state is the segment's own ([`Known`]), else the segment's cell state at the state's g
/// (IK nearest the previous segment's planned joints) and the indicator at its Ω and feed; ∞
/// where the model has no solution at a feed below `min_feed`.
fn evaluate(
    cell: &MillCell,
    known: &[Known],
    state: &State,
    min_feed: f64,
    budget: &Budget,
) -> Result<(f64, bool), MillPlanError> {
    if let Some([rpm, feed, g, mu]) = known[state.segment].direct {
        if [rpm, feed, g].map(f64::to_bits) == [state.rpm, state.feed, state.g].map(f64::to_bits) {
            return Ok((mu, false));
        }
    }
    budget.check("the chatter judge of the executed trajectory")?;
    let reference = state.segment.checked_sub(1).map(|p| known[p].joints);
    let cell_state: CellState = cell.evaluate(state.segment, state.g, reference.as_ref())?;
    match chatter_indicator(
        &cell_state.modal,
        &cell.milling_process(),
        state.rpm,
        state.feed,
        cell.indicator_settings(),
    ) {
        Ok(i) => Ok((i.spectral_radius, true)),
        Err(_) if state.feed < min_feed => Ok((f64::INFINITY, true)),
        Err(e) => Err(e.into()),
    }
}
