//! The measures of seed 002 Tables 4–6 over test processes.
//!
//! # The raw agent, paper-style ([`closed_loop`])
//! The paper measures the raw agent in closed loop and reports mean errors
//! in the thousands of µm for agents that fail (Table 6, medium density,
//! γ = 0.999): a missed point is measured, not an abort. kerf's closed loop:
//! * the agent steers from rest at the start; an action that would leave
//!   the velocity / acceleration limits ([`Lattice::allows`] false) is
//!   replaced by the nearest allowed one (a *limit substitution*, counted);
//! * for each point the closest sample is kept, whether or not it lies
//!   within the precision (the motion never goes backward, so that is the
//!   last sample before the point or the first after it);
//! * the run ends at rest inside the last point's window, at rest beyond
//!   the last window, or at the step cap 5 × RPRO's steps + 300 (counted as
//!   *capped*).
//!
//! Two completions are read off one run:
//! * **paper-style** ([`ClosedLoop::paper_steps`]): the process is complete
//!   when every point's closest sample lies within the precision, and its
//!   steps are the index of the sample that passed the last point (its
//!   closest sample, the earliest of equals). No rest is required.
//! * **at rest** ([`ClosedLoop::completed`]): as paper-style, and the run
//!   ended at rest inside the last window; its steps are the run's periods.
//!
//! Why both. The paper counts a process's steps until the agent "completed
//! the task" (section 3: RPRO 86 steps, the agent 69, each with a mean
//! accuracy) and reports accuracies of points reached; it never says the
//! agent must come to rest, and Table 6's medians below RPRO's fit an agent
//! counted at its last point. A deployment does need the axis at rest on
//! the last point — and gets it from RPRO's shield ([`Shielded`]), not from
//! the raw agent. So the paper-style column is the one beside Tables 4–6,
//! and the at-rest column says whether the raw agent also stops. RPRO's
//! steps for the paper-style correlation are counted the same way
//! ([`Outcome::paper_steps`]: the sample of its pass of the last point),
//! like for like.
//!
//! # The measures ([`evaluate`])
//! * **Steps correlation** (Tables 4 and 5 of the seed; "Steps Count
//!   Correlation"): Pearson's r between RPRO's and the agent's steps over
//!   the processes the raw agent completed — paper-style (both counted to
//!   the last point) and at rest (both counted to the stop).
//! * **Mean error** (Tables 5 and 6, "Mean Error", µm): the median over
//!   all processes (completed or not, as the paper's failed agents show) of
//!   a run's mean distance of the closest samples to their points.
//! * **Share of points passed** within the precision, over all points.
//! * **Steps** (Table 6, "Steps Count"): the median number of steps of the
//!   completed runs, for each completion.
//!
//! RPRO's own numbers (the seed: median 110 steps for dense points, 500
//! for medium) come from [`baseline`]. The shielded agent ([`Shielded`]) is
//! measured too when asked: what a deployment would run.

use crate::{
    course::Course,
    error::StepError,
    lattice::{Action, Lattice, State},
    rpro::{Rpro, RproSettings},
    run::{run, Controller, Decision, Run},
};

use super::{
    agent::{Agent, Shielded},
    env::Recording,
};

/// Steps and mean error of one finished run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outcome {
    /// Periods (to the stop on the last point).
    pub steps: usize,
    /// Paper-style steps: the sample index of the pass of the last point
    /// (module documentation); [`Outcome::steps`] for a run without passes.
    pub paper_steps: usize,
    /// Mean pass error [m].
    pub mean_error: f64,
}

impl From<&Run> for Outcome {
    fn from(r: &Run) -> Self {
        Self {
            steps: r.steps(),
            paper_steps: r.passes.last().map_or(r.steps(), |p| p.step),
            mean_error: r.mean_error(),
        }
    }
}

