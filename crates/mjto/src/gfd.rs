//! The 3D geometric feasible domain (GFD) of one representative tool
//! orientation (RTO), seed 001 section 2.4 and Figure 4.
//!
//! At a CL point C the GFD samples the wrist coordinates q̃ = (q4, q5, q6)
//! around the reference configuration q̂ (the IKT, eq. 3, of the nominal
//! tool axis with the preferred standoff). A sample is a *candidate* when
//!
//! 1. its tool axis O(q4, q5) (eq. 2) is within the lead and tilt limits
//!    against the nominal axis (the constrained angles (φ, ϕ) of Figure 4),
//! 2. q4, q5, q6 are inside their joint ranges, and
//! 3. the translational axes q1..q3 = C − q6 · O (eq. 3) are inside their
//!    strokes.
//!
//! Candidates are sorted by the weighted distance of eq. 55 to q̂. Whether
//! a candidate is collision-free is evaluated lazily, on demand, and
//! memoised: the RTO selection (eq. 56, [`crate::selection`]) and the RTO
//! insertion of Figure 6 usually need a handful of them.

use kerf_budget::{Budget, Interrupt};
use nalgebra::Vector3;

use crate::collision::CollisionWorld;
use crate::machine::AxisLimits;
use crate::request::{GfdGrid, Weights};

/// One angle-feasible, in-stroke sample of a GFD.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// Wrist coordinates (q4, q5, q6) (rad, rad, m).
    pub q: [f64; 3],
    /// Weighted distance Δd to the reference, seed 001 eq. 55.
    pub distance: f64,
    /// Lead angle of the tool axis against the nominal axis (rad).
    pub lead: f64,
    /// Tilt angle of the tool axis against the nominal axis (rad).
    pub tilt: f64,
}

/// The GFD of one RTO.
#[derive(Debug, Clone, PartialEq)]
pub struct Gfd {
    /// Index of the CL point of this RTO.
    pub cl_index: usize,
    /// Its normalized arc length u.
    pub u: f64,
    /// The CL point C in the machine frame (m).
    pub point: Vector3<f64>,
    /// The reference wrist configuration q̂ = (q4, q5, q6).
    pub reference: [f64; 3],
    /// Angle-feasible, in-range, in-stroke samples, sorted by
    /// [`Candidate::distance`] (ties in grid order).
    pub candidates: Vec<Candidate>,
    /// Samples outside the lead/tilt limits.
    pub angle_rejected: usize,
    /// Samples with q4, q5 or q6 outside its joint range.
    pub range_rejected: usize,
    /// Samples whose q1..q3 (eq. 3) leave their stroke.
    pub stroke_rejected: usize,
    /// Samples of the grid (the sum of the candidates and the three
    /// rejection counts).
    pub total: usize,
    /// Lazy collision status per candidate: `Some(true)` free.
    free: Vec<Option<bool>>,
    /// The sample values of the tensor grid per axis (q4, q5, q6), each
    /// non-decreasing.
    axes: [Vec<f64>; 3],
    /// Grid index (i4, i5, i6) of each candidate.
    grid_index: Vec<[usize; 3]>,
    /// Candidate index of each grid sample (`None`: rejected), at
    /// `(i4 · n5 + i5) · n6 + i6`.
    cell: Vec<Option<usize>>,
}

/// An axis-aligned box of GFD grid samples around a candidate (kerf, issue
/// 16: the interval constraints of the RTOs, see [`Gfd::free_box`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridBox {
    /// Lowest grid index per axis (q4, q5, q6).
    pub lo_index: [usize; 3],
    /// Highest grid index per axis (inclusive).
    pub hi_index: [usize; 3],
    /// Lower corner (q4, q5, q6) (rad, rad, m).
    pub lo: [f64; 3],
    /// Upper corner (q4, q5, q6) (rad, rad, m).
    pub hi: [f64; 3],
}

