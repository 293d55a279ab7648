//! Initial RTO selection, seed 001 eq. 56.
//!
//! One free candidate q̃_i is chosen in the GFD of every RTO i = 0..m to
//!
//! ```text
//! minimize  k1 Σ_{i=0..m} Δd_{i,p}  +  k2 Σ_{i=1..m} ‖q̃_i − q̃_{i−1}‖ / σ_i        (eq. 56)
//! ```
//!
//! with Δd the distance of eq. 55 to the layer's reference and σ_i the
//! path length between the CL points of RTOs i−1 and i.
//!
//! * **Norm.** ‖·‖ in eq. 56 is called Euclidean in the seed, but q̃ mixes
//!   radians and metres; it is taken with the same weights as eq. 55,
//!   `‖Δq̃‖ = sqrt(k4 Δq4² + k5 Δq5² + k6 Δq6²)`
//!   ([`crate::gfd::weighted_distance`]), so both terms of eq. 56 share
//!   one metric.
//! * **Solver.** The seed solves eq. 56 with Dijkstra's algorithm. The
//!   candidate graph is layered (edges only join consecutive RTOs) and
//!   therefore a DAG, on which Dijkstra's shortest path equals dynamic
//!   programming layer by layer,
//!   `cost_i(b) = k1 Δd_b + min_a (cost_{i−1}(a) + k2 ‖q̃_b − q̃_a‖ / σ_i)`.
//!   This is exact, in O(Σ n_{i−1} n_i) for n_i candidates per layer
//!   (about 0.25 M edge evaluations per layer pair on the default
//!   9 × 9 × 6 grid).
//! * **Lazy collision checks.** The DP is solved over every candidate not
//!   yet known to collide; only the vertices of the optimal path are
//!   collision-checked; colliding ones are excluded and the DP is solved
//!   again (from the first layer that changed), until the optimal path is
//!   collision-free. The result equals the eager method (check every
//!   candidate, then solve over the free ones): the lazy DP optimises over
//!   a superset S of the free set F, so its optimum is ≤ the optimum over
//!   F; when that optimum path lies in F it is also optimal over F. Ties
//!   are broken the same way in both (lowest candidate index, predecessor
//!   first, i.e. the lexicographically least path key (cost, p_m, …,
//!   p_0)), and a minimum of that key over S that lies in F is the minimum
//!   over F, so the chosen indices are identical, not just the cost.
//!   [`select_rtos_eager`] is the eager reference.

use crate::collision::CollisionWorld;
use crate::gfd::{weighted_distance, Gfd};
use crate::request::Weights;
use crate::PlanError;

/// Edge cost of eq. 56 between consecutive RTO candidates (`σ` > 0).
fn edge_cost(a: &[f64; 3], b: &[f64; 3], sigma: f64, w: &Weights) -> f64 {
    w.k2 * weighted_distance(a, b, w) / sigma
}

/// Checks the inputs shared by both solvers.
fn validate(gfds: &[Gfd], path_lengths: &[f64], w: &Weights) -> Result<(), PlanError> {
    if gfds.is_empty() {
        return Err(PlanError::invalid(
            "rto_indices",
            "no RTO to select: at least one GFD is required",
        ));
    }
    if path_lengths.len() + 1 != gfds.len() {
        return Err(PlanError::invalid(
            "path_lengths",
            format!(
                "{} path lengths for {} RTOs: one per consecutive pair is required",
                path_lengths.len(),
                gfds.len()
            ),
        ));
    }
    if let Some((i, s)) = path_lengths
        .iter()
        .enumerate()
        .find(|(_, s)| !(s.is_finite() && **s > 0.0))
    {
        return Err(PlanError::invalid(
            format!("path_lengths[{i}]"),
            format!("{s} must be finite and > 0"),
        ));
    }
    for (name, v) in [
        ("k1", w.k1),
        ("k2", w.k2),
        ("k4", w.k4),
        ("k5", w.k5),
        ("k6", w.k6),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(PlanError::invalid(
                format!("options.weights.{name}"),
                format!("{v} must be finite and ≥ 0"),
            ));
        }
    }
    Ok(())
}

