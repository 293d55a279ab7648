//! A cheap, rigorous first stage of the head-shape-vs-triangle test: a few
//! separating axes.
//!
//! Two convex sets are disjoint when their projections on some axis are
//! (separating-axis theorem; Ericson, *Real-Time Collision Detection*,
//! 2005, section 5.2.1). For a head shape inflated by the clearance `c` and
//! a workpiece triangle, a gap `g` between the projections on a unit axis
//! proves `distance > c` as soon as `g > c`. The axes tried here are the
//! triangle's normal, the shape's own axes (cylinder axis, box axes) and
//! the direction from the shape's centre to the triangle's nearest point;
//! when none of them separates, the caller runs parry's exact test. A
//! triangle is declared clear only with a gap larger than
//! `c +` [`SEPARATION_MARGIN`], far above the rounding of the f64
//! projections (1e-15 m at the part's metre scale), so the verdict of the
//! whole check is the one parry's exact test gives.

use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::shape::Triangle;

/// Gap (m) beyond the clearance that a separating axis must show before a
/// triangle is declared clear without the exact test: 1 nm, six orders of
/// magnitude above the rounding of the projections.
pub const SEPARATION_MARGIN: f64 = 1e-9;

/// A head primitive in its parry frame (cylinders along the local y axis,
/// as parry's [`Cylinder`](parry3d_f64::shape::Cylinder)), not inflated.
#[derive(Debug, Clone, Copy)]
pub(super) enum LocalPrimitive {
    /// Cylinder along local y.
    Cylinder {
        /// Radius (m).
        radius: f64,
        /// Half length (m).
        half_length: f64,
    },
    /// Box with its half extents along local x, y, z (m).
    Cuboid {
        /// Half extents (m).
        half: [f64; 3],
    },
    /// Ball (m).
    Ball {
        /// Radius (m).
        radius: f64,
    },
}

/// A primitive placed in the mesh frame.
#[derive(Debug, Clone, Copy)]
pub(super) enum Placed {
    Cylinder {
        centre: Vector,
        axis: Vector,
        radius: f64,
        half_length: f64,
    },
    Cuboid {
        centre: Vector,
        axes: [Vector; 3],
        half: [f64; 3],
    },
    Ball {
        centre: Vector,
        radius: f64,
    },
}

impl LocalPrimitive {
    /// The primitive at `pose` (mesh frame).
    pub(super) fn placed(&self, pose: &Pose) -> Placed {
        let centre = pose.translation;
        match *self {
            LocalPrimitive::Cylinder {
                radius,
                half_length,
            } => Placed::Cylinder {
                centre,
                axis: pose.rotation * Vector::Y,
                radius,
                half_length,
            },
            LocalPrimitive::Cuboid { half } => Placed::Cuboid {
                centre,
                axes: [
                    pose.rotation * Vector::X,
                    pose.rotation * Vector::Y,
                    pose.rotation * Vector::Z,
                ],
                half,
            },
            LocalPrimitive::Ball { radius } => Placed::Ball { centre, radius },
        }
    }
}

impl Placed {
    fn centre(&self) -> Vector {
        match *self {
            Placed::Cylinder { centre, .. }
            | Placed::Cuboid { centre, .. }
            | Placed::Ball { centre, .. } => centre,
        }
    }

    /// Half width of the projection on the unit axis `n` (m): the support
    /// function `max_x n·(x - centre)`.
    ///
    /// * cylinder (centre p, unit axis a, radius r, half length h): the
    ///   points `p + s a + r u` (|s| ≤ h, u ⊥ a unit) give
    ///   `h |n·a| + r |n - (n·a) a| = h |n·a| + r √(1 - (n·a)²)`;
    /// * box: `Σ h_i |n·u_i|` (Ericson 2005, section 4.4.1, the OBB
    ///   projection radius);
    /// * ball: r.
    fn extent(&self, n: Vector) -> f64 {
        match *self {
            Placed::Cylinder {
                axis,
                radius,
                half_length,
                ..
            } => {
                let c = n.dot(axis);
                half_length * c.abs() + radius * (1.0 - c * c).max(0.0).sqrt()
            }
            Placed::Cuboid { axes, half, .. } => {
                half[0] * n.dot(axes[0]).abs()
                    + half[1] * n.dot(axes[1]).abs()
                    + half[2] * n.dot(axes[2]).abs()
            }
            Placed::Ball { radius, .. } => radius,
        }
    }

