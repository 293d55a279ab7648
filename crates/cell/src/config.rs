//! The cell file: which robot (by URDF name), its mass sidecar, the static scene, extra tool
//! geometry, and the contact rules. Paths are relative to the cell file.
//!
//! See `urdf/cells/laser_bpillar.yaml` and `urdf/cells/irb6660_plate.yaml` for commented
//! examples.

use std::path::{Path, PathBuf};

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};
use serde::Deserialize;

use crate::CellError;

/// A pose: position (m) and unit quaternion `[x, y, z, w]`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseSpec {
    /// Position (m).
    pub position: [f64; 3],
    /// Orientation as a unit quaternion `[x, y, z, w]` (normalised on use; must not be zero).
    #[serde(default = "identity_quaternion")]
    pub orientation: [f64; 4],
}

fn identity_quaternion() -> [f64; 4] {
    [0.0, 0.0, 0.0, 1.0]
}

impl Default for PoseSpec {
    fn default() -> Self {
        Self {
            position: [0.0; 3],
            orientation: identity_quaternion(),
        }
    }
}

impl PoseSpec {
    /// The pose as an isometry.
    ///
    /// # Errors
    /// [`CellError::InvalidValue`] for a non-finite value or a quaternion of norm ≤ 1e-9.
    pub fn isometry(&self, field: &str) -> Result<Isometry3<f64>, CellError> {
        if self
            .position
            .iter()
            .chain(self.orientation.iter())
            .any(|v| !v.is_finite())
        {
            return Err(CellError::InvalidValue {
                field: field.to_string(),
                value: f64::NAN,
                requirement: "position and orientation must be finite",
            });
        }
        let [x, y, z, w] = self.orientation;
        let q = Quaternion::new(w, x, y, z);
        if q.norm() <= 1e-9 {
            return Err(CellError::InvalidValue {
                field: format!("{field}.orientation"),
                value: q.norm(),
                requirement: "quaternion norm must be > 0",
            });
        }
        let [px, py, pz] = self.position;
        Ok(Isometry3::from_parts(
            Translation3::new(px, py, pz),
            UnitQuaternion::from_quaternion(q),
        ))
    }
}

/// A convex primitive or a mesh. In YAML one key of `box`, `cylinder`, `mesh`, e.g.
/// `{box: {size: [1, 1, 0.1]}}`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(try_from = "GeometryFields")]
pub enum GeometrySpec {
    /// A solid box of the given full size (m), centred on its frame.
    Box {
        /// Full edge lengths along x, y, z (m).
        size: [f64; 3],
    },
    /// A solid cylinder along its frame's z axis, centred on its frame.
    Cylinder {
        /// Radius (m).
        radius: f64,
        /// Length (m).
        length: f64,
    },
    /// A triangle mesh surface (OBJ, STL, PLY as `kerf_mjto::mesh::parse` reads them), in metres.
    Mesh {
        /// Path relative to the cell file.
        path: PathBuf,
    },
}

/// The YAML form of [`GeometrySpec`]: exactly one field set.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct GeometryFields {
    #[serde(rename = "box")]
    cuboid: Option<BoxFields>,
    cylinder: Option<CylinderFields>,
    mesh: Option<MeshFields>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct BoxFields {
    size: [f64; 3],
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct CylinderFields {
    radius: f64,
    length: f64,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct MeshFields {
    path: PathBuf,
}

impl TryFrom<GeometryFields> for GeometrySpec {
    type Error = String;

    fn try_from(g: GeometryFields) -> Result<Self, String> {
        match (g.cuboid, g.cylinder, g.mesh) {
            (Some(b), None, None) => Ok(GeometrySpec::Box { size: b.size }),
            (None, Some(c), None) => Ok(GeometrySpec::Cylinder {
                radius: c.radius,
                length: c.length,
            }),
            (None, None, Some(m)) => Ok(GeometrySpec::Mesh { path: m.path }),
            _ => Err("a geometry has exactly one of box, cylinder, mesh".to_string()),
        }
    }
}

/// Role of a scene object.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ObjectKind {
    /// The part being processed: the tool's intended engagement may touch it.
    Workpiece,
    /// Anything else (fixtures, tables): every approach within the threshold is a contact.
    Fixture,
}

/// One static object of the scene.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectSpec {
    /// Unique name, used in contact reports.
    pub name: String,
    /// Workpiece or fixture.
    pub kind: ObjectKind,
    /// Its geometry.
    pub geometry: GeometrySpec,
    /// Object frame in the robot's base frame.
    #[serde(default)]
    pub pose: PoseSpec,
}

/// A shape added to a robot link (tools the URDF does not model).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ToolShapeSpec {
    /// Unique name, used in contact reports and allowances.
    pub name: String,
    /// The URDF link carrying it (may be a link fixed to a moving link, e.g. `tool0`).
    pub link: String,
    /// Box or cylinder (no mesh).
    pub geometry: GeometrySpec,
    /// Shape frame in the link frame.
    #[serde(default)]
    pub origin: PoseSpec,
    /// Its mass (kg), as a uniform solid; 0 = massless.
    #[serde(default)]
    pub mass: f64,
}

