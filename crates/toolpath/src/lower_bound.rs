//! T_lb: the time of the second-order bang-bang optimum along a path (issue
//! 14, item 3), the bound a jerk-limited feed plan is compared with.
//!
//! The path is sampled by arc length ([`crate::samples`]). The speed may not
//! exceed the velocity-limit curve v_lim(s) = min(F, √(A_n / κ(s))) (the
//! programmed feed and the normal acceleration v²κ ≤ A_n); the tangential
//! acceleration is bounded by A_t. The optimum accelerates at A_t, follows
//! v_lim or decelerates at A_t, switching where these meet (Bobrow, Dubowsky
//! and Gibson, "Time-optimal control of robotic manipulators along specified
//! paths", IJRR 4(3), 1985, section 4): a forward pass
//! v_{i+1} = min(v_lim,i+1, √(v_i² + 2 A_t Δs)) from rest and a backward pass
//! v_i = min(v_i, √(v_{i+1}² + 2 A_t Δs)) to rest. Within an interval the
//! fastest motion between the two speeds accelerates at A_t up to the
//! interval's cap (the larger limit of its two samples), cruises there and
//! decelerates at A_t: its time is exact, so a straight line (limit F all
//! along) is timed exactly from its two end samples alone (the trapezoid or
//! the triangle), and [`crate::sample_path`] samples lines at their ends
//! only. Within a curved interval the limit between the samples is taken as
//! the larger of the two: the bound converges as the samples get closer.

use kerf_budget::{bytes_of, Budget};

use crate::error::{check_positive, ToolpathError};
use crate::samples::{check_samples, PathSample};

/// The limits of the bang-bang bound.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BangBangLimits {
    /// Largest speed F \[m/s\] (the programmed feed, at most the machine's).
    pub feed: f64,
    /// Largest tangential acceleration A_t \[m/s²\].
    pub tangential_acceleration: f64,
    /// Largest normal acceleration A_n \[m/s²\].
    pub normal_acceleration: f64,
}

impl BangBangLimits {
    /// Checks that every limit is finite and > 0.
    ///
    /// # Errors
    /// [`ToolpathError::InvalidParameter`] naming the limit.
    pub fn validate(&self) -> Result<(), ToolpathError> {
        check_positive(&[
            ("feed [m/s]", self.feed),
            (
                "tangential acceleration [m/s^2]",
                self.tangential_acceleration,
            ),
            ("normal acceleration [m/s^2]", self.normal_acceleration),
        ])
    }
}

/// The bound and its speed profile.
#[derive(Debug, Clone, PartialEq)]
pub struct BangBang {
    /// T_lb \[s\].
    pub time: f64,
    /// The optimal speed at every sample \[m/s\] (0 at both ends).
    pub speed: Vec<f64>,
    /// The velocity-limit curve at every sample \[m/s\].
    pub limit: Vec<f64>,
}

/// The bang-bang bound along `samples` (module documentation).
///
/// # Arguments
/// * `samples` — at least two, arc length strictly increasing.
/// * `limits` — F, A_t, A_n.
///
/// # Errors
/// [`ToolpathError::InvalidParameter`] for bad limits, fewer than two
/// samples, an arc length that does not increase, or a curvature that is
/// not finite and ≥ 0.
pub fn bang_bang(
    samples: &[PathSample],
    limits: &BangBangLimits,
) -> Result<BangBang, ToolpathError> {
    limits.validate()?;
    check_samples(samples)?;
    let limit: Vec<f64> = samples
        .iter()
        .map(|p| {
            if !(p.curvature.is_finite() && p.curvature >= 0.0) {
                return Err(ToolpathError::InvalidParameter {
                    name: "curvature [1/m]".to_string(),
                    value: p.curvature,
                    reason: "must be finite and >= 0".to_string(),
                });
            }
            Ok(if p.curvature > 0.0 {
                limits
                    .feed
                    .min((limits.normal_acceleration / p.curvature).sqrt())
            } else {
                limits.feed
            })
        })
        .collect::<Result<_, _>>()?;
    bang_bang_on(
        samples,
        limit,
        limits.tangential_acceleration,
        &Budget::unlimited(),
    )
}

