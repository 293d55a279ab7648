//! Verification of a feed plan on its output (issue 14, item 3): the plan
//! sampled at the interpolation period, every quantity evaluated on the
//! path's exact geometry at the plan's arc length
//! ([`crate::derivatives_at`]), as a ratio to its limit. A plan holds its
//! limits when every ratio is at most 1 (plus rounding, see
//! [`PlanCheck::holds`]).
//!
//! At every point of the plan (speed v, tangential acceleration a, jerk j,
//! unit tangent t, κ n = d²p/ds²):
//! * feed: v over min(F, the programmed feed there — at a sample its own,
//!   between two samples the lower of theirs);
//! * tangential acceleration |a| / A_t and jerk |j| / J_t;
//! * normal acceleration κ v² / a_n,lim (seed 003 eq. 18);
//! * normal jerk κ² v³ / j_n,lim (seed 003 eq. 20: j_n = v³/ρ², the limit of
//!   eq. 21);
//! * contour error ρ |1 − |G(j v/ρ)|| / ε_lim, the steady-state radius error
//!   of eq. 17's servo (as [`crate::metrics()`]);
//! * per axis i, by the chain rule of [`crate::axis`]: |t_i v| / V_i,
//!   |(κn)_i v² + t_i a| / A_i, |x_i‴ v³ + 3 (κn)_i v a + t_i j| / J_i with
//!   x‴ the central difference of κ n over ±1 µm of arc length.
//!
//! Between two consecutive points: the chord error, the largest distance
//! from their chord of the path between them, at every sample in between
//! and at a quarter, half and three quarters of the arc (seed 003 eq. 15's
//! quantity, measured), over Δ_lim.

use kerf_budget::Budget;

use crate::constraints::FeedConstraints;
use crate::error::check_positive;
use crate::feed::FeedPlan;
use crate::samples::{derivatives_at, PathSample};
use crate::smooth::SmoothedPath;
use crate::vec3::{cross, dot, norm, sub};
use crate::ToolpathError;

/// Arc-length step of the central difference of κ n \[m\].
const THIRD_STEP: f64 = 1e-6;

/// The largest ratio of one quantity to its limit and when it happens.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Worst {
    /// The largest ratio (0 if never positive).
    pub ratio: f64,
    /// Its time \[s\].
    pub time: f64,
}

impl Worst {
    fn note(&mut self, ratio: f64, time: f64) {
        if ratio > self.ratio || ratio.is_nan() {
            self.ratio = ratio;
            self.time = time;
        }
    }
}

/// The largest ratio to every limit of a plan (module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlanCheck {
    /// Speed over the feed (F and the per-sample feeds).
    pub feed: Worst,
    /// |a| over A_t.
    pub tangential_acceleration: Worst,
    /// |j| over J_t.
    pub tangential_jerk: Worst,
    /// κ v² over the normal acceleration limit.
    pub normal_acceleration: Worst,
    /// κ² v³ over the normal jerk limit.
    pub normal_jerk: Worst,
    /// The chord error of a period over Δ_lim.
    pub chord_error: Worst,
    /// The contour error over ε_lim (0 without a servo).
    pub contour_error: Worst,
    /// Axis speeds over their limits (0 without axis limits).
    pub axis_velocity: [Worst; 3],
    /// Axis accelerations over their limits.
    pub axis_acceleration: [Worst; 3],
    /// Axis jerks over their limits.
    pub axis_jerk: [Worst; 3],
    /// Points checked.
    pub points: usize,
}

impl PlanCheck {
    /// Every quantity with its name, in a fixed order.
    pub fn all(&self) -> Vec<(&'static str, Worst)> {
        let mut out = vec![
            ("feed", self.feed),
            ("tangential acceleration", self.tangential_acceleration),
            ("tangential jerk", self.tangential_jerk),
            ("normal acceleration", self.normal_acceleration),
            ("normal jerk", self.normal_jerk),
            ("chord error", self.chord_error),
            ("contour error", self.contour_error),
        ];
        for i in 0..3 {
            out.push((
                ["X velocity", "Y velocity", "Z velocity"][i],
                self.axis_velocity[i],
            ));
            out.push((
                ["X acceleration", "Y acceleration", "Z acceleration"][i],
                self.axis_acceleration[i],
            ));
            out.push((["X jerk", "Y jerk", "Z jerk"][i], self.axis_jerk[i]));
        }
        out
    }

    /// The quantity with the largest ratio.
    pub fn worst(&self) -> (&'static str, Worst) {
        self.all()
            .into_iter()
            .fold(("none", Worst::default()), |best, x| {
                if x.1.ratio > best.1.ratio || x.1.ratio.is_nan() {
                    x
                } else {
                    best
                }
            })
    }

    /// Whether every ratio is at most 1 + `margin` (the stated rounding
    /// margin; NaN fails).
    pub fn holds(&self, margin: f64) -> bool {
        self.all().iter().all(|(_, w)| w.ratio <= 1.0 + margin)
    }
}

/// Checks `plan` along `path` (`samples` being [`crate::sample_path`] of it)
/// against `constraints`, sampled at `period` (module documentation).
///
/// # Errors
/// [`ToolpathError::InvalidParameter`] for invalid constraints or a
/// period that is not finite and > 0.
pub fn check_plan(
    path: &SmoothedPath,
    samples: &[PathSample],
    plan: &FeedPlan,
    constraints: &FeedConstraints<'_>,
    period: f64,
) -> Result<PlanCheck, ToolpathError> {
    check_plan_within(
        path,
        samples,
        plan,
        constraints,
        period,
        &Budget::unlimited(),
    )
}

