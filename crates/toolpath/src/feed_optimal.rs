//! A near time-optimal, jerk-limited, bidirectional feed plan (issue 14,
//! item 3) that tracks the velocity-limit curve ([`crate::limit_curve`](mod@crate::limit_curve))
//! instead of holding whole feed-sensitive intervals at their lowest limit
//! ([`crate::plan_feed`]).
//!
//! **Structure of the optimum.** Between two local minima of the speed the
//! speed rises and falls once, and at every local minimum and maximum the
//! tangential acceleration is zero. With |a| ≤ A and |j| ≤ J, the fastest
//! motion over a distance d from v₀ to v₁ (zero acceleration at both) under
//! a cap is an S-curve up to the highest peak that fits, a cruise there and
//! an S-curve down (the S-curves of [`crate::scurve`], Lin, Tsai and Yau,
//! "Development of a dynamics-based NURBS interpolator with real-time
//! look-ahead algorithm", IJMTM 47(15), 2007, the jerk-limited S-shape
//! profile with bidirectional look-ahead). The second-order analogue is the
//! bang-bang switching structure of Bobrow, Dubowsky and Gibson, IJRR 4(3),
//! 1985, section 4, whose speed touches the limit curve at its critical
//! points. The planner:
//!
//! 1. **Critical points** (knots): the start and end at rest and every
//!    local minimum of the limit curve (both ends of a flat minimum), each
//!    at its limit with zero acceleration.
//! 2. **Bidirectional scan**: every knot at its limit, then its speed is
//!    lowered to what one S-curve from its predecessor reaches in their gap
//!    (forward) and to what lets one S-curve reach its successor (backward),
//!    until nothing changes ([`crate::scurve::reachable_closed_form`]).
//!    **Pruning**: a local minimum the scan lowered does not bind (the
//!    optimum passes below its limit while still speeding up or slowing
//!    down, not with zero acceleration there); it is removed and the scan
//!    repeated, until every remaining knot is at its limit or permanent.
//! 3. **Each gap** is run as up–cruise–down with the highest peak that fits,
//!    at most the gap's cap (the largest limit in the gap).
//! 4. **Exact check under the limit curve**: the gap's speed is compared
//!    with the limit at every node inside it whose limit is below the speed
//!    at an end of the phase there, and at every phase boundary. The speed
//!    is monotone within a constant-jerk phase of an S-curve, so a node is
//!    exceeded iff it lies beyond (rising) or before (falling) the arc
//!    length where the speed crosses its limit: a quadratic in time, solved
//!    in closed form. These points bound the speed over every interval
//!    against that interval's limit. Where it exceeds the limit, a
//!    permanent knot is added at the node with the lowest exceeded limit, at
//!    that limit (a gap of one interval gets that interval's limit as its
//!    cap instead). Then back to 2. Knots are removed at most once each and
//!    permanent knots only added, so this ends.
//!
//! The speed is never above the limit curve, and |a| ≤ A, |j| ≤ J exactly
//! (the tangential budget of [`crate::FeedConstraints::tangential`]). The
//! losses against the jerk-limited optimum are the zero acceleration at the
//! knots added in 4 (a staircase where an S-curve would rise or fall faster
//! than the limit curve: about 2 % of T on the gear outline with seed 003's
//! limits) and the conservative limit curve (0.3 % of T_lb there). Against
//! the second-order bound T_lb, the jerk limit itself costs: each rise and
//! fall between two binding minima is the double S-curve, slower than the
//! bang-bang one (e.g. 0.161 s instead of 0.135 s over 6.8 mm from 27 to
//! 24 mm/s with A_t 0.8 m/s², J_t 20 m/s³).

use kerf_budget::{bytes_of, Budget, Interrupt};

use crate::constraints::FeedConstraints;
use crate::feed::{place_phases, FeedPlan, PlacedPhase};
use crate::limit_curve::{limit_curve, LimitCurve};
use crate::samples::PathSample;
use crate::scurve::{reachable_closed_form as reachable, scurve_distance, scurve_phases, Phase};
use crate::ToolpathError;