/// RPRO on every course, one result per course. RPRO's module promises
/// that every run finishes; on some database processes kerf's RPRO reports
/// [`StepError::NoViableAction`] (a defect of its look-ahead, measured by
/// `benches/imitation.rs`), so each result is kept and [`evaluate`] leaves
/// the failed processes out.
pub fn baseline(
    courses: &[Course],
    settings: RproSettings,
    max_steps: usize,
) -> Vec<Result<Outcome, StepError>> {
    courses
        .iter()
        .map(|c| {
            let mut rpro = Rpro::new(c, settings)?;
            run(c, &mut rpro, max_steps).map(|r| Outcome::from(&r))
        })
        .collect()
}

/// Median of the values (mean of the middle two for an even count);
/// `None` when empty.
pub fn median(values: &[f64]) -> Option<f64> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| !x.is_nan()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

/// Pearson's correlation coefficient of paired samples; `None` for fewer
/// than two pairs or a constant sample.
pub fn pearson(x: &[f64], y: &[f64]) -> Option<f64> {
    let n = x.len().min(y.len());
    if n < 2 {
        return None;
    }
    let mx = x[..n].iter().sum::<f64>() / n as f64;
    let my = y[..n].iter().sum::<f64>() / n as f64;
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in x[..n].iter().zip(&y[..n]) {
        sxy += (a - mx) * (b - my);
        sxx += (a - mx) * (a - mx);
        syy += (b - my) * (b - my);
    }
    if sxx <= 0.0 || syy <= 0.0 {
        return None;
    }
    Some(sxy / (sxx * syy).sqrt())
}

/// The record of one closed-loop run ([`closed_loop`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ClosedLoop {
    /// Periods.
    pub steps: usize,
    /// Paper-style completion (module documentation): the sample index of
    /// the last point's closest sample when every point's closest sample
    /// lies within the precision, `None` otherwise.
    pub paper_steps: Option<usize>,
    /// At rest inside the last window with every point passed within the
    /// precision.
    pub completed: bool,
    /// Ended by the step cap.
    pub capped: bool,
    /// Actions replaced because they left the limits.
    pub substitutions: usize,
    /// Per target: distance [m or rad] of the closest sample to the point.
    pub errors: Vec<f64>,
    /// Per target: whether that sample lies within the precision.
    pub within: Vec<bool>,
    /// Per target: the index of that sample (0 = the start).
    pub samples: Vec<usize>,
}

impl ClosedLoop {
    /// Mean over the targets of [`ClosedLoop::errors`].
    pub fn mean_error(&self) -> f64 {
        if self.errors.is_empty() {
            return 0.0;
        }
        self.errors.iter().sum::<f64>() / self.errors.len() as f64
    }

    /// Targets passed within the precision.
    pub fn passed(&self) -> usize {
        self.within.iter().filter(|w| **w).count()
    }
}

/// The allowed action nearest to `wanted` at `s` (module documentation):
/// `wanted` itself when allowed, else keep, else the other; between
/// accelerate and decelerate (from keep) the one that brings the
/// acceleration toward 0 first.
fn nearest_allowed(lat: &Lattice, s: State, wanted: Action) -> Option<Action> {
    let toward = if s.m > 0 {
        Action::Decelerate
    } else {
        Action::Accelerate
    };
    let order = match wanted {
        Action::Accelerate => [Action::Accelerate, Action::Keep, Action::Decelerate],
        Action::Decelerate => [Action::Decelerate, Action::Keep, Action::Accelerate],
        Action::Keep => [
            Action::Keep,
            toward,
            if toward == Action::Accelerate {
                Action::Decelerate
            } else {
                Action::Accelerate
            },
        ],
    };
    order.into_iter().find(|a| lat.allows(s, a.sign()))
}

