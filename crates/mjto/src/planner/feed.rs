//! The time law of one iterate: the paper's constant feed, or the time-optimal variable feed
//! (issue 16, item 1; [`crate::optimal_feed`]), sampled at the controller period Δt and checked
//! against every Table 2 limit on those samples (what the executor runs).

use std::time::Instant;

use super::{Context, Iterate, Samples, LIMIT_TOLERANCE};
use crate::error::{ConstraintFamily, LimitViolation};
use crate::executed::executed_jerk_violations;
use crate::machine::JOINT_NAMES;
use crate::metrics::limit_violations;
use crate::optimal_feed::{steady_feed, FeedLimit, FeedMode, FeedProblem, OptimalFeed};
use crate::plan::{FeedReport, StageTimes};
use crate::rotary::RotaryQp;
use crate::timelaw::{chain_rule, checked_grid_times, TimeLaw, MAX_SAMPLES};
use crate::tip::{tip_rate, tip_speed};
use crate::PlanError;

/// Stations of the time-optimal problem per knot span of the joint splines.
pub const STATIONS_PER_SPAN: usize = 2;

/// Fewest and most stations of the time-optimal problem.
pub const STATION_RANGE: (usize, usize) = (64, 600);

/// Fraction of the joint limits first given to the time-optimal solver. Its constraints hold
/// at its stations; the joint path's derivatives move between them, so the controller samples
/// can exceed a limit slightly. Then the margin shrinks by the worst sample's excess (and
/// [`MARGIN_STEP`] more) and the law is solved again, at most [`MARGIN_ATTEMPTS`] times.
pub const FIRST_MARGIN: f64 = 0.98;

/// Fraction of the process limits (feedrate, path acceleration and jerk) first given to the
/// time-optimal solver; shrunk like the joints' margin when a sample exceeds one.
pub const FIRST_PROCESS_MARGIN: f64 = 0.9999;

/// Extra shrink factor of the process margin after a violation (the process limits are
/// smooth along the path: their excess between stations is small).
pub const PROCESS_MARGIN_STEP: f64 = 0.9995;

/// Extra shrink factor of the margin after a violation.
pub const MARGIN_STEP: f64 = 0.99;

/// Most solves of the time-optimal law per iterate.
pub const MARGIN_ATTEMPTS: usize = 8;

/// The "joint" of a limit violation of the tool tip's speed against the feedrate.
pub const TOOL_TIP: &str = "tool tip";

/// A timed iterate: its samples and the report of its feed.
pub(super) struct Timed {
    pub samples: Samples,
    pub feed: FeedReport,
    /// Whether the samples are new (the time-optimal law), not the constant feed's.
    pub resampled: bool,
}

