//! The head and the workpiece as parry shapes, ready for configuration
//! queries.

use std::sync::atomic::{AtomicUsize, Ordering};

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};
use parry3d_f64::math::{Pose, Rotation, Vector};
use parry3d_f64::partitioning::BvhNode;
use parry3d_f64::query::{intersection_test, DefaultQueryDispatcher, QueryDispatcher};
use parry3d_f64::shape::{Ball, Cuboid, Cylinder, RoundShape, Shape, TriMesh, TriMeshFlags};

use super::head::{machine_err, HeadLink, HeadModel, Primitive};
use super::separation::{LocalPrimitive, TriangleAxes, SEPARATION_MARGIN};
use crate::mesh::MeshData;
use crate::PlanError;

/// One head primitive as a parry shape (inflated by the clearance).
pub(super) struct WorldShape {
    /// Shape frame in the link frame (parry cylinders are along y: the
    /// URDF z-cylinder is turned by Rx(π/2)).
    pub(super) local: Pose,
    shape: Box<dyn Shape>,
    /// The primitive as a parry shape, not inflated (the distance queries
    /// of [`super::distance`]).
    pub(super) raw: Box<dyn Shape>,
    /// The primitive (not inflated) in the same frame, for the
    /// separating-axis first stage and the motion bounds.
    pub(super) primitive: LocalPrimitive,
}

/// What [`CollisionWorld::shape_query`] found for one placed shape.
#[derive(Debug, Clone, Copy)]
pub(super) struct ShapeVerdict {
    /// Within the clearance of the workpiece (parry's exact verdict).
    pub(super) hit: bool,
    /// When not `hit`: the shape is at least `clearance + clear_by` (m)
    /// from the workpiece; 0 when nothing more is known.
    pub(super) clear_by: f64,
}

/// Euclidean distance between two boxes (0 when they overlap): a lower
/// bound on the distance between any two sets they contain.
pub(super) fn aabb_gap(a: &Aabb, b: &Aabb) -> f64 {
    let lo = (b.mins - a.maxs).max(a.mins - b.maxs).max(Vector::ZERO);
    lo.length()
}

/// The shapes of one link and their joint bounding box in the link frame.
pub(super) struct WorldLink {
    pub(super) link: HeadLink,
    local_aabb: Aabb,
    pub(super) shapes: Vec<WorldShape>,
}

/// The head and the workpiece, ready for configuration queries.
///
/// `Sync`: queries take `&self` (the query counter is atomic), so samples
/// can be checked from several threads.
pub struct CollisionWorld {
    head: HeadModel,
    pub(super) links: Vec<WorldLink>,
    pub(super) mesh: TriMesh,
    /// The mesh's triangles with their normals, by triangle index.
    pub(super) triangles: Vec<TriangleAxes>,
    pub(super) mesh_aabb: Aabb,
    /// Machine-frame point subtracted from every coordinate.
    pub(super) origin: Vector3<f64>,
    clearance: f64,
    pub(super) queries: AtomicUsize,
}

impl std::fmt::Debug for CollisionWorld {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CollisionWorld")
            .field("links", &self.head.links())
            .field("triangles", &self.mesh.num_triangles())
            .field("origin", &self.origin)
            .field("clearance", &self.clearance)
            .field("queries", &self.queries())
            .finish()
    }
}

/// nalgebra isometry (machine frame, f64) to a parry pose relative to
/// `origin`.
pub(super) fn to_pose(iso: &Isometry3<f64>, origin: &Vector3<f64>) -> Pose {
    let t = iso.translation.vector - origin;
    let q = iso.rotation.quaternion();
    Pose::from_parts(
        Vector::new(t.x, t.y, t.z),
        Rotation::from_xyzw(q.i, q.j, q.k, q.w),
    )
}

