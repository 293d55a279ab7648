//! Collision checking of the laser cutting head against the workpiece.
//!
//! The head is the set of URDF `<collision>` primitives (box, cylinder,
//! sphere) of the links `z_ram`, `c_axis`, `a_axis` and `nozzle` of
//! `urdf/laser_cutter.urdf` (and, if they carry geometry, the gantry links
//! `x_carriage` and `y_carriage`). They are placed by a specialised forward
//! kinematics of the chain of seed 001 eq. 2,
//! `Trans(q1, q2, q3) · Rz(q4) · Ry(q5) · Trans(0, 0, q6)`, and tested with
//! parry3d against a BVH-accelerated [`TriMesh`] of the workpiece.
//!
//! * A configuration collides when some head shape is within `clearance`
//!   of a workpiece triangle: every head primitive is inflated by the
//!   clearance (a parry [`RoundShape`], i.e. the Minkowski sum with a ball
//!   of that radius), so an intersection test is exactly the test
//!   `distance <= clearance`.
//! * The workpiece is a surface (sheet metal, as the B-pillar of seed
//!   001): a head shape entirely enclosed by a closed mesh without touching
//!   any triangle is not reported. Head shapes are centimetres wide, sheet
//!   parts millimetres thick, so this does not occur in practice.
//! * The nozzle is tested first (it is nearest the part), then the tilt
//!   housing (`a_axis`), the fork and C-axis motor (`c_axis`), the ram; a
//!   link whose bounding box misses the workpiece bounding box is skipped
//!   without any triangle test, then every shape's own box is matched
//!   against the mesh BVH by parry.
//! * The geometry runs on `parry3d-f64` (the f64 build of parry3d 0.31).
//!   The f32 build's GJK test of a cylinder against a large triangle
//!   reports contact across a 1 mm gap (the nozzle above a flange at 3°
//!   tilt) as soon as the triangle is a centimetre off the query origin;
//!   the f64 build returns the true 0.86 mm (checked in
//!   `tests/collision.rs`). Coordinates are still taken relative to the
//!   centre of the workpiece bounding box.

use std::sync::atomic::{AtomicUsize, Ordering};

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};
use parry3d_f64::math::{Pose, Rotation, Vector};
use parry3d_f64::query::intersection_test;
use parry3d_f64::shape::{Ball, Cuboid, Cylinder, RoundShape, Shape, TriMesh, TriMeshFlags};

use crate::mesh::MeshData;
use crate::PlanError;

/// A link of the cutting head that can carry collision geometry, in the
/// order the collision check visits them (nearest the workpiece first).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum HeadLink {
    /// `nozzle`: frame at the CL point C, z = tool axis O (moves with q6).
    Nozzle,
    /// `a_axis`: frame at M, tilted by q5 about the C-axis-rotated y axis.
    AAxis,
    /// `c_axis`: frame at M, rotated by q4 about z.
    CAxis,
    /// `z_ram`: frame at M = (q1, q2, q3), axes parallel to the machine frame.
    ZRam,
    /// `y_carriage`: at (q1, q2, 0).
    YCarriage,
    /// `x_carriage`: at (q1, 0, 0).
    XCarriage,
}

impl HeadLink {
    /// Every head link, in check order.
    pub const ALL: [HeadLink; 6] = [
        HeadLink::Nozzle,
        HeadLink::AAxis,
        HeadLink::CAxis,
        HeadLink::ZRam,
        HeadLink::YCarriage,
        HeadLink::XCarriage,
    ];