impl Context<'_> {
    /// The samples of `it` every Δt under the constant feed (seed 001 eq. 13 with the S-curve
    /// ramps of [`crate::timelaw`]).
    ///
    /// # Errors
    /// [`PlanError::Interrupted`].
    pub(super) fn constant_samples(
        &self,
        it: &Iterate,
        times: &mut StageTimes,
    ) -> Result<Samples, PlanError> {
        self.law_samples(it, &self.law, self.sample_times.clone(), times)
    }

    /// The samples of `it` at `sample_times` under the S-curve `law`.
    fn law_samples(
        &self,
        it: &Iterate,
        law: &TimeLaw,
        sample_times: Vec<f64>,
        times: &mut StageTimes,
    ) -> Result<Samples, PlanError> {
        let t = Instant::now();
        let states: Vec<[f64; 4]> = sample_times.iter().map(|&t| law.eval(t)).collect();
        let samples = self.sample(it, sample_times, &states)?;
        times.evaluation += t.elapsed().as_secs_f64();
        Ok(samples)
    }

    /// Times `it` under the request's feed law, given its constant-feed samples
    /// ([`Self::constant_samples`]), and samples it every Δt.
    ///
    /// # Errors
    /// [`PlanError::Infeasible`] (time-optimal law) when no station of the path allows the
    /// requested feedrate at steady state, with the largest feed it allows and the joint that
    /// limits it; [`PlanError::LimitViolation`] when no margin of [`MARGIN_ATTEMPTS` margins] keeps the
    /// samples within the limits; [`PlanError::Solver`] and [`PlanError::Interrupted`].
    pub(super) fn timed(
        &self,
        it: &Iterate,
        samples: Samples,
        times: &mut StageTimes,
    ) -> Result<Timed, PlanError> {
        let constant_time = self.law.duration();
        let mode = self.request.options.feed_law;
        // The feed is the tool tip's speed g ṡ, g = |dC/ds| (crate::tip): where the M-path fit
        // makes g > 1 the S-curve at f would move the tip faster than f. The S-curve at
        // f / max g keeps it (g is 1 to 1e-3 on cases 1 and 2).
        let g_max = samples
            .q
            .iter()
            .zip(&samples.qd)
            .zip(&samples.sd)
            .filter(|(_, &sd)| sd > 1e-9)
            .map(|((q, qd), &sd)| tip_speed(q, qd) / sd)
            .fold(1.0f64, f64::max);
        let resampled = g_max > 1.0 + LIMIT_TOLERANCE;
        let (law, samples) = if resampled {
            let r = self.request;
            let law = TimeLaw::new(
                self.v.sigma,
                r.feedrate / g_max,
                r.feed_acceleration,
                r.feed_jerk,
            )?
            .on_grid(r.sample_period)?;
            let sample_times = law.checked_sample_times(r.sample_period, MAX_SAMPLES)?;
            let samples = self.law_samples(it, &law, sample_times, times)?;
            (law, samples)
        } else {
            (self.law, samples)
        };
        // The S-curve is the fastest rest-to-rest law under the feedrate, path acceleration and
        // path jerk alone (bang-bang in jerk); joint limits can only slow it. So when every
        // joint is inside its limits on its samples, it is the time-optimal law too (to the
        // rounding of its phases to the sample grid, and f / max g above), and the TOPP3
        // problem need not be solved.
        if mode == FeedMode::Constant || self.within_limits(&samples) {
            let limits = match mode {
                FeedMode::Constant => Vec::new(),
                FeedMode::TimeOptimal => law
                    .phases()
                    .into_iter()
                    .map(|(s_start, s_end, by)| FeedLimit {
                        s_start,
                        s_end,
                        limited_by: by.to_string(),
                    })
                    .collect(),
            };
            let peak_feed = peak_tip_speed(&samples);
            return Ok(Timed {
                samples,
                feed: FeedReport {
                    law: mode,
                    cycle_time: law.duration(),
                    constant_feed_time: constant_time,
                    peak_feed,
                    limits,
                },
                resampled,
            });
        }
        self.optimal(it, times, constant_time)
    }

    fn within_limits(&self, s: &Samples) -> bool {
        self.violations(s).is_empty()
    }

    /// Every limit the samples break: Table 2 at the samples (eq. 7, analytic), the jerk the
    /// executor commands between them ([`crate::executed`]) and the feedrate as the tool tip's
    /// speed ([`crate::tip`], joint [`TOOL_TIP`]).
    pub(super) fn violations(&self, s: &Samples) -> Vec<LimitViolation> {
        let limits = self.limits();
        let mut v = limit_violations(
            &s.times,
            &s.q,
            &s.qd,
            &s.qdd,
            &s.qddd,
            limits,
            LIMIT_TOLERANCE,
        );
        v.extend(executed_jerk_violations(
            &s.times,
            &s.q,
            &s.qd,
            &s.qdd,
            limits,
            LIMIT_TOLERANCE,
        ));
        let f = self.request.feedrate;
        if let Some((speed, time)) = worst_tip_speed(s) {
            if speed.is_nan() || speed > f * (1.0 + LIMIT_TOLERANCE) {
                v.push(LimitViolation {
                    joint: TOOL_TIP.into(),
                    quantity: "velocity",
                    value: speed,
                    limit: f,
                    time,
                });
            }
        }
        v
    }

    fn optimal(
        &self,
        it: &Iterate,
        times: &mut StageTimes,
        constant_time: f64,
    ) -> Result<Timed, PlanError> {
        let t0 = Instant::now();
        let sigma = self.v.sigma;
        let spans = it
            .q4
            .knots()
            .n_coeffs()
            .saturating_sub(super::DEGREE)
            .max(1);
        let n = (spans * STATIONS_PER_SPAN).clamp(STATION_RANGE.0, STATION_RANGE.1);
        let stations: Vec<f64> = (0..=n).map(|k| sigma * k as f64 / n as f64).collect();
        // [q, q', q'', q'''] per joint in arc length at s (q' = q_u/σ, ...). u is clamped to
        // [0, 1]: the evaluation cannot fail (a failure leaves NaN, which the limit checks
        // refuse).
        let at = |s: f64| {
            let mut d = [[0.0; 6]; 4];
            let joints = it
                .joints((s / sigma).clamp(0.0, 1.0), 3)
                .unwrap_or([[f64::NAN; 4]; 6]);
            for (j, e) in joints.iter().enumerate() {
                let mut scale = 1.0;
                for (order, row) in d.iter_mut().enumerate() {
                    row[j] = e[order] * scale;
                    scale /= sigma;
                }
            }
            d
        };
        let derivatives: Vec<[[f64; 6]; 4]> = stations.iter().map(|&s| at(s)).collect();
        let limits = self.limits();
        let r = self.request;
        self.reachable(&stations, &derivatives)?;
        let tip = tip_factors(&stations, &at);
        let mut problem = FeedProblem {
            stations: &stations,
            derivatives: &derivatives,
            joints: limits,
            feed: r.feedrate,
            acc: r.feed_acceleration,
            jerk: r.feed_jerk,
            margin: FIRST_MARGIN,
            process_margin: FIRST_PROCESS_MARGIN,
            tip: &tip,
        };
        let mut last = Vec::new();
        for _ in 0..MARGIN_ATTEMPTS {
            self.budget.check("the time-optimal feed")?;
            let margin = problem.margin;
            let t = Instant::now();
            let law = OptimalFeed::solve(&problem)?;
            times.feed += t.elapsed().as_secs_f64();
            let sample_times = checked_grid_times(law.duration(), r.sample_period, MAX_SAMPLES)?;
            let states = law.eval_many(&sample_times)?;
            let samples = self.sample(it, sample_times, &states)?;
            let (mut violations, mut process): (Vec<_>, Vec<_>) = self
                .violations(&samples)
                .into_iter()
                .partition(|v| v.joint != TOOL_TIP);
            process.extend(process_violations(&samples.times, &states, &problem));
            if let Some(excess) = process
                .iter()
                .map(|v| v.value.abs() / v.limit)
                .reduce(f64::max)
            {
                problem.process_margin = problem.process_margin / excess * PROCESS_MARGIN_STEP;
            }
            if violations.is_empty() && process.is_empty() {
                let report = FeedReport {
                    law: FeedMode::TimeOptimal,
                    cycle_time: law.duration(),
                    constant_feed_time: constant_time,
                    peak_feed: peak_tip_speed(&samples),
                    limits: law.limits(&problem),
                };
                log::debug!(
                    "time-optimal feed: {} stations, margin {margin}, T = {:.4} s ({:.1} ms)",
                    stations.len(),
                    law.duration(),
                    t0.elapsed().as_secs_f64() * 1e3
                );
                return Ok(Timed {
                    samples,
                    feed: report,
                    resampled: true,
                });
            }
            // A position limit is the geometry's: no time law mends it.
            let mut excess = 1.0f64;
            for v in &violations {
                if v.quantity == "position" {
                    return Err(PlanError::LimitViolation { violations });
                }
                excess = excess.max(v.value.abs() / v.limit);
            }
            if !violations.is_empty() {
                problem.margin = margin / excess * MARGIN_STEP;
            }
            violations.extend(process);
            last = violations;
        }
        Err(PlanError::LimitViolation { violations: last })
    }

    /// Refuses a feedrate that no station allows at steady state (issue 16, "bad input").
    fn reachable(&self, stations: &[f64], derivatives: &[[[f64; 6]; 4]]) -> Result<(), PlanError> {
        let limits = self.limits();
        let mut best = (0.0f64, 0usize, None);
        for (k, d) in derivatives.iter().enumerate() {
            let (v, by) = steady_feed(d, limits);
            if v > best.0 {
                best = (v, k, by);
            }
        }
        let f = self.request.feedrate;
        if best.0 >= f {
            return Ok(());
        }
        let (v, k, by) = best;
        let (joint, family) = by.unwrap_or((0, ConstraintFamily::Velocity));
        Err(PlanError::Infeasible {
            problem: "time-optimal feed".into(),
            family,
            detail: format!(
                "no point of the path allows f = {f:.6} m/s at steady state; the fastest, s = {:.4} m of {:.4} m, allows {v:.6} m/s, limited by the {} {} limit",
                stations[k],
                self.v.sigma,
                JOINT_NAMES[joint],
                crate::optimal_feed::family_word(family)
            ),
            max_feasible_feedrate: Some(v),
        })
    }
}

