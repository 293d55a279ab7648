//! Kinematic figures of a sampled joint trajectory: finite-difference
//! derivatives, peaks, RMS jerk and the check against the joint limits of
//! Table 2 (seed 001), filling [`Metrics`].
//!
//! The same estimator is applied to the MJTO plan and to the
//! quaternion-interpolation baseline, so the comparison of section 3
//! (Figures 10, 13, 15, 16) is fair.

use crate::error::LimitViolation;
use crate::machine::{AxisLimits, JOINT_NAMES};
use crate::plan::Metrics;

/// Relative tolerance of [`kinematic_metrics`]' limit check: values up to
/// `limit · (1 + 1e-6)` (positions: `1e-6` of the stroke outside it) are
/// rounding, not violations.
pub const LIMIT_REL_TOL: f64 = 1e-6;

/// One joint vector q1..q6 per sample.
pub type JointSeries = Vec<[f64; 6]>;

/// Points of the finite-difference stencil.
const STENCIL: usize = 5;

/// Weights of the derivatives of orders 0..=3 at `z` from the values at
/// the nodes `x` (Fornberg, "Generation of finite difference formulas on
/// arbitrarily spaced grids", Math. Comp. 51(184), 1988, algorithm of
/// Table 1): `f^(m)(z) ≈ Σ_j w[j][m] f(x_j)`, exact for polynomials of
/// degree < `x.len()`.
fn fornberg(z: f64, x: &[f64]) -> [[f64; 4]; STENCIL] {
    const M: usize = 3;
    let mut c = [[0.0; 4]; STENCIL];
    let n = x.len().min(STENCIL);
    if n == 0 {
        return c;
    }
    let mut c1 = 1.0;
    let mut c4 = x[0] - z;
    c[0][0] = 1.0;
    for i in 1..n {
        let mn = i.min(M);
        let mut c2 = 1.0;
        let c5 = c4;
        c4 = x[i] - z;
        for j in 0..i {
            let c3 = x[i] - x[j];
            c2 *= c3;
            if j == i - 1 {
                for k in (1..=mn).rev() {
                    c[i][k] = c1 * (k as f64 * c[i - 1][k - 1] - c5 * c[i - 1][k]) / c2;
                }
                c[i][0] = -c1 * c5 * c[i - 1][0] / c2;
            }
            for k in (1..=mn).rev() {
                c[j][k] = (c4 * c[j][k] - k as f64 * c[j][k - 1]) / c3;
            }
            c[j][0] = c4 * c[j][0] / c3;
        }
        c1 = c2;
    }
    c
}

/// Velocity, acceleration and jerk of sampled positions by finite
/// differences.
///
/// At sample `i` the derivatives of the polynomial through the five
/// samples `i-2 ..= i+2` (the window is shifted inward at the ends; fewer
/// samples give a smaller window) are taken, with Fornberg's weights for
/// arbitrary spacing: on the uniform Δt grid these are the classic central
/// differences, e.g. jerk `(x_{i+2} - 2x_{i+1} + 2x_{i-1} - x_{i-2}) / (2Δt³)`,
/// and on the possibly uneven last interval the divided differences of the
/// same polynomial. Velocity is O(Δt⁴), acceleration O(Δt³) and jerk
/// O(Δt²) accurate for smooth motion; polynomials of degree ≤ 4 are
/// differentiated exactly. The SAME estimator is applied to MJTO and the
/// QI baseline so the comparison is fair.
///
/// # Arguments
/// * `times` - strictly increasing sample times (s).
/// * `positions` - joint positions per sample.
///
/// # Returns
/// `(velocities, accelerations, jerks)`, one entry per sample (the
/// shorter of the two inputs). Repeated or non-finite times give
/// non-finite derivatives, which [`kinematic_metrics`] and
/// [`limit_violations`] report; a single sample has zero derivatives.
///
/// # Performance
/// O(samples); allocates the three result vectors.
pub fn finite_differences(
    times: &[f64],
    positions: &[[f64; 6]],
) -> (JointSeries, JointSeries, JointSeries) {
    let n = times.len().min(positions.len());
    let (times, positions) = (&times[..n], &positions[..n]);
    let width = n.min(STENCIL);
    let mut vel = Vec::with_capacity(n);
    let mut acc = Vec::with_capacity(n);
    let mut jerk = Vec::with_capacity(n);
    for i in 0..n {
        let lo = i.saturating_sub(width / 2).min(n - width);
        let nodes = &times[lo..lo + width];
        let w = fornberg(times[i], nodes);
        let mut d = [[0.0; 6]; 3];
        for (wj, p) in w.iter().zip(&positions[lo..lo + width]) {
            for (order, row) in d.iter_mut().enumerate() {
                for (slot, x) in row.iter_mut().zip(p) {
                    *slot += wj[order + 1] * x;
                }
            }
        }
        vel.push(d[0]);
        acc.push(d[1]);
        jerk.push(d[2]);
    }
    (vel, acc, jerk)
}

