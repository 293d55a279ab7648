//! The collision verdicts of a whole sequence of configurations (a sampled
//! trajectory) by conservative advancement: one query per head shape
//! decides a run of samples when the shape cannot reach the workpiece
//! within them.
//!
//! For one head shape S (not inflated), placed at the anchor sample i and
//! at a later sample j, every point of S_j lies within the Hausdorff
//! distance H(S_i, S_j) of S_i, so the distance to the workpiece W obeys
//! `d(S_j, W) ≥ d(S_i, W) - H(S_i, S_j)` (the distance function is
//! 1-Lipschitz; the principle of conservative advancement, Mirtich,
//! *Impulse-based dynamic simulation of rigid body systems*, PhD thesis,
//! UC Berkeley, 1996, section 2.3.2). [`motion_bound`] bounds H from the
//! two placements of the shape's frame, which carry every joint's
//! displacement: translation of the shape's centre plus its rotation times
//! its radius about the centre. The anchor's query
//! ([`CollisionWorld::shape_query`]) gives the exact verdict at i and, when
//! clear, a certified `d(S_i, W) ≥ clearance + clear_by`; every following
//! sample with `motion_bound(i, j) < clear_by` is then clear by more than
//! the clearance without any query of its own. The first sample that is
//! not covered becomes the next anchor. So every sample's verdict is
//! exactly the per-sample check's ([`CollisionWorld::colliding_links`]):
//! tested directly at the anchors, proven clear elsewhere.

use std::sync::atomic::Ordering;

use parry3d_f64::math::{Pose, Vector};

use super::separation::{LocalPrimitive, SEPARATION_MARGIN};
use super::world::{to_pose, CollisionWorld};

/// Most samples one anchor query is asked to cover (the query's search box
/// is widened by the motion over them; see [`CollisionWorld::colliding_links_along`]).
pub const MAX_WINDOW: usize = 64;

/// Most per-sample queries made after a widened query that covered no
/// sample, before the next widened one (the count doubles from 1 after each
/// such failure and resets after a success).
pub const MAX_BACKOFF: usize = 16;

/// Largest widening (m) of an anchor query's search box: wider boxes
/// bring in more triangles than the samples they cover save (measured on
/// cases 1 and 2, BENCHMARKS.md).
pub const MAX_EXPAND: f64 = 0.003;

/// An upper bound (m) on the Hausdorff distance between a head primitive
/// placed at `a` and at `b` (mesh frame; the primitive is centred on its
/// frame's origin, cylinders along the frame's y axis as in parry).
///
/// * ball: `|Δc|`, the centre's displacement;
/// * cylinder (radius r, half length h): `|Δc| + √(r² + h²) |a_b - a_a|`
///   with `a` the unit axis: the rotation of least angle φ taking `a_a` to
///   `a_b` about the centre maps the cylinder onto itself up to the spin
///   about its own axis (which leaves the set unchanged), and moves a point
///   at distance ρ from the centre by `2 sin(φ/2) ρ = |a_b - a_a| ρ`;
/// * box (half extents h): `|Δc| + |h| · 2 |vec(q_a* q_b)|`: the relative
///   rotation of angle θ moves a point at distance ρ from the centre by
///   `2 sin(θ/2) ρ`, and `sin(θ/2)` is the norm of the vector part of the
///   unit relative quaternion (exact for small angles, unlike `acos`).
///
/// # Performance
/// O(1), no allocation.
pub(super) fn motion_bound(primitive: &LocalPrimitive, a: &Pose, b: &Pose) -> f64 {
    let dc = (b.translation - a.translation).length();
    match *primitive {
        LocalPrimitive::Ball { .. } => dc,
        LocalPrimitive::Cylinder {
            radius,
            half_length,
        } => {
            let da = (b.rotation * Vector::Y - a.rotation * Vector::Y).length();
            dc + radius.hypot(half_length) * da
        }
        LocalPrimitive::Cuboid { half } => {
            let rel = a.rotation.conjugate() * b.rotation;
            let sin_half = Vector::new(rel.x, rel.y, rel.z).length();
            dc + Vector::new(half[0], half[1], half[2]).length() * 2.0 * sin_half
        }
    }
}