/// Relative tolerance of the check under the limit curve.
const TOLERANCE: f64 = 1e-12;

/// A critical point.
#[derive(Debug, Clone, Copy)]
struct Knot {
    /// Its node in the limit curve.
    node: usize,
    /// Its speed \[m/s\].
    v: f64,
    /// The cap of the gap from it to the next knot \[m/s\].
    cap: f64,
    /// (v, next v, cap) when the gap last passed the check.
    passed: Option<(f64, f64, f64)>,
    /// Kept even when the scan lowers it (the ends, and knots added where
    /// a gap exceeded the limit curve).
    permanent: bool,
}

/// Plans a near time-optimal feed along `samples` under `constraints`
/// (module documentation). The plan's [`FeedPlan::intervals`] are its
/// critical points, each as (s, s, v).
///
/// # Errors
/// [`ToolpathError::InvalidParameter`] for bad constraints
/// ([`FeedConstraints::validate`]), or if the repair of step 4 does not end
/// (not expected: reported rather than looping).
pub fn plan_feed_optimal(
    samples: &[PathSample],
    constraints: &FeedConstraints<'_>,
) -> Result<FeedPlan, ToolpathError> {
    plan_feed_optimal_within(samples, constraints, &Budget::unlimited())
}

/// Bytes of the limit curve and the knots per sample, at most (three nodes per sample, each
/// with its arc length, limit and interval limit, and a knot).
const BYTES_PER_SAMPLE: u64 = 3 * 4 * 8 + 48;

/// [`plan_feed_optimal`] under a budget: the limit curve's memory is checked before it is
/// built, the deadline at every round, every pass of the scan and every few hundred gaps.
///
/// # Errors
/// As [`plan_feed_optimal`]; [`ToolpathError::Interrupted`] when the budget runs out.
pub fn plan_feed_optimal_within(
    samples: &[PathSample],
    constraints: &FeedConstraints<'_>,
    budget: &Budget,
) -> Result<FeedPlan, ToolpathError> {
    constraints.validate(samples)?;
    budget.check_memory(
        bytes_of::<u8>(samples.len() as u64).saturating_mul(BYTES_PER_SAMPLE),
        &format!("feed plan: limit curve of {} samples", samples.len()),
    )?;
    let curve = limit_curve(samples, constraints);
    let (a, j) = constraints.tangential();
    let mut knots = critical_points(&curve);
    let most_rounds = 4 * curve.s.len() + 100;
    let mut rounds = 0usize;
    loop {
        rounds += 1;
        if rounds > most_rounds {
            return Err(ToolpathError::InvalidParameter {
                name: "feed plan rounds".to_string(),
                value: rounds as f64,
                reason: "the check under the limit curve did not settle".to_string(),
            });
        }
        budget.check("feed planning")?;
        settle(&mut knots, &curve, a, j, budget)?;
        let mut changed = false;
        let mut inserts: Vec<(usize, Knot)> = Vec::new();
        for k in 0..knots.len() - 1 {
            if k % 256 == 255 {
                budget.check("feed planning (check under the limit curve)")?;
            }
            let (p, q) = (knots[k], knots[k + 1]);
            if p.passed == Some((p.v, q.v, p.cap)) {
                continue;
            }
            let d = curve.s[q.node] - curve.s[p.node];
            let phases = gap_phases(p.v, q.v, d, p.cap, a, j);
            let found = excess(&curve, &p, &q, &phases);
            if found.iter().all(Option::is_none) {
                knots[k].passed = Some((p.v, q.v, p.cap));
                continue;
            }
            changed = true;
            // A knot where the gap exceeds the limit (one where it rises, one
            // where it falls); a lower cap only when no node inside the gap
            // is exceeded (a gap of one interval, whose limit then binds).
            let mut nodes: Vec<usize> = Vec::with_capacity(2);
            for e in found.iter().flatten() {
                if e.node > p.node && e.node < q.node {
                    nodes.push(e.node);
                } else {
                    let cap = e.lowest.max(p.v.max(q.v));
                    knots[k].cap = cap.min(p.cap * (1.0 - TOLERANCE));
                    knots[k].passed = None;
                }
            }
            nodes.sort_unstable();
            nodes.dedup();
            for node in nodes {
                inserts.push((
                    k + 1,
                    Knot {
                        node,
                        v: curve.node[node],
                        cap: p.cap,
                        passed: None,
                        permanent: true,
                    },
                ));
            }
        }
        if !inserts.is_empty() {
            let mut merged = Vec::with_capacity(knots.len() + inserts.len());
            let mut next = inserts.into_iter().peekable();
            for (i, knot) in knots.iter().enumerate() {
                while next.peek().is_some_and(|(at, _)| *at == i) {
                    if let (Some(prev), Some((_, new))) = (merged.last_mut(), next.next()) {
                        let prev: &mut Knot = prev;
                        prev.passed = None;
                        merged.push(new);
                    }
                }
                merged.push(*knot);
            }
            knots = merged;
        }
        if !changed {
            break;
        }
    }
    Ok(place(&knots, &curve, a, j))
}