    /// True when an axis proves the shape, inflated by `clearance`, clear
    /// of the triangle by more than [`SEPARATION_MARGIN`].
    #[cfg(test)]
    pub(super) fn separated(&self, tri: &TriangleAxes, clearance: f64) -> bool {
        let need = clearance + SEPARATION_MARGIN;
        self.gap(tri, need) > need
    }

    /// A lower bound on the distance (m) between the primitive (not
    /// inflated) and the triangle: the largest gap between their
    /// projections over the axes tried (≤ 0 when none separates). Stops at
    /// the first axis whose gap exceeds `enough`.
    ///
    /// Axes, cheapest and likeliest first: the triangle's normal; the
    /// shape's own axes; the direction from the shape's centre to the
    /// triangle's nearest point; the cross products of the shape's axes
    /// with the triangle's edges (the edge-edge axes of the separating-axis
    /// test of a box and a triangle, Ericson 2005, section 5.2.9; for a
    /// cylinder, its axis with each edge, which separates a long triangle
    /// lying beside it); for a cylinder, the directions from its axis to
    /// each vertex, perpendicular to the axis.
    pub(super) fn gap(&self, tri: &TriangleAxes, enough: f64) -> f64 {
        let c = self.centre();
        let gap = |n: Vector| -> f64 {
            let (lo, hi) = tri.projection(n);
            let s = n.dot(c);
            let e = self.extent(n);
            (lo - (s + e)).max((s - e) - hi)
        };
        let mut best = f64::NEG_INFINITY;
        let mut try_axis = |n: Option<Vector>| -> bool {
            if let Some(n) = n {
                best = best.max(gap(n));
            }
            best > enough
        };
        if try_axis(tri.normal) {
            return best;
        }
        let own: &[Vector] = match self {
            Placed::Cylinder { axis, .. } => std::slice::from_ref(axis),
            Placed::Cuboid { axes, .. } => axes,
            Placed::Ball { .. } => &[],
        };
        for &a in own {
            if try_axis(Some(a)) {
                return best;
            }
        }
        let d = closest_point_on_triangle(c, &tri.vertices) - c;
        // A centre on (or numerically on) the triangle: no direction.
        if try_axis((d.length() > 1e-12).then(|| d.normalize())) {
            return best;
        }
        let [v0, v1, v2] = tri.vertices;
        for e in [v1 - v0, v2 - v1, v0 - v2] {
            for &a in own {
                if try_axis(a.cross(e).try_normalize()) {
                    return best;
                }
            }
        }
        if let Placed::Cylinder { axis, .. } = self {
            for v in tri.vertices {
                let r = v - c;
                if try_axis((r - r.dot(*axis) * *axis).try_normalize()) {
                    return best;
                }
            }
        }
        best
    }
}

/// A workpiece triangle with its unit normal (`None` when degenerate).
#[derive(Debug, Clone, Copy)]
pub(super) struct TriangleAxes {
    vertices: [Vector; 3],
    normal: Option<Vector>,
}

impl TriangleAxes {
    pub(super) fn new(t: &Triangle) -> Self {
        let normal = (t.b - t.a).cross(t.c - t.a).try_normalize();
        Self {
            vertices: [t.a, t.b, t.c],
            normal,
        }
    }

    /// `(min, max)` of `n·v` over the vertices: the triangle's projection
    /// (a convex hull projects onto the hull of its vertices' projections).
    fn projection(&self, n: Vector) -> (f64, f64) {
        let [a, b, c] = self.vertices.map(|v| n.dot(v));
        (a.min(b).min(c), a.max(b).max(c))
    }
}