/// The parry shape of a primitive inflated by `clearance` (m, ≥ 0), and
/// its pose correction (cylinder axis z → y).
fn parry_shape(p: &Primitive, clearance: f64) -> (Box<dyn Shape>, LocalPrimitive, Isometry3<f64>) {
    let z_to_y = Isometry3::from_parts(
        Translation3::identity(),
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2),
    );
    match *p {
        Primitive::Box { half_extents: h } => {
            let c = Cuboid::new(Vector::new(h[0], h[1], h[2]));
            let s: Box<dyn Shape> = if clearance > 0.0 {
                Box::new(RoundShape {
                    inner_shape: c,
                    border_radius: clearance,
                })
            } else {
                Box::new(c)
            };
            (s, LocalPrimitive::Cuboid { half: h }, Isometry3::identity())
        }
        Primitive::Cylinder {
            radius,
            half_length,
        } => {
            let c = Cylinder::new(half_length, radius);
            let s: Box<dyn Shape> = if clearance > 0.0 {
                Box::new(RoundShape {
                    inner_shape: c,
                    border_radius: clearance,
                })
            } else {
                Box::new(c)
            };
            (
                s,
                LocalPrimitive::Cylinder {
                    radius,
                    half_length,
                },
                z_to_y,
            )
        }
        Primitive::Sphere { radius } => (
            Box::new(Ball::new(radius + clearance)),
            LocalPrimitive::Ball { radius },
            Isometry3::identity(),
        ),
    }
}

