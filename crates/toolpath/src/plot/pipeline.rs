//! [`pipeline_plots`]: the figures of a smoothed path and its feed plan,
//! after seed 000 (KIRL) Fig. 5 (the input points as red dots and the
//! smoothed trajectory in XY) and seed 003 (DRLS) Figs. 12–14 (feed, chord
//! error, normal acceleration, normal jerk, contour error, tangential
//! acceleration and tangential jerk along the path, each with its limit).
//!
//! Every quantity is plotted against the arc length s of the plan's
//! samples at the interpolation period, in millimetres (speeds in mm/s,
//! errors in µm), with the path's geometry at s from
//! [`crate::derivatives_at`] (κ = |d²p/ds²|). The formulas and their
//! sources:
//!
//! * feed limit curve: v_f = min(v_p, v_Δ, v_a, v_j, v_c), seed 003 eq. 22
//!   ([`crate::CurvatureLimits::speed`]) at the path's samples;
//! * chord error of a period: measured, the largest distance of the path
//!   between two consecutive positions from the chord joining them
//!   ([`chord_error`]); and seed 003 eq. 15, Δ = ρ − √(ρ² − (L/2)²) with
//!   the period's arc length L ([`sagitta`]);
//! * normal acceleration a_n = v²/ρ, seed 003 eq. 18;
//! * normal jerk j_n = v³/ρ², seed 003 eq. 20 (the normal acceleration
//!   turning at constant speed and curvature); and the whole rate of change
//!   of the normal acceleration vector on a plane curve (Frenet–Serret,
//!   dn/ds = −κ t): d(v²κ n)/dt = (2 v a κ + v³ dκ/ds) n − v³ κ² t, with
//!   dκ/ds by a central difference of ±1 µm;
//! * contour error: the steady-state radius error of seed 003 eq. 17's
//!   servo, ρ (1 − |G(j v/ρ)|) ([`contour_error`]);
//! * tangential acceleration and jerk: the plan's own a and j (exact,
//!   piecewise constant jerk), against ±A_t and ±J_t.

use super::chart::{Chart, Style};
use crate::error::{check_positive, ToolpathError};
use crate::feed::{FeedLimits, FeedSample};
use crate::samples::{check_samples, derivatives_at, PathSample};
use crate::smooth::SmoothedPath;
use crate::speed_limit::Servo;
use crate::vec3::{cross, norm, sub};

/// Millimetres per metre: the plots' length unit.
const MM: f64 = 1e3;
/// Micrometres per metre: the plots' error unit.
const UM: f64 = 1e6;
/// Step of the central difference of κ in s \[m\].
const DKAPPA_STEP: f64 = 1e-6;

/// The figures of one smoothed path and its feed plan.
///
/// # Arguments
/// * `path`, `samples` — the path and its [`crate::sample_path`].
/// * `feed` — the plan sampled at `period` ([`crate::FeedPlan::sample`]).
/// * `limits` — the limits it was planned under.
/// * `period` — the time between `feed` samples \[s\]; the chord error is
///   that of one period.
///
/// # Returns
/// (file name, SVG document) pairs: `path_xy.svg`, `feed.svg`,
/// `chord_error.svg`, `normal_acceleration.svg`, `normal_jerk.svg`,
/// `contour_error.svg` (only with a servo in the limits),
/// `tangential_acceleration.svg`, `tangential_jerk.svg`.
///
/// # Errors
/// [`ToolpathError::InvalidParameter`] for bad limits, a `period` not
/// finite and > 0, fewer than two samples or feed samples, arc lengths that
/// do not increase, or any plotted value that is not finite (naming the
/// chart, the series and the point: nothing is dropped silently).
pub fn pipeline_plots(
    path: &SmoothedPath,
    samples: &[PathSample],
    feed: &[FeedSample],
    limits: &FeedLimits,
    period: f64,
) -> Result<Vec<(String, String)>, ToolpathError> {
    pipeline_charts(path, samples, feed, limits, period)?
        .into_iter()
        .map(|(name, chart)| Ok((name, chart.render()?)))
        .collect()
}

