//! A smoothed path sampled by arc length: positions, unit tangents and
//! curvature at every sample, for feed planning ([`crate::lower_bound`]).

use kerf_budget::{bytes_of, Budget};

use crate::error::ToolpathError;
use crate::smooth::{Piece, SmoothedPath};
use crate::vec3::{dot, norm, scale, sub};

/// One sample of a path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathSample {
    /// Arc length from the path's start \[m\].
    pub s: f64,
    /// Position \[m\].
    pub point: [f64; 3],
    /// Unit tangent.
    pub tangent: [f64; 3],
    /// Curvature \[1/m\].
    pub curvature: f64,
    /// Index of its piece in [`SmoothedPath::pieces`].
    pub piece: usize,
    /// Its parameter in the piece (a line's fraction of its length, a
    /// corner curve's parameter).
    pub u: f64,
    /// Whether the curvature is known to be monotone from this sample to the
    /// next: [`crate::sample_path_adaptive`] places samples at every extremum of a
    /// corner's curvature (and a line's is 0), so the larger curvature of an
    /// interval's two ends is its largest; [`sample_path`] does not (false).
    pub monotone: bool,
    /// |dκ/ds| at the sample \[1/m²\], the larger of its one-sided values
    /// (they differ at a spline's knots and where a corner meets a line);
    /// [`crate::sample_path_adaptive`] also samples every maximum of |dκ/ds| on a
    /// corner, so on a [`Self::monotone`] interval the larger of its ends'
    /// bounds it. 0 from [`sample_path`] (not computed).
    pub curvature_slope: f64,
}

/// Samples a smoothed path: lines at their two ends, corners at
/// ⌈length / `max_step`⌉ equal parameter steps (their arc lengths by
/// [`crate::CornerCurve::length_between`]; a step is `max_step` long on
/// average, longer where the curve's speed in its parameter is above its
/// mean). Consecutive pieces share their joining sample (kept once).
///
/// # Arguments
/// * `max_step` — mean arc length between samples of a corner \[m\], > 0.
pub fn sample_path(path: &SmoothedPath, max_step: f64) -> Vec<PathSample> {
    // Only the budget interrupts, and an unlimited one never does.
    sample_path_within(path, max_step, &Budget::unlimited()).unwrap_or_default()
}

/// Samples between two checks of the deadline in [`sample_path_within`].
const CHECK_EVERY: usize = 4096;

/// [`sample_path`] under a budget: every piece's sample count is computed first and their
/// memory checked before any is made (a step of 10⁻³⁰⁰ m is refused by the estimate), the
/// deadline every few thousand samples.
///
/// # Errors
/// [`kerf_budget::Interrupt`] when the budget runs out.
pub fn sample_path_within(
    path: &SmoothedPath,
    max_step: f64,
    budget: &Budget,
) -> Result<Vec<PathSample>, kerf_budget::Interrupt> {
    let mut counts: Vec<(f64, usize)> = Vec::with_capacity(path.pieces.len());
    let mut total: f64 = 1.0;
    for (k, piece) in path.pieces.iter().enumerate() {
        if k % CHECK_EVERY == 0 {
            budget.check("path sampling")?;
        }
        counts.push(match piece {
            // A line at its two ends: its curvature is 0, positions on it are exact
            // by proportion, and T_lb times a whole line exactly.
            Piece::Line { start, end } => (norm(sub(*end, *start)), 1),
            Piece::Corner(c) => {
                let l = c.curve.length(8);
                let steps = (l / max_step).ceil().max(1.0);
                total += steps;
                // Saturates for an absurd step; the estimate below refuses it.
                (l, steps.min(u64::MAX as f64) as usize)
            }
        });
        if matches!(piece, Piece::Line { .. }) {
            total += 1.0;
        }
    }
    let count = total.min(u64::MAX as f64) as u64;
    budget.check_memory(
        bytes_of::<PathSample>(count),
        &format!(
            "path samples: {} pieces at {max_step:.3e} m steps on corners, {count} samples",
            path.pieces.len()
        ),
    )?;
    // Reserved up to 2²⁰ samples: an unlimited budget's absurd count grows as it is sampled.
    let mut out: Vec<PathSample> =
        Vec::with_capacity(usize::try_from(count.min(1 << 20)).unwrap_or(0));
    let mut s0 = 0.0;
    for ((index, piece), &(length, steps)) in path.pieces.iter().enumerate().zip(&counts) {
        let mut s = s0;
        for k in 0..=steps {
            if k % CHECK_EVERY == CHECK_EVERY - 1 {
                budget.check("path sampling")?;
            }
            if k == 0 && !out.is_empty() {
                continue;
            }
            let u = k as f64 / steps as f64;
            let sample = match piece {
                Piece::Line { start, end } => {
                    let d = sub(*end, *start);
                    PathSample {
                        s: s0 + u * length,
                        point: std::array::from_fn(|i| start[i] + u * d[i]),
                        tangent: scale(d, 1.0 / length),
                        curvature: 0.0,
                        piece: index,
                        u,
                        monotone: false,
                        curvature_slope: 0.0,
                    }
                }
                Piece::Corner(c) => {
                    if k > 0 {
                        s += c.curve.length_between((k - 1) as f64 / steps as f64, u);
                    }
                    let d1 = c.curve.d1(u);
                    PathSample {
                        s,
                        point: c.curve.point(u),
                        tangent: scale(d1, 1.0 / norm(d1)),
                        curvature: c.curve.curvature(u),
                        piece: index,
                        u,
                        monotone: false,
                        curvature_slope: 0.0,
                    }
                }
            };
            out.push(sample);
        }
        // The next piece starts where this one's last sample is (a corner's
        // summed sub-lengths, not its separately computed total).
        s0 = out.last().map_or(s0, |p| p.s);
    }
    Ok(out)
}

