//! A jerk-limited feed plan along a sampled path (issue 14, item 3, the
//! deterministic planner of seed 003's "Feedrate planning", after its
//! reference 19, Jia et al. 2017: constant speed through feedrate-sensitive
//! intervals, jerk-limited acceleration and deceleration between them).
//!
//! 1. The velocity-limit curve of every sample (seed 003 eq. 22,
//!    [`crate::CurvatureLimits::speed`]). A sensitive interval is a run of
//!    samples whose limit is below the programmed feed F; it is run at one
//!    speed, its lowest limit, so the tangential acceleration and jerk are
//!    zero there and every curvature limit holds at every point of it.
//! 2. Between intervals (and from rest at the start, to rest at the end)
//!    the limit is F. Each gap is run as an S-curve up ([`crate::scurve`]),
//!    a cruise and an S-curve down, with the highest peak that fits.
//! 3. Bidirectional: an interval's speed is lowered until the gaps before
//!    and after it can reach it and leave it ([`crate::scurve::reachable`]),
//!    forward then backward, until nothing changes.
//!
//! The plan is a list of constant-jerk phases; [`FeedPlan::sample`]
//! evaluates it at the interpolation period, where its limits are checked
//! (`tests/feed.rs`).

use kerf_budget::{bytes_of, Budget, Interrupt};

use crate::error::{check_positive, ToolpathError};
use crate::samples::{check_samples, PathSample};
use crate::scurve::{reachable, scurve_distance, scurve_phases, Phase};
use crate::speed_limit::CurvatureLimits;

/// The limits of a feed plan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FeedLimits {
    /// F and the curvature limits (seed 003 eqs. 15–22).
    pub curvature: CurvatureLimits,
    /// Largest tangential acceleration \[m/s²\].
    pub tangential_acceleration: f64,
    /// Largest tangential jerk \[m/s³\].
    pub tangential_jerk: f64,
}

impl FeedLimits {
    /// Checks every limit.
    ///
    /// # Errors
    /// [`ToolpathError::InvalidParameter`] naming the limit.
    pub fn validate(&self) -> Result<(), ToolpathError> {
        self.curvature.validate()?;
        check_positive(&[
            (
                "tangential acceleration [m/s^2]",
                self.tangential_acceleration,
            ),
            ("tangential jerk [m/s^3]", self.tangential_jerk),
        ])
    }
}

/// A constant-jerk phase placed along the path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlacedPhase {
    /// Start time \[s\].
    pub t0: f64,
    /// Arc length, speed and acceleration at its start.
    pub s0: f64,
    /// Speed at its start \[m/s\].
    pub v0: f64,
    /// Acceleration at its start \[m/s²\].
    pub a0: f64,
    /// The phase.
    pub phase: Phase,
}

impl PlacedPhase {
    /// (s, v, a) at `dt` into the phase (exact integration of constant jerk).
    pub fn at(&self, dt: f64) -> (f64, f64, f64) {
        let j = self.phase.jerk;
        (
            self.s0 + self.v0 * dt + 0.5 * self.a0 * dt * dt + j * dt * dt * dt / 6.0,
            self.v0 + self.a0 * dt + 0.5 * j * dt * dt,
            self.a0 + j * dt,
        )
    }
}

/// Constant-jerk phases placed end to end from rest at arc length `s0` (exact integration
/// of each; phases of no duration are skipped).
///
/// # Returns
/// The placed phases and their total time \[s\].
pub(crate) fn place_phases(
    phases: impl IntoIterator<Item = Phase>,
    s0: f64,
) -> (Vec<PlacedPhase>, f64) {
    let mut placed = Vec::new();
    let (mut t, mut s, mut v, mut acc) = (0.0, s0, 0.0, 0.0);
    for ph in phases.into_iter().filter(|p| p.duration > 0.0) {
        let p = PlacedPhase {
            t0: t,
            s0: s,
            v0: v,
            a0: acc,
            phase: ph,
        };
        let (s1, v1, a1) = p.at(ph.duration);
        placed.push(p);
        t += ph.duration;
        (s, v, acc) = (s1, v1, a1);
    }
    (placed, t)
}