/// The error for a layer without any usable candidate.
fn no_feasible(g: &Gfd) -> PlanError {
    PlanError::NoFeasibleOrientation {
        index: g.cl_index,
        u: g.u,
        reason: format!(
            "{} grid samples: {} outside the lead/tilt limits, {} outside the q4/q5/q6 range, \
             {} outside the q1..q3 stroke, {} of the {} remaining candidates collide",
            g.total,
            g.angle_rejected,
            g.range_rejected,
            g.stroke_rejected,
            g.known_colliding(),
            g.candidates.len()
        ),
    }
}

/// Forward DP tables: cost to reach each candidate, and its predecessor.
struct Dp {
    cost: Vec<Vec<f64>>,
    pred: Vec<Vec<usize>>,
}

impl Dp {
    fn new(gfds: &[Gfd]) -> Self {
        Self {
            cost: gfds
                .iter()
                .map(|g| vec![f64::INFINITY; g.candidates.len()])
                .collect(),
            pred: gfds
                .iter()
                .map(|g| vec![usize::MAX; g.candidates.len()])
                .collect(),
        }
    }

    /// Recomputes layers `from..` (earlier layers are unchanged);
    /// candidates known to collide get an infinite cost.
    fn solve_from(&mut self, gfds: &[Gfd], sigma: &[f64], w: &Weights, from: usize) {
        for (i, g) in gfds.iter().enumerate().skip(from) {
            let (before, rest) = self.cost.split_at_mut(i);
            let Some(cost) = rest.first_mut() else { return };
            let Some(pred) = self.pred.get_mut(i) else {
                return;
            };
            let prev = before
                .last()
                .zip(i.checked_sub(1).and_then(|k| gfds.get(k)));
            let s = i
                .checked_sub(1)
                .and_then(|k| sigma.get(k))
                .copied()
                .unwrap_or(1.0);
            for (b, cand) in g.candidates.iter().enumerate() {
                let (c, p) = if g.known_status(b) == Some(false) {
                    (f64::INFINITY, usize::MAX)
                } else if let Some((prev_cost, prev_gfd)) = prev {
                    let mut best = f64::INFINITY;
                    let mut arg = usize::MAX;
                    for (a, (ca, qa)) in prev_cost.iter().zip(&prev_gfd.candidates).enumerate() {
                        if !ca.is_finite() {
                            continue;
                        }
                        let v = ca + edge_cost(&qa.q, &cand.q, s, w);
                        if v < best {
                            best = v;
                            arg = a;
                        }
                    }
                    (w.k1 * cand.distance + best, arg)
                } else {
                    (w.k1 * cand.distance, usize::MAX)
                };
                if let (Some(cs), Some(ps)) = (cost.get_mut(b), pred.get_mut(b)) {
                    *cs = c;
                    *ps = p;
                }
            }
        }
    }

    /// The optimal path (one candidate index per layer), or `None` if the
    /// last layer is unreachable.
    fn path(&self) -> Option<Vec<usize>> {
        let last = self.cost.last()?;
        let mut best = f64::INFINITY;
        let mut arg = None;
        for (b, &c) in last.iter().enumerate() {
            if c < best {
                best = c;
                arg = Some(b);
            }
        }
        let n = self.cost.len();
        let mut path = vec![0; n];
        let mut p = arg?;
        for i in (0..n).rev() {
            *path.get_mut(i)? = p;
            if i > 0 {
                p = *self.pred.get(i)?.get(p)?;
            }
        }
        Some(path)
    }
}

