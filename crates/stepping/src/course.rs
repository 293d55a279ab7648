//! A course: the reference points of one axis (or of a path parameter) as
//! windows on the lattice.

use crate::{
    error::{check_positive, StepError},
    lattice::Lattice,
};

/// Reference points along one axis, in the order they are passed, with the
/// precision each must be passed within, on a [`Lattice`].
///
/// Point 0 is the start (the axis is at rest there); points 1.. are the
/// targets. Positions increase strictly: a path that turns back is a
/// multi-axis path ([`crate::multi`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Course {
    /// The axis lattice.
    pub lattice: Lattice,
    /// Absolute positions of every point, the start first.
    pub points: Vec<f64>,
    /// Precision [m or rad]: a point is passed when a sample lies within
    /// this distance of it.
    pub precision: f64,
    /// Window `[lo, hi]` of each target (points 1..) in lattice position
    /// units from the start, rounded inward (a sample inside the window is
    /// inside the precision).
    pub windows: Vec<(i64, i64)>,
    /// Crawl velocity index: the largest even `n` with `3n + 1` no more than
    /// the narrowest window's width, so that a motion no faster than it
    /// cannot step over a window.
    pub crawl: i64,
    /// Largest distance between adjacent points (the agent's distance
    /// normalization, seed 002 section 3).
    pub max_gap: f64,
}

/// Lattice positions beyond which a course is refused (i64 headroom).
const MAX_UNITS: f64 = 1e15;

impl Course {
    /// Validates `points` (start first) and builds their windows.
    ///
    /// # Errors
    /// * [`StepError::InvalidParameter`] for a precision that is not finite
    ///   and > 0, or below the lattice's resolution (a window narrower than
    ///   one crawl step);
    /// * [`StepError::InvalidPoint`] for fewer than two points, a NaN or
    ///   infinite point, a point not beyond its predecessor by more than
    ///   twice the precision ("repeated": the two would be one point at
    ///   this precision), or a course too long for the lattice.
    pub fn new(lattice: Lattice, points: Vec<f64>, precision: f64) -> Result<Self, StepError> {
        check_positive("precision", precision)?;
        if points.len() < 2 {
            return Err(StepError::InvalidPoint {
                index: points.len(),
                reason: "a course needs a start and at least one point to pass".to_string(),
            });
        }
        for (i, p) in points.iter().enumerate() {
            if !p.is_finite() {
                return Err(StepError::InvalidPoint {
                    index: i,
                    reason: format!("coordinate {p} is not finite"),
                });
            }
        }
        let mut max_gap = 0.0f64;
        for i in 1..points.len() {
            let gap = points[i] - points[i - 1];
            if gap <= 2.0 * precision {
                return Err(StepError::InvalidPoint {
                    index: i,
                    reason: format!(
                        "{} beyond point {} (at {}): points must increase by more than twice \
                         the precision {precision} (a repeated point, or one that turns back)",
                        gap,
                        i - 1,
                        points[i - 1]
                    ),
                });
            }
            max_gap = max_gap.max(gap);
        }
        let start = points[0];
        let u = lattice.unit_p;
        let mut windows = Vec::with_capacity(points.len() - 1);
        for (i, p) in points.iter().enumerate().skip(1) {
            let lo = ((p - precision - start) / u).ceil();
            let hi = ((p + precision - start) / u).floor();
            if hi > MAX_UNITS {
                return Err(StepError::InvalidPoint {
                    index: i,
                    reason: format!(
                        "{} from the start is beyond the lattice's range ({} units of {u})",
                        p - start,
                        MAX_UNITS
                    ),
                });
            }
            windows.push((lo as i64, hi as i64));
        }
        let narrowest = windows
            .iter()
            .map(|(lo, hi)| hi - lo + 1)
            .min()
            .unwrap_or(0);
        let crawl = (((narrowest - 1) / 3) & !1).min(lattice.max_n);
        if crawl < 2 {
            return Err(StepError::InvalidParameter {
                name: "precision".to_string(),
                value: precision,
                reason: format!(
                    "below the lattice resolution: a window of ±precision holds {narrowest} \
                     position steps of J·Δt³/6 = {u}, at least 7 are needed"
                ),
            });
        }
        Ok(Self {
            lattice,
            points,
            precision,
            windows,
            crawl,
            max_gap,
        })
    }

    /// Number of targets (points after the start).
    pub fn targets(&self) -> usize {
        self.windows.len()
    }

    /// Whether lattice position `q` lies in target `i`'s window.
    #[inline]
    pub fn in_window(&self, i: usize, q: i64) -> bool {
        self.windows
            .get(i)
            .is_some_and(|&(lo, hi)| lo <= q && q <= hi)
    }

    /// Distance [m or rad] from lattice position `q` to target `i`
    /// (signed: positive before it).
    pub fn distance_to(&self, i: usize, q: i64) -> f64 {
        let p = self
            .lattice
            .position(crate::lattice::State { q, n: 0, m: 0 });
        self.points
            .get(i + 1)
            .map_or(0.0, |t| t - self.points[0] - p)
    }
}