/// The coefficients of one rotary-axis QP under the request's feed law.
///
/// With the constant feed this is seed 001's QP (eq. 61) with its kinematic bounds at the
/// requested feedrate (eq. 15, 40-42). With the time-optimal law those bounds are kept where
/// they are feasible (the geometry then needs no slow-down at constant feed); where they are
/// not, the QP is solved with the bounds at the largest feedrate that makes it feasible
/// (bisection of [`RotaryQp::max_feasible_feedrate`]) and the time law slows the feed down
/// where the joints need it, instead of refusing the cut (issue 16: the saddle cut).
///
/// # Errors
/// As [`RotaryQp::solve`]: every error of the constant feed, and with the time-optimal law the
/// kinematic infeasibility only when no feedrate makes the QP feasible.
pub(super) fn rotary_coefficients(
    problem: &RotaryQp,
    mode: FeedMode,
) -> Result<Vec<f64>, PlanError> {
    match problem.solve() {
        Ok((coeffs, _)) => Ok(coeffs),
        Err(PlanError::Infeasible {
            family:
                ConstraintFamily::Velocity | ConstraintFamily::Acceleration | ConstraintFamily::Jerk,
            max_feasible_feedrate: Some(feed),
            ..
        }) if mode == FeedMode::TimeOptimal => {
            let relaxed = RotaryQp {
                feedrate: feed,
                ..*problem
            };
            relaxed.solve().map(|(coeffs, _)| coeffs)
        }
        Err(e) => Err(e),
    }
}