impl GridBox {
    /// Whether `q` = (q4, q5, q6) lies in the box, each coordinate within
    /// `tol` of its interval.
    pub fn contains(&self, q: &[f64; 3], tol: f64) -> bool {
        (0..3).all(|k| q[k] >= self.lo[k] - tol && q[k] <= self.hi[k] + tol)
    }
}

/// Unit tool axis O(q4, q5) of seed 001 eq. 2.
pub fn tool_axis(q4: f64, q5: f64) -> Vector3<f64> {
    let (s4, c4) = q4.sin_cos();
    let (s5, c5) = q5.sin_cos();
    Vector3::new(c4 * s5, s4 * s5, c5)
}

/// Weighted distance of seed 001 eq. 55 between two wrist
/// configurations: `sqrt(k4 Δq4² + k5 Δq5² + k6 Δq6²)`.
///
/// It is also the joint-space norm of the RTO-change term of eq. 56 (see
/// [`crate::selection`]): k4, k5 (1/rad²) and k6 (1/m²) make rad and m
/// commensurable.
pub fn weighted_distance(a: &[f64; 3], b: &[f64; 3], w: &Weights) -> f64 {
    let d4 = a[0] - b[0];
    let d5 = a[1] - b[1];
    let d6 = a[2] - b[2];
    (w.k4 * d4 * d4 + w.k5 * d5 * d5 + w.k6 * d6 * d6).sqrt()
}

/// `n` samples centred on `centre` spanning ± `half` (the centre exactly
/// in the middle for odd `n`; just the centre for n ≤ 1).
fn centred(centre: f64, half: f64, n: usize) -> Vec<f64> {
    if n <= 1 {
        return vec![centre];
    }
    let mid = (n - 1) as f64 / 2.0;
    (0..n)
        .map(|j| {
            if 2 * j == n - 1 {
                centre
            } else {
                centre + half * (j as f64 - mid) / mid
            }
        })
        .collect()
}

/// Half span of the q4 samples around a reference with tilt q̂5.
///
/// `q4_half_range` is read as the angle the tool axis sweeps on the unit
/// sphere; a rotation δ of q4 moves the axis by about δ·sin|q5| (eq. 2), so
/// the q4 span is `q4_half_range / sin|q̂5|`, at most π. Near the singular
/// vertical pose (q5 → 0), where q4 is undefined (eq. 3), the grid spans
/// every q4: the reference q4 there is arbitrary, and the orientation of the
/// head about the vertical (its fork arms) decides collisions.
pub fn q4_half_span(q4_half_range: f64, q5_reference: f64) -> f64 {
    let s = q5_reference.sin().abs();
    if s * std::f64::consts::PI <= q4_half_range {
        std::f64::consts::PI
    } else {
        q4_half_range / s
    }
}

/// The q6 sample range around the reference standoff: symmetric, reaching
/// the nearer end of the stroke (e.g. [−0.1, −0.04] m for −0.07 m on the
/// stroke [−0.1, 0.02] m). The samples stay near the preferred standoff
/// instead of spending most levels where the tilt housing (radius 0.045 m
/// around M, `urdf/laser_cutter.urdf`) already contains the CL point.
pub fn q6_span(reference: f64, stroke: &AxisLimits) -> (f64, f64) {
    let half = (reference - stroke.min)
        .min(stroke.max - reference)
        .max(0.0);
    (reference - half, reference + half)
}

/// `within(v, l)`: `l.min <= v <= l.max`, false for NaN.
fn within(v: f64, l: &AxisLimits) -> bool {
    l.min <= v && v <= l.max
}

