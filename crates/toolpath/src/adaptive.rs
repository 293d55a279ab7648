//! [`sample_path_adaptive`]: a smoothed path sampled for feed planning with
//! steps bounded in arc length and turning, and a sample at every feature of
//! a corner's curvature, so that the curvature is monotone between samples.

use kerf_budget::{bytes_of, Budget, Interrupt};

use crate::corner_curve::CornerCurve;
use crate::error::ToolpathError;
use crate::maximum::golden_argmax;
use crate::samples::PathSample;
use crate::smooth::{Piece, SmoothedPath};
use crate::vec3::{dot, norm, scale, sub};

/// The relative slack the velocity-limit curve adds to the larger curvature
/// (and |dκ/ds|) of a [`PathSample::monotone`] interval's ends: on the flat
/// top of a curvature plateau an extremum pair can hide inside one step
/// (`tests/adaptive_samples.rs` measures the largest such excess on the
/// shipped paths and every corner method, 6.9·10⁻⁵ on a CCR corner of the
/// butterfly, and checks it is below this). It costs 0.05 % of the speed
/// where the acceleration law binds.
pub const MONOTONE_SLACK: f64 = 1e-3;

/// The relative slack the velocity-limit curve adds to the larger |dκ/ds|
/// of a [`PathSample::monotone`] interval's ends for the axes' jerk: a
/// maximum of |dκ/ds| narrower than the feature scan and the march's
/// quartile check can stay between two samples. Measured by
/// `tests/adaptive_samples.rs` on the shipped paths and every corner method:
/// at most 1.3 % on kerf's corners of the outlines, 9.1 % on the dense
/// rosette's nearly straight corners (turning about 10⁻⁶ rad, curvature
/// 0.03 1/m, where the curvature's own rounding shapes its slope).
pub const SLOPE_SLACK: f64 = 0.15;

/// The fewest steps [`sample_path_adaptive`] takes on a corner.
pub const MIN_CORNER_STEPS: usize = 8;

/// Points per knot span of the scan for a corner's features
/// ([`features`]).
pub const FEATURE_SCAN: usize = 32;

/// Golden-section steps locating a feature: the bracket shrinks to
/// 0.618²⁴ ≈ 10⁻⁵ of two scan steps, the value's error quadratic in that.
const EXTREMUM_STEPS: usize = 24;

/// The parameter step of the differences of [`slope`].
const SLOPE_STEP: f64 = 1e-7;

/// Samples a smoothed path for feed planning with steps bounded in arc
/// length and in turning, and a sample at every feature of a corner's
/// curvature.
///
/// * Lines are sampled at their two ends (as [`crate::sample_path`]).
/// * A corner's features are found first ([`features`]): every local
///   extremum of its curvature κ and every local maximum of |dκ/ds|, and a
///   spline's inner knots. They are sampled exactly, so between two samples
///   κ is monotone ([`PathSample::monotone`]) and |dκ/ds| is at most the
///   larger of its ends' ([`PathSample::curvature_slope`]): the limit curve
///   can bound an interval by its ends.
/// * Between features the parameter is marched so that every step is at
///   most `max_step` long (and at most 1/[`MIN_CORNER_STEPS`] of the
///   corner) and its tangent turns by at most `max_turn`.
///
/// The spacing follows the curve: a corner's flat ends take steps of up to
/// `max_step`, its apex steps of about `max_turn / κ`. A corner's curvature
/// profile keeps its shape when the corner is scaled, so a bound on the
/// turning per step resolves the apex of a 2 µm-radius hairpin and of a
/// 5 mm-radius bend alike, where a fixed arc-length step either misses the
/// first or oversamples the second.
///
/// Each step is predicted from the speed |C′| and the curvature at its start
/// (Δu = min(`max_step`, `max_turn`/κ) / |C′|) and shrunk until the angle
/// between its end tangents and its length
/// ([`crate::CornerCurve::length_between`]) are within the bounds and the
/// curvature and |dκ/ds| at its quartiles are not above its ends' (a check
/// of what the features promise). The angle between the end tangents is
/// the step's whole turning where the curvature keeps one sign (kerf's
/// corner, ICR); across an inflection (CCR's circumscribed curves) it is
/// less.
///
/// # Arguments
/// * `max_step` — the longest step on a corner \[m\], > 0.
/// * `max_turn` — the largest turning of the tangent over one step \[rad\],
///   in (0, π/2].
///
/// # Returns
/// The samples, as [`crate::sample_path`]'s (consecutive pieces share their
/// joining sample); `Err(InvalidParameter)` for a bound out of range.
///
/// # Performance
/// About θ/`max_turn` + L/`max_step` samples per corner of turning θ and
/// length L (at least [`MIN_CORNER_STEPS`]), each with a quadrature of its
/// length (8 points) and five curvature evaluations; the feature scan costs
/// [`FEATURE_SCAN`] curvature slopes per knot span and a golden section
/// per feature.
pub fn sample_path_adaptive(
    path: &SmoothedPath,
    max_step: f64,
    max_turn: f64,
) -> Result<Vec<PathSample>, ToolpathError> {
    sample_path_adaptive_within(path, max_step, max_turn, &Budget::unlimited())
}

