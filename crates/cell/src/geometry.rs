//! Collision geometry of the cell as parry shapes: the robot's shapes on their bodies and the
//! static scene objects, with conversions between nalgebra and parry poses.

use std::path::Path;

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use parry3d_f64::math::{Pose, Rotation, Vector};
use parry3d_f64::shape::{Ball, Cuboid, Cylinder, SharedShape, TriMesh, TriMeshFlags};

use crate::config::{GeometrySpec, ObjectKind};
use crate::CellError;

/// nalgebra isometry → parry pose.
pub fn to_pose(iso: &Isometry3<f64>) -> Pose {
    let t = iso.translation.vector;
    let q = iso.rotation.quaternion();
    Pose::from_parts(
        Vector::new(t.x, t.y, t.z),
        Rotation::from_xyzw(q.i, q.j, q.k, q.w),
    )
}

/// parry pose → nalgebra isometry.
pub fn to_isometry(pose: &Pose) -> Isometry3<f64> {
    let t = pose.translation;
    let r = pose.rotation;
    Isometry3::from_parts(
        Translation3::new(t.x, t.y, t.z),
        UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(r.w, r.x, r.y, r.z)),
    )
}

/// parry vector → nalgebra vector.
pub fn to_vector3(v: Vector) -> Vector3<f64> {
    Vector3::new(v.x, v.y, v.z)
}

/// URDF and cell-file cylinders run along z, parry's along y: the shape frame is turned by
/// Rx(π/2) (`y → z`).
fn z_to_y() -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::identity(),
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2),
    )
}

fn positive(field: &str, v: f64) -> Result<f64, CellError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(CellError::InvalidValue {
            field: field.to_string(),
            value: v,
            requirement: "must be finite and > 0",
        })
    }
}

/// A convex primitive as a parry shape and the correction of its frame.
///
/// # Errors
/// [`CellError::InvalidValue`] for a size that is not finite and > 0.
pub fn primitive(
    field: &str,
    geometry: &GeometrySpec,
) -> Result<(SharedShape, Isometry3<f64>), CellError> {
    match geometry {
        GeometrySpec::Box { size } => {
            let h = [
                positive(field, size[0])? / 2.0,
                positive(field, size[1])? / 2.0,
                positive(field, size[2])? / 2.0,
            ];
            Ok((
                SharedShape::new(Cuboid::new(Vector::new(h[0], h[1], h[2]))),
                Isometry3::identity(),
            ))
        }
        GeometrySpec::Cylinder { radius, length } => Ok((
            SharedShape::new(Cylinder::new(
                positive(field, *length)? / 2.0,
                positive(field, *radius)?,
            )),
            z_to_y(),
        )),
        GeometrySpec::Mesh { .. } => Err(CellError::InvalidValue {
            field: field.to_string(),
            value: f64::NAN,
            requirement: "robot and tool shapes must be box or cylinder",
        }),
    }
}

/// A URDF `<collision>` geometry as a cell geometry.
///
/// # Errors
/// [`CellError::InvalidValue`] for meshes and capsules (the robots of this project use boxes,
/// cylinders and spheres).
pub fn urdf_shape(
    field: &str,
    g: &urdf_rs::Geometry,
) -> Result<(SharedShape, Isometry3<f64>), CellError> {
    match g {
        urdf_rs::Geometry::Box { size } => primitive(field, &GeometrySpec::Box { size: size.0 }),
        urdf_rs::Geometry::Cylinder { radius, length } => primitive(
            field,
            &GeometrySpec::Cylinder {
                radius: *radius,
                length: *length,
            },
        ),
        urdf_rs::Geometry::Sphere { radius } => Ok((
            SharedShape::new(Ball::new(positive(field, *radius)?)),
            Isometry3::identity(),
        )),
        _ => Err(CellError::InvalidValue {
            field: field.to_string(),
            value: f64::NAN,
            requirement: "URDF collision geometry must be box, cylinder or sphere",
        }),
    }
}

/// One collision shape of the robot.
#[derive(Clone)]
pub struct RobotShape {
    /// `<link>/<index>` for a URDF collision element, or the tool shape's name.
    pub name: String,
    /// The URDF link it belongs to.
    pub link: String,
    /// The body carrying it (`None` = the fixed base).
    pub body: Option<usize>,
    /// Shape frame in the body frame (parry convention).
    pub local: Pose,
    /// The shape.
    pub shape: SharedShape,
}

/// One static object of the scene.
#[derive(Clone)]
pub struct SceneObject {
    /// Its name.
    pub name: String,
    /// Workpiece or fixture.
    pub kind: ObjectKind,
    /// Its pose in the base frame (parry convention: cylinder frames already turned).
    pub pose: Pose,
    /// The shape (triangle mesh surface or solid primitive).
    pub shape: SharedShape,
    /// Its bounding box in the base frame.
    pub aabb: parry3d_f64::bounding_volume::Aabb,
    /// Number of triangles (0 for primitives).
    pub triangles: usize,
}

impl SceneObject {
    /// Builds a scene object; meshes are read relative to `base_dir`.
    ///
    /// # Errors
    /// [`CellError::MissingMesh`] when a mesh file does not exist; [`CellError::BadMesh`]
    /// when it cannot be parsed or triangulated; [`CellError::InvalidValue`] for bad sizes.
    pub fn build(
        name: &str,
        kind: ObjectKind,
        geometry: &GeometrySpec,
        pose: &Isometry3<f64>,
        base_dir: &Path,
    ) -> Result<Self, CellError> {
        let (shape, fix, triangles) = match geometry {
            GeometrySpec::Mesh { path } => {
                let full = if path.is_absolute() {
                    path.clone()
                } else {
                    base_dir.join(path)
                };
                if !full.is_file() {
                    return Err(CellError::MissingMesh {
                        object: name.to_string(),
                        path: full,
                    });
                }
                let bad = |reason: String| CellError::BadMesh {
                    object: name.to_string(),
                    path: full.clone(),
                    reason,
                };
                let bytes = std::fs::read(&full).map_err(|e| bad(e.to_string()))?;
                let ext = full
                    .extension()
                    .and_then(|e| e.to_str())
                    .unwrap_or_default()
                    .to_string();
                let mesh = kerf_mjto::mesh::parse(&bytes, &ext, &full.display().to_string())
                    .map_err(|e| bad(e.to_string()))?;
                let vertices: Vec<Vector> = mesh
                    .vertices
                    .iter()
                    .map(|v| Vector::new(v[0], v[1], v[2]))
                    .collect();
                let n = mesh.triangles.len();
                let tri = TriMesh::with_flags(vertices, mesh.triangles, TriMeshFlags::empty())
                    .map_err(|e| bad(format!("{e:?}")))?;
                (SharedShape::new(tri), Isometry3::identity(), n)
            }
            other => {
                let (s, fix) = primitive(&format!("objects.{name}.geometry"), other)?;
                (s, fix, 0)
            }
        };
        let pose = to_pose(&(pose * fix));
        let aabb = shape.compute_aabb(&pose);
        Ok(Self {
            name: name.to_string(),
            kind,
            pose,
            shape,
            aabb,
            triangles,
        })
    }
}