    /// The URDF link name.
    pub fn name(self) -> &'static str {
        match self {
            HeadLink::Nozzle => "nozzle",
            HeadLink::AAxis => "a_axis",
            HeadLink::CAxis => "c_axis",
            HeadLink::ZRam => "z_ram",
            HeadLink::YCarriage => "y_carriage",
            HeadLink::XCarriage => "x_carriage",
        }
    }

    /// The head link of a URDF link name (`tool0` is the nozzle frame).
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "nozzle" | "tool0" => Some(HeadLink::Nozzle),
            "a_axis" => Some(HeadLink::AAxis),
            "c_axis" => Some(HeadLink::CAxis),
            "z_ram" => Some(HeadLink::ZRam),
            "y_carriage" => Some(HeadLink::YCarriage),
            "x_carriage" => Some(HeadLink::XCarriage),
            _ => None,
        }
    }

    /// Pose of the link frame in the machine frame (`base_link`) at `q`.
    ///
    /// The specialised forward kinematics of `urdf/laser_cutter.urdf`
    /// (seed 001 eq. 2): `z_ram = Trans(q1, q2, q3)`, `c_axis = z_ram ·
    /// Rz(q4)`, `a_axis = c_axis · Ry(q5)`, `nozzle = a_axis · Trans(0, 0,
    /// q6)`; the origin of `nozzle` is C = M + q6 · O with O = (cos q4 sin
    /// q5, sin q4 sin q5, cos q5). [`HeadModel::from_urdf`] checks that the
    /// URDF has exactly this chain.
    ///
    /// # Arguments
    /// * `q` - joint vector q1..q6 (m, rad).
    pub fn pose(self, q: &[f64; 6]) -> Isometry3<f64> {
        let [q1, q2, q3, q4, q5, q6] = *q;
        let ram =
            || Isometry3::from_parts(Translation3::new(q1, q2, q3), UnitQuaternion::identity());
        let c_axis = || ram() * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), q4);
        let a_axis = || c_axis() * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), q5);
        match self {
            HeadLink::XCarriage => Isometry3::translation(q1, 0.0, 0.0),
            HeadLink::YCarriage => Isometry3::translation(q1, q2, 0.0),
            HeadLink::ZRam => ram(),
            HeadLink::CAxis => c_axis(),
            HeadLink::AAxis => a_axis(),
            HeadLink::Nozzle => a_axis() * Translation3::new(0.0, 0.0, q6),
        }
    }
}

/// A convex collision primitive of a URDF `<collision>` element.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Primitive {
    /// URDF `<box size>`: half extents along the shape's x, y, z (m).
    Box {
        /// Half the URDF size (m).
        half_extents: [f64; 3],
    },
    /// URDF `<cylinder>`: along the shape's local z axis, centred.
    Cylinder {
        /// Radius (m).
        radius: f64,
        /// Half the URDF length (m).
        half_length: f64,
    },
    /// URDF `<sphere>`.
    Sphere {
        /// Radius (m).
        radius: f64,
    },
}

/// One collision primitive of the head, in its link frame.
#[derive(Debug, Clone, PartialEq)]
pub struct HeadShape {
    /// The link carrying it.
    pub link: HeadLink,
    /// The URDF `<origin>`: shape frame in the link frame.
    pub origin: Isometry3<f64>,
    /// The primitive.
    pub primitive: Primitive,
}

/// The collision geometry of the cutting head.
#[derive(Debug, Clone, PartialEq)]
pub struct HeadModel {
    shapes: Vec<HeadShape>,
}

/// The joints the specialised kinematics of [`HeadLink::pose`] expects:
/// name, parent, child, prismatic?, axis.
const CHAIN: [(&str, &str, &str, bool, [f64; 3]); 6] = [
    ("q1", "base_link", "x_carriage", true, [1.0, 0.0, 0.0]),
    ("q2", "x_carriage", "y_carriage", true, [0.0, 1.0, 0.0]),
    ("q3", "y_carriage", "z_ram", true, [0.0, 0.0, 1.0]),
    ("q4", "z_ram", "c_axis", false, [0.0, 0.0, 1.0]),
    ("q5", "c_axis", "a_axis", false, [0.0, 1.0, 0.0]),
    ("q6", "a_axis", "nozzle", true, [0.0, 0.0, 1.0]),
];

fn machine_err(reason: String) -> PlanError {
    PlanError::invalid("machine", reason)
}

/// The URDF `<origin xyz rpy>` as an isometry (REP 103 fixed-axis roll,
/// pitch, yaw: `R = Rz(yaw) Ry(pitch) Rx(roll)`).
fn origin_isometry(what: &str, pose: &urdf_rs::Pose) -> Result<Isometry3<f64>, PlanError> {
    let (xyz, rpy) = (pose.xyz.0, pose.rpy.0);
    if xyz.iter().chain(rpy.iter()).any(|v| !v.is_finite()) {
        return Err(machine_err(format!(
            "{what}: origin xyz {xyz:?} rpy {rpy:?} is not finite"
        )));
    }
    Ok(Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    ))
}

fn positive_size(what: &str, v: f64) -> Result<f64, PlanError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(machine_err(format!(
            "{what}: size {v} must be finite and > 0"
        )))
    }
}

