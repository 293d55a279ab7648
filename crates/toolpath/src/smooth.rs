//! A G01 polyline smoothed corner by corner ([`crate::corner`]): straight
//! pieces and curvature-continuous corner transitions, within a tolerance
//! of the polyline everywhere.

use kerf_budget::{bytes_of, Budget};

use crate::baseline::CornerMethod;
use crate::corner::CornerTransition;
use crate::error::{check_positive, ToolpathError};
use crate::vec3::{distance_to_segment, norm, sub};

/// Gaps between two pieces up to this are rounding, not a line \[m\]: two
/// corners that use all of the segment between them meet where the rounding
/// of their end points leaves a line of 1e-17 m, which would give the path a
/// step of zero length.
pub const JOIN_GAP: f64 = 1e-12;

/// One piece of a smoothed path.
#[derive(Debug, Clone, Copy, PartialEq)]
// A corner is about 500 bytes with a baseline's spline, a line 48: boxing
// would cost an allocation per corner and the pieces' Copy.
#[allow(clippy::large_enum_variant)]
pub enum Piece {
    /// A straight piece.
    Line {
        /// Start \[m\].
        start: [f64; 3],
        /// End \[m\].
        end: [f64; 3],
    },
    /// A corner transition.
    Corner(CornerTransition),
}

/// A smoothed polyline.
#[derive(Debug, Clone, PartialEq)]
pub struct SmoothedPath {
    /// The polyline it smooths.
    pub polyline: Vec<[f64; 3]>,
    /// The tolerance \[m\].
    pub tolerance: f64,
    /// Lines and corners in order, each starting where the previous ends.
    pub pieces: Vec<Piece>,
}

impl SmoothedPath {
    /// The largest distance from the polyline, exact per kerf corner (module
    /// [`crate::corner`]), exact or bounded per baseline corner (module
    /// [`crate::baseline`]); 0 without corners \[m\].
    pub fn max_deviation(&self) -> f64 {
        self.corners().map(|c| c.deviation).fold(0.0, f64::max)
    }

    /// The largest curvature \[1/m\].
    pub fn max_curvature(&self) -> f64 {
        self.corners().map(|c| c.max_curvature).fold(0.0, f64::max)
    }

    /// The corner transitions.
    pub fn corners(&self) -> impl Iterator<Item = &CornerTransition> {
        self.pieces.iter().filter_map(|p| match p {
            Piece::Corner(c) => Some(c),
            Piece::Line { .. } => None,
        })
    }

    /// Points along the path: each piece at `per_piece` + 1 equally spaced
    /// parameters (lines by length, corners by their curve's parameter).
    pub fn sample(&self, per_piece: usize) -> Vec<[f64; 3]> {
        let n = per_piece.max(1);
        let mut out = Vec::with_capacity(self.pieces.len() * (n + 1));
        for p in &self.pieces {
            for k in 0..=n {
                let u = k as f64 / n as f64;
                out.push(match p {
                    Piece::Line { start, end } => {
                        std::array::from_fn(|d| start[d] + u * (end[d] - start[d]))
                    }
                    Piece::Corner(c) => c.curve.point(u),
                });
            }
        }
        out
    }