/// The point of triangle `t` nearest to `p` (Ericson 2005, section 5.1.5,
/// `ClosestPtPointTriangle`, by Voronoi regions). Only its direction from
/// `p` is used, as an axis; the separation test itself projects the
/// vertices, so rounding here cannot make the test wrong.
fn closest_point_on_triangle(p: Vector, t: &[Vector; 3]) -> Vector {
    let [a, b, c] = *t;
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return a + v * ab;
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return a + w * ac;
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return b + w * (c - b);
    }
    let denom = va + vb + vc;
    if denom.abs() < f64::MIN_POSITIVE {
        // Degenerate triangle: any vertex gives a usable direction.
        return a;
    }
    let v = vb / denom;
    let w = vc / denom;
    a + ab * v + ac * w
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]

    use super::*;
    use parry3d_f64::math::Rotation;
    use parry3d_f64::query::intersection_test;
    use parry3d_f64::shape::{Ball, Cuboid, Cylinder, RoundShape, Shape};

    /// Deterministic pseudo-random numbers in [-1, 1) (SplitMix64).
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        }
        fn vector(&mut self, scale: f64) -> Vector {
            Vector::new(self.next(), self.next(), self.next()) * scale
        }
    }

    /// Every separation claimed by the axes is confirmed by parry's exact
    /// distance, over random shapes and triangles from touching to far
    /// apart; and the prefilter does separate most clearly separated pairs.
    #[test]
    fn separation_is_never_claimed_for_touching_pairs() {
        let mut rng = Rng(7);
        let mut claimed = 0;
        let mut clear = 0;
        let mut clear_separated = 0;
        for k in 0..20_000 {
            let clearance = [0.0, 0.001, 0.01][k % 3];
            let prim = match k % 3 {
                0 => LocalPrimitive::Cylinder {
                    radius: 0.005 + 0.05 * rng.next().abs(),
                    half_length: 0.005 + 0.1 * rng.next().abs(),
                },
                1 => LocalPrimitive::Cuboid {
                    half: [
                        0.005 + 0.05 * rng.next().abs(),
                        0.005 + 0.05 * rng.next().abs(),
                        0.005 + 0.1 * rng.next().abs(),
                    ],
                },
                _ => LocalPrimitive::Ball {
                    radius: 0.005 + 0.05 * rng.next().abs(),
                },
            };
            let shape: Box<dyn Shape> = match prim {
                LocalPrimitive::Cylinder {
                    radius,
                    half_length,
                } => Box::new(RoundShape {
                    inner_shape: Cylinder::new(half_length, radius),
                    border_radius: clearance,
                }),
                LocalPrimitive::Cuboid { half } => Box::new(RoundShape {
                    inner_shape: Cuboid::new(Vector::new(half[0], half[1], half[2])),
                    border_radius: clearance,
                }),
                LocalPrimitive::Ball { radius } => Box::new(Ball::new(radius + clearance)),
            };
            let axis = rng.vector(1.0).try_normalize().unwrap_or(Vector::Z);
            let pose = Pose::from_parts(
                rng.vector(0.15),
                Rotation::from_axis_angle(axis, 3.0 * rng.next()),
            );
            let centre = rng.vector(0.1);
            let tri = Triangle::new(
                centre + rng.vector(0.08),
                centre + rng.vector(0.08),
                centre + rng.vector(0.08),
            );
            let placed = prim.placed(&pose);
            let sep = placed.separated(&TriangleAxes::new(&tri), clearance);
            let exact = intersection_test(&Pose::IDENTITY, &tri, &pose, shape.as_ref())
                .unwrap()
                .intersecting;
            // Raw distance of the uninflated primitive.
            let raw: Box<dyn Shape> = match prim {
                LocalPrimitive::Cylinder {
                    radius,
                    half_length,
                } => Box::new(Cylinder::new(half_length, radius)),
                LocalPrimitive::Cuboid { half } => {
                    Box::new(Cuboid::new(Vector::new(half[0], half[1], half[2])))
                }
                LocalPrimitive::Ball { radius } => Box::new(Ball::new(radius)),
            };
            let d = parry3d_f64::query::distance(&Pose::IDENTITY, &tri, &pose, raw.as_ref())
                .unwrap()
                .distance;
            if sep {
                claimed += 1;
                assert!(!exact, "case {k}: separated but parry reports contact");
                assert!(d > clearance, "case {k}: separated at distance {d}");
            }
            if d > clearance + 0.01 {
                clear += 1;
                clear_separated += usize::from(sep);
            }
        }
        assert!(claimed > 1000, "only {claimed} separations claimed");
        // Pairs 1 cm apart are nearly all separated by the axes (the point
        // of the filter).
        assert!(
            clear_separated * 10 >= clear * 9,
            "{clear_separated} of {clear}"
        );
    }

    #[test]
    fn closest_point_matches_parry_projection() {
        use parry3d_f64::query::PointQuery;
        let mut rng = Rng(11);
        for _ in 0..2000 {
            let tri = Triangle::new(rng.vector(0.1), rng.vector(0.1), rng.vector(0.1));
            let p = rng.vector(0.2);
            let ours = closest_point_on_triangle(p, &[tri.a, tri.b, tri.c]);
            let theirs = tri.project_local_point(p, true).point;
            assert!((ours - theirs).length() < 1e-12, "{ours:?} vs {theirs:?}");
        }
    }
}