/// Step 1: the start, the end and every local minimum of the limit curve.
fn critical_points(curve: &LimitCurve) -> Vec<Knot> {
    let n = curve.s.len();
    let lim = &curve.node;
    let cap_max = curve.interval.iter().copied().fold(0.0, f64::max);
    let knot = |node: usize, v: f64| Knot {
        node,
        v,
        cap: cap_max,
        passed: None,
        permanent: false,
    };
    let mut knots = vec![knot(0, 0.0)];
    knots[0].permanent = true;
    let mut k = 1;
    while k + 1 < n {
        let mut end = k;
        while end + 2 < n && lim[end + 1] == lim[k] {
            end += 1;
        }
        if lim[k - 1] > lim[k] && lim[end + 1] > lim[k] {
            knots.push(knot(k, lim[k]));
            if end > k {
                knots.push(knot(end, lim[k]));
            }
        }
        k = end + 1;
    }
    let mut end = knot(n - 1, 0.0);
    end.permanent = true;
    knots.push(end);
    for g in 0..knots.len() - 1 {
        knots[g].cap = largest_limit(curve, knots[g].node, knots[g + 1].node);
    }
    knots
}

/// The largest limit between nodes `a` and `b` (a gap's first cap).
fn largest_limit(curve: &LimitCurve, a: usize, b: usize) -> f64 {
    curve.interval[a..b].iter().copied().fold(0.0, f64::max)
}

/// Step 2 with pruning: every knot back at its limit, the scan, and the
/// knots it lowered (not binding: the speed passes below the limit there
/// without stopping to rise or fall) removed, until none is; a removed
/// knot comes back, for good, if its gap then exceeds the limit there.
fn settle(
    knots: &mut Vec<Knot>,
    curve: &LimitCurve,
    a: f64,
    j: f64,
    budget: &Budget,
) -> Result<(), Interrupt> {
    loop {
        let last = knots.len() - 1;
        for knot in &mut knots[1..last] {
            knot.v = curve.node[knot.node];
        }
        scan(knots, curve, a, j, budget)?;
        let before = knots.len();
        let mut kept: Vec<Knot> = Vec::with_capacity(before);
        for (i, k) in knots.iter().enumerate() {
            if i > 0 && i < last && !k.permanent && k.v < curve.node[k.node] * (1.0 - TOLERANCE) {
                if let Some(prev) = kept.last_mut() {
                    prev.cap = f64::NAN;
                }
                continue;
            }
            kept.push(*k);
        }
        if kept.len() == before {
            return Ok(());
        }
        for g in 0..kept.len() - 1 {
            if kept[g].cap.is_nan() {
                kept[g].cap = largest_limit(curve, kept[g].node, kept[g + 1].node);
                kept[g].passed = None;
            }
        }
        *knots = kept;
    }
}

