//! The exact distance between the head and the workpiece at a
//! configuration, for certifying motions by conservative advancement
//! (`kerf_approach`'s clearance check, issue 27).
//!
//! The distance at `q` is
//!
//! ```text
//! D(q) = min over head shapes S_i(q) and workpiece triangles T_k of
//!        d(S_i(q), T_k),   d(A, B) = min_{x ∈ A, y ∈ B} |x − y|,
//! ```
//!
//! the Euclidean separation distance of the head primitives (not inflated
//! by the clearance) from the triangle mesh; `d(S_i, T_k)` is parry's exact
//! convex distance (GJK, Gilbert, Johnson, Keerthi, IEEE Journal of Robotics
//! and Automation 4(2), 1988), 0 when they touch or overlap.
//!
//! It is found by branch and bound over the same structures the boolean
//! check uses ([`CollisionWorld::colliding_links`]): the shapes are visited
//! by increasing lower bound (the gap between the shape's box and the
//! workpiece's box); for each, parry's best-first search of the mesh BVH
//! (`Bvh::find_best`) visits the nodes nearest the shape's box first and
//! prunes every node whose box gap already reaches the best distance found
//! so far (over every shape); a triangle that survives first meets the
//! separating axes of `separation` (its gap is a rigorous lower bound on
//! `d(S_i, T_k)`; Ericson, *Real-Time Collision Detection*, 2005, section
//! 5.2.1) and gets parry's exact distance only when that bound, less
//! [`super::SEPARATION_MARGIN`], is below the best. Every bound used is a
//! lower bound of the distance it prunes, so the result is the minimum of
//! parry's distances over all shape-triangle pairs (`tests/collision_distance.rs`
//! checks it against that brute force).
//!
//! # As the clearance function of `kerf_approach`
//! With `L = world.head().lipschitz()` ([`super::HeadModel::lipschitz`])
//! as the check's per-joint bounds and the clearance `c`:
//!
//! ```text
//! |q: &[f64]| match <[f64; 6]>::try_from(q).map(|q| world.distance_up_to(&q, cutoff)) {
//!     Ok(Ok(Some(d))) => Clearance::new(d.distance, format!("workpiece ({})", d.link)),
//!     Ok(Ok(None)) => Clearance::new(cutoff, "workpiece"),   // a lower bound: safe
//!     _ => Clearance::new(f64::NAN, "invalid configuration"),   // refused by the check
//! }
//! ```
//!
//! With `cutoff ≥ c + S`, `S = Σ_j L_j v_j T` the largest sweep of one
//! control period `T` at the velocity limits `v_j`, the check's verdicts
//! are those it gives with exact distances: a sample reported at `cutoff`
//! is truly at least that far, and paired with any sample `d' ≥ c` it meets
//! the two-sample condition `d' + cutoff ≥ 2c + M` for every pair sweep
//! `M ≤ S` (refinement only shortens the sweep), which is all the exact value
//! could do; a sample below `cutoff` is reported exactly.

use std::sync::atomic::Ordering;

use nalgebra::{Point3, Vector3};
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::partitioning::BvhNode;
use parry3d_f64::query::{
    closest_points, contact, ClosestPoints, DefaultQueryDispatcher, PointQuery, QueryDispatcher,
};
use parry3d_f64::shape::Triangle;

use super::separation::SEPARATION_MARGIN;
use super::world::{aabb_gap, to_pose, CollisionWorld, WorldShape};
use crate::PlanError;

/// The distance from the head to the workpiece at one configuration
/// ([`CollisionWorld::distance`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Distance {
    /// Euclidean distance (m) between the nearest head shape (not inflated
    /// by the clearance) and the nearest workpiece triangle; exactly 0 when
    /// some shape touches or intersects the workpiece (no penetration
    /// depth: the workpiece is a surface, not a solid).
    pub distance: f64,
    /// The URDF name of the head link of the nearest shape (one of them on
    /// a tie).
    pub link: &'static str,
    /// The point of that shape nearest the workpiece (machine frame, m).
    pub head_point: Point3<f64>,
    /// The point of the workpiece nearest the head (machine frame, m); at
    /// `distance` from `head_point` up to parry's tolerance. When the two
    /// intersect, parry's contact points with that triangle instead (the
    /// deepest points along the contact normal; their distance is the
    /// penetration depth against that one triangle). Should parry give
    /// neither (a pair at the edge of its tolerance): the triangle's point
    /// nearest the shape's centre, and that centre as `head_point`.
    pub workpiece_point: Point3<f64>,
}