/// The bang-bang bound under a given velocity-limit curve (one speed per
/// sample, e.g. [`crate::CurvatureLimits::speed`] of each sample's
/// curvature: seed 003 eq. 22) and the tangential acceleration A_t.
///
/// # Errors
/// [`ToolpathError::InvalidParameter`] for A_t not finite and > 0, a limit
/// that is not finite and > 0, another count of limits than samples, fewer
/// than two samples or an arc length that does not increase.
pub fn bang_bang_under(
    samples: &[PathSample],
    limit: Vec<f64>,
    tangential_acceleration: f64,
) -> Result<BangBang, ToolpathError> {
    bang_bang_under_within(
        samples,
        limit,
        tangential_acceleration,
        &Budget::unlimited(),
    )
}

/// [`bang_bang_under`] under a budget: the speeds' memory is checked before they are made,
/// the deadline before each of the three linear passes.
///
/// # Errors
/// As [`bang_bang_under`]; [`ToolpathError::Interrupted`] when the budget runs out.
pub fn bang_bang_under_within(
    samples: &[PathSample],
    limit: Vec<f64>,
    tangential_acceleration: f64,
    budget: &Budget,
) -> Result<BangBang, ToolpathError> {
    budget.check("lower bound T_lb")?;
    budget.check_memory(
        bytes_of::<f64>(samples.len() as u64),
        &format!("lower bound T_lb: speeds at {} samples", samples.len()),
    )?;
    check_samples(samples)?;
    check_positive(&[("tangential acceleration [m/s^2]", tangential_acceleration)])?;
    if limit.len() != samples.len() {
        return Err(ToolpathError::InvalidParameter {
            name: "velocity limits".to_string(),
            value: limit.len() as f64,
            reason: format!("one per sample ({})", samples.len()),
        });
    }
    if let Some(v) = limit.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
        return Err(ToolpathError::InvalidParameter {
            name: "velocity limit [m/s]".to_string(),
            value: *v,
            reason: "must be finite and > 0".to_string(),
        });
    }
    bang_bang_on(samples, limit, tangential_acceleration, budget)
}

/// The passes of the module documentation on checked input.
fn bang_bang_on(
    samples: &[PathSample],
    limit: Vec<f64>,
    a: f64,
    budget: &Budget,
) -> Result<BangBang, ToolpathError> {
    let n = samples.len();
    let mut speed = limit.clone();
    speed[0] = 0.0;
    budget.check("lower bound T_lb")?;
    for i in 0..n - 1 {
        let ds = samples[i + 1].s - samples[i].s;
        speed[i + 1] = speed[i + 1].min((speed[i] * speed[i] + 2.0 * a * ds).sqrt());
    }
    speed[n - 1] = 0.0;
    budget.check("lower bound T_lb")?;
    for i in (0..n - 1).rev() {
        let ds = samples[i + 1].s - samples[i].s;
        speed[i] = speed[i].min((speed[i + 1] * speed[i + 1] + 2.0 * a * ds).sqrt());
    }
    budget.check("lower bound T_lb")?;
    let time = samples
        .windows(2)
        .zip(speed.windows(2))
        .zip(limit.windows(2))
        .map(|((p, v), l)| interval_time(p[1].s - p[0].s, v[0], v[1], l[0].max(l[1]), a))
        .sum();
    Ok(BangBang { time, speed, limit })
}

/// The least time over `ds` from speed `v0` to `v1` with |acceleration| ≤
/// `a` and speed ≤ `cap` (the ends reachable from each other: |v1² − v0²| ≤
/// 2 a ds): accelerate at a, cruise at the cap if it is reached, decelerate
/// at a. The peak without a cap is √((v0² + v1²)/2 + a ds).
fn interval_time(ds: f64, v0: f64, v1: f64, cap: f64, a: f64) -> f64 {
    let peak = (0.5 * (v0 * v0 + v1 * v1) + a * ds).sqrt();
    if peak <= cap {
        (2.0 * peak - v0 - v1) / a
    } else {
        let accelerate = (cap * cap - v0 * v0) / (2.0 * a);
        let decelerate = (cap * cap - v1 * v1) / (2.0 * a);
        (2.0 * cap - v0 - v1) / a + (ds - accelerate - decelerate).max(0.0) / cap
    }
}