/// Step 2: the bidirectional scan of the knot speeds.
fn scan(
    knots: &mut [Knot],
    curve: &LimitCurve,
    a: f64,
    j: f64,
    budget: &Budget,
) -> Result<(), Interrupt> {
    loop {
        budget.check("feed planning (bidirectional scan)")?;
        let mut changed = false;
        for k in 0..knots.len() - 1 {
            let d = curve.s[knots[k + 1].node] - curve.s[knots[k].node];
            if knots[k + 1].v > knots[k].v {
                let r = reachable(knots[k].v, d, knots[k + 1].v, a, j);
                if r < knots[k + 1].v {
                    knots[k + 1].v = r;
                    changed = true;
                }
            }
        }
        for k in (0..knots.len() - 1).rev() {
            let d = curve.s[knots[k + 1].node] - curve.s[knots[k].node];
            if knots[k].v > knots[k + 1].v {
                let r = reachable(knots[k + 1].v, d, knots[k].v, a, j);
                if r < knots[k].v {
                    knots[k].v = r;
                    changed = true;
                }
            }
        }
        if !changed {
            return Ok(());
        }
    }
}

/// Step 3: S-curve from `v0` up to the highest peak (at most `cap`) whose
/// up and down S-curves fit in `d`, cruise, S-curve down to `v1`.
fn gap_phases(v0: f64, v1: f64, d: f64, cap: f64, a: f64, j: f64) -> Vec<Phase> {
    let excess = |vp: f64| scurve_distance(v0, vp, a, j) + scurve_distance(vp, v1, a, j) - d;
    let low = v0.max(v1);
    let peak = if cap <= low || excess(low) > 0.0 {
        low
    } else if excess(cap) <= 0.0 {
        cap
    } else {
        // The distance rises with the peak: the Illinois variant of regula
        // falsi keeps a bracket [lo (fits), hi (does not)] and converges
        // superlinearly; lo is returned, so the S-curves always fit.
        let (mut lo, mut hi) = (low, cap);
        let (mut f_lo, mut f_hi) = (excess(lo), excess(hi));
        let mut side = 0i8;
        for _ in 0..100 {
            if hi - lo <= 1e-13 * hi {
                break;
            }
            let mut mid = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
            if !(mid > lo && mid < hi) {
                mid = 0.5 * (lo + hi);
            }
            let f = excess(mid);
            if f <= 0.0 {
                lo = mid;
                f_lo = f;
                if side == -1 {
                    f_hi *= 0.5;
                }
                side = -1;
            } else {
                hi = mid;
                f_hi = f;
                if side == 1 {
                    f_lo *= 0.5;
                }
                side = 1;
            }
        }
        lo
    };
    let used = scurve_distance(v0, peak, a, j) + scurve_distance(peak, v1, a, j);
    let mut phases = scurve_phases(v0, peak, a, j);
    if peak > 0.0 && d > used {
        phases.push(Phase {
            duration: (d - used) / peak,
            jerk: 0.0,
        });
    }
    phases.extend(scurve_phases(peak, v1, a, j));
    phases
}

/// Where a gap exceeds the limit curve.
#[derive(Debug, Clone, Copy)]
struct Excess {
    /// The lowest exceeded limit \[m/s\].
    lowest: f64,
    /// Its node (inside the gap where possible).
    node: usize,
}