impl HeadModel {
    /// Collects the head's collision primitives from a URDF.
    ///
    /// # Arguments
    /// * `robot` - the parsed URDF of the laser cutting machine, e.g.
    ///   `LaserMachine::default_machine()?.robot().urdf()`.
    ///
    /// # Returns
    /// The shapes of the links `x_carriage`, `y_carriage`, `z_ram`,
    /// `c_axis`, `a_axis`, `nozzle` and `tool0` (the nozzle frame; its
    /// fixed joint must be the identity). Geometry of `base_link` (the
    /// static machine bed the workpiece rests on) is ignored.
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] (field `machine`) when the joints q1..q6
    /// are not the chain of seed 001 eq. 2 with identity origins (the
    /// specialised kinematics would be wrong), when another link carries
    /// collision geometry, for mesh or capsule geometry (only box, cylinder
    /// and sphere are supported), for non-positive or non-finite sizes, and
    /// when no link has collision geometry at all.
    pub fn from_urdf(robot: &urdf_rs::Robot) -> Result<Self, PlanError> {
        for (name, parent, child, prismatic, axis) in CHAIN {
            let j = robot
                .joints
                .iter()
                .find(|j| j.name == name)
                .ok_or_else(|| machine_err(format!("joint {name} is missing")))?;
            let kind_ok = if prismatic {
                j.joint_type == urdf_rs::JointType::Prismatic
            } else {
                matches!(
                    j.joint_type,
                    urdf_rs::JointType::Revolute | urdf_rs::JointType::Continuous
                )
            };
            let o = origin_isometry(&format!("joint {name}"), &j.origin)?;
            let identity = o.translation.vector.norm() <= 1e-12 && o.rotation.angle() <= 1e-12;
            let a = j.axis.xyz.0;
            let axis_ok = a.iter().zip(axis).all(|(x, y)| (x - y).abs() <= 1e-12);
            if !kind_ok || j.parent.link != parent || j.child.link != child || !identity || !axis_ok
            {
                return Err(machine_err(format!(
                    "joint {name} must be {} {parent} -> {child} about/along {axis:?} with an \
                     identity origin (seed 001 eq. 2), found {:?} {} -> {} axis {a:?}",
                    if prismatic { "prismatic" } else { "revolute" },
                    j.joint_type,
                    j.parent.link,
                    j.child.link
                )));
            }
        }
        let mut shapes = Vec::new();
        for link in &robot.links {
            if link.collision.is_empty() {
                continue;
            }
            if link.name == "base_link" {
                log::debug!("base_link collision geometry ignored (static machine bed)");
                continue;
            }
            let head_link = HeadLink::from_name(&link.name).ok_or_else(|| {
                machine_err(format!(
                    "link '{}' has collision geometry but is not on the head chain \
                     (x_carriage, y_carriage, z_ram, c_axis, a_axis, nozzle, tool0)",
                    link.name
                ))
            })?;
            let tool_offset = if link.name == "tool0" {
                let j = robot
                    .joints
                    .iter()
                    .find(|j| j.child.link == "tool0")
                    .ok_or_else(|| machine_err("link tool0 has no parent joint".into()))?;
                let o = origin_isometry("joint to tool0", &j.origin)?;
                if j.parent.link != "nozzle" || j.joint_type != urdf_rs::JointType::Fixed {
                    return Err(machine_err("tool0 must be fixed to the nozzle link".into()));
                }
                o
            } else {
                Isometry3::identity()
            };
            for (k, c) in link.collision.iter().enumerate() {
                let what = format!("link '{}' collision {k}", link.name);
                let origin = tool_offset * origin_isometry(&what, &c.origin)?;
                let primitive = match &c.geometry {
                    urdf_rs::Geometry::Box { size } => {
                        let s = size.0;
                        Primitive::Box {
                            half_extents: [
                                positive_size(&what, s[0])? / 2.0,
                                positive_size(&what, s[1])? / 2.0,
                                positive_size(&what, s[2])? / 2.0,
                            ],
                        }
                    }
                    urdf_rs::Geometry::Cylinder { radius, length } => Primitive::Cylinder {
                        radius: positive_size(&what, *radius)?,
                        half_length: positive_size(&what, *length)? / 2.0,
                    },
                    urdf_rs::Geometry::Sphere { radius } => Primitive::Sphere {
                        radius: positive_size(&what, *radius)?,
                    },
                    other => {
                        return Err(machine_err(format!(
                            "{what}: geometry {other:?} is not supported (use box, cylinder \
                             or sphere)"
                        )))
                    }
                };
                shapes.push(HeadShape {
                    link: head_link,
                    origin,
                    primitive,
                });
            }
        }
        if shapes.is_empty() {
            return Err(machine_err(
                "no head link has collision geometry: nothing to check".into(),
            ));
        }
        shapes.sort_by_key(|s| s.link);
        Ok(Self { shapes })
    }

    /// Names of the links with collision geometry, in check order
    /// (nozzle first).
    pub fn links(&self) -> Vec<&str> {
        let mut out: Vec<&str> = Vec::new();
        for s in &self.shapes {
            if out.last() != Some(&s.link.name()) {
                out.push(s.link.name());
            }
        }
        out
    }

    /// The collision primitives, in check order.
    pub fn shapes(&self) -> &[HeadShape] {
        &self.shapes
    }

    /// Poses of the links with collision geometry at `q`, in the machine
    /// frame (see [`HeadLink::pose`]).
    pub fn link_poses(&self, q: &[f64; 6]) -> Vec<(&'static str, Isometry3<f64>)> {
        self.links()
            .into_iter()
            .filter_map(HeadLink::from_name)
            .map(|l| (l.name(), l.pose(q)))
            .collect()
    }
}