/// The charts of [`pipeline_plots`] before rendering, with their data (for
/// tables of the plotted maxima, or other renderings).
///
/// # Errors
/// As [`pipeline_plots`], except that non-finite plotted values are found
/// when a chart is rendered or validated ([`Chart::validate`]).
pub fn pipeline_charts(
    path: &SmoothedPath,
    samples: &[PathSample],
    feed: &[FeedSample],
    limits: &FeedLimits,
    period: f64,
) -> Result<Vec<(String, Chart)>, ToolpathError> {
    limits.validate()?;
    check_positive(&[("period [s]", period)])?;
    check_samples(samples)?;
    if feed.len() < 2 {
        return Err(ToolpathError::InvalidParameter {
            name: "feed samples".to_string(),
            value: feed.len() as f64,
            reason: "a plot needs at least two".to_string(),
        });
    }
    // A NaN arc length would be clamped to the path's start by
    // `derivatives_at`: refuse it here.
    for (k, p) in feed.iter().enumerate() {
        if let Some(v) = [p.t, p.s, p.v, p.a, p.j]
            .into_iter()
            .find(|v| !v.is_finite())
        {
            return Err(ToolpathError::InvalidParameter {
                name: format!("feed sample {k}"),
                value: v,
                reason: "not finite".to_string(),
            });
        }
    }
    let curvature = |s: f64| norm(derivatives_at(path, samples, s).2);
    let c = &limits.curvature;
    let x_label = "arc length s [mm]";
    let at = |f: &dyn Fn(&FeedSample) -> f64| -> Vec<[f64; 2]> {
        feed.iter().map(|p| [p.s * MM, f(p)]).collect()
    };
    let kappa: Vec<f64> = feed.iter().map(|p| curvature(p.s)).collect();
    let mut out = Vec::new();

    // Seed 000 Fig. 5: the input points (red dots) and the smoothed path.
    let xy = |p: &[f64; 3]| [p[0] * MM, p[1] * MM];
    let chart = Chart::new("Path in XY: G01 polyline and smoothed", "x [mm]", "y [mm]")
        .with_series(
            "G01 polyline",
            path.polyline.iter().map(xy).collect(),
            Style::Line,
            Some("#aaaaaa"),
        )
        .with_series(
            "smoothed",
            samples.iter().map(|q| xy(&q.point)).collect(),
            Style::Line,
            None,
        )
        .with_series(
            "G01 points",
            path.polyline.iter().map(xy).collect(),
            Style::Markers,
            Some("#d62728"),
        )
        .with_equal_aspect();
    out.push(("path_xy.svg".to_string(), chart));

    // Seed 003 Figs. 12b–14b: the feed, F and the velocity-limit curve of
    // eq. 22 at the path's samples (exact curvature there).
    let chart = Chart::new("Feed along the path", x_label, "feed v [mm/s]")
        .line("planned feed v", at(&|p| p.v * MM))
        .line(
            "limit v_f (eq. 22)",
            samples
                .iter()
                .map(|q| [q.s * MM, c.speed(q.curvature) * MM])
                .collect(),
        )
        .limit("programmed feed F", c.feed * MM);
    out.push(("feed.svg".to_string(), chart));

    // Chord error of each period: measured, and seed 003 eq. 15's estimate.
    let mut measured = Vec::with_capacity(feed.len());
    let mut estimate = Vec::with_capacity(feed.len());
    for w in feed.windows(2) {
        let (s0, s1) = (w[0].s, w[1].s);
        measured.push([s0 * MM, chord_error(path, samples, s0, s1) * UM]);
        // Eq. 15 with the period's chord (about v T) at the middle's curvature.
        let sag = sagitta(0.5 * (s1 - s0), curvature(0.5 * (s0 + s1)));
        estimate.push([s0 * MM, sag * UM]);
    }
    let chart = Chart::new(
        "Chord error per interpolation period",
        x_label,
        "chord error [µm]",
    )
    .line("measured", measured)
    .line("eq. 15 estimate", estimate)
    .limit("limit Δ_lim", c.chord_error * UM);
    out.push(("chord_error.svg".to_string(), chart));

    // Eq. 18: a_n = v² / ρ = v² κ.
    let normal: Vec<[f64; 2]> = feed
        .iter()
        .zip(&kappa)
        .map(|(p, k)| [p.s * MM, p.v * p.v * k * MM])
        .collect();
    let chart = Chart::new("Normal acceleration", x_label, "a_n [mm/s²]")
        .line("a_n = v² κ (eq. 18)", normal)
        .limit("limit a_n,lim", c.normal_acceleration * MM);
    out.push(("normal_acceleration.svg".to_string(), chart));

    // Eq. 20: j_n = v³ / ρ² (the normal acceleration turning at constant
    // speed and curvature); and the whole rate of change of the normal
    // acceleration vector a_n n on a plane curve (each piece of a smoothed
    // path is planar): d(v²κ n)/dt = (2 v a κ + v³ dκ/ds) n − v³ κ² t.
    let mut eq20 = Vec::with_capacity(feed.len());
    let mut full = Vec::with_capacity(feed.len());
    for (p, k) in feed.iter().zip(&kappa) {
        let v3 = p.v * p.v * p.v;
        let dk =
            (curvature(p.s + DKAPPA_STEP) - curvature(p.s - DKAPPA_STEP)) / (2.0 * DKAPPA_STEP);
        let turning = v3 * k * k;
        let growing = 2.0 * p.v * p.a * k + v3 * dk;
        eq20.push([p.s * MM, turning * MM]);
        full.push([p.s * MM, turning.hypot(growing) * MM]);
    }
    let chart = Chart::new("Normal jerk", x_label, "j_n [mm/s³]")
        .line("|d(a_n n)/dt|", full)
        .line("j_n = v³ κ² (eq. 20)", eq20)
        .limit("limit j_n,lim", c.normal_jerk * MM);
    out.push(("normal_jerk.svg".to_string(), chart));

    if let Some(servo) = &c.servo {
        let contour: Vec<[f64; 2]> = feed
            .iter()
            .zip(&kappa)
            .map(|(p, k)| [p.s * MM, contour_error(servo, p.v, *k) * UM])
            .collect();
        let chart = Chart::new(
            "Contour error (steady state)",
            x_label,
            "contour error [µm]",
        )
        .line("ρ (1 − |G(jv/ρ)|), eq. 17", contour)
        .limit("limit ε_lim", servo.contour_error * UM);
        out.push(("contour_error.svg".to_string(), chart));
    }

    let (a, j) = (limits.tangential_acceleration, limits.tangential_jerk);
    let chart = Chart::new("Tangential acceleration", x_label, "a_t [mm/s²]")
        .line("a_t = dv/dt", at(&|p| p.a * MM))
        .limit("+A_t", a * MM)
        .limit("−A_t", -a * MM);
    out.push(("tangential_acceleration.svg".to_string(), chart));
    let chart = Chart::new("Tangential jerk", x_label, "j_t [mm/s³]")
        .line("j_t = da/dt", at(&|p| p.j * MM))
        .limit("+J_t", j * MM)
        .limit("−J_t", -j * MM);
    out.push(("tangential_jerk.svg".to_string(), chart));
    Ok(out)
}