/// Runs `controller` in closed loop on `course` from rest (module
/// documentation): limit substitutions instead of aborts, the closest
/// sample of every point, at most `max_steps` periods.
///
/// # Errors
/// The controller's own errors; [`StepError::Violation`] when no action is
/// allowed (not reachable from rest on a valid lattice).
///
/// # Performance
/// One decision per period plus O(1) amortized bookkeeping.
pub fn closed_loop(
    controller: &mut dyn Controller,
    course: &Course,
    max_steps: usize,
) -> Result<ClosedLoop, StepError> {
    let lat = &course.lattice;
    let n = course.targets();
    let last = n - 1;
    let mut state = State::REST;
    // Per target: the closest sample so far, (position, sample index); the
    // earliest of equally close samples.
    let mut best_q: Vec<Option<(i64, usize)>> = vec![None; n];
    let closer = |best: &mut Option<(i64, usize)>, i: usize, q: i64, k: usize| {
        let better = best
            .is_none_or(|(b, _)| course.distance_to(i, q).abs() < course.distance_to(i, b).abs());
        if better {
            *best = Some((q, k));
        }
    };
    // The first sample at the current position (the motion never goes
    // backward, so that is the earliest sample as close to a point ahead).
    let mut since = 0usize;
    // The first point still ahead (distance > 0) of the current sample.
    let mut ahead = 0usize;
    let (mut target, mut seen) = (0usize, false);
    let (mut steps, mut substitutions) = (0usize, 0usize);
    let (completed_rest, capped) = loop {
        while target < last && state.q > course.windows[target].1 {
            target += 1;
            seen = false;
        }
        if course.in_window(target, state.q) {
            seen = true;
        }
        if state.at_rest() && target == last {
            if course.in_window(last, state.q) {
                break (true, false);
            }
            if state.q > course.windows[last].1 {
                break (false, false);
            }
        }
        if steps >= max_steps {
            break (false, true);
        }
        let decision = Decision {
            step: steps,
            state,
            target,
            seen,
        };
        let wanted = controller.decide(course, &decision)?;
        let action = nearest_allowed(lat, state, wanted).ok_or_else(|| StepError::Violation {
            step: steps,
            reason: "no action within the limits".to_string(),
        })?;
        substitutions += usize::from(action != wanted);
        let next = state.step(action.sign());
        while ahead < n && course.distance_to(ahead, next.q) <= 0.0 {
            closer(&mut best_q[ahead], ahead, state.q, since);
            closer(&mut best_q[ahead], ahead, next.q, steps + 1);
            ahead += 1;
        }
        if next.q != state.q {
            since = steps + 1;
        }
        state = next;
        steps += 1;
    };
    for (i, b) in best_q.iter_mut().enumerate().skip(ahead) {
        closer(b, i, state.q, since);
    }
    let of = |i: usize| best_q[i].unwrap_or((state.q, since));
    let errors: Vec<f64> = (0..n)
        .map(|i| course.distance_to(i, of(i).0).abs())
        .collect();
    let within: Vec<bool> = (0..n).map(|i| course.in_window(i, of(i).0)).collect();
    let samples: Vec<usize> = (0..n).map(|i| of(i).1).collect();
    let all_within = within.iter().all(|w| *w);
    Ok(ClosedLoop {
        steps,
        paper_steps: all_within.then(|| samples[last]),
        completed: completed_rest && all_within,
        capped,
        substitutions,
        errors,
        within,
        samples,
    })
}

/// The step cap of a closed-loop run on a process RPRO finished in
/// `rpro_steps` periods: 5 × `rpro_steps` + 300.
pub fn step_cap(rpro_steps: usize) -> usize {
    5 * rpro_steps + 300
}

