//! A smoothed path sampled by arc length: positions, unit tangents and
//! curvature at every sample, for feed planning ([`crate::lower_bound`]).

use crate::corner_curve::CornerCurve;
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
    /// next: [`sample_path_adaptive`] places samples at every extremum of a
    /// corner's curvature (and a line's is 0), so the larger curvature of an
    /// interval's two ends is its largest; [`sample_path`] does not (false).
    pub monotone: bool,
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
    let mut out: Vec<PathSample> = Vec::new();
    let mut s0 = 0.0;
    for (index, piece) in path.pieces.iter().enumerate() {
        let (length, steps) = match piece {
            // A line at its two ends: its curvature is 0, positions on it are exact
            // by proportion, and T_lb times a whole line exactly.
            Piece::Line { start, end } => (norm(sub(*end, *start)), 1),
            Piece::Corner(c) => {
                let l = c.curve.length(8);
                (l, (l / max_step).ceil().max(1.0) as usize)
            }
        };
        let mut s = s0;
        for k in 0..=steps {
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
                    }
                }
            };
            out.push(sample);
        }
        // The next piece starts where this one's last sample is (a corner's
        // summed sub-lengths, not its separately computed total).
        s0 = out.last().map_or(s0, |p| p.s);
    }
    out
}

/// Samples a smoothed path for feed planning with steps bounded in arc
/// length and in turning: lines at their two ends (as [`sample_path`]),
/// corners by marching their parameter so that every step is at most
/// `max_step` long (and at most 1/[`MIN_CORNER_STEPS`] of the corner) and its
/// tangent turns by at most `max_turn`; then a sample at every extremum of
/// the corner's curvature.
///
/// The spacing follows the curve: a corner's flat ends (curvature near 0)
/// take steps of up to `max_step`, its apex steps of about
/// `max_turn / κ`. A corner's curvature profile keeps its shape when the
/// corner is scaled, so a bound on the turning per step resolves the apex of
/// a 2 µm-radius hairpin and of a 5 mm-radius bend alike, where a fixed
/// arc-length step either misses the first or oversamples the second.
///
/// Each step is predicted from the speed |C′| and the curvature at its start
/// (Δu = min(`max_step`, `max_turn`/κ) / |C′|), then halved until its
/// length ([`crate::CornerCurve::length_between`]) and the angle between
/// its two tangents are within the bounds and the curvature at its quartiles
/// is not above its ends' (a narrow bump would hide between two samples). The angle between the end
/// tangents is the step's whole turning where the corner's curvature keeps
/// one sign (kerf's corner, ICR); across an inflection (CCR's circumscribed
/// curves) it is less, and a sample inserted at the inflection splits the
/// step into halves that may each turn more.
///
/// # Arguments
/// * `max_step` — the longest step on a corner \[m\], > 0.
/// * `max_turn` — the largest turning of the tangent over one step \[rad\],
///   in (0, π/2].
///
/// # Returns
/// The samples, as [`sample_path`]'s (consecutive pieces share their joining
/// sample); `Err(InvalidParameter)` for a bound out of range.
///
/// # Performance
/// About θ/`max_turn` + L/`max_step` samples per corner of turning θ and
/// length L, each with a quadrature of its length (8 points); a rejected
/// step costs one more.
pub fn sample_path_adaptive(
    path: &SmoothedPath,
    max_step: f64,
    max_turn: f64,
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
                    });
                }
            }
            Piece::Corner(c) => {
                let curve = &c.curve;
                // The corner's own first sample (u = 0): the joining sample
                // of the previous piece, kept in its place below.
                let first = corner_sample(curve, index, 0.0, s0);
                // At least MIN_CORNER_STEPS steps: a corner's two curvature
                // peaks and the dip between them are then told apart, however
                // little the corner turns.
                let step = max_step.min(curve.length(8) / MIN_CORNER_STEPS as f64);
                let local = insert_extrema(curve, march(curve, index, first, step, max_turn));
                match out.last_mut() {
                    Some(last) => {
                        last.monotone = true;
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
    PathSample {
        s,
        point: curve.point(u),
        tangent: scale(d1, 1.0 / norm(d1)),
        curvature: curve.curvature(u),
        piece,
        u,
        monotone: true,
    }
}

/// Marches a corner curve from `first` (u = 0) to u = 1 in steps of at most
/// `max_step` arc length and `max_turn` turning ([`sample_path_adaptive`]),
/// with a sample at every inner knot of a spline.
fn march(
    curve: &CornerCurve,
    piece: usize,
    first: PathSample,
    max_step: f64,
    max_turn: f64,
) -> Vec<PathSample> {
    let cos_turn = max_turn.cos();
    // A spline's inner knots, where its curvature may have a kink (a peak
    // between two samples that their values would not show): every one is
    // sampled.
    let breaks: Vec<f64> = match curve {
        CornerCurve::Spline(spline) => {
            let mut k: Vec<f64> = spline
                .knots()
                .iter()
                .copied()
                .filter(|&u| u > 0.0 && u < 1.0)
                .collect();
            k.dedup();
            k
        }
        CornerCurve::Quintic(_) => Vec::new(),
    };
    let mut local = vec![first];
    let mut here = first;
    while here.u < 1.0 {
        let next_break = breaks.iter().copied().find(|&b| b > here.u).unwrap_or(1.0);
        let speed = norm(curve.d1(here.u));
        let reach = if here.curvature > 0.0 {
            max_step.min(max_turn / here.curvature)
        } else {
            max_step
        };
        let mut du = if speed > 0.0 {
            (reach / speed).min(next_break - here.u)
        } else {
            next_break - here.u
        };
        let next = loop {
            let u = if here.u + du >= next_break {
                next_break
            } else {
                here.u + du
            };
            let ds = curve.length_between(here.u, u);
            let candidate = corner_sample(curve, piece, u, here.s + ds);
            // The curvature at the step's quartiles within its ends' (up to
            // MONOTONE_SLACK): a bump inside the step (a spline's narrow peak
            // near a knot) splits it until the samples show the bump.
            let top = here.curvature.max(candidate.curvature) * (1.0 + MONOTONE_SLACK);
            let within = ds <= max_step * (1.0 + 1e-9)
                && dot(here.tangent, candidate.tangent) >= cos_turn
                && [0.25, 0.5, 0.75]
                    .iter()
                    .all(|f| curve.curvature(here.u + f * (u - here.u)) <= top);
            // A step of 1e-12 in u is below any turning a feed plan resolves.
            if within || du < 1e-12 {
                break candidate;
            }
            du *= 0.5;
        };
        local.push(next);
        here = next;
    }
    local
}

/// The relative slack the velocity-limit curve adds to the larger curvature
/// of a [`PathSample::monotone`] interval's ends: on the flat top of a
/// curvature plateau an extremum pair can hide inside one step
/// (`tests/adaptive_samples.rs` measures the largest such excess on the
/// shipped paths and every corner method, and checks it is below this).
pub const MONOTONE_SLACK: f64 = 1e-4;

/// The fewest steps [`sample_path_adaptive`] takes on a corner.
pub const MIN_CORNER_STEPS: usize = 16;

/// Golden-section steps locating an extremum of the curvature.
const EXTREMUM_STEPS: usize = 40;

/// Inserts a sample at every local extremum of the curvature between the
/// samples of one corner: where the sampled curvature turns at sample i (its
/// changes before and after differ in sign), the extremum lies on
/// [u_{i−1}, u_{i+1}]; it is located by golden section and sampled (arc
/// length from its neighbour by quadrature) unless it is sample i itself.
/// The curvature is then monotone between neighbours unless an extremum pair
/// hides inside one step, which the turning bound of the march makes too
/// short for on these polynomial curves (`check_plan` verifies the plan on
/// the exact geometry regardless).
fn insert_extrema(curve: &CornerCurve, local: Vec<PathSample>) -> Vec<PathSample> {
    let mut out = Vec::with_capacity(local.len() + 4);
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for i in 0..local.len() {
        if i == 0 || i + 1 == local.len() {
            out.push(local[i]);
            continue;
        }
        let (a, b, c) = (&local[i - 1], &local[i], &local[i + 1]);
        let before = b.curvature - a.curvature;
        let after = c.curvature - b.curvature;
        if before == 0.0 || after == 0.0 || (before > 0.0) == (after > 0.0) {
            out.push(*b);
            continue;
        }
        let sign = if before > 0.0 { 1.0 } else { -1.0 };
        let (mut lo, mut hi) = (a.u, c.u);
        for _ in 0..EXTREMUM_STEPS {
            let m1 = hi - g * (hi - lo);
            let m2 = lo + g * (hi - lo);
            if sign * curve.curvature(m1) < sign * curve.curvature(m2) {
                lo = m1;
            } else {
                hi = m2;
            }
        }
        let u = 0.5 * (lo + hi);
        let (from, side) = if u < b.u { (a, 0) } else { (b, 1) };
        let at = corner_sample(curve, b.piece, u, from.s + curve.length_between(from.u, u));
        let beyond = sign * at.curvature > sign * b.curvature;
        let inside = if side == 0 {
            at.s > a.s && at.s < b.s
        } else {
            at.s > b.s && at.s < c.s
        };
        if beyond && inside && side == 0 {
            out.push(at);
            out.push(*b);
        } else if beyond && inside {
            out.push(*b);
            out.push(at);
        } else {
            out.push(*b);
        }
    }
    out
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