/// The point of `path` at arc length `s`, exactly on its geometry: on a
/// line by proportion, on a corner by Newton's method on the arc length
/// from the sample before it (3 steps from the linear guess, each with
/// [`crate::CornerCurve::length_between`]), clamped to the path's ends.
///
/// # Arguments
/// * `samples` — [`sample_path`] of `path`.
pub fn point_at(path: &SmoothedPath, samples: &[PathSample], s: f64) -> [f64; 3] {
    derivatives_at(path, samples, s).0
}

/// The point of `path` at arc length `s` with its first and second
/// derivatives in arc length: (p, dp/ds, d²p/ds²). dp/ds is the unit
/// tangent; d²p/ds² = κ n, from the curve's parameter derivatives C′, C″ by
/// the chain rule: (C″ − (C″·t) t) / |C′|² (a line's is zero).
///
/// # Arguments
/// * `samples` — [`sample_path`] of `path`; `s` is clamped to its ends.
///
/// # Performance
/// As [`point_at`]: a binary search and, on a corner, 3 Newton steps.
pub fn derivatives_at(
    path: &SmoothedPath,
    samples: &[PathSample],
    s: f64,
) -> ([f64; 3], [f64; 3], [f64; 3]) {
    let (piece, u) = parameter_at(path, samples, s);
    match path.pieces.get(piece) {
        Some(Piece::Line { start, end }) => {
            let d = sub(*end, *start);
            let t = scale(d, 1.0 / norm(d));
            (std::array::from_fn(|k| start[k] + u * d[k]), t, [0.0; 3])
        }
        Some(Piece::Corner(c)) => {
            let d1 = c.curve.d1(u);
            let d2 = c.curve.d2(u);
            let speed = norm(d1);
            let t = scale(d1, 1.0 / speed);
            let along = dot(d2, t);
            let n: [f64; 3] = std::array::from_fn(|k| (d2[k] - along * t[k]) / (speed * speed));
            (c.curve.point(u), t, n)
        }
        None => {
            let last = &samples[samples.len() - 1];
            (last.point, last.tangent, [0.0; 3])
        }
    }
}

/// The piece and its parameter at arc length `s`, as [`point_at`] finds them.
fn parameter_at(path: &SmoothedPath, samples: &[PathSample], s: f64) -> (usize, f64) {
    let k = samples.partition_point(|p| p.s < s);
    if k == 0 {
        return (samples[0].piece, samples[0].u);
    }
    if k >= samples.len() {
        let last = &samples[samples.len() - 1];
        return (last.piece, last.u);
    }
    let (a, b) = (&samples[k - 1], &samples[k]);
    let ua = if a.piece == b.piece { a.u } else { 0.0 };
    let guess = ua + (s - a.s) / (b.s - a.s) * (b.u - ua);
    match path.pieces.get(b.piece) {
        Some(Piece::Corner(c)) => {
            let mut u = guess;
            for _ in 0..3 {
                let f = c.curve.length_between(ua, u) - (s - a.s);
                let speed = norm(c.curve.d1(u));
                if speed > 0.0 {
                    u = (u - f / speed).clamp(ua, b.u);
                }
            }
            (b.piece, u)
        }
        _ => (b.piece, guess),
    }
}

/// At least two samples with increasing arc length.
pub(crate) fn check_samples(samples: &[PathSample]) -> Result<(), ToolpathError> {
    if samples.len() < 2 {
        return Err(ToolpathError::InvalidParameter {
            name: "samples".to_string(),
            value: samples.len() as f64,
            reason: "a path needs at least two".to_string(),
        });
    }
    for (k, w) in samples.windows(2).enumerate() {
        if w[1].s.partial_cmp(&w[0].s) != Some(std::cmp::Ordering::Greater) {
            return Err(ToolpathError::InvalidParameter {
                name: format!("arc length of sample {}", k + 1),
                value: w[1].s,
                reason: format!("must exceed the previous one ({})", w[0].s),
            });
        }
    }
    Ok(())
}
