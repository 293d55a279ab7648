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
//!   `‖Δq̃‖ = sqrt(k4 Δq4² + k5 Δq5² + k6 Δq6²)` (as
//!   [`crate::gfd::weighted_distance`]), so both terms of eq. 56 share one
//!   metric. It is evaluated as a plain norm of coordinates pre-scaled by
//!   (√k4, √k5, √k6).
//! * **Solver.** The seed solves eq. 56 with Dijkstra's algorithm. The
//!   candidate graph is layered (edges only join consecutive RTOs) and
//!   therefore a DAG, on which Dijkstra's shortest path equals dynamic
//!   programming layer by layer,
//!   `cost_i(b) = k1 Δd_b + min_a (cost_{i−1}(a) + k2 ‖q̃_b − q̃_a‖ / σ_i)`.
//!   This is exact, in O(Σ n_{i−1} n_i) for n_i candidates per layer
//!   (about 0.15 M edge evaluations per layer pair on the default
//!   9 × 9 × (5 + 1) grid, ≈ 1 ms per pass over 6 layers).
//! * **Lazy collision checks.** The DP is solved over every candidate not
//!   yet known to collide; only the vertices of the optimal path are
//!   collision-checked; colliding ones are excluded and the DP is solved
//!   again (from the first layer that changed), until the optimal path is
//!   collision-free. To save rounds, a layer whose path vertex collided is
//!   also searched ahead: its unchecked candidates are checked in order of
//!   the cost of the best full path through them (forward + backward DP)
//!   until one is free.
//! * **Equivalence with the eager method** (check every candidate, then
//!   solve over the free ones; [`select_rtos_eager`]): the same indices
//!   and a bit-identical cost. Each lazy DP runs over a set S ⊇ F, the
//!   free candidates, so its forward costs are ≤ those over F (a minimum
//!   over more paths; floating-point addition is monotone, so this holds
//!   for the computed values too). The loop stops when the backtracked
//!   path P lies in F. Along P each forward cost is attained by P's own
//!   prefix, which lies in F, so the DP over F has the same forward costs
//!   there; ties go to the lowest index in both (last layer and
//!   predecessors), and a lower index tying over F would have had a cost
//!   ≤ over S and won there. So the eager DP backtracks the same P.

use kerf_budget::{Budget, Interrupt};

use crate::collision::CollisionWorld;
use crate::gfd::Gfd;
use crate::request::Weights;
use crate::PlanError;

/// The candidate coordinates scaled by (√k4, √k5, √k6), so the joint-space
/// norm of eq. 56 (weighted as eq. 55) is a plain Euclidean norm.
fn scaled(q: &[f64; 3], w: &Weights) -> [f64; 3] {
    [w.k4.sqrt() * q[0], w.k5.sqrt() * q[1], w.k6.sqrt() * q[2]]
}