impl Gfd {
    /// Samples the GFD of one RTO.
    ///
    /// # Arguments
    /// * `cl_index`, `u` - the CL point's index and normalized arc length.
    /// * `point` - the CL point C in the machine frame (m).
    /// * `reference` - q̂ = (q4, q5, q6), the IKT (eq. 3) of the nominal
    ///   axis with the preferred standoff.
    /// * `grid` - q4: `q4_steps` (odd) values over reference ±
    ///   [`q4_half_span`], the reference in the middle; q5: `q5_steps` over
    ///   reference ± `q5_half_range`; q6: `q6_steps` values spread evenly
    ///   over [`q6_span`] (the reference alone for one step), plus the
    ///   reference q6.
    /// * `weights` - k4, k5, k6 of eq. 55.
    /// * `max_lead`, `max_tilt` - limits on |lead| and |tilt| (rad).
    /// * `lead_tilt` - (lead, tilt) of a unit tool axis against the
    ///   nominal one at this point (e.g. the path frames' `lead_tilt_at`:
    ///   lead = atan2(O·t, O·n), tilt = atan2(O·b, O·n)).
    /// * `limits` - the machine's joint limits q1..q6.
    ///
    /// # Returns
    /// The GFD; non-finite inputs reject every sample (so an empty GFD,
    /// never a NaN candidate).
    ///
    /// # Performance
    /// O(q4_steps · q5_steps · (q6_steps + 1)) with one `lead_tilt` call
    /// per (q4, q5) pair; no collision query.
    #[allow(clippy::too_many_arguments)]
    pub fn build(
        cl_index: usize,
        u: f64,
        point: &Vector3<f64>,
        reference: [f64; 3],
        grid: &GfdGrid,
        weights: &Weights,
        max_lead: f64,
        max_tilt: f64,
        lead_tilt: &dyn Fn(&Vector3<f64>) -> (f64, f64),
        limits: &[AxisLimits; 6],
    ) -> Self {
        let [l1, l2, l3, l4, l5, l6] = limits;
        // Eq. 55 measures q4 against the IKT reference, which eq. 3 leaves
        // undefined at q5 = 0 and ill-defined near it (the nominal q4 of a
        // near-vertical axis swings with noise). A q4 offset δ moves the tool
        // axis by δ·sin|q5| (eq. 2), so the q4 term is weighted by sin²q̂5:
        // the distance to the reference is the axis displacement, and near
        // the vertical the choice of q4 is left to the RTO-change term of
        // eq. 56 and to collisions. Elsewhere (sin²q̂5 ≈ 1 on walls) eq. 55
        // is unchanged.
        let reference_weights = Weights {
            k4: weights.k4 * reference[1].sin().powi(2),
            ..*weights
        };
        let q4s = centred(
            reference[0],
            q4_half_span(grid.q4_half_range, reference[1]),
            grid.q4_steps,
        );
        let q5s = centred(reference[1], grid.q5_half_range, grid.q5_steps);
        let (lo, hi) = q6_span(reference[2], l6);
        let mut q6s: Vec<f64> = if grid.q6_steps <= 1 || hi <= lo {
            vec![reference[2]]
        } else {
            let n = grid.q6_steps - 1;
            (0..=n)
                .map(|k| {
                    // Exact end points: rounding must not push them out of
                    // the stroke.
                    if k == n {
                        hi
                    } else {
                        lo + (hi - lo) * k as f64 / n as f64
                    }
                })
                .collect()
        };
        if !q6s.iter().any(|&v| (v - reference[2]).abs() <= 1e-12) {
            q6s.push(reference[2]);
        }
        // Grid order along q6 (the reference may have been appended), so
        // that neighbouring indices are neighbouring standoffs.
        q6s.sort_by(f64::total_cmp);
        let mut gfd = Gfd {
            cl_index,
            u,
            point: *point,
            reference,
            candidates: Vec::new(),
            angle_rejected: 0,
            range_rejected: 0,
            stroke_rejected: 0,
            total: q4s.len() * q5s.len() * q6s.len(),
            free: Vec::new(),
            axes: [Vec::new(), Vec::new(), Vec::new()],
            grid_index: Vec::new(),
            cell: Vec::new(),
        };
        let mut index = Vec::new();
        for (i4, &q4) in q4s.iter().enumerate() {
            for (i5, &q5) in q5s.iter().enumerate() {
                if !within(q4, l4) || !within(q5, l5) {
                    gfd.range_rejected += q6s.len();
                    continue;
                }
                let o = tool_axis(q4, q5);
                let (lead, tilt) = lead_tilt(&o);
                // Written so that NaN angles or limits reject.
                if !(lead.abs() <= max_lead && tilt.abs() <= max_tilt) {
                    gfd.angle_rejected += q6s.len();
                    continue;
                }
                for (i6, &q6) in q6s.iter().enumerate() {
                    if !within(q6, l6) {
                        gfd.range_rejected += 1;
                        continue;
                    }
                    // Seed 001 eq. 3: M = C - q6 O.
                    let m = point - q6 * o;
                    if !(within(m.x, l1) && within(m.y, l2) && within(m.z, l3)) {
                        gfd.stroke_rejected += 1;
                        continue;
                    }
                    let q = [q4, q5, q6];
                    index.push([i4, i5, i6]);
                    gfd.candidates.push(Candidate {
                        q,
                        distance: weighted_distance(&q, &reference, &reference_weights),
                        lead,
                        tilt,
                    });
                }
            }
        }
        // Stable: equal distances keep grid order.
        let mut order: Vec<usize> = (0..gfd.candidates.len()).collect();
        order.sort_by(|&a, &b| {
            gfd.candidates[a]
                .distance
                .total_cmp(&gfd.candidates[b].distance)
        });
        let (n5, n6) = (q5s.len(), q6s.len());
        gfd.cell = vec![None; gfd.total];
        let mut sorted = Vec::with_capacity(order.len());
        for (p, &k) in order.iter().enumerate() {
            let [i4, i5, i6] = index[k];
            gfd.cell[(i4 * n5 + i5) * n6 + i6] = Some(p);
            gfd.grid_index.push(index[k]);
            sorted.push(gfd.candidates[k]);
        }
        gfd.candidates = sorted;
        gfd.free = vec![None; gfd.candidates.len()];
        gfd.axes = [q4s, q5s, q6s];
        gfd
    }