/// The largest distance of the path between arc lengths `s0` and `s1` from
/// the chord joining its points there: measured at the path samples
/// strictly between them and at the middle arc length \[m\].
pub fn chord_error(path: &SmoothedPath, samples: &[PathSample], s0: f64, s1: f64) -> f64 {
    let a = derivatives_at(path, samples, s0).0;
    let b = derivatives_at(path, samples, s1).0;
    let chord = sub(b, a);
    let len = norm(chord);
    let distance = |q: [f64; 3]| {
        if len > 0.0 {
            norm(cross(sub(q, a), chord)) / len
        } else {
            norm(sub(q, a))
        }
    };
    let lo = samples.partition_point(|q| q.s <= s0);
    let hi = samples.partition_point(|q| q.s < s1);
    samples[lo..hi.max(lo)]
        .iter()
        .map(|q| distance(q.point))
        .fold(
            distance(derivatives_at(path, samples, 0.5 * (s0 + s1)).0),
            f64::max,
        )
}

/// Seed 003 eq. 17's quantity: the steady-state radius error ρ (1 − |G(jω)|)
/// of the servo G(s) = ω_n² / (s² + 2ζω_n s + ω_n²) on a circle of radius
/// ρ = 1/κ at speed v (ω = v/ρ = vκ); 0 on a line \[m\].
///
/// Written without the cancellation of 1 − |G| near 1 (which, times a
/// radius of 10¹³ m at a numerically straight joint, gives millimetres):
/// with |D| = √((ω_n² − ω²)² + (2ζω_nω)²), 1 − |G| = (|D|² − ω_n⁴) /
/// (|D| (|D| + ω_n²)) = ω² (ω² + (4ζ² − 2) ω_n²) / (|D| (|D| + ω_n²)),
/// so ρ (1 − |G|) = v² κ (ω² + (4ζ² − 2) ω_n²) / (|D| (|D| + ω_n²)).
pub fn contour_error(servo: &Servo, v: f64, kappa: f64) -> f64 {
    let (wn, z) = (servo.natural_frequency, servo.damping);
    let w = v * kappa;
    let d = (wn * wn - w * w).hypot(2.0 * z * wn * w);
    (v * v * kappa * (w * w + (4.0 * z * z - 2.0) * wn * wn) / (d * (d + wn * wn))).abs()
}

/// Seed 003 eq. 15's chord error Δ = ρ − √(ρ² − h²) of a chord of half
/// length h on a circle of curvature κ = 1/ρ, as h² κ / (1 + √(1 − (hκ)²))
/// (no cancellation for large ρ); ρ where the chord would exceed the
/// diameter \[m\].
pub fn sagitta(half: f64, kappa: f64) -> f64 {
    let x = half * kappa;
    if x >= 1.0 {
        return 1.0 / kappa;
    }
    half * half * kappa / (1.0 + (1.0 - x * x).sqrt())
}