/// The Tables 4–6 measures of one agent on a test set.
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluation {
    /// Test processes.
    pub processes: usize,
    /// Processes RPRO finished ([`baseline`]); the others are left out of
    /// every measure.
    pub rpro_completed: usize,
    /// Processes the raw agent completed paper-style in closed loop
    /// ([`ClosedLoop::paper_steps`]: every point passed within the
    /// precision, counted to the last point).
    pub paper_completed: usize,
    /// Pearson r of RPRO's and the raw agent's paper-style steps (both to
    /// the pass of the last point) over the paper-style completed processes.
    pub paper_correlation: Option<f64>,
    /// Median over paper-style completed processes of the raw agent's
    /// paper-style steps.
    pub paper_median_steps: Option<f64>,
    /// RPRO's median paper-style steps over the same processes.
    pub rpro_paper_median_steps_completed: Option<f64>,
    /// Median over the paper-style completed processes of the raw agent's
    /// mean error [µm].
    pub paper_median_error_um: Option<f64>,
    /// Processes the raw agent completed at rest in closed loop
    /// ([`ClosedLoop::completed`]).
    pub completed: usize,
    /// Raw runs ended by the step cap ([`step_cap`]).
    pub capped: usize,
    /// Pearson r of RPRO's and the raw agent's steps (both to the stop)
    /// over the processes completed at rest.
    pub correlation: Option<f64>,
    /// Median over all processes of the raw agent's mean error [µm]
    /// ([`ClosedLoop::mean_error`]).
    pub median_error_um: Option<f64>,
    /// Points passed within the precision over all points of all runs.
    pub passed_share: f64,
    /// Median over processes completed at rest of the raw agent's steps.
    pub median_steps: Option<f64>,
    /// Limit substitutions over all raw decisions.
    pub substitutions: usize,
    /// Raw decisions (periods) over all runs.
    pub decisions: usize,
    /// Raw runs with at least one limit substitution.
    pub substituted_runs: usize,
    /// RPRO's median mean error [µm] over the processes it finished.
    pub rpro_median_error_um: Option<f64>,
    /// RPRO's median steps over the processes it finished.
    pub rpro_median_steps: Option<f64>,
    /// RPRO's median paper-style steps (to its pass of the last point) over
    /// the processes it finished.
    pub rpro_paper_median_steps: Option<f64>,
    /// RPRO's median steps over the processes the agent completed at rest.
    pub rpro_median_steps_completed: Option<f64>,
    /// The shielded agent, when asked for.
    pub shielded: Option<ShieldedEvaluation>,
}

/// The shielded agent on a test set ([`Shielded`]: RPRO's viability check
/// and the progress rule), run by [`run`] with the cap [`step_cap`].
#[derive(Debug, Clone, PartialEq)]
pub struct ShieldedEvaluation {
    /// Processes the shielded agent finished.
    pub completed: usize,
    /// Runs ended by the step cap.
    pub capped: usize,
    /// Pearson r of RPRO's and the shielded agent's steps (completed
    /// processes).
    pub correlation: Option<f64>,
    /// Median mean error [µm].
    pub median_error_um: Option<f64>,
    /// Median steps.
    pub median_steps: Option<f64>,
    /// Overridden decisions over all decisions.
    pub override_fraction: f64,
}