    /// The grid sample values per axis (q4, q5, q6), each non-decreasing.
    pub fn grid_axes(&self) -> &[Vec<f64>; 3] {
        &self.axes
    }

    /// Grid index (i4, i5, i6) of candidate `p`, `None` if out of range.
    pub fn grid_index(&self, p: usize) -> Option<[usize; 3]> {
        self.grid_index.get(p).copied()
    }

    /// The candidate at grid index `g`, `None` when that sample was
    /// rejected (lead/tilt, range, stroke) or `g` is outside the grid.
    pub fn candidate_at(&self, g: [usize; 3]) -> Option<usize> {
        let [n4, n5, n6] = self.axes.each_ref().map(Vec::len);
        if g[0] >= n4 || g[1] >= n5 || g[2] >= n6 {
            return None;
        }
        self.cell
            .get((g[0] * n5 + g[1]) * n6 + g[2])
            .copied()
            .flatten()
    }

    /// The candidates inside a box (every grid sample of it, when the box
    /// came from [`Self::free_box`]).
    pub fn box_candidates(&self, b: &GridBox) -> Vec<Option<usize>> {
        let mut out = Vec::new();
        for i4 in b.lo_index[0]..=b.hi_index[0] {
            for i5 in b.lo_index[1]..=b.hi_index[1] {
                for i6 in b.lo_index[2]..=b.hi_index[2] {
                    out.push(self.candidate_at([i4, i5, i6]));
                }
            }
        }
        out
    }