/// Step 4: where the gap from `p` to `q` run as `phases` exceeds the limit
/// curve, while its speed rises and while it falls (`None` where nowhere).
fn excess(curve: &LimitCurve, p: &Knot, q: &Knot, phases: &[Phase]) -> [Option<Excess>; 2] {
    // The lowest exceeded limit where the speed rises (or cruises), and where it falls.
    let mut worst: [Option<Excess>; 2] = [None, None];
    let mut note = |limit: f64, node: usize, falling: bool| {
        let w = worst[usize::from(falling)].get_or_insert(Excess {
            lowest: limit,
            node,
        });
        if limit < w.lowest {
            w.lowest = limit;
            w.node = node;
        }
    };
    let end_s = curve.s[q.node];
    let mut ph = PlacedPhase {
        t0: 0.0,
        s0: curve.s[p.node],
        v0: p.v,
        a0: 0.0,
        phase: Phase {
            duration: 0.0,
            jerk: 0.0,
        },
    };
    let mut k = p.node + 1;
    for phase in phases.iter().filter(|x| x.duration > 0.0) {
        ph.phase = *phase;
        let (s1, v1, a1) = ph.at(phase.duration);
        // The speed is monotone in the phase: nodes whose limit is above
        // both its ends cannot be exceeded.
        let top = ph.v0.max(v1);
        let falling = v1 < ph.v0;
        while k < q.node && curve.s[k] <= s1 {
            let limit = curve.node[k] * (1.0 + TOLERANCE);
            if limit < top {
                // Where the speed crosses the limit (v is monotone in the
                // phase): exceeded after it when rising, before it when falling.
                let exceeded = if falling {
                    limit < v1 || curve.s[k] < ph.at(time_of_speed(&ph, limit)).0
                } else {
                    limit < ph.v0 || curve.s[k] > ph.at(time_of_speed(&ph, limit)).0
                };
                if exceeded {
                    note(curve.node[k], k, falling);
                }
            }
            k += 1;
        }
        // The phase's end, inside interval k − 1 (nodes k − 1 and k).
        if s1 < end_s && k > 0 && k < curve.s.len() {
            let limit = curve.interval[k - 1];
            if v1 > limit * (1.0 + TOLERANCE) {
                let inside = |n: usize| n > p.node && n < q.node;
                let node = match (inside(k - 1), inside(k)) {
                    (true, true) if curve.node[k] < curve.node[k - 1] => k,
                    (true, _) => k - 1,
                    (false, true) => k,
                    (false, false) => p.node,
                };
                note(limit, node, falling);
            }
        }
        ph.s0 = s1;
        ph.v0 = v1;
        ph.a0 = a1;
    }
    worst
}

/// The time in `ph` at which its speed is `v` (between its end speeds; v
/// is monotone in the phase): the root in the phase of
/// j t²/2 + a₀ t − (v − v₀) = 0, written 2Δ/(a₀ + √(a₀² + 2jΔ)) (signs
/// flipped when the speed falls) so that it does not cancel.
fn time_of_speed(ph: &PlacedPhase, v: f64) -> f64 {
    let (a0, j) = (ph.a0, ph.phase.jerk);
    let dv = v - ph.v0;
    let sign = if a0 > 0.0 || (a0 == 0.0 && j > 0.0) {
        1.0
    } else {
        -1.0
    };
    let root = (a0 * a0 + 2.0 * j * dv).max(0.0).sqrt();
    let den = sign * a0 + root;
    let t = if den > 0.0 {
        2.0 * sign * dv / den
    } else {
        0.0
    };
    t.clamp(0.0, ph.phase.duration)
}

/// The plan: every gap's phases in order, placed by exact integration.
fn place(knots: &[Knot], curve: &LimitCurve, a: f64, j: f64) -> FeedPlan {
    let phases = knots.windows(2).flat_map(|w| {
        let d = curve.s[w[1].node] - curve.s[w[0].node];
        gap_phases(w[0].v, w[1].v, d, w[0].cap, a, j)
    });
    let (placed, t) = place_phases(phases, curve.s[0]);
    FeedPlan {
        phases: placed,
        time: t,
        length: curve.s[curve.s.len() - 1],
        intervals: knots
            .iter()
            .map(|k| (curve.s[k.node], curve.s[k.node], k.v))
            .collect(),
    }
}