/// Runs `agent` in closed loop ([`closed_loop`]; and behind the shield,
/// [`run`], when `shielded`) on every course RPRO finished, and compares
/// with RPRO's `baseline` (same order). Each run's step cap is
/// [`step_cap`] of RPRO's steps on it.
///
/// # Errors
/// [`StepError::InvalidParameter`] when `baseline` and `courses` differ in
/// length; [`StepError::Network`] for a non-finite Q-value;
/// [`Shielded::new`]'s errors.
pub fn evaluate(
    agent: &Agent,
    courses: &[Course],
    baseline: &[Result<Outcome, StepError>],
    shielded: Option<RproSettings>,
) -> Result<Evaluation, StepError> {
    if baseline.len() != courses.len() {
        return Err(StepError::InvalidParameter {
            name: "baseline runs".to_string(),
            value: baseline.len() as f64,
            reason: format!("one per course needed, {} courses", courses.len()),
        });
    }
    let finished: Vec<(&Course, &Outcome)> = courses
        .iter()
        .zip(baseline)
        .filter_map(|(c, b)| b.as_ref().ok().map(|b| (c, b)))
        .collect();
    let (mut rpro_steps, mut agent_steps, mut all_err) = (vec![], vec![], vec![]);
    let (mut capped, mut substitutions, mut decisions, mut substituted_runs) = (0, 0, 0, 0);
    let (mut passed, mut points) = (0usize, 0usize);
    let (mut rpro_paper, mut agent_paper, mut paper_err) = (vec![], vec![], vec![]);
    let mut raw = agent.clone();
    for &(c, b) in &finished {
        let r = closed_loop(&mut raw, c, step_cap(b.steps))?;
        if let Some(k) = r.paper_steps {
            rpro_paper.push(b.paper_steps as f64);
            agent_paper.push(k as f64);
            paper_err.push(r.mean_error() * 1e6);
        }
        all_err.push(r.mean_error() * 1e6);
        passed += r.passed();
        points += r.within.len();
        capped += usize::from(r.capped);
        substitutions += r.substitutions;
        substituted_runs += usize::from(r.substitutions > 0);
        decisions += r.steps;
        if r.completed {
            rpro_steps.push(b.steps as f64);
            agent_steps.push(r.steps as f64);
        }
    }
    let all_rpro_steps: Vec<f64> = finished.iter().map(|(_, b)| b.steps as f64).collect();
    let all_rpro_paper: Vec<f64> = finished.iter().map(|(_, b)| b.paper_steps as f64).collect();
    let all_rpro_err: Vec<f64> = finished.iter().map(|(_, b)| b.mean_error * 1e6).collect();
    let shielded = match shielded {
        None => None,
        Some(settings) => {
            let (mut steps, mut err, mut rpro) = (vec![], vec![], vec![]);
            let (mut overrides, mut decisions, mut capped) = (0usize, 0usize, 0usize);
            for &(c, b) in &finished {
                let mut s = Shielded::new(agent.clone(), c, settings)?;
                match run(c, &mut s, step_cap(b.steps)) {
                    Ok(r) => {
                        rpro.push(b.steps as f64);
                        steps.push(r.steps() as f64);
                        err.push(r.mean_error() * 1e6);
                    }
                    Err(StepError::StepCap { .. }) => capped += 1,
                    Err(_) => {}
                }
                overrides += s.overrides();
                decisions += s.decisions();
            }
            Some(ShieldedEvaluation {
                completed: steps.len(),
                capped,
                correlation: pearson(&rpro, &steps),
                median_error_um: median(&err),
                median_steps: median(&steps),
                override_fraction: overrides as f64 / decisions.max(1) as f64,
            })
        }
    };
    Ok(Evaluation {
        processes: courses.len(),
        rpro_completed: finished.len(),
        paper_completed: agent_paper.len(),
        paper_correlation: pearson(&rpro_paper, &agent_paper),
        paper_median_steps: median(&agent_paper),
        rpro_paper_median_steps_completed: median(&rpro_paper),
        paper_median_error_um: median(&paper_err),
        completed: agent_steps.len(),
        capped,
        correlation: pearson(&rpro_steps, &agent_steps),
        median_error_um: median(&all_err),
        passed_share: passed as f64 / points.max(1) as f64,
        median_steps: median(&agent_steps),
        substitutions,
        decisions,
        substituted_runs,
        rpro_median_error_um: median(&all_rpro_err),
        rpro_median_steps: median(&all_rpro_steps),
        rpro_paper_median_steps: median(&all_rpro_paper),
        rpro_median_steps_completed: median(&rpro_steps),
        shielded,
    })
}

/// Share of a recorded RPRO run's periods where the agent's greedy action
/// equals RPRO's recorded decision (the agreement eq. 4 rewards), on
/// RPRO's own states.
///
/// # Errors
/// [`StepError::Network`] for a non-finite Q-value.
pub fn agreement(agent: &Agent, course: &Course, recording: &Recording) -> Result<f64, StepError> {
    let mut same = 0usize;
    for (d, a) in recording.decisions.iter().zip(&recording.actions) {
        same += usize::from(agent.greedy(course, d)? == *a);
    }
    Ok(same as f64 / recording.steps().max(1) as f64)
}