/// One placed head shape and the lower bound of its distance.
struct Candidate<'a> {
    /// Gap between the shape's box and the workpiece's box (m).
    lower: f64,
    link: &'static str,
    shape: &'a WorldShape,
    /// The shape's pose in the mesh frame.
    pose: Pose,
    /// Its box in the mesh frame.
    aabb: Aabb,
}

/// Parry's distance of a pair as a safe number: an unsupported pair (excluded
/// by [`CollisionWorld::new`]) or a NaN counts as touching.
fn safe_distance(
    d: Result<parry3d_f64::query::ShapeDistance, parry3d_f64::query::Unsupported>,
) -> f64 {
    match d {
        Ok(d) if d.distance >= 0.0 => d.distance,
        _ => 0.0,
    }
}

impl CollisionWorld {
    /// The exact distance from the head to the workpiece at `q` (module
    /// documentation): the minimum over every head shape and workpiece
    /// triangle of parry's exact distance, with the nearest link and points.
    ///
    /// Unlike [`CollisionWorld::colliding_links`] the head is not inflated:
    /// `q` collides at this world's clearance exactly when
    /// `distance ≤ clearance` (up to parry's tolerance, below 1 nm).
    /// Counts one query.
    ///
    /// # Arguments
    /// * `q` - joint vector q1..q6 (m, rad).
    ///
    /// # Returns
    /// The [`Distance`]: ≥ 0, exactly 0 for touching or intersecting
    /// shapes.
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] (field `q`) when a joint value is NaN
    /// or infinite: such a configuration cannot be placed, and no distance
    /// (not even NaN) is given for it. A clearance callback should turn the
    /// error into a refusal (e.g. a NaN distance, which `kerf_approach`
    /// rejects), never into a large distance. [`PlanError::Mesh`] should no
    /// triangle give a distance (not for any mesh [`CollisionWorld::new`]
    /// accepts: it has triangles, and parry's answers are finite).
    ///
    /// # Performance
    /// Branch and bound over the mesh BVH: a few exact triangle distances
    /// near the nearest one, plus one closest-point query (GJK) for the
    /// points, or one contact query (EPA) when intersecting. On the shipped
    /// B-pillar (4 964 triangles, 7 head shapes; test profile, 2-core
    /// machine, `tests/collision_distance.rs` prints the figures): 16 µs
    /// with the head clear within a few centimetres of the part, 30 µs
    /// colliding, 37 µs with the head 0.3 m above it (a wide flat part has
    /// many nearly equidistant triangles), against 0.2-3 µs for
    /// [`CollisionWorld::is_free`]. Where only distances near the clearance
    /// matter, [`CollisionWorld::distance_up_to`] costs 1-3 µs clear of the
    /// part. Allocates the list of placed shapes.
    pub fn distance(&self, q: &[f64; 6]) -> Result<Distance, PlanError> {
        self.nearest(q, f64::INFINITY)?
            .ok_or_else(|| PlanError::Mesh {
                source_name: "workpiece".into(),
                reason: "no triangle gave a distance".into(),
            })
    }

    /// [`CollisionWorld::distance`] when it is below `cutoff`, else only
    /// the fact that it is not: the search starts with `cutoff` as the best
    /// distance, so shapes and BVH nodes at least that far are never
    /// searched, and a head far from the part costs a few box tests.
    /// Counts one query.
    ///
    /// # Arguments
    /// * `q` - joint vector q1..q6 (m, rad).
    /// * `cutoff` - the distance (m) beyond which the exact value is not
    ///   needed; `+∞` is [`CollisionWorld::distance`], ≤ 0 always answers
    ///   `None`.
    ///
    /// # Returns
    /// `Some(d)` exactly when the distance is below `cutoff`, `d` then
    /// being the [`CollisionWorld::distance`] answer (the minimum of the
    /// same parry distances); `None` when every head shape is at least
    /// `cutoff` from every triangle: each pair was either pruned by a
    /// rigorous lower bound ≥ `cutoff` or measured by parry at ≥ `cutoff`.
    /// So `cutoff` is then a safe lower bound of the distance (as a
    /// clearance callback may report it).
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] (field `q`) for a non-finite joint
    /// value, (field `cutoff`) for a NaN cutoff.
    ///
    /// # Performance
    /// At most the cost of [`CollisionWorld::distance`]; with the head
    /// farther than `cutoff`, one pose and box test per shape plus the BVH
    /// nodes and triangles within `cutoff` of the shapes' boxes: with a
    /// 1 cm cut-off on the B-pillar, 3 µs clear within a few centimetres,
    /// 1 µs 0.3 m above the part (test profile).
    pub fn distance_up_to(&self, q: &[f64; 6], cutoff: f64) -> Result<Option<Distance>, PlanError> {
        if cutoff.is_nan() {
            return Err(PlanError::invalid("cutoff", "NaN is not a distance"));
        }
        self.nearest(q, cutoff)
    }

    /// The branch and bound of the module documentation, starting from the
    /// best distance `cutoff`.
    fn nearest(&self, q: &[f64; 6], cutoff: f64) -> Result<Option<Distance>, PlanError> {
        self.queries.fetch_add(1, Ordering::Relaxed);
        if let Some((k, v)) = q.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(PlanError::invalid(
                "q",
                format!("q{} = {v}: a configuration must be finite", k + 1),
            ));
        }
        let mut candidates: Vec<Candidate<'_>> = Vec::with_capacity(8);
        for link in &self.links {
            let link_pose = to_pose(&link.link.pose(q), &self.origin);
            for s in &link.shapes {
                let pose = link_pose * s.local;
                let aabb = s.raw.compute_aabb(&pose);
                candidates.push(Candidate {
                    lower: aabb_gap(&aabb, &self.mesh_aabb),
                    link: link.link.name(),
                    shape: s,
                    pose,
                    aabb,
                });
            }
        }
        candidates.sort_by(|a, b| a.lower.total_cmp(&b.lower));

        let mut best = cutoff;
        let mut found: Option<(usize, u32)> = None;
        for (k, c) in candidates.iter().enumerate() {
            // Sorted: no later shape can come closer either.
            if c.lower >= best {
                break;
            }
            let placed = c.shape.primitive.placed(&c.pose);
            let hit = self.mesh.bvh().find_best(
                best,
                |node: &BvhNode, _| aabb_gap(&node.aabb(), &c.aabb),
                |i, best_cost| {
                    if best_cost.is_finite() {
                        let enough = best_cost + SEPARATION_MARGIN;
                        let gap = self
                            .triangles
                            .get(i as usize)
                            .map_or(f64::NEG_INFINITY, |t| placed.gap(t, enough));
                        if gap > enough {
                            return None;
                        }
                    }
                    Some(safe_distance(DefaultQueryDispatcher.distance(
                        &c.pose,
                        &self.mesh.triangle(i),
                        c.shape.raw.as_ref(),
                    )))
                },
            );
            if let Some((i, d)) = hit {
                best = d;
                found = Some((k, i));
            }
            if best <= 0.0 {
                break;
            }
        }
        Ok(found.and_then(|(k, i)| {
            let c = candidates.get(k)?;
            let (w, h) = closest_pair(c.shape, &c.pose, &self.mesh.triangle(i), best);
            let point = |v: Vector| Point3::from(Vector3::new(v.x, v.y, v.z) + self.origin);
            Some(Distance {
                distance: best,
                link: c.link,
                head_point: point(h),
                workpiece_point: point(w),
            })
        }))
    }
}

/// The points (workpiece, head) of triangle `tri` and shape `s` at pose `p`
/// (mesh frame) that realise their distance `d`: parry's closest points when
/// apart, its contact points when touching; should parry give neither (a
/// pair at the edge of its tolerance), the triangle's point nearest the
/// shape's centre, and that centre.
fn closest_pair(s: &WorldShape, p: &Pose, tri: &Triangle, d: f64) -> (Vector, Vector) {
    let shape = s.raw.as_ref();
    if d > 0.0 {
        let margin = d * (1.0 + 1e-6) + SEPARATION_MARGIN;
        if let Ok(ClosestPoints::WithinMargin(w, h)) =
            closest_points(&Pose::IDENTITY, tri, p, shape, margin)
        {
            return (w, h);
        }
    }
    if let Ok(Some(c)) = contact(&Pose::IDENTITY, tri, p, shape, d + SEPARATION_MARGIN) {
        return (c.point1, c.point2);
    }
    let centre = p.translation;
    (tri.project_local_point(centre, true).point, centre)
}