/// [`sample_path_adaptive`] under a budget: the samples' memory is estimated before any is
/// made (per corner L/`max_step` + θ/`max_turn` + [`MIN_CORNER_STEPS`] + its features, about
/// 2 per scan span), the deadline checked at every step of the march.
///
/// # Errors
/// As [`sample_path_adaptive`]; [`ToolpathError::Interrupted`] when the budget runs out.
pub fn sample_path_adaptive_within(
    path: &SmoothedPath,
    max_step: f64,
    max_turn: f64,
    budget: &Budget,
) -> Result<Vec<PathSample>, ToolpathError> {
    if !(max_step.is_finite() && max_step > 0.0) {
        return Err(ToolpathError::InvalidParameter {
            name: "max_step".to_string(),
            value: max_step,
            reason: "must be finite and > 0".to_string(),
        });
    }
    if !(max_turn > 0.0 && max_turn <= std::f64::consts::FRAC_PI_2) {
        return Err(ToolpathError::InvalidParameter {
            name: "max_turn".to_string(),
            value: max_turn,
            reason: "must be in (0, pi/2] rad".to_string(),
        });
    }
    let mut estimate: f64 = 1.0;
    for piece in &path.pieces {
        budget.check("adaptive path sampling")?;
        estimate += match piece {
            Piece::Line { .. } => 1.0,
            Piece::Corner(c) => {
                (c.curve.length(8) / max_step).ceil()
                    + (c.turn.abs() / max_turn).ceil()
                    + (MIN_CORNER_STEPS + 2 * FEATURE_SCAN) as f64
            }
        };
    }
    let count = estimate.min(u64::MAX as f64) as u64;
    budget.check_memory(
        bytes_of::<PathSample>(count),
        &format!(
            "adaptive path samples: {} pieces at steps of {max_step:.3e} m and {max_turn:.3e} \
             rad, about {count} samples",
            path.pieces.len()
        ),
    )?;
    let mut out: Vec<PathSample> = Vec::new();
    let mut s0 = 0.0;
    for (index, piece) in path.pieces.iter().enumerate() {
        match piece {
            Piece::Line { start, end } => {
                let d = sub(*end, *start);
                let length = norm(d);
                let tangent = scale(d, 1.0 / length);
                // The joining sample starts this line's interval: curvature 0.
                if let Some(last) = out.last_mut() {
                    last.monotone = true;
                }
                for u in [0.0, 1.0] {
                    if u == 0.0 && !out.is_empty() {
                        continue;
                    }
                    out.push(PathSample {
                        s: s0 + u * length,
                        point: std::array::from_fn(|i| start[i] + u * d[i]),
                        tangent,
                        curvature: 0.0,
                        piece: index,
                        u,
                        monotone: true,
                        curvature_slope: 0.0,
                    });
                }
            }
            Piece::Corner(c) => {
                let curve = &c.curve;
                // The corner's own first sample (u = 0); the joining sample
                // of the previous piece stays in its place below.
                let first = corner_sample(curve, index, 0.0, s0);
                let step = max_step.min(curve.length(8) / MIN_CORNER_STEPS as f64);
                let local = march(curve, index, first, step, max_turn, budget)?;
                match out.last_mut() {
                    Some(last) => {
                        last.monotone = true;
                        last.curvature_slope = last.curvature_slope.max(local[0].curvature_slope);
                        out.extend_from_slice(&local[1..]);
                    }
                    None => out.extend_from_slice(&local),
                }
            }
        }
        s0 = out.last().map_or(s0, |p| p.s);
    }
    Ok(out)
}

/// The sample of a corner curve at parameter `u` and arc length `s`.
fn corner_sample(curve: &CornerCurve, piece: usize, u: f64, s: f64) -> PathSample {
    let d1 = curve.d1(u);
    let curvature = curve.curvature(u);
    PathSample {
        s,
        point: curve.point(u),
        tangent: scale(d1, 1.0 / norm(d1)),
        curvature,
        piece,
        u,
        monotone: true,
        curvature_slope: slope(curve, u, curvature, 0.0, 1.0),
    }
}