/// Both rotary-axis QPs, q4 (`problems[0]`) and q5 (`problems[1]`), each by `solve` (e.g.
/// [`rotary_coefficients`]), q5's on a second thread: the two are independent (seed 001
/// eq. 61, one QP per axis on the same knots). The same coefficients as solving them one after
/// the other, and the same error: q4's when both fail.
///
/// # Errors
/// As [`rotary_coefficients`]; [`PlanError::Solver`] if the q5 thread panics (a bug).
///
/// # Performance
/// The rotary stage's wall time halves when a second core is free (case 1: two solves of
/// ~2.6 ms); the CPU time is unchanged.
pub(super) fn rotary_pair(
    problems: &[RotaryQp; 2],
    solve: &(dyn Fn(&RotaryQp) -> Result<Vec<f64>, PlanError> + Sync),
) -> Result<[Vec<f64>; 2], PlanError> {
    let (first, second) = std::thread::scope(|scope| {
        let second = scope.spawn(|| solve(&problems[1]));
        let first = solve(&problems[0]);
        (first, second.join())
    });
    let second = second.unwrap_or_else(|_| {
        Err(PlanError::Solver {
            problem: problems[1].axis_name.into(),
            detail: "internal error: the QP thread panicked".into(),
        })
    });
    Ok([first?, second?])
}