/// Edge cost of eq. 56, `c · ‖a − b‖` with `c = k2 / σ_i`, on scaled
/// coordinates.
#[inline]
fn edge(a: [f64; 3], b: [f64; 3], c: f64) -> f64 {
    let dx = a[0] - b[0];
    let dy = a[1] - b[1];
    let dz = a[2] - b[2];
    c * (dx * dx + dy * dy + dz * dz).sqrt()
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

/// One layer of the DP: scaled candidate coordinates (structure of
/// arrays, so the inner loop vectorises) and node costs k1 · Δd.
struct Layer {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    node: Vec<f64>,
}

impl Layer {
    fn new(g: &Gfd, w: &Weights) -> Self {
        let s: Vec<[f64; 3]> = g.candidates.iter().map(|c| scaled(&c.q, w)).collect();
        Self {
            x: s.iter().map(|v| v[0]).collect(),
            y: s.iter().map(|v| v[1]).collect(),
            z: s.iter().map(|v| v[2]).collect(),
            node: g.candidates.iter().map(|c| w.k1 * c.distance).collect(),
        }
    }

    fn point(&self, b: usize) -> Option<[f64; 3]> {
        Some([*self.x.get(b)?, *self.y.get(b)?, *self.z.get(b)?])
    }

    /// `min_a (cost[a] + c ‖s_a − p‖)` over this layer, the lowest index
    /// on ties; `(∞, usize::MAX)` when every cost is infinite.
    fn relax(&self, cost: &[f64], p: [f64; 3], c: f64, buf: &mut Vec<f64>) -> (f64, usize) {
        buf.clear();
        buf.extend(
            cost.iter()
                .zip(&self.x)
                .zip(&self.y)
                .zip(&self.z)
                .map(|(((ca, &x), &y), &z)| ca + edge([x, y, z], p, c)),
        );
        let mut best = f64::INFINITY;
        let mut arg = usize::MAX;
        for (a, &v) in buf.iter().enumerate() {
            if v < best {
                best = v;
                arg = a;
            }
        }
        (best, arg)
    }
}

/// DP tables over the layered candidate graph: forward cost to reach each
/// candidate (with its predecessor) and backward cost from it to the end.
/// Candidates known to collide cost ∞.
struct Dp {
    layers: Vec<Layer>,
    /// `c[i] = k2 / σ_i`, the edge factor between layers i − 1 and i
    /// (`c[0]` unused).
    c: Vec<f64>,
    fwd: Vec<Vec<f64>>,
    pred: Vec<Vec<usize>>,
    bwd: Vec<Vec<f64>>,
    buf: Vec<f64>,
}

impl Dp {
    fn new(gfds: &[Gfd], sigma: &[f64], w: &Weights) -> Self {
        let inf = |g: &Gfd| vec![f64::INFINITY; g.candidates.len()];
        Self {
            layers: gfds.iter().map(|g| Layer::new(g, w)).collect(),
            c: std::iter::once(0.0)
                .chain(sigma.iter().map(|s| w.k2 / s))
                .collect(),
            fwd: gfds.iter().map(inf).collect(),
            pred: gfds
                .iter()
                .map(|g| vec![usize::MAX; g.candidates.len()])
                .collect(),
            bwd: gfds.iter().map(inf).collect(),
            buf: Vec::new(),
        }
    }

    /// Recomputes the forward costs of layers `from..` (earlier layers
    /// are unchanged): `fwd_i(b) = k1 Δd_b + min_a (fwd_{i−1}(a) + k2
    /// ‖q̃_b − q̃_a‖ / σ_i)`.
    fn forward(&mut self, gfds: &[Gfd], from: usize, budget: &Budget) -> Result<(), Interrupt> {
        for (i, g) in gfds.iter().enumerate().skip(from) {
            let (done, rest) = self.fwd.split_at_mut(i);
            let (Some(cost), Some(pred), Some(layer)) =
                (rest.first_mut(), self.pred.get_mut(i), self.layers.get(i))
            else {
                return Ok(());
            };
            let prev = done
                .last()
                .zip(i.checked_sub(1).and_then(|k| self.layers.get(k)));
            let c = self.c.get(i).copied().unwrap_or(0.0);
            for (b, (cs, ps)) in cost.iter_mut().zip(pred.iter_mut()).enumerate() {
                // Each candidate relaxes a whole previous layer (up to 10⁴ edges).
                budget.check("RTO selection")?;
                let (Some(p), Some(&node)) = (layer.point(b), layer.node.get(b)) else {
                    continue;
                };
                (*cs, *ps) = if g.known_status(b) == Some(false) {
                    (f64::INFINITY, usize::MAX)
                } else if let Some((prev_cost, prev_layer)) = prev {
                    let (best, arg) = prev_layer.relax(prev_cost, p, c, &mut self.buf);
                    (node + best, arg)
                } else {
                    (node, usize::MAX)
                };
            }
        }
        Ok(())
    }

    /// Recomputes every backward cost: `bwd_i(b) = k1 Δd_b + min_c
    /// (bwd_{i+1}(c) + k2 ‖q̃_c − q̃_b‖ / σ_{i+1})`.
    fn backward(&mut self, gfds: &[Gfd], budget: &Budget) -> Result<(), Interrupt> {
        for (i, g) in gfds.iter().enumerate().rev() {
            let (head, after) = self.bwd.split_at_mut(i + 1);
            let (Some(cost), Some(layer)) = (head.last_mut(), self.layers.get(i)) else {
                return Ok(());
            };
            let next = after.first().zip(self.layers.get(i + 1));
            let c = self.c.get(i + 1).copied().unwrap_or(0.0);
            for (b, cs) in cost.iter_mut().enumerate() {
                budget.check("RTO selection")?;
                let (Some(p), Some(&node)) = (layer.point(b), layer.node.get(b)) else {
                    continue;
                };
                *cs = if g.known_status(b) == Some(false) {
                    f64::INFINITY
                } else if let Some((next_cost, next_layer)) = next {
                    node + next_layer.relax(next_cost, p, c, &mut self.buf).0
                } else {
                    node
                };
            }
        }
        Ok(())
    }

    /// Cost of the best full path through candidate `b` of layer `i`.
    fn through(&self, i: usize, b: usize) -> f64 {
        let get = |t: &Vec<Vec<f64>>| t.get(i).and_then(|l| l.get(b)).copied();
        match (
            get(&self.fwd),
            get(&self.bwd),
            self.layers.get(i).and_then(|l| l.node.get(b)),
        ) {
            (Some(f), Some(k), Some(n)) => f + k - n,
            _ => f64::INFINITY,
        }
    }

    /// The optimal path (one candidate index per layer; lowest index on
    /// ties, predecessors likewise), or `None` if no finite path exists.
    fn path(&self) -> Option<Vec<usize>> {
        let last = self.fwd.last()?;
        let mut best = f64::INFINITY;
        let mut arg = None;
        for (b, &c) in last.iter().enumerate() {
            if c < best {
                best = c;
                arg = Some(b);
            }
        }
        let n = self.fwd.len();
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
/// * `budget` - checked at each DP layer and before each look-ahead collision query.
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
/// * [`PlanError::Interrupted`] when the budget runs out or is cancelled.
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
    budget: &Budget,
) -> Result<Vec<usize>, PlanError> {
    validate(gfds, path_lengths, weights)?;
    let mut dp = Dp::new(gfds, path_lengths, weights);
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
        dp.forward(gfds, from, budget)?;
        let path = dp.path().ok_or_else(|| PlanError::Solver {
            problem: "RTO selection".into(),
            detail: "no finite-cost path through the candidate layers".into(),
        })?;
        let mut collided = Vec::new();
        for (i, (&p, g)) in path.iter().zip(gfds.iter_mut()).enumerate() {
            if !g.is_free(p, world) {
                collided.push(i);
            }
        }
        let Some(&first) = collided.first() else {
            log::debug!(
                "RTO selection: {rounds} round(s), {} candidates checked",
                gfds.iter().map(Gfd::collision_checked).sum::<usize>()
            );
            return Ok(path);
        };
        // Look ahead in the layers whose vertex collided: check their
        // candidates in order of the best full path through them until one
        // is free, so the next optimum is likely free. Extra knowledge
        // never changes the result (module docs), it saves DP rounds.
        dp.forward(gfds, first, budget)?;
        dp.backward(gfds, budget)?;
        for &i in &collided {
            let Some(g) = gfds.get_mut(i) else { continue };
            let mut order: Vec<(f64, usize)> = (0..g.candidates.len())
                .filter(|&b| g.known_status(b).is_none())
                .map(|b| (dp.through(i, b), b))
                .collect();
            order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            for (_, b) in order {
                budget.check("RTO selection")?;
                if g.is_free(b, world) {
                    break;
                }
            }
        }
        from = first;
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
    select_rtos(gfds, path_lengths, weights, world, &Budget::unlimited())
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
    let mut prev: Option<[f64; 3]> = None;
    for (i, (g, &p)) in gfds.iter().zip(choice).enumerate() {
        let c = g.candidates.get(p)?;
        let q = scaled(&c.q, weights);
        let node = weights.k1 * c.distance;
        cost = match prev {
            None => node,
            Some(a) => {
                let sigma = *path_lengths.get(i - 1)?;
                node + (cost + edge(a, q, weights.k2 / sigma))
            }
        };
        prev = Some(q);
    }
    Some(cost)
}