impl CollisionWorld {
    /// Builds the world: places the workpiece and builds its BVH.
    ///
    /// # Arguments
    /// * `head` - the head geometry ([`HeadModel::from_urdf`]).
    /// * `mesh` - the workpiece in its own frame (m).
    /// * `workpiece_pose` - workpiece frame → machine frame; the vertices
    ///   are transformed once here.
    /// * `clearance` - required distance between head and workpiece (m,
    ///   ≥ 0); a head shape at distance ≤ `clearance` collides.
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] (`options.clearance`) for a negative
    /// or non-finite clearance; [`PlanError::Mesh`] (source `workpiece`)
    /// for every failure of [`MeshData::validated`] or of parry's mesh
    /// builder.
    ///
    /// # Performance
    /// O(n log n) in the number of triangles (BVH build); a 20 000-triangle
    /// part takes a few milliseconds.
    pub fn new(
        head: HeadModel,
        mesh: &MeshData,
        workpiece_pose: &Isometry3<f64>,
        clearance: f64,
    ) -> Result<Self, PlanError> {
        if !clearance.is_finite() || clearance < 0.0 {
            return Err(PlanError::invalid(
                "options.clearance",
                format!("{clearance} must be finite and ≥ 0"),
            ));
        }
        let mesh_err = |reason: String| PlanError::Mesh {
            source_name: "workpiece".into(),
            reason,
        };
        let mesh = mesh.clone().validated("workpiece")?;
        let placed: Vec<Vector3<f64>> = mesh
            .vertices
            .iter()
            .map(|v| (workpiece_pose * nalgebra::Point3::new(v[0], v[1], v[2])).coords)
            .collect();
        if placed.iter().any(|v| !v.iter().all(|c| c.is_finite())) {
            return Err(PlanError::invalid("workpiece_pose", "not finite"));
        }
        let (lo, hi) = placed.iter().fold(
            (
                Vector3::repeat(f64::INFINITY),
                Vector3::repeat(f64::NEG_INFINITY),
            ),
            |(lo, hi), v| (lo.inf(v), hi.sup(v)),
        );
        let origin = (lo + hi) / 2.0;
        let vertices: Vec<Vector> = placed
            .iter()
            .map(|v| {
                let d = v - origin;
                Vector::new(d.x, d.y, d.z)
            })
            .collect();
        let trimesh = TriMesh::with_flags(vertices, mesh.triangles, TriMeshFlags::empty())
            .map_err(|e| mesh_err(format!("cannot build the collision mesh: {e:?}")))?;
        let mesh_aabb = trimesh.local_aabb();
        let triangles = (0..trimesh.num_triangles() as u32)
            .map(|i| TriangleAxes::new(&trimesh.triangle(i)))
            .collect();

        let mut links: Vec<WorldLink> = Vec::new();
        for s in &head.shapes {
            let (shape, primitive, fix) = parry_shape(&s.primitive, clearance);
            let (raw, _, _) = parry_shape(&s.primitive, 0.0);
            let local = to_pose(&(s.origin * fix), &Vector3::zeros());
            let aabb = shape.compute_aabb(&local);
            // Every pair must be supported by parry's dispatcher: probe once.
            let unsupported = |_| {
                machine_err(format!(
                    "parry3d cannot test {:?} against a triangle mesh",
                    s.primitive
                ))
            };
            intersection_test(&Pose::IDENTITY, &trimesh, &local, shape.as_ref())
                .map_err(unsupported)?;
            if trimesh.num_triangles() > 0 {
                DefaultQueryDispatcher
                    .distance(&local, &trimesh.triangle(0), raw.as_ref())
                    .map_err(unsupported)?;
            }
            let ws = WorldShape {
                local,
                shape,
                raw,
                primitive,
            };
            match links.last_mut() {
                Some(l) if l.link == s.link => {
                    l.local_aabb = l.local_aabb.merged(&aabb);
                    l.shapes.push(ws);
                }
                _ => links.push(WorldLink {
                    link: s.link,
                    local_aabb: aabb,
                    shapes: vec![ws],
                }),
            }
        }
        Ok(Self {
            head,
            links,
            mesh: trimesh,
            triangles,
            mesh_aabb,
            origin,
            clearance,
            queries: AtomicUsize::new(0),
        })
    }

    /// The head geometry.
    pub fn head(&self) -> &HeadModel {
        &self.head
    }

    /// The required clearance (m).
    pub fn clearance(&self) -> f64 {
        self.clearance
    }

    /// Number of workpiece triangles.
    pub fn triangles(&self) -> usize {
        self.mesh.num_triangles()
    }

    /// Tests the links of the head at `q`; `all = false` stops at the
    /// first colliding link.
    fn check(&self, q: &[f64; 6], all: bool, exhaustive: bool) -> Vec<&'static str> {
        self.queries.fetch_add(1, Ordering::Relaxed);
        if q.iter().any(|v| !v.is_finite()) {
            // A configuration that cannot be placed is never free.
            return self.links.iter().map(|l| l.link.name()).collect();
        }
        let mut hits = Vec::new();
        for link in &self.links {
            let pose = to_pose(&link.link.pose(q), &self.origin);
            if !link
                .local_aabb
                .transform_by(&pose)
                .intersects(&self.mesh_aabb)
            {
                continue;
            }
            let hit = link.shapes.iter().any(|s| {
                if exhaustive {
                    self.shape_hits_exhaustive(&(pose * s.local), s)
                } else {
                    self.shape_hits(&(pose * s.local), s)
                }
            });
            if hit {
                hits.push(link.link.name());
                if !all {
                    break;
                }
            }
        }
        hits
    }

    /// Whether one placed head shape (pose `p` in the mesh frame) is within
    /// the clearance of the workpiece: parry's composite test
    /// (`intersects_shape`: every triangle whose BVH leaf box meets the
    /// shape's box, then the exact triangle-vs-shape test), with the
    /// separating axes of [`super::separation`] as a rigorous first stage
    /// before each exact triangle test.
    pub(super) fn shape_hits(&self, p: &Pose, s: &WorldShape) -> bool {
        self.shape_query(p, s, 0.0).hit
    }

    /// [`Self::shape_hits`], and a certified bound on how far the shape is
    /// from the workpiece when it does not hit: the triangles are searched
    /// in the shape's box widened by `expand` (m, ≥ 0), each separated
    /// by the axes of [`super::separation`] or, failing them, tested by
    /// parry's exact test.
    ///
    /// # Returns
    /// `hit` exactly as parry's composite test decides it (the widened
    /// search only adds triangles outside the shape's box, which cannot
    /// touch it, and the first stage only skips the exact test where an
    /// axis proves separation); when not `hit`, `clear_by` ≥ 0 with
    /// `distance(shape, workpiece) ≥ clearance + clear_by`: `expand` for the
    /// triangles outside the widened box, each separating gap for the
    /// others, 0 as soon as a triangle needed the exact test, minus
    /// [`SEPARATION_MARGIN`] each time.
    pub(super) fn shape_query(&self, p: &Pose, s: &WorldShape, expand: f64) -> ShapeVerdict {
        // The pose as parry's `intersection_test(IDENTITY, mesh, p, shape)`
        // hands it to the composite test.
        let pos12 = Pose::IDENTITY.inv_mul(p);
        let aabb = s.shape.compute_aabb(&pos12);
        let wide = if expand > 0.0 {
            aabb.loosened(expand)
        } else {
            aabb
        };
        let clear = |by: f64| ShapeVerdict {
            hit: false,
            clear_by: (by - SEPARATION_MARGIN).max(0.0),
        };
        if !wide.intersects(&self.mesh_aabb) {
            // Every triangle lies in the mesh's box.
            return clear(aabb_gap(&aabb, &self.mesh_aabb));
        }
        // parry's test looks no further than the shape's own box.
        let may_hit = aabb.intersects(&self.mesh_aabb);
        let placed = s.primitive.placed(&pos12);
        let need = self.clearance + SEPARATION_MARGIN;
        // Triangles outside the widened box are more than `expand` beyond
        // the inflated shape.
        let mut bound = expand;
        for i in self
            .mesh
            .bvh()
            .leaves(|node: &BvhNode| node.aabb().intersects(&wide))
        {
            let gap = self
                .triangles
                .get(i as usize)
                .map_or(f64::NEG_INFINITY, |t| placed.gap(t, need + bound));
            if gap > need {
                bound = bound.min(gap - self.clearance);
                continue;
            }
            bound = 0.0;
            if may_hit
                && DefaultQueryDispatcher
                    .intersection_test(&pos12, &self.mesh.triangle(i), s.shape.as_ref())
                    // Unsupported pairs were excluded in new(); be conservative.
                    .map_or(true, |r| r.intersecting)
            {
                return ShapeVerdict {
                    hit: true,
                    clear_by: 0.0,
                };
            }
        }
        clear(bound)
    }

    /// [`Self::shape_hits`] without the first stage: parry's composite test.
    fn shape_hits_exhaustive(&self, p: &Pose, s: &WorldShape) -> bool {
        s.shape.compute_aabb(p).intersects(&self.mesh_aabb)
            && intersection_test(&Pose::IDENTITY, &self.mesh, p, s.shape.as_ref())
                // Unsupported pairs were excluded in new(); be conservative.
                .map_or(true, |r| r.intersecting)
    }

    /// Names of the head links within the clearance of the workpiece at
    /// `q`, in check order; empty when `q` is collision-free.
    ///
    /// A non-finite `q` cannot be placed and is reported as colliding on
    /// every link. Counts one query.
    ///
    /// # Performance
    /// Tests every link (no early exit); use [`CollisionWorld::is_free`]
    /// when the names are not needed.
    pub fn colliding_links(&self, q: &[f64; 6]) -> Vec<&'static str> {
        self.check(q, true, false)
    }

    /// [`CollisionWorld::colliding_links`] by parry's composite test alone
    /// (`intersection_test` of every shape against the whole mesh, the
    /// exact test of every candidate triangle), without the
    /// separating-axis first stage: the reference the faster paths are
    /// tested against. Counts one query.
    pub fn colliding_links_exhaustive(&self, q: &[f64; 6]) -> Vec<&'static str> {
        self.check(q, true, true)
    }

    /// True when no head shape is within the clearance of the workpiece at
    /// `q` (false for a non-finite `q`). Counts one query.
    ///
    /// # Performance
    /// Stops at the first colliding link; links whose bounding box misses
    /// the workpiece's cost a box test only.
    pub fn is_free(&self, q: &[f64; 6]) -> bool {
        self.check(q, false, false).is_empty()
    }

    /// Number of configuration queries so far.
    pub fn queries(&self) -> usize {
        self.queries.load(Ordering::Relaxed)
    }

    /// Restarts the query count (a world kept for the next plan of the same part).
    pub fn reset_queries(&self) {
        self.queries.store(0, Ordering::Relaxed);
    }
}