/// Initial RTO selection of seed 001 eq. 56, lazy in collision checks.
///
/// # Arguments
/// * `gfds` - the GFD of every RTO, in path order (their lazy collision
///   status is filled in).
/// * `path_lengths` - σ_i (m) between the CL points of consecutive RTOs,
///   `gfds.len() - 1` values, each > 0.
/// * `weights` - k1, k2 of eq. 56 and k4, k5, k6 of eq. 55.
/// * `world` - the collision world.
///
/// # Returns
/// The chosen candidate index in each GFD: the collision-free optimum of
/// eq. 56 (identical to [`select_rtos_eager`], see the module docs).
///
/// # Errors
/// * [`PlanError::NoFeasibleOrientation`] for the first RTO without a
///   collision-free candidate, with the sample counts (total,
///   angle-rejected, range-rejected, stroke-rejected, colliding).
/// * [`PlanError::InvalidRequest`] for no GFD, a wrong number of path
///   lengths, a non-positive or non-finite σ, or a negative or non-finite
///   weight.
///
/// # Performance
/// Each round is one DP, O(Σ n_{i−1} n_i), and checks at most m + 1 new
/// candidates; rounds stop when the optimal path is free. Typically a few
/// rounds and a few dozen queries instead of Σ n_i.
pub fn select_rtos(
    gfds: &mut [Gfd],
    path_lengths: &[f64],
    weights: &Weights,
    world: &CollisionWorld,
) -> Result<Vec<usize>, PlanError> {
    validate(gfds, path_lengths, weights)?;
    let mut dp = Dp::new(gfds);
    let mut from = 0;
    let mut rounds = 0usize;
    loop {
        rounds += 1;
        if let Some(g) = gfds
            .iter()
            .find(|g| (0..g.candidates.len()).all(|p| g.known_status(p) == Some(false)))
        {
            return Err(no_feasible(g));
        }
        dp.solve_from(gfds, path_lengths, weights, from);
        let path = dp.path().ok_or_else(|| PlanError::Solver {
            problem: "RTO selection".into(),
            detail: "no finite-cost path through the candidate layers".into(),
        })?;
        let mut dirty: Option<usize> = None;
        for (i, (&p, g)) in path.iter().zip(gfds.iter_mut()).enumerate() {
            if !g.is_free(p, world) {
                dirty.get_or_insert(i);
            }
        }
        match dirty {
            None => {
                log::debug!(
                    "RTO selection: {rounds} round(s), {} candidates checked",
                    gfds.iter().map(Gfd::collision_checked).sum::<usize>()
                );
                return Ok(path);
            }
            Some(i) => from = i,
        }
    }
}

/// Initial RTO selection of eq. 56 with every candidate collision-checked
/// first (the reference for [`select_rtos`]; same result, many more
/// queries).
///
/// # Errors
/// As [`select_rtos`].
pub fn select_rtos_eager(
    gfds: &mut [Gfd],
    path_lengths: &[f64],
    weights: &Weights,
    world: &CollisionWorld,
) -> Result<Vec<usize>, PlanError> {
    validate(gfds, path_lengths, weights)?;
    for g in gfds.iter_mut() {
        for p in 0..g.candidates.len() {
            g.is_free(p, world);
        }
    }
    select_rtos(gfds, path_lengths, weights, world)
}

/// The objective of eq. 56 for a choice of one candidate per GFD,
/// accumulated in the order the DP uses (so equal paths give bit-equal
/// costs).
///
/// # Returns
/// `None` for a length mismatch or an index out of range.
pub fn selection_cost(
    gfds: &[Gfd],
    choice: &[usize],
    path_lengths: &[f64],
    weights: &Weights,
) -> Option<f64> {
    if choice.len() != gfds.len() || path_lengths.len() + 1 != gfds.len() {
        return None;
    }
    let mut cost = 0.0;
    let mut prev: Option<&[f64; 3]> = None;
    for (i, (g, &p)) in gfds.iter().zip(choice).enumerate() {
        let c = g.candidates.get(p)?;
        cost = match prev {
            None => weights.k1 * c.distance,
            Some(q) => {
                let s = *path_lengths.get(i - 1)?;
                weights.k1 * c.distance + (cost + edge_cost(q, &c.q, s, weights))
            }
        };
        prev = Some(&c.q);
    }
    Some(cost)
}