/// The tool tip's largest speed over the samples (m/s) and its time: the feed as executed (a NaN
/// speed counts as the largest).
fn worst_tip_speed(s: &Samples) -> Option<(f64, f64)> {
    s.q.iter()
        .zip(&s.qd)
        .zip(&s.times)
        .map(|((q, qd), &t)| (tip_speed(q, qd), t))
        .max_by(|a, b| a.0.total_cmp(&b.0))
}

/// The tool tip's largest speed over the samples (m/s), for the report.
fn peak_tip_speed(s: &Samples) -> f64 {
    worst_tip_speed(s).map_or(0.0, |w| w.0)
}

/// `[g, g', g'']` per station: `g = |dC/ds|` from the joint path's derivatives in s
/// ([`crate::tip::tip_rate`], `at(s)` as in [`FeedProblem::derivatives`]), its derivatives by
/// central differences over ±[`TIP_STEP`] of the path (one-sided at the ends).
fn tip_factors(stations: &[f64], at: &dyn Fn(f64) -> [[f64; 6]; 4]) -> Vec<[f64; 3]> {
    let sigma = stations.last().copied().unwrap_or(0.0);
    let h = TIP_STEP * sigma.max(f64::MIN_POSITIVE);
    let g = |s: f64| {
        let d = at(s.clamp(0.0, sigma));
        tip_rate(&d[0], &d[1]).norm()
    };
    stations
        .iter()
        .map(|&s| {
            // Keep the three points inside [0, σ].
            let c = s.clamp(h, sigma - h);
            let (gm, g0, gp) = (g(c - h), g(c), g(c + h));
            let g1 = (gp - gm) / (2.0 * h);
            let g2 = (gp - 2.0 * g0 + gm) / (h * h);
            [g(s), g1 + g2 * (s - c), g2]
        })
        .collect()
}

/// Step of the differences of [`tip_factors`], as a fraction of the path length.
pub const TIP_STEP: f64 = 1e-4;

/// `[g, g', g'']` at path position `s`, linear between the stations.
fn tip_at(p: &FeedProblem, s: f64) -> [f64; 3] {
    let n = p.stations.len();
    if p.tip.len() != n || n < 2 {
        return [1.0, 0.0, 0.0];
    }
    let h = p.stations[1] - p.stations[0];
    let x = (s / h).clamp(0.0, (n - 1) as f64);
    let k = (x.floor() as usize).min(n - 2);
    let w = x - k as f64;
    std::array::from_fn(|i| p.tip[k][i] * (1.0 - w) + p.tip[k + 1][i] * w)
}

/// The samples whose tool tip's tangential acceleration or jerk (through [`tip_at`] and seed
/// 001 eq. 7 in arc length: `g' ṡ² + g s̈`, `g'' ṡ³ + 3 g' ṡ s̈ + g s⃛`) exceeds the request's
/// path acceleration or jerk (relative tolerance [`LIMIT_TOLERANCE`]), at most one per
/// quantity (the worst), as joint [`TOOL_TIP`]. The tip's speed against the feedrate is checked
/// exactly, by [`Context::violations`].
fn process_violations(times: &[f64], states: &[[f64; 4]], p: &FeedProblem) -> Vec<LimitViolation> {
    let rows: Vec<[f64; 4]> = states
        .iter()
        .map(|st| {
            let [g, g1, g2] = tip_at(p, st[0]);
            chain_rule([0.0, g, g1, g2], *st, 1.0)
        })
        .collect();
    let mut out: Vec<LimitViolation> = Vec::new();
    for (i, quantity, limit) in [(2, "acceleration", p.acc), (3, "jerk", p.jerk)] {
        let worst = times
            .iter()
            .zip(&rows)
            .map(|(&t, r)| (t, r[i]))
            .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()));
        if let Some((time, value)) = worst {
            if value.abs() > limit * (1.0 + LIMIT_TOLERANCE) {
                out.push(LimitViolation {
                    joint: TOOL_TIP.into(),
                    quantity,
                    value,
                    limit,
                    time,
                });
            }
        }
    }
    out
}