impl CollisionWorld {
    /// [`CollisionWorld::colliding_links`] of every configuration of
    /// `qs`, decided by conservative advancement (module docs): the result
    /// equals `qs.iter().map(|q| self.colliding_links(q))`, sample for
    /// sample and link for link.
    ///
    /// Each head shape is queried at an anchor sample with its search box
    /// widened by the shape's motion over the next samples (at most
    /// [`MAX_WINDOW`] samples and [`MAX_EXPAND`]); the samples the certified
    /// clearance covers need no query; the first one not covered is the
    /// next anchor. A widened query that covers nothing (the shape is near
    /// the workpiece, as the nozzle tip over the cut) is followed by 1, 2,
    /// 4, ... up to [`MAX_BACKOFF`] per-sample queries before the next
    /// widened one. Every sample whose shape is not proven clear this way
    /// is tested exactly. A non-finite configuration collides on every
    /// link, as in [`CollisionWorld::colliding_links`], and is never covered
    /// from an anchor on the other side of it. Counts one query per
    /// configuration.
    ///
    /// # Performance
    /// One query per shape per anchor; far from the workpiece an anchor
    /// covers up to [`MAX_WINDOW`] samples. Near it (the nozzle tip over the
    /// cut) nearly every sample gets the per-sample query. Case 2 (final
    /// plan): 2.7 µs per sample against 4.1 µs for one
    /// [`CollisionWorld::colliding_links`] per sample (BENCHMARKS.md).
    /// Allocates the placements of one shape at a time and one name list
    /// per colliding sample.
    pub fn colliding_links_along(&self, qs: &[[f64; 6]]) -> Vec<Vec<&'static str>> {
        self.queries.fetch_add(qs.len(), Ordering::Relaxed);
        let n = qs.len();
        let finite: Vec<bool> = qs.iter().map(|q| q.iter().all(|v| v.is_finite())).collect();
        // One bit per link (in check order) per sample.
        let mut hits = vec![0u32; n];
        let every_link = (1u32 << self.links.len()) - 1;
        for (k, ok) in finite.iter().enumerate() {
            if !ok {
                hits[k] = every_link;
            }
        }
        let mut link_poses: Vec<Option<Pose>> = Vec::with_capacity(n);
        let mut placements: Vec<Option<Pose>> = Vec::with_capacity(n);
        for (l, link) in self.links.iter().enumerate() {
            let bit = 1u32 << l;
            link_poses.clear();
            link_poses.extend(
                qs.iter()
                    .zip(&finite)
                    .map(|(q, &ok)| ok.then(|| to_pose(&link.link.pose(q), &self.origin))),
            );
            for s in &link.shapes {
                placements.clear();
                placements.extend(link_poses.iter().map(|p| p.map(|p| p * s.local)));
                let motion =
                    |a: &Pose, j: usize| placements[j].map(|b| motion_bound(&s.primitive, a, &b));
                let mut window = 1usize;
                // Plain queries to make before the next widened one, and
                // how many the last failed widening earned.
                let (mut plain_left, mut backoff) = (0usize, 0usize);
                let mut k = 0;
                while k < n {
                    let Some(anchor) = placements[k] else {
                        k += 1;
                        continue;
                    };
                    if hits[k] & bit != 0 {
                        // Another shape of this link decided it.
                        k += 1;
                        continue;
                    }
                    if plain_left > 0 {
                        // Near the workpiece: the per-sample query.
                        plain_left -= 1;
                        if self.shape_query(&anchor, s, 0.0).hit {
                            hits[k] |= bit;
                        }
                        k += 1;
                        continue;
                    }
                    // Widen the search by the motion over the next samples.
                    let mut expand: f64 = 0.0;
                    for j in k + 1..(k + 1 + window).min(n) {
                        match motion(&anchor, j) {
                            Some(m) => expand = expand.max(m),
                            None => break,
                        }
                    }
                    let verdict =
                        self.shape_query(&anchor, s, (expand + SEPARATION_MARGIN).min(MAX_EXPAND));
                    let mut j = k + 1;
                    if verdict.hit {
                        hits[k] |= bit;
                    } else {
                        while j < n && motion(&anchor, j).is_some_and(|m| m <= verdict.clear_by) {
                            j += 1;
                        }
                    }
                    let covered = j - k - 1;
                    if covered == 0 {
                        backoff = (2 * backoff).clamp(1, MAX_BACKOFF);
                        plain_left = backoff;
                        window = 1;
                    } else {
                        backoff = 0;
                        window = (2 * covered + 1).min(MAX_WINDOW);
                    }
                    k = j;
                }
            }
        }
        hits.iter()
            .map(|&h| {
                self.links
                    .iter()
                    .enumerate()
                    .filter(|(l, _)| h & (1 << l) != 0)
                    .map(|(_, link)| link.link.name())
                    .collect()
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]

    use super::*;
    use parry3d_f64::math::Rotation;

    /// The bound is never below the largest displacement of the
    /// primitive's points (sampled on its surface), for random pose pairs.
    #[test]
    fn motion_bound_covers_every_point() {
        let mut seed = 3u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let prims = [
            LocalPrimitive::Cylinder {
                radius: 0.09,
                half_length: 0.15,
            },
            LocalPrimitive::Cuboid {
                half: [0.05, 0.015, 0.1],
            },
            LocalPrimitive::Ball { radius: 0.02 },
        ];
        for _ in 0..3000 {
            let mut pose = |scale: f64| {
                let axis = Vector::new(next(), next(), next())
                    .try_normalize()
                    .unwrap_or(Vector::Z);
                Pose::from_parts(
                    Vector::new(next(), next(), next()) * 0.01,
                    Rotation::from_axis_angle(axis, scale * next()),
                )
            };
            let a = pose(3.0);
            let small = pose(0.2);
            let b = a * small;
            for prim in &prims {
                let bound = motion_bound(prim, &a, &b);
                // Surface points in the primitive's frame.
                for u in 0..24 {
                    let t = u as f64 / 24.0 * std::f64::consts::TAU;
                    for v in [-1.0, -0.5, 0.0, 0.5, 1.0] {
                        let p = match *prim {
                            LocalPrimitive::Cylinder {
                                radius,
                                half_length,
                            } => Vector::new(radius * t.cos(), v * half_length, radius * t.sin()),
                            LocalPrimitive::Cuboid { half } => Vector::new(
                                half[0] * t.cos().signum(),
                                half[1] * v,
                                half[2] * t.sin().signum(),
                            ),
                            LocalPrimitive::Ball { radius } => {
                                Vector::new(radius * t.cos(), 0.0, radius * t.sin())
                            }
                        };
                        // The nearest point of the moved primitive: for a
                        // cylinder the same point up to the spin about its
                        // axis, which the bound need not cover; check the
                        // point itself for boxes and the centre for balls.
                        let moved = match prim {
                            LocalPrimitive::Cylinder { .. } => {
                                // distance from a*p to the moved cylinder's
                                // matching circle: align by the least rotation.
                                let axis_a = a.rotation * Vector::Y;
                                let axis_b = b.rotation * Vector::Y;
                                let least = Rotation::from_rotation_arc(axis_a, axis_b);
                                let pa = a * p;
                                let rel = least * (pa - a.translation) + b.translation;
                                // ... which is a point of the cylinder at b.
                                let local = b.inverse() * rel;
                                let LocalPrimitive::Cylinder {
                                    radius,
                                    half_length,
                                } = *prim
                                else {
                                    unreachable!()
                                };
                                assert!((local.x.hypot(local.z) - radius).abs() < 1e-9);
                                assert!(local.y.abs() <= half_length + 1e-9);
                                (rel - pa).length()
                            }
                            LocalPrimitive::Cuboid { .. } => ((b * p) - (a * p)).length(),
                            LocalPrimitive::Ball { .. } => (b.translation - a.translation).length(),
                        };
                        assert!(moved <= bound + 1e-12, "{prim:?}: {moved} > {bound}");
                    }
                }
            }
        }
    }
}