    /// The largest box of collision-free candidates grown around candidate
    /// `p` (kerf, issue 16 item 3; not in seed 001, whose RTOs are single
    /// grid picks, eq. 57-60 and 62-64).
    ///
    /// The box is a block of the tensor grid, `[lo_index, hi_index]` per
    /// axis, every sample of which is a candidate (inside the lead/tilt
    /// limits, the joint ranges and the q1..q3 stroke, see [`Self::build`])
    /// and collision-free (checked lazily here, memoised). It starts as the
    /// single sample of `p` and grows one grid layer at a time, the six
    /// faces in turn (−q4, +q4, −q5, +q5, −q6, +q6), a face only when
    /// every sample of the new layer qualifies, until no face can grow:
    /// maximal, not necessarily maximum, in volume.
    ///
    /// # Arguments
    /// * `p` - the candidate the box grows from (it should be free).
    /// * `max_steps` - largest number of grid steps per axis on each side of
    ///   `p`.
    /// * `away_from` - when given (q4, q5, q6), a face never grows towards
    ///   it along an axis where `p` differs from it (so the box excludes a
    ///   configuration known to fail, e.g. a colliding trajectory).
    /// * `world`, `budget` - collision world; the budget is checked before
    ///   each query.
    ///
    /// # Returns
    /// The box, or `None` if `p` is out of range or itself collides.
    ///
    /// # Errors
    /// The budget's [`Interrupt`].
    ///
    /// # Performance
    /// At most one collision query per sample of the final box plus one
    /// per rejected layer (early exit on the first failing sample);
    /// ≤ Π (2 max_steps + 1) samples.
    pub fn free_box(
        &mut self,
        p: usize,
        max_steps: [usize; 3],
        away_from: Option<[f64; 3]>,
        world: &CollisionWorld,
        budget: &Budget,
    ) -> Result<Option<GridBox>, Interrupt> {
        let Some(start) = self.grid_index(p) else {
            return Ok(None);
        };
        budget.check("the RTO box")?;
        if !self.is_free(p, world) {
            return Ok(None);
        }
        let n = self.axes.each_ref().map(Vec::len);
        let q = self.candidates[p].q;
        let (mut lo, mut hi) = (start, start);
        loop {
            let mut grew = false;
            for face in 0..6 {
                let (k, up) = (face / 2, face % 2 == 1);
                let blocked_by_target = away_from.is_some_and(|t| {
                    let d = t[k] - q[k];
                    d != 0.0 && (d > 0.0) == up
                });
                let next = if up {
                    (hi[k] + 1 < n[k] && hi[k] - start[k] < max_steps[k]).then(|| hi[k] + 1)
                } else {
                    (lo[k] > 0 && start[k] - lo[k] < max_steps[k]).then(|| lo[k] - 1)
                };
                let Some(layer) = next.filter(|_| !blocked_by_target) else {
                    continue;
                };
                let (mut llo, mut lhi) = (lo, hi);
                llo[k] = layer;
                lhi[k] = layer;
                if self.layer_free(llo, lhi, world, budget)? {
                    if up {
                        hi[k] = layer;
                    } else {
                        lo[k] = layer;
                    }
                    grew = true;
                }
            }
            if !grew {
                break;
            }
        }
        let value = |k: usize, i: usize| self.axes[k][i];
        Ok(Some(GridBox {
            lo_index: lo,
            hi_index: hi,
            lo: [0, 1, 2].map(|k| value(k, lo[k])),
            hi: [0, 1, 2].map(|k| value(k, hi[k])),
        }))
    }