    /// The largest distance of `points` from the polyline \[m\] (brute force
    /// over its segments: for checks).
    pub fn distance_from_polyline(&self, points: &[[f64; 3]]) -> f64 {
        points
            .iter()
            .map(|p| {
                self.polyline
                    .windows(2)
                    .map(|w| distance_to_segment(*p, w[0], w[1]))
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max)
    }
}

/// Smooths every corner of a polyline.
///
/// # Arguments
/// * `polyline` — at least two points, finite, no two consecutive equal.
/// * `tolerance` — δ \[m\].
///
/// # Returns
/// The path: a transition at every corner that turns (each within δ of the
/// polyline, using at most half of each segment it shares with another
/// corner and all of a first or last segment), lines between them.
///
/// # Errors
/// [`ToolpathError::BadPoint`] for a non-finite point or two equal
/// consecutive points; [`ToolpathError::InvalidParameter`] for δ not finite
/// and > 0, fewer than two points, or a reversal (the path must stop there:
/// not smoothed).
pub fn smooth_polyline(
    polyline: &[[f64; 3]],
    tolerance: f64,
) -> Result<SmoothedPath, ToolpathError> {
    smooth_polyline_with(polyline, tolerance, &CornerMethod::Kerf)
}

/// Smooths every corner of a polyline by a chosen method: kerf's corner or
/// a baseline ([`crate::baseline`]).
///
/// # Arguments
/// * `polyline`, `tolerance` — as [`smooth_polyline`].
/// * `method` — the corner construction; [`CornerMethod::Kerf`] gives
///   exactly [`smooth_polyline`]'s path.
///
/// # Returns
/// As [`smooth_polyline`], every corner built by `method`.
///
/// # Errors
/// As [`smooth_polyline`], and [`ToolpathError::InvalidParameter`] for bad
/// swarm settings ([`crate::baseline::NurbsSettings::check`]) or a NURBS
/// corner the swarm found no feasible point for.
pub fn smooth_polyline_with(
    polyline: &[[f64; 3]],
    tolerance: f64,
    method: &CornerMethod,
) -> Result<SmoothedPath, ToolpathError> {
    smooth_polyline_within(polyline, tolerance, method, &Budget::unlimited())
}

/// [`smooth_polyline_with`] under a budget: the pieces' memory (a corner and a line per
/// vertex, and the polyline's copy) is checked before they are built, the deadline at every
/// corner (and within the NURBS swarm).
///
/// # Errors
/// As [`smooth_polyline_with`]; [`ToolpathError::Interrupted`] when the budget runs out.
pub fn smooth_polyline_within(
    polyline: &[[f64; 3]],
    tolerance: f64,
    method: &CornerMethod,
    budget: &Budget,
) -> Result<SmoothedPath, ToolpathError> {
    method.check()?;
    smooth_polyline_by(
        polyline,
        tolerance,
        budget,
        |prev, vertex, next, tolerance, available, index| {
            method.transition_within(prev, vertex, next, tolerance, available, index, budget)
        },
    )
}

/// [`smooth_polyline_within`] with every corner built by `corner` (a method this crate does
/// not know, e.g. a learned one with its own state): called once per inner vertex, in order,
/// as `corner(prev, vertex, next, tolerance, available, index)` with the arguments of
/// [`CornerMethod::transition`]. The caller's corner must keep the contract of
/// [`CornerMethod::transition`]: within δ of the polyline, at most `available` on each side.
///
/// # Errors
/// As [`smooth_polyline_within`]; `corner`'s own errors (an `InvalidParameter` named with the
/// corner's point).
pub fn smooth_polyline_by<F>(
    polyline: &[[f64; 3]],
    tolerance: f64,
    budget: &Budget,
    mut corner: F,
) -> Result<SmoothedPath, ToolpathError>
where
    F: FnMut(
        [f64; 3],
        [f64; 3],
        [f64; 3],
        f64,
        f64,
        usize,
    ) -> Result<Option<CornerTransition>, ToolpathError>,
{
    let vertices = polyline.len() as u64;
    budget.check_memory(
        bytes_of::<Piece>(vertices.saturating_mul(2))
            .saturating_add(bytes_of::<[f64; 3]>(vertices)),
        &format!(
            "smoothed path: {vertices} vertices ({} B per corner)",
            std::mem::size_of::<Piece>()
        ),
    )?;
    if polyline.len() < 2 {
        return Err(ToolpathError::InvalidParameter {
            name: "points".to_string(),
            value: polyline.len() as f64,
            reason: "a path needs at least two".to_string(),
        });
    }
    check_positive(&[("tolerance [m]", tolerance)])?;
    for (index, p) in polyline.iter().enumerate() {
        if p.iter().any(|v| !v.is_finite()) {
            return Err(ToolpathError::BadPoint {
                index,
                reason: "not finite".to_string(),
            });
        }
        if index > 0 && norm(sub(*p, polyline[index - 1])) == 0.0 {
            return Err(ToolpathError::BadPoint {
                index,
                reason: "equals the point before it".to_string(),
            });
        }
    }
    let n = polyline.len();
    let length = |i: usize| norm(sub(polyline[i + 1], polyline[i]));
    // The share of segment i (from point i to i + 1) a corner at either end
    // may use: all of it next to a path end, else half.
    let share = |i: usize| {
        if i == 0 || i == n - 2 {
            length(i)
        } else {
            0.5 * length(i)
        }
    };
    let mut pieces = Vec::new();
    let mut cursor = polyline[0];
    for v in 1..n - 1 {
        budget.check("corner smoothing")?;
        let available = share(v - 1).min(share(v));
        match corner(
            polyline[v - 1],
            polyline[v],
            polyline[v + 1],
            tolerance,
            available,
            v,
        )
        .map_err(|e| match e {
            ToolpathError::InvalidParameter {
                name,
                value,
                reason,
            } => ToolpathError::InvalidParameter {
                name: format!("corner at point {v}: {name}"),
                value,
                reason,
            },
            other => other,
        })? {
            None => {}
            Some(c) => {
                let start = c.curve.start();
                if norm(sub(start, cursor)) > JOIN_GAP {
                    pieces.push(Piece::Line {
                        start: cursor,
                        end: start,
                    });
                }
                cursor = c.curve.end();
                pieces.push(Piece::Corner(c));
            }
        }
    }
    let last = polyline[n - 1];
    if norm(sub(last, cursor)) > JOIN_GAP {
        pieces.push(Piece::Line {
            start: cursor,
            end: last,
        });
    }
    Ok(SmoothedPath {
        polyline: polyline.to_vec(),
        tolerance,
        pieces,
    })
}