/// One head primitive as a parry shape (inflated by the clearance).
struct WorldShape {
    /// Shape frame in the link frame (parry cylinders are along y: the
    /// URDF z-cylinder is turned by Rx(π/2)).
    local: Pose,
    shape: Box<dyn Shape>,
}

/// The shapes of one link and their joint bounding box in the link frame.
struct WorldLink {
    link: HeadLink,
    local_aabb: Aabb,
    shapes: Vec<WorldShape>,
}

/// The head and the workpiece, ready for configuration queries.
///
/// `Sync`: queries take `&self` (the query counter is atomic), so samples
/// can be checked from several threads.
pub struct CollisionWorld {
    head: HeadModel,
    links: Vec<WorldLink>,
    mesh: TriMesh,
    mesh_aabb: Aabb,
    /// Machine-frame point subtracted before the f32 conversion.
    origin: Vector3<f64>,
    clearance: f64,
    queries: AtomicUsize,
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
/// `origin` (f32).
fn to_pose(iso: &Isometry3<f64>, origin: &Vector3<f64>) -> Pose {
    let t = iso.translation.vector - origin;
    let q = iso.rotation.quaternion();
    Pose::from_parts(
        Vector::new(t.x, t.y, t.z),
        Rotation::from_xyzw(q.i, q.j, q.k, q.w),
    )
}

/// The parry shape of a primitive inflated by `clearance` (m, ≥ 0), and
/// its pose correction (cylinder axis z → y).
fn parry_shape(p: &Primitive, clearance: f64) -> (Box<dyn Shape>, Isometry3<f64>) {
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
            (s, Isometry3::identity())
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
            (s, z_to_y)
        }
        Primitive::Sphere { radius } => (
            Box::new(Ball::new(radius + clearance)),
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

        let mut links: Vec<WorldLink> = Vec::new();
        for s in &head.shapes {
            let (shape, fix) = parry_shape(&s.primitive, clearance);
            let local = to_pose(&(s.origin * fix), &Vector3::zeros());
            let aabb = shape.compute_aabb(&local);
            // Every pair must be supported by parry's dispatcher: probe once.
            intersection_test(&Pose::IDENTITY, &trimesh, &local, shape.as_ref()).map_err(|_| {
                machine_err(format!(
                    "parry3d cannot test {:?} against a triangle mesh",
                    s.primitive
                ))
            })?;
            let ws = WorldShape { local, shape };
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
    fn check(&self, q: &[f64; 6], all: bool) -> Vec<&'static str> {
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
                let p = pose * s.local;
                s.shape.compute_aabb(&p).intersects(&self.mesh_aabb)
                    && intersection_test(&Pose::IDENTITY, &self.mesh, &p, s.shape.as_ref())
                        // Unsupported pairs were excluded in new(); be conservative.
                        .map_or(true, |r| r.intersecting)
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
        self.check(q, true)
    }

    /// True when no head shape is within the clearance of the workpiece at
    /// `q` (false for a non-finite `q`). Counts one query.
    ///
    /// # Performance
    /// Stops at the first colliding link; links whose bounding box misses
    /// the workpiece's cost a box test only.
    pub fn is_free(&self, q: &[f64; 6]) -> bool {
        self.check(q, false).is_empty()
    }

    /// Number of configuration queries so far.
    pub fn queries(&self) -> usize {
        self.queries.load(Ordering::Relaxed)
    }
}