    /// Whether every grid sample of the block `[lo, hi]` is a collision-free
    /// candidate (known colliding or rejected samples are tested first).
    fn layer_free(
        &mut self,
        lo: [usize; 3],
        hi: [usize; 3],
        world: &CollisionWorld,
        budget: &Budget,
    ) -> Result<bool, Interrupt> {
        let mut unknown = Vec::new();
        for i4 in lo[0]..=hi[0] {
            for i5 in lo[1]..=hi[1] {
                for i6 in lo[2]..=hi[2] {
                    match self.candidate_at([i4, i5, i6]) {
                        None => return Ok(false),
                        Some(c) => match self.known_status(c) {
                            Some(false) => return Ok(false),
                            Some(true) => {}
                            None => unknown.push(c),
                        },
                    }
                }
            }
        }
        for c in unknown {
            budget.check("the RTO box")?;
            if !self.is_free(c, world) {
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// Full joint vector of candidate `p` at this CL point: q1..q3 = C −
    /// q6 · O(q4, q5) (seed 001 eq. 3), then q4, q5, q6.
    ///
    /// # Panics
    /// If `p >= self.candidates.len()` (a programming error: indices come
    /// from this GFD).
    pub fn joint_vector(&self, p: usize) -> [f64; 6] {
        let [q4, q5, q6] = self.candidates[p].q;
        let m = self.point - q6 * tool_axis(q4, q5);
        [m.x, m.y, m.z, q4, q5, q6]
    }

    /// Whether candidate `p` is collision-free, evaluated on first use and
    /// memoised (one [`CollisionWorld`] query at most per candidate).
    ///
    /// # Panics
    /// If `p >= self.candidates.len()`.
    pub fn is_free(&mut self, p: usize, world: &CollisionWorld) -> bool {
        if let Some(known) = self.free[p] {
            return known;
        }
        let free = world.is_free(&self.joint_vector(p));
        self.free[p] = Some(free);
        free
    }

    /// The collision status of candidate `p` if already evaluated
    /// (`Some(true)` free), without querying.
    pub fn known_status(&self, p: usize) -> Option<bool> {
        self.free.get(p).copied().flatten()
    }

    /// The free candidate nearest to `target` = (q4, q5, q6) in the metric
    /// of eq. 55, checking candidates lazily in order of that distance
    /// (ties in candidate order).
    ///
    /// # Returns
    /// The candidate index, or `None` when every candidate collides.
    ///
    /// # Errors
    /// The budget's [`Interrupt`], checked before each collision query.
    ///
    /// # Performance
    /// O(n log n) sort plus as many collision queries as colliding
    /// candidates nearer than the answer (memoised ones are free).
    pub fn nearest_free(
        &mut self,
        target: [f64; 3],
        weights: &Weights,
        world: &CollisionWorld,
        budget: &Budget,
    ) -> Result<Option<usize>, Interrupt> {
        Ok(self
            .nearest_free_k(target, weights, world, budget, 1)?
            .first()
            .copied())
    }

    /// The first `k` free candidates in order of the eq. 55 distance to
    /// `target` (ties in candidate order), as [`Self::nearest_free`].
    ///
    /// # Returns
    /// Up to `k` candidate indices, nearest first (fewer when fewer are
    /// free).
    ///
    /// # Errors
    /// The budget's [`Interrupt`], checked before each collision query.
    ///
    /// # Performance
    /// O(n log n) sort plus a collision query per unchecked candidate nearer
    /// than the k-th free one.
    pub fn nearest_free_k(
        &mut self,
        target: [f64; 3],
        weights: &Weights,
        world: &CollisionWorld,
        budget: &Budget,
        k: usize,
    ) -> Result<Vec<usize>, Interrupt> {
        let mut order: Vec<(f64, usize)> = self
            .candidates
            .iter()
            .enumerate()
            .map(|(p, c)| (weighted_distance(&c.q, &target, weights), p))
            .collect();
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut found = Vec::new();
        for (_, p) in order {
            if found.len() >= k {
                break;
            }
            budget.check("the search for a free GFD candidate")?;
            if self.is_free(p, world) {
                found.push(p);
            }
        }
        Ok(found)
    }

    /// Number of candidates whose collision status has been evaluated.
    pub fn collision_checked(&self) -> usize {
        self.free.iter().filter(|f| f.is_some()).count()
    }

    /// Number of candidates known to collide.
    pub fn known_colliding(&self) -> usize {
        self.free.iter().filter(|f| **f == Some(false)).count()
    }
}