/// An intended proximity between one robot shape and one workpiece, not a contact.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AllowanceSpec {
    /// The robot shape: `<link>/<index of its URDF collision element>` or a tool shape's name.
    pub shape: String,
    /// The scene object (must be a workpiece).
    pub object: String,
    /// What is allowed: `standoff` (with `min_distance`) or `engagement`.
    pub allow: AllowKind,
    /// For a standoff: the distance below which the shape is still a contact (m, ≥ 0, at
    /// most the cell threshold).
    #[serde(default)]
    pub min_distance: Option<f64>,
    /// Why (kept for the reader; not used).
    #[serde(default)]
    pub reason: String,
}

/// The kind of an allowance, as written in the cell file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AllowKind {
    /// See [`Allow::Standoff`].
    Standoff,
    /// See [`Allow::Engagement`].
    Engagement,
}

impl AllowanceSpec {
    /// The allowance with its parameter.
    ///
    /// # Errors
    /// [`CellError::InvalidValue`] for a standoff without `min_distance` or an engagement
    /// with one.
    pub fn allow(&self) -> Result<Allow, CellError> {
        match (self.allow, self.min_distance) {
            (AllowKind::Standoff, Some(min_distance)) => Ok(Allow::Standoff { min_distance }),
            (AllowKind::Engagement, None) => Ok(Allow::Engagement),
            (AllowKind::Standoff, None) => Err(CellError::InvalidValue {
                field: format!("contact.allowances[{}].min_distance", self.shape),
                value: f64::NAN,
                requirement: "a standoff needs min_distance",
            }),
            (AllowKind::Engagement, Some(v)) => Err(CellError::InvalidValue {
                field: format!("contact.allowances[{}].min_distance", self.shape),
                value: v,
                requirement: "an engagement takes no min_distance",
            }),
        }
    }
}

/// What an allowance permits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Allow {
    /// Process standoff: this shape is a contact only below `min_distance` (m, ≥ 0, below
    /// the cell threshold) instead of the threshold: e.g. a laser nozzle that works 1 mm off
    /// the sheet.
    Standoff {
        /// The distance below which it is still a contact (m).
        min_distance: f64,
    },
    /// Engagement: this shape cuts into the object by design (a milling cutter in its stock);
    /// its distance to that object is never a contact.
    Engagement,
}

/// Contact rules.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// A robot shape nearer than this to a scene object is in contact (m, ≥ 0).
    pub threshold: f64,
    /// Intended proximities that are not contacts.
    #[serde(default)]
    pub allowances: Vec<AllowanceSpec>,
    /// Also check the URDF root link's own geometry (static robot base) against the scene.
    #[serde(default)]
    pub check_base: bool,
}

/// The robot part of a cell file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotSpec {
    /// Must equal the URDF's `<robot name>`.
    pub name: String,
    /// The mass sidecar, relative to the cell file.
    pub inertia: PathBuf,
    /// Joint positions at start, URDF joint order (m, rad).
    pub initial_positions: Vec<f64>,
}

/// A parsed cell file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellFile {
    /// The robot.
    pub robot: RobotSpec,
    /// Static scene objects.
    #[serde(default)]
    pub objects: Vec<ObjectSpec>,
    /// Tool shapes added to robot links.
    #[serde(default)]
    pub tool: Vec<ToolShapeSpec>,
    /// Contact rules.
    pub contact: ContactSpec,
    /// Directory the relative paths are resolved against (the cell file's directory).
    #[serde(skip)]
    pub base_dir: PathBuf,
    /// The file it was read from (`<memory>` when parsed from text).
    #[serde(skip)]
    pub source: PathBuf,
}

impl CellFile {
    /// Reads a cell file.
    ///
    /// # Errors
    /// [`CellError::FileRead`] or [`CellError::Parse`].
    pub fn from_file(path: &Path) -> Result<Self, CellError> {
        let text = std::fs::read_to_string(path).map_err(|e| CellError::FileRead {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })?;
        let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
        Self::from_str_in(&text, &dir, path)
    }

    /// Parses cell-file text whose relative paths are resolved against `base_dir`.
    ///
    /// # Errors
    /// [`CellError::Parse`].
    pub fn from_str_in(text: &str, base_dir: &Path, source: &Path) -> Result<Self, CellError> {
        let mut file: Self = serde_yaml_ng::from_str(text).map_err(|e| CellError::Parse {
            path: source.to_path_buf(),
            what: "cell file",
            reason: e.to_string(),
        })?;
        file.base_dir = base_dir.to_path_buf();
        file.source = source.to_path_buf();
        Ok(file)
    }

    /// A path of the file resolved against its directory.
    pub fn resolve(&self, rel: &Path) -> PathBuf {
        if rel.is_absolute() {
            rel.to_path_buf()
        } else {
            self.base_dir.join(rel)
        }
    }

    /// A [`CellError::CellFile`] naming this file.
    pub(crate) fn error(&self, reason: String) -> CellError {
        CellError::CellFile {
            path: self.source.clone(),
            reason,
        }
    }
}