/// [`check_plan`] under a budget: the plan's points at the period are checked for memory
/// before they are made ([`FeedPlan::sample_within`]), the deadline every thousand points.
///
/// # Errors
/// As [`check_plan`]; [`ToolpathError::Interrupted`] when the budget runs out.
pub fn check_plan_within(
    path: &SmoothedPath,
    samples: &[PathSample],
    plan: &FeedPlan,
    constraints: &FeedConstraints<'_>,
    period: f64,
    budget: &Budget,
) -> Result<PlanCheck, ToolpathError> {
    constraints.validate(samples)?;
    check_positive(&[("check period [s]", period)])?;
    let lim = &constraints.limits;
    let c = &lim.curvature;
    let timed = plan.sample_within(period, budget)?;
    let mut out = PlanCheck {
        points: timed.len(),
        ..PlanCheck::default()
    };
    let mut previous: Option<[f64; 3]> = None;
    let mut previous_s = 0.0;
    for (k, p) in timed.iter().enumerate() {
        if k % 1024 == 1023 {
            budget.check("feed plan check")?;
        }
        let (x, t, kn) = derivatives_at(path, samples, p.s);
        let kappa = norm(kn);
        let (v, a, j) = (p.v, p.a, p.j);
        let feed = c.feed.min(cap_at(samples, constraints, p.s));
        out.feed.note(v / feed, p.t);
        out.tangential_acceleration
            .note(a.abs() / lim.tangential_acceleration, p.t);
        out.tangential_jerk.note(j.abs() / lim.tangential_jerk, p.t);
        out.normal_acceleration
            .note(kappa * v * v / c.normal_acceleration, p.t);
        out.normal_jerk
            .note(kappa * kappa * v * v * v / c.normal_jerk, p.t);
        if let (Some(servo), true) = (&c.servo, kappa > 0.0) {
            let rho = 1.0 / kappa;
            let wn = servo.natural_frequency;
            let w = v / rho;
            let gain = wn * wn
                / ((wn * wn - w * w).powi(2) + (2.0 * servo.damping * wn * w).powi(2)).sqrt();
            out.contour_error
                .note(rho * (1.0 - gain).abs() / servo.contour_error, p.t);
        }
        if let Some(axes) = &constraints.axes {
            let lo = (p.s - THIRD_STEP).max(samples[0].s);
            let hi = (p.s + THIRD_STEP).min(plan.length);
            let k3: [f64; 3] = if hi > lo {
                let (k_lo, k_hi) = (
                    derivatives_at(path, samples, lo).2,
                    derivatives_at(path, samples, hi).2,
                );
                std::array::from_fn(|i| (k_hi[i] - k_lo[i]) / (hi - lo))
            } else {
                [0.0; 3]
            };
            for i in 0..3 {
                out.axis_velocity[i].note((t[i] * v).abs() / axes.velocity[i], p.t);
                out.axis_acceleration[i]
                    .note((kn[i] * v * v + t[i] * a).abs() / axes.acceleration[i], p.t);
                let jerk = k3[i] * v * v * v + 3.0 * kn[i] * v * a + t[i] * j;
                out.axis_jerk[i].note(jerk.abs() / axes.jerk[i], p.t);
            }
        }
        if let Some(x0) = previous {
            let e = chord_error(path, samples, x0, x, previous_s, p.s);
            out.chord_error.note(e / c.chord_error, p.t);
        }
        previous = Some(x);
        previous_s = p.s;
    }
    Ok(out)
}

/// The programmed feed at arc length `s` (infinite without caps).
fn cap_at(samples: &[PathSample], constraints: &FeedConstraints<'_>, s: f64) -> f64 {
    let Some(caps) = constraints.caps else {
        return f64::INFINITY;
    };
    let k = samples.partition_point(|q| q.s < s);
    if k >= samples.len() {
        caps[samples.len() - 1]
    } else if samples[k].s == s || k == 0 {
        caps[k]
    } else {
        caps[k - 1].min(caps[k])
    }
}

/// The largest distance from the chord x0–x1 of the path between arc
/// lengths `s0` and `s1` (module documentation).
fn chord_error(
    path: &SmoothedPath,
    samples: &[PathSample],
    x0: [f64; 3],
    x1: [f64; 3],
    s0: f64,
    s1: f64,
) -> f64 {
    let chord = sub(x1, x0);
    let len = norm(chord);
    let distance = |q: [f64; 3]| {
        let d = sub(q, x0);
        if len > 0.0 {
            // Beyond the chord's ends, the distance to the nearer end.
            let along = dot(d, chord) / len;
            if along < 0.0 {
                norm(d)
            } else if along > len {
                norm(sub(q, x1))
            } else {
                norm(cross(d, chord)) / len
            }
        } else {
            norm(d)
        }
    };
    let lo = samples.partition_point(|q| q.s <= s0);
    let hi = samples.partition_point(|q| q.s < s1);
    let mut e: f64 = 0.0;
    for q in &samples[lo..hi.max(lo)] {
        e = e.max(distance(q.point));
    }
    if s1 > s0 {
        for f in [0.25, 0.5, 0.75] {
            e = e.max(distance(
                derivatives_at(path, samples, s0 + f * (s1 - s0)).0,
            ));
        }
    }
    e
}