/// One sample of a feed plan in time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FeedSample {
    /// Time \[s\].
    pub t: f64,
    /// Arc length \[m\].
    pub s: f64,
    /// Speed \[m/s\].
    pub v: f64,
    /// Tangential acceleration \[m/s²\].
    pub a: f64,
    /// Tangential jerk \[m/s³\].
    pub j: f64,
}

/// A feed plan.
#[derive(Debug, Clone, PartialEq)]
pub struct FeedPlan {
    /// The phases in order.
    pub phases: Vec<PlacedPhase>,
    /// Total time T \[s\].
    pub time: f64,
    /// Path length \[m\].
    pub length: f64,
    /// Speed of each sensitive interval (arc lengths and speed).
    pub intervals: Vec<(f64, f64, f64)>,
}

impl FeedPlan {
    /// The plan at every multiple of `period` and at its end.
    pub fn sample(&self, period: f64) -> Vec<FeedSample> {
        // Only the budget interrupts, and an unlimited one never does.
        self.sample_within(period, &Budget::unlimited())
            .unwrap_or_default()
    }

    /// The number of points of [`Self::sample`] at `period`: ⌊T / period⌋ + 2 at most
    /// (saturating; a plan of 10³⁰⁰ s gives `u64::MAX`).
    pub fn sample_count(&self, period: f64) -> u64 {
        let count = (self.time / period).floor() + 2.0;
        if count.is_finite() && count < u64::MAX as f64 {
            count as u64
        } else {
            u64::MAX
        }
    }

    /// [`Self::sample`] under a budget: the points' memory is checked before any is made (a
    /// plan of 10³⁰⁰ s at a 4 ms period is refused by the estimate), the deadline every few
    /// thousand points.
    ///
    /// # Errors
    /// [`Interrupt`] when the budget runs out.
    pub fn sample_within(
        &self,
        period: f64,
        budget: &Budget,
    ) -> Result<Vec<FeedSample>, Interrupt> {
        let count = self.sample_count(period);
        budget.check_memory(
            bytes_of::<FeedSample>(count),
            &format!(
                "feed plan at the interpolation period: {:.3e} s / {period} s = {count} points",
                self.time
            ),
        )?;
        let mut out = Vec::with_capacity(usize::try_from(count.min(1 << 20)).unwrap_or(0));
        let mut k = 0usize;
        let mut p = 0usize;
        loop {
            if k % 4096 == 4095 {
                budget.check("feed plan sampling")?;
            }
            let t = (k as f64 * period).min(self.time);
            while p + 1 < self.phases.len() && self.phases[p + 1].t0 <= t {
                p += 1;
            }
            let ph = &self.phases[p];
            let (s, v, a) = ph.at(t - ph.t0);
            out.push(FeedSample {
                t,
                s: s.min(self.length),
                v: v.max(0.0),
                a,
                j: ph.phase.jerk,
            });
            if t >= self.time {
                break;
            }
            k += 1;
        }
        Ok(out)
    }
}

/// Plans the feed along `samples` (module documentation).
///
/// # Errors
/// [`ToolpathError::InvalidParameter`] for bad limits, fewer than two
/// samples, or an arc length that does not increase.
pub fn plan_feed(samples: &[PathSample], limits: &FeedLimits) -> Result<FeedPlan, ToolpathError> {
    plan_feed_within(samples, limits, &Budget::unlimited())
}

