//! A smoothed path sampled by arc length: positions, unit tangents and
//! curvature at every sample, for feed planning ([`crate::lower_bound`]).

use crate::smooth::{Piece, SmoothedPath};
use crate::vec3::{norm, scale, sub};

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
}

/// Samples a smoothed path: lines at both ends and every `max_step` or
/// less, corners at equal parameter steps fine enough that no step is
/// longer than `max_step` (arc length by [`crate::QuinticBezier::length_between`]).
/// Consecutive pieces share their joining sample (kept once).
///
/// # Arguments
/// * `max_step` — largest arc length between samples \[m\], > 0.
pub fn sample_path(path: &SmoothedPath, max_step: f64) -> Vec<PathSample> {
    let mut out: Vec<PathSample> = Vec::new();
    let mut s0 = 0.0;
    for piece in &path.pieces {
        let (length, steps) = match piece {
            Piece::Line { start, end } => {
                let l = norm(sub(*end, *start));
                (l, (l / max_step).ceil().max(1.0) as usize)
            }
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
                    }
                }
            };
            out.push(sample);
        }
        s0 += length;
        if let (Piece::Corner(_), Some(last)) = (piece, out.last_mut()) {
            // The corner's summed sub-lengths and its total differ by
            // rounding only; the next piece starts at the summed end.
            s0 = last.s;
        }
    }
    out
}
