//! The naive planner of issue 5 section 3: constant spindle speed and feed
//! (and constant g, 0 by default) over the whole path — the conventional
//! "one safe setting per operation" practice.
//!
//! # Rule
//!
//! On the DP's grid (Ω = Ω_min + k·20 rpm, f = k·1e-3 m/s, f > 0), the
//! FASTEST pair — the highest feed, then among equal feeds the lowest
//! max |μ| — that is chatter-free (|μ|max < 1) at EVERY segment:
//!
//! 1. screen all pairs with the cache (max over the N segments): the
//!    committed cache of the default cell, or the request's per-path cache
//!    ([`crate::path_cache`]) for any other path or process;
//! 2. verify the best screened candidates by direct evaluation at every
//!    segment (branch-continuous IK, as the plan), at most
//!    [`MAX_VERIFICATIONS`] candidates, so the chosen pair is chatter-free
//!    by the model itself, not only by the interpolation;
//! 3. if no pair passes, fall back to the IVP pair (Ω0, f0) = (2000 rpm,
//!    0.04 m/s) with [`NaiveResult::chatter_free`] = false (its chatter is
//!    flagged, and the plan's table row says "no").
//!
//! A constant setting does not start from the IVP: the naive plan is a
//! steady setting and is not bound by the step limits at the first
//! segment (it is the baseline a process engineer would program, not a
//! policy of the environment).

use kerf_budget::Budget;
use kerf_mill::MillCell;

use crate::cache::{direct_indicator, IndicatorCache};
use crate::env::PhysicalState;
use crate::error::MillPlanError;

/// How many cache-screened candidates are verified directly at most.
pub const MAX_VERIFICATIONS: usize = 10;

/// The naive plan.
#[derive(Debug, Clone, PartialEq)]
pub struct NaiveResult {
    /// Constant spindle speed \[rpm\].
    pub rpm: f64,
    /// Constant feed [m/s].
    pub feed: f64,
    /// Constant redundancy angle \[rad\].
    pub g: f64,
    /// Chatter-free at every segment by direct evaluation (false: the IVP
    /// fallback, chatter flagged).
    pub chatter_free: bool,
    /// Largest |μ|max over the segments by direct evaluation, of the
    /// returned pair.
    pub max_spectral_radius: f64,
    /// Candidates verified directly.
    pub verified: usize,
    /// The state sequence (one per segment).
    pub states: Vec<PhysicalState>,
}

/// Largest |μ| over all segments by direct evaluation at constant
/// (Ω, f, g), stopping at the first segment with |μ| ≥ 1 when `early_stop`.
/// `None`: a segment is infeasible at g.
fn direct_max(
    cell: &MillCell,
    rpm: f64,
    feed: f64,
    g: f64,
    early_stop: bool,
    budget: &Budget,
) -> Result<Option<f64>, MillPlanError> {
    let mut reference: Option<[f64; 6]> = None;
    let mut max: f64 = 0.0;
    for seg in 0..cell.path().segments().len() {
        budget.check("the naive plan's verification")?;
        let cs = match cell.evaluate(seg, g, reference.as_ref()) {
            Ok(cs) => cs,
            Err(e) if crate::cache::is_infeasible(&e) => return Ok(None),
            Err(e) => return Err(e.into()),
        };
        reference = Some(cs.joints);
        let Some(mu) = direct_indicator(cell, seg, rpm, feed, g, reference.as_ref())? else {
            return Ok(None);
        };
        max = max.max(mu);
        if early_stop && mu >= 1.0 {
            break;
        }
    }
    Ok(Some(max))
}

/// The naive plan (module documentation).
///
/// # Arguments
/// * `cell`, `cache` — model and indicator cache; `g` — the constant
///   redundancy angle \[rad\] (0 for the paper's setting).
///
/// # Errors
/// [`MillPlanError::InvalidParameter`] for a NaN g, or a g infeasible at
/// some segment; model errors.
///
/// # Performance
/// 101 × 60 × N cache queries and up to 10 × N direct evaluations.
pub fn solve(
    cell: &MillCell,
    cache: &IndicatorCache,
    g: f64,
) -> Result<NaiveResult, MillPlanError> {
    solve_within(cell, cache, g, &Budget::unlimited())
}

/// [`solve`] under a time budget, checked per (Ω, f) pair of the cached
/// search and per segment of each direct verification.
///
/// # Errors
/// As [`solve`], and [`MillPlanError::Interrupted`].
pub fn solve_within(
    cell: &MillCell,
    cache: &IndicatorCache,
    g: f64,
    budget: &Budget,
) -> Result<NaiveResult, MillPlanError> {
    if g.is_nan() {
        return Err(MillPlanError::InvalidParameter {
            name: "naive redundancy angle g [rad]".to_string(),
            value: g,
            reason: "is NaN".to_string(),
        });
    }
    let lim = *cell.state_limits();
    let n = cell.path().segments().len();
    let n_rpm = ((lim.spindle_rpm[1] - lim.spindle_rpm[0]) / lim.max_spindle_step_rpm + 1e-9)
        .floor() as usize;
    let n_feed = (lim.feed[1] / lim.max_feed_step + 1e-9).floor() as usize;
    let mut candidates: Vec<(f64, f64, f64)> = Vec::new();
    for i in 0..=n_rpm {
        let rpm = lim.spindle_rpm[0] + i as f64 * lim.max_spindle_step_rpm;
        for j in 1..=n_feed {
            budget.check("the naive plan's search")?;
            let feed = j as f64 * lim.max_feed_step;
            if feed < lim.feed[0] {
                continue;
            }
            let mut max: f64 = 0.0;
            let mut ok = true;
            for seg in 0..n {
                match cache.try_query(seg, rpm, feed, g)? {
                    Some(mu) if mu < 1.0 => max = max.max(mu),
                    _ => {
                        ok = false;
                        break;
                    }
                }
            }
            if ok {
                candidates.push((feed, max, rpm));
            }
        }
    }
    candidates.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.total_cmp(&b.1)));
    let constant = |rpm: f64, feed: f64| -> Vec<PhysicalState> {
        (0..n)
            .map(|segment| PhysicalState {
                segment,
                rpm,
                feed,
                g,
            })
            .collect()
    };
    let mut verified = 0;
    for (feed, _, rpm) in candidates.iter().take(MAX_VERIFICATIONS) {
        verified += 1;
        if let Some(max) = direct_max(cell, *rpm, *feed, g, true, budget)? {
            if max < 1.0 {
                return Ok(NaiveResult {
                    rpm: *rpm,
                    feed: *feed,
                    g,
                    chatter_free: true,
                    max_spectral_radius: max,
                    verified,
                    states: constant(*rpm, *feed),
                });
            }
        }
    }
    // Fallback: the IVP pair, chatter flagged.
    let (rpm, feed) = (
        2000.0_f64.clamp(lim.spindle_rpm[0], lim.spindle_rpm[1]),
        0.04,
    );
    let max = direct_max(cell, rpm, feed, g, false, budget)?.ok_or_else(|| {
        MillPlanError::InvalidParameter {
            name: "naive redundancy angle g [rad]".to_string(),
            value: g,
            reason: "infeasible (IK or joint limit) at some segment: no constant plan exists"
                .to_string(),
        }
    })?;
    Ok(NaiveResult {
        rpm,
        feed,
        g,
        chatter_free: max < 1.0,
        max_spectral_radius: max,
        verified,
        states: constant(rpm, feed),
    })
}