/// Peak |velocity|, |acceleration|, |jerk| and RMS jerk
/// (`√(Σ j² / samples)`) per joint, and the limit check of every sample
/// ([`limit_violations`] with [`LIMIT_REL_TOL`]).
///
/// `max_cl_error`, `max_lead_angle`, `max_tilt_angle` and
/// `colliding_samples` are left 0 for the caller to fill.
///
/// A NaN anywhere makes the affected peak NaN and is reported as a
/// violation (`within_limits` false).
///
/// # Arguments
/// * `times` - sample times (s), for the violation messages.
/// * `positions`, `velocities`, `accelerations`, `jerks` - per sample
///   (e.g. from [`finite_differences`]).
/// * `limits` - limits of q1..q6.
pub fn kinematic_metrics(
    times: &[f64],
    positions: &[[f64; 6]],
    velocities: &[[f64; 6]],
    accelerations: &[[f64; 6]],
    jerks: &[[f64; 6]],
    limits: &[AxisLimits; 6],
) -> Metrics {
    let violations = limit_violations(
        times,
        positions,
        velocities,
        accelerations,
        jerks,
        limits,
        LIMIT_REL_TOL,
    );
    let mut rms = [0.0; 6];
    for j in jerks {
        for (r, x) in rms.iter_mut().zip(j) {
            *r += x * x;
        }
    }
    if !jerks.is_empty() {
        for r in &mut rms {
            *r = (*r / jerks.len() as f64).sqrt();
        }
    }
    Metrics {
        peak_velocity: peak(velocities),
        peak_acceleration: peak(accelerations),
        peak_jerk: peak(jerks),
        rms_jerk: rms,
        within_limits: violations.is_empty(),
        limit_violations: violations.iter().map(describe).collect(),
        ..Metrics::default()
    }
}

/// Largest |x| per joint; NaN if any sample is NaN.
fn peak(values: &[[f64; 6]]) -> [f64; 6] {
    let mut out = [0.0_f64; 6];
    for v in values {
        for (o, x) in out.iter_mut().zip(v) {
            let a = x.abs();
            if !o.is_nan() && (a.is_nan() || a > *o) {
                *o = a;
            }
        }
    }
    out
}

/// One line per violation, e.g.
/// `q4 velocity 12.000000 exceeds 10.000000 at t = 1.234 s`.
fn describe(v: &LimitViolation) -> String {
    let verb = if v.quantity == "position" {
        "outside the stroke limit"
    } else {
        "exceeds"
    };
    format!(
        "{} {} {:.6} {verb} {:.6} at t = {:.3} s",
        v.joint, v.quantity, v.value, v.limit, v.time
    )
}

/// Every limit violation of the samples: at most the worst one per joint
/// and quantity, in joint order then position, velocity, acceleration,
/// jerk.
///
/// A position violates when it lies more than `rel_tol · (max - min)`
/// outside `[min, max]` (`limit` is then the bound it crosses); a
/// velocity, acceleration or jerk when `|x| > limit · (1 + rel_tol)`. The
/// worst is the one farthest beyond its bound; a NaN sample is always a
/// violation and the worst.
///
/// # Arguments
/// * `times` - sample times (s); a missing time is reported as NaN.
/// * `positions`, `velocities`, `accelerations`, `jerks` - per sample
///   (may have different lengths; each is checked over its own length).
/// * `limits` - limits of q1..q6.
/// * `rel_tol` - relative tolerance (≥ 0).
///
/// # Performance
/// O(samples); allocates only the result.
pub fn limit_violations(
    times: &[f64],
    positions: &[[f64; 6]],
    velocities: &[[f64; 6]],
    accelerations: &[[f64; 6]],
    jerks: &[[f64; 6]],
    limits: &[AxisLimits; 6],
    rel_tol: f64,
) -> Vec<LimitViolation> {
    let rel_tol = if rel_tol.is_finite() {
        rel_tol.max(0.0)
    } else {
        0.0
    };
    let mut out = Vec::new();
    for (joint, (name, l)) in JOINT_NAMES.iter().zip(limits).enumerate() {
        let tol = rel_tol * (l.max - l.min).abs();
        let quantities: [(&'static str, &[[f64; 6]], f64, f64); 4] = [
            ("position", positions, l.min - tol, l.max + tol),
            (
                "velocity",
                velocities,
                -l.vel * (1.0 + rel_tol),
                l.vel * (1.0 + rel_tol),
            ),
            (
                "acceleration",
                accelerations,
                -l.acc * (1.0 + rel_tol),
                l.acc * (1.0 + rel_tol),
            ),
            (
                "jerk",
                jerks,
                -l.jerk * (1.0 + rel_tol),
                l.jerk * (1.0 + rel_tol),
            ),
        ];
        for (quantity, samples, lo, hi) in quantities {
            // (excess, index, value); NaN excess = infinitely bad.
            let mut worst: Option<(f64, usize, f64)> = None;
            for (i, s) in samples.iter().enumerate() {
                let x = s[joint];
                let excess = if x.is_nan() {
                    f64::INFINITY
                } else if x > hi {
                    x - hi
                } else if x < lo {
                    lo - x
                } else {
                    continue;
                };
                if worst.is_none_or(|(w, _, _)| excess > w) {
                    worst = Some((excess, i, x));
                }
            }
            if let Some((_, i, value)) = worst {
                let limit = match quantity {
                    "position" if value < l.min => l.min,
                    "position" => l.max,
                    "velocity" => l.vel,
                    "acceleration" => l.acc,
                    _ => l.jerk,
                };
                out.push(LimitViolation {
                    joint: (*name).to_string(),
                    quantity,
                    value,
                    limit,
                    time: times.get(i).copied().unwrap_or(f64::NAN),
                });
            }
        }
    }
    out
}
