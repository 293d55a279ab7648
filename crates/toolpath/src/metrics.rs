//! The metrics of seeds 000 and 003 on what the machine would run: the feed
//! plan sampled at the interpolation period, mapped to positions along the
//! path.
//!
//! * T_m: the plan's time.
//! * κ_max: the largest curvature of the path's samples.
//! * θ_max: the largest angle between consecutive chords of the
//!   interpolated points (seed 000 section 4.2: "the largest angle between
//!   consecutive path segments").
//! * a_rms, j_rms: seed 000 eqs. 16–17, √(Σ‖a_i‖²/N) and √(Σ‖j_i‖²/N), with
//!   the Cartesian acceleration and jerk of the interpolated points by
//!   central second and third differences at the period.
//! * Chord error: the largest distance of the path between two consecutive
//!   interpolated points from the chord joining them (seed 003 eq. 15's
//!   quantity, measured instead of estimated).
//! * Contour error: the steady-state radius error of seed 003 eq. 17's
//!   servo, ρ (1 − |G(j v/ρ)|), at every interpolated point (its own
//!   speed and the path's radius there): an estimate, not a simulation.
//!
//! Positions are on the path's geometry at the plan's arc length
//! ([`crate::samples::point_at`]), not interpolated between samples: a
//! linear interpolation put kinks every sample into the third differences
//! (j_rms several times its true value when the period's step is shorter
//! than the sample spacing).

use kerf_budget::{bytes_of, Budget, Interrupt};

use crate::feed::{FeedPlan, FeedSample};
use crate::samples::{point_at, PathSample};
use crate::smooth::SmoothedPath;
use crate::speed_limit::Servo;
use crate::vec3::{add, cross, dot, norm, scale, sub};

/// The metrics of one plan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Metrics {
    /// T_m \[s\].
    pub time: f64,
    /// κ_max \[1/m\].
    pub max_curvature: f64,
    /// θ_max \[rad\].
    pub max_turning_angle: f64,
    /// a_rms \[m/s²\].
    pub rms_acceleration: f64,
    /// j_rms \[m/s³\].
    pub rms_jerk: f64,
    /// The largest chord error \[m\].
    pub max_chord_error: f64,
    /// The largest steady-state contour error \[m\] (0 without a servo).
    pub max_contour_error: f64,
    /// Interpolated points N.
    pub points: usize,
}

/// The metrics of `plan` along `samples` at `period` (module
/// documentation), `samples` being [`crate::sample_path`] of `path`.
pub fn metrics(
    plan: &FeedPlan,
    path: &SmoothedPath,
    samples: &[PathSample],
    period: f64,
    servo: Option<&Servo>,
) -> Metrics {
    let timed = plan.sample(period);
    let points: Vec<[f64; 3]> = timed.iter().map(|p| point_at(path, samples, p.s)).collect();
    metrics_of(plan, samples, &timed, &points, period, servo)
}

/// [`metrics()`] under a budget: the plan's points at the period are checked for memory before
/// they are made, the deadline every thousand points placed on the path.
///
/// # Errors
/// [`Interrupt`] when the budget runs out.
pub fn metrics_within(
    plan: &FeedPlan,
    path: &SmoothedPath,
    samples: &[PathSample],
    period: f64,
    servo: Option<&Servo>,
    budget: &Budget,
) -> Result<Metrics, Interrupt> {
    let count = plan.sample_count(period);
    budget.check_memory(
        bytes_of::<[f64; 3]>(count).saturating_add(bytes_of::<FeedSample>(count)),
        &format!(
            "metrics at the interpolation period: {:.3e} s / {period} s = {count} points",
            plan.time
        ),
    )?;
    let timed = plan.sample_within(period, budget)?;
    let mut points: Vec<[f64; 3]> = Vec::with_capacity(timed.len());
    for (k, p) in timed.iter().enumerate() {
        if k % 1024 == 1023 {
            budget.check("metrics")?;
        }
        points.push(point_at(path, samples, p.s));
    }
    budget.check("metrics")?;
    Ok(metrics_of(plan, samples, &timed, &points, period, servo))
}

/// The metrics of the plan's points `timed` at `period`, placed on the path at `points`.
fn metrics_of(
    plan: &FeedPlan,
    samples: &[PathSample],
    timed: &[FeedSample],
    points: &[[f64; 3]],
    period: f64,
    servo: Option<&Servo>,
) -> Metrics {
    let n = points.len();
    let max_curvature = samples.iter().map(|p| p.curvature).fold(0.0, f64::max);
    let mut max_turning_angle: f64 = 0.0;
    for w in points.windows(3) {
        let (c1, c2) = (sub(w[1], w[0]), sub(w[2], w[1]));
        if norm(c1) > 0.0 && norm(c2) > 0.0 {
            max_turning_angle = max_turning_angle.max(norm(cross(c1, c2)).atan2(dot(c1, c2)));
        }
    }
    let t2 = period * period;
    let (mut sum_a, mut count_a) = (0.0, 0usize);
    for w in points.windows(3) {
        let a = scale(add(sub(w[2], scale(w[1], 2.0)), w[0]), 1.0 / t2);
        sum_a += dot(a, a);
        count_a += 1;
    }
    let (mut sum_j, mut count_j) = (0.0, 0usize);
    for w in points.windows(4) {
        // Third difference: p3 − 3 p2 + 3 p1 − p0.
        let d = add(sub(w[3], scale(w[2], 3.0)), sub(scale(w[1], 3.0), w[0]));
        let j = scale(d, 1.0 / (t2 * period));
        sum_j += dot(j, j);
        count_j += 1;
    }
    let mut max_chord_error: f64 = 0.0;
    for (w, p) in points.windows(2).zip(timed.windows(2)) {
        let chord = sub(w[1], w[0]);
        let len = norm(chord);
        let lo = samples.partition_point(|q| q.s < p[0].s);
        let hi = samples.partition_point(|q| q.s <= p[1].s);
        for q in &samples[lo..hi.min(samples.len())] {
            let d = if len > 0.0 {
                norm(cross(sub(q.point, w[0]), chord)) / len
            } else {
                norm(sub(q.point, w[0]))
            };
            max_chord_error = max_chord_error.max(d);
        }
    }
    let mut max_contour_error: f64 = 0.0;
    if let Some(servo) = servo {
        let wn = servo.natural_frequency;
        for p in timed {
            let k = samples
                .partition_point(|q| q.s < p.s)
                .min(samples.len() - 1);
            let kappa = samples[k].curvature;
            if kappa > 0.0 && p.v > 0.0 {
                let rho = 1.0 / kappa;
                let w = p.v / rho;
                let gain = wn * wn
                    / ((wn * wn - w * w).powi(2) + (2.0 * servo.damping * wn * w).powi(2)).sqrt();
                max_contour_error = max_contour_error.max(rho * (1.0 - gain).abs());
            }
        }
    }
    Metrics {
        time: plan.time,
        max_curvature,
        max_turning_angle,
        rms_acceleration: (sum_a / count_a.max(1) as f64).sqrt(),
        rms_jerk: (sum_j / count_j.max(1) as f64).sqrt(),
        max_chord_error,
        max_contour_error,
        points: n,
    }
}
