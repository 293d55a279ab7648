//! Per-corner figures of a smoothed path, as seed 003 (DRLS) Table 2 gives them for its
//! W-shaped path: for each local corner, the maximum approximation error and the maximum
//! curvature, here with the vertex and its turning angle.

use crate::corner::Binding;
use crate::smooth::SmoothedPath;

/// One corner's figures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CornerMetrics {
    /// Index of the vertex in [`SmoothedPath::polyline`] (`None` if the path's polyline does
    /// not hold it: a path built by hand).
    pub index: Option<usize>,
    /// The vertex the transition replaces \[m\].
    pub vertex: [f64; 3],
    /// Turning angle θ between the incoming and outgoing segments \[rad\].
    pub turn: f64,
    /// Approximation error: the largest distance of the transition from the polyline, exact
    /// (sin θ · s (16a + 6b + c)/32, proved in [`crate::corner`], attained at its middle) \[m\].
    pub approximation_error: f64,
    /// The transition's largest curvature \[1/m\] (sampled, then refined by golden section).
    pub max_curvature: f64,
    /// What fixed the transition's size: the tolerance or the segments' length.
    pub binding: Binding,
}

/// The figures of every corner of `path`, in path order (straight vertices, which have no
/// transition, are left out).
pub fn corner_metrics(path: &SmoothedPath) -> Vec<CornerMetrics> {
    let mut next = 1;
    path.corners()
        .map(|c| {
            let index = (next..path.polyline.len()).find(|&k| path.polyline[k] == c.vertex);
            if let Some(k) = index {
                next = k + 1;
            }
            CornerMetrics {
                index,
                vertex: c.vertex,
                turn: c.turn,
                approximation_error: c.deviation,
                max_curvature: c.max_curvature,
                binding: c.binding,
            }
        })
        .collect()
}