/// |dκ/ds| at `u` within [`lo`, `hi`]: the larger of the forward and
/// backward differences of the curvature over [`SLOPE_STEP`] in u (one side
/// at an end of the range), divided by the speed |C′|. At a knot the two
/// sides differ and the larger is kept. Truncation O(SLOPE_STEP κ″),
/// rounding about 1e-16 κ / SLOPE_STEP.
fn slope(curve: &CornerCurve, u: f64, curvature: f64, lo: f64, hi: f64) -> f64 {
    let speed = norm(curve.d1(u));
    if speed <= 0.0 {
        return 0.0;
    }
    let mut slope = 0.0f64;
    if u + SLOPE_STEP <= hi {
        slope = slope.max((curve.curvature(u + SLOPE_STEP) - curvature).abs());
    }
    if u - SLOPE_STEP >= lo {
        slope = slope.max((curvature - curve.curvature(u - SLOPE_STEP)).abs());
    }
    slope / (SLOPE_STEP * speed)
}

/// The parameters a corner's samples must include, sorted, in (0, 1): a
/// spline's inner knots, and on each knot span every local extremum of κ
/// and every local maximum of |dκ/ds|, found on [`FEATURE_SCAN`] + 1
/// equally spaced parameters and refined by golden section on the two scan
/// steps around each (on the first or last scan step where |dκ/ds| falls
/// away from the span's end). A feature narrower than a scan step could hide
/// between two scan points; the march's quartile check and `check_plan` on
/// the plan's output stand behind that.
pub fn features(curve: &CornerCurve) -> Vec<f64> {
    let mut spans: Vec<f64> = vec![0.0];
    if let CornerCurve::Spline(spline) = curve {
        spans.extend(
            spline
                .knots()
                .iter()
                .copied()
                .filter(|&u| u > 0.0 && u < 1.0),
        );
        spans.dedup();
    }
    spans.push(1.0);
    let mut out: Vec<f64> = spans[1..spans.len() - 1].to_vec();
    for w in spans.windows(2) {
        let (lo, hi) = (w[0], w[1]);
        if hi <= lo {
            continue;
        }
        let h = (hi - lo) / FEATURE_SCAN as f64;
        let grid: Vec<f64> = (0..=FEATURE_SCAN).map(|k| lo + k as f64 * h).collect();
        let kappa: Vec<f64> = grid.iter().map(|&u| curve.curvature(u)).collect();
        let slopes: Vec<f64> = grid
            .iter()
            .zip(&kappa)
            .map(|(&u, &k)| slope(curve, u, k, lo, hi))
            .collect();
        for j in 1..FEATURE_SCAN {
            let (a, b) = (grid[j - 1], grid[j + 1]);
            let (before, after) = (kappa[j] - kappa[j - 1], kappa[j + 1] - kappa[j]);
            if before != 0.0 && after != 0.0 && (before > 0.0) != (after > 0.0) {
                let sign = if before > 0.0 { 1.0 } else { -1.0 };
                out.push(golden_argmax(a, b, EXTREMUM_STEPS, |u| {
                    sign * curve.curvature(u)
                }));
            }
            if slopes[j] > slopes[j - 1] && slopes[j] > slopes[j + 1] {
                out.push(golden_argmax(a, b, EXTREMUM_STEPS, |u| {
                    slope(curve, u, curve.curvature(u), lo, hi)
                }));
            }
        }
        // A maximum of |dκ/ds| inside the first or last scan step shows as a
        // slope falling away from the span's end: searched there too.
        let n = FEATURE_SCAN;
        let slope_at = |u: f64| slope(curve, u, curve.curvature(u), lo, hi);
        if slopes[0] > slopes[1] {
            let u = golden_argmax(grid[0], grid[1], EXTREMUM_STEPS, slope_at);
            if slope_at(u) > slopes[0] {
                out.push(u);
            }
        }
        if slopes[n] > slopes[n - 1] {
            let u = golden_argmax(grid[n - 1], grid[n], EXTREMUM_STEPS, slope_at);
            if slope_at(u) > slopes[n] {
                out.push(u);
            }
        }
    }
    out.sort_by(f64::total_cmp);
    out.dedup_by(|a, b| (*a - *b).abs() <= 1e-9);
    out
}