/// [`plan_feed`] under a budget, checked at every pass of the bidirectional scan and every
/// few thousand samples or intervals.
///
/// # Errors
/// As [`plan_feed`]; [`ToolpathError::Interrupted`] when the budget runs out.
pub fn plan_feed_within(
    samples: &[PathSample],
    limits: &FeedLimits,
    budget: &Budget,
) -> Result<FeedPlan, ToolpathError> {
    limits.validate()?;
    check_samples(samples)?;
    let f = limits.curvature.feed;
    let (a, j) = (limits.tangential_acceleration, limits.tangential_jerk);
    // Step 1: sensitive intervals [s_start, s_end] at their lowest limit.
    let mut intervals: Vec<(f64, f64, f64)> = Vec::new();
    let mut open: Option<(f64, f64)> = None;
    for (k, p) in samples.iter().enumerate() {
        if k % 4096 == 4095 {
            budget.check("feed planning")?;
        }
        let v = limits.curvature.speed(p.curvature);
        if v < f {
            open = Some(match open {
                None => (samples[k.saturating_sub(1)].s, v),
                Some((s0, m)) => (s0, m.min(v)),
            });
        } else if let Some((s0, m)) = open.take() {
            intervals.push((s0, p.s, m));
        }
    }
    let length = samples[samples.len() - 1].s;
    if let Some((s0, m)) = open {
        intervals.push((s0, length, m));
    }
    // Step 3: bidirectional feasibility of the gaps.
    let gap = |k: usize, iv: &[(f64, f64, f64)]| -> f64 {
        let from = if k == 0 { 0.0 } else { iv[k - 1].1 };
        let to = if k == iv.len() { length } else { iv[k].0 };
        (to - from).max(0.0)
    };
    loop {
        budget.check("feed planning (bidirectional scan)")?;
        let mut changed = false;
        // Forward: the speed at the end of gap k reachable from its start.
        for k in 0..intervals.len() {
            let from = if k == 0 { 0.0 } else { intervals[k - 1].2 };
            let reach = reachable(from, gap(k, &intervals), f, a, j);
            if intervals[k].2 > reach {
                intervals[k].2 = reach;
                changed = true;
            }
        }
        // Backward: the speed at the start of gap k + 1 from which its end is reachable.
        for k in (0..intervals.len()).rev() {
            let to = if k + 1 == intervals.len() {
                0.0
            } else {
                intervals[k + 1].2
            };
            let reach = reachable(to, gap(k + 1, &intervals), f, a, j);
            if intervals[k].2 > reach {
                intervals[k].2 = reach;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    if let Some(bad) = intervals.iter().find(|iv| iv.2 <= 0.0) {
        return Err(ToolpathError::InvalidParameter {
            name: format!("speed of the sensitive interval at {} m", bad.0),
            value: bad.2,
            reason: "no positive speed is reachable there".to_string(),
        });
    }
    // Step 2: the phases.
    let mut phases: Vec<Phase> = Vec::new();
    for k in 0..=intervals.len() {
        if k % 1024 == 1023 {
            budget.check("feed planning")?;
        }
        let v0 = if k == 0 { 0.0 } else { intervals[k - 1].2 };
        let v1 = if k == intervals.len() {
            0.0
        } else {
            intervals[k].2
        };
        let d = gap(k, &intervals);
        // The highest peak whose up and down S-curves fit in the gap.
        let fits = |vp: f64| scurve_distance(v0, vp, a, j) + scurve_distance(vp, v1, a, j) <= d;
        let low = v0.max(v1);
        let peak = if fits(f) {
            f
        } else {
            let (mut lo, mut hi) = (low, f);
            for _ in 0..100 {
                let mid = 0.5 * (lo + hi);
                if fits(mid) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            lo
        };
        let used = scurve_distance(v0, peak, a, j) + scurve_distance(peak, v1, a, j);
        phases.extend(scurve_phases(v0, peak, a, j));
        if peak > 0.0 && d > used {
            phases.push(Phase {
                duration: (d - used) / peak,
                jerk: 0.0,
            });
        }
        phases.extend(scurve_phases(peak, v1, a, j));
        if k < intervals.len() {
            let (s0, s1, v) = intervals[k];
            phases.push(Phase {
                duration: (s1 - s0) / v,
                jerk: 0.0,
            });
        }
    }
    let (placed, t) = place_phases(phases, 0.0);
    Ok(FeedPlan {
        phases: placed,
        time: t,
        length,
        intervals,
    })
}