/// Marches a corner curve from `first` (u = 0) to u = 1 in steps of at most
/// `max_step` arc length and `max_turn` turning, landing on every one of
/// its [`features`] ([`sample_path_adaptive`]).
fn march(
    curve: &CornerCurve,
    piece: usize,
    first: PathSample,
    max_step: f64,
    max_turn: f64,
    budget: &Budget,
) -> Result<Vec<PathSample>, Interrupt> {
    let cos_turn = max_turn.cos();
    let mut breaks = features(curve);
    breaks.push(1.0);
    let mut local = vec![first];
    let mut here = first;
    let mut next_break = 0usize;
    while here.u < 1.0 {
        budget.check("adaptive path sampling")?;
        while breaks[next_break] <= here.u {
            next_break += 1;
        }
        let target = breaks[next_break];
        let speed = norm(curve.d1(here.u));
        let reach = if here.curvature > 0.0 {
            max_step.min(max_turn / here.curvature)
        } else {
            max_step
        };
        let mut du = if speed > 0.0 {
            (reach / speed).min(target - here.u)
        } else {
            target - here.u
        };
        let next = loop {
            let u = if here.u + du >= target {
                target
            } else {
                here.u + du
            };
            // A step of 1e-12 in u is below any turning a feed plan resolves.
            let last_try = du < 1e-12;
            // The cheap test first: the turn, from the tangent at the end.
            let d1 = curve.d1(u);
            let cos = dot(here.tangent, d1) / norm(d1);
            if cos < cos_turn && !last_try {
                // Towards the step that turns max_turn (the turning grows
                // about linearly with the step), at least halving.
                let turned = cos.clamp(-1.0, 1.0).acos();
                du *= (0.9 * max_turn / turned).min(0.5);
                continue;
            }
            let ds = curve.length_between(here.u, u);
            if ds > max_step * (1.0 + 1e-9) && !last_try {
                du *= (0.9 * max_step / ds).min(0.5);
                continue;
            }
            let candidate = corner_sample(curve, piece, u, here.s + ds);
            // The curvature and |dκ/ds| at the step's quartiles within its
            // ends' (up to MONOTONE_SLACK): a bump the feature scan missed
            // (a hairpin's apex is narrower than a scan step) splits the step.
            let top = here.curvature.max(candidate.curvature) * (1.0 + MONOTONE_SLACK);
            let slope_top =
                here.curvature_slope.max(candidate.curvature_slope) * (1.0 + MONOTONE_SLACK);
            let flat = [0.25, 0.5, 0.75].iter().all(|f| {
                let v = here.u + f * (u - here.u);
                let k = curve.curvature(v);
                k <= top && slope(curve, v, k, here.u, u) <= slope_top
            });
            if flat || last_try {
                break candidate;
            }
            du *= 0.5;
        };
        local.push(next);
        here = next;
    }
    Ok(local)
}

/// How a smoothed path is sampled for feed planning.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sampling {
    /// [`crate::sample_path`]: corners at equal parameter steps of `step`
    /// arc length on average \[m\].
    Fixed {
        /// Mean arc length between a corner's samples \[m\], > 0.
        step: f64,
    },
    /// [`sample_path_adaptive`].
    Adaptive {
        /// The longest step on a corner \[m\], > 0.
        max_step: f64,
        /// The largest turning over one step \[rad\], in (0, π/2].
        max_turn: f64,
    },
}

impl Default for Sampling {
    /// Fixed 10 µm steps (the figures of BENCHMARKS.md's G-code sections).
    fn default() -> Self {
        Sampling::Fixed { step: 1e-5 }
    }
}

impl Sampling {
    /// Adaptive samples of at most 1 mm and 2° (BENCHMARKS.md, "Sampling
    /// the path").
    pub fn adaptive() -> Self {
        Sampling::Adaptive {
            max_step: 1e-3,
            max_turn: 2f64.to_radians(),
        }
    }

    /// Samples `path`.
    ///
    /// # Errors
    /// `InvalidParameter` for a bound out of range.
    pub fn sample(&self, path: &SmoothedPath) -> Result<Vec<PathSample>, ToolpathError> {
        self.sample_within(path, &Budget::unlimited())
    }

    /// [`Self::sample`] under a budget ([`crate::samples::sample_path_within`],
    /// [`sample_path_adaptive_within`]).
    ///
    /// # Errors
    /// As [`Self::sample`]; [`ToolpathError::Interrupted`] when the budget runs out.
    pub fn sample_within(
        &self,
        path: &SmoothedPath,
        budget: &Budget,
    ) -> Result<Vec<PathSample>, ToolpathError> {
        match *self {
            Sampling::Fixed { step } => {
                if !(step.is_finite() && step > 0.0) {
                    return Err(ToolpathError::InvalidParameter {
                        name: "sample step".to_string(),
                        value: step,
                        reason: "must be finite and > 0".to_string(),
                    });
                }
                Ok(crate::samples::sample_path_within(path, step, budget)?)
            }
            Sampling::Adaptive { max_step, max_turn } => {
                sample_path_adaptive_within(path, max_step, max_turn, budget)
            }
        }
    }

    /// The same sampling `factor` times finer (every bound divided by it).
    pub fn finer(&self, factor: f64) -> Self {
        match *self {
            Sampling::Fixed { step } => Sampling::Fixed {
                step: step / factor,
            },
            Sampling::Adaptive { max_step, max_turn } => Sampling::Adaptive {
                max_step: max_step / factor,
                max_turn: max_turn / factor,
            },
        }
    }
}
