//! The mass sidecar of a URDF without `<inertial>` elements: link masses, centres of mass and
//! inertia tensors, and the joints' drive parameters (armature, viscous and Coulomb friction).
//!
//! File format (YAML, SI units):
//! ```yaml
//! links:
//!   link_2:
//!     mass: 280.0                      # kg, finite and > 0
//!     center_of_mass: [0.0, 0.0, 0.64] # m, in the link frame
//!     # inertia about the centre of mass, link-frame axes [kg m^2]:
//!     # [ixx, iyy, izz, ixy, ixz, iyz]
//!     inertia: [54.6, 54.6, 4.2, 0.0, 0.0, 0.0]
//! joints:
//!   joint_2: {armature: 5.0, viscous: 200.0, coulomb: 100.0}
//! ```

use std::collections::BTreeMap;
use std::path::Path;

use nalgebra::{Matrix3, Vector3};
use serde::Deserialize;

use crate::CellError;

/// Mass properties of one link, in its own frame.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinkInertia {
    /// Mass (kg).
    pub mass: f64,
    /// Centre of mass in the link frame (m).
    pub center_of_mass: [f64; 3],
    /// Inertia about the centre of mass in link-frame axes (kg m²): `[ixx, iyy, izz, ixy, ixz, iyz]`.
    pub inertia: [f64; 6],
}

impl LinkInertia {
    /// The inertia tensor about the centre of mass (kg m²).
    pub fn tensor(&self) -> Matrix3<f64> {
        let [xx, yy, zz, xy, xz, yz] = self.inertia;
        Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz)
    }

    /// The centre of mass as a vector (m).
    pub fn com(&self) -> Vector3<f64> {
        Vector3::from(self.center_of_mass)
    }

    /// Checks mass > 0, finite values, and a positive definite tensor that satisfies the
    /// triangle inequalities of principal moments (`I1 + I2 >= I3`).
    pub fn check(&self, link: &str) -> Result<(), CellError> {
        let err = |reason: String| CellError::Inertia {
            link: link.to_string(),
            reason,
        };
        if !(self.mass.is_finite() && self.mass > 0.0) {
            return Err(err(format!("mass {} must be finite and > 0", self.mass)));
        }
        if self
            .center_of_mass
            .iter()
            .chain(self.inertia.iter())
            .any(|v| !v.is_finite())
        {
            return Err(err("center_of_mass and inertia must be finite".into()));
        }
        let eig = self.tensor().symmetric_eigen().eigenvalues;
        let (lo, sum) = (eig.min(), eig.sum());
        if lo <= 0.0 {
            return Err(err(format!(
                "inertia tensor must be positive definite (principal moments {eig:?})"
            )));
        }
        if eig.iter().any(|&e| 2.0 * e > sum * (1.0 + 1e-9)) {
            return Err(err(format!(
                "principal moments {eig:?} break the triangle inequality I1 + I2 >= I3"
            )));
        }
        Ok(())
    }
}

/// Drive parameters of one joint.
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointDrive {
    /// Reflected rotor inertia (kg m² or kg), added to the joint's diagonal of the mass matrix.
    #[serde(default)]
    pub armature: f64,
    /// Viscous friction coefficient (N m s/rad or N s/m).
    #[serde(default)]
    pub viscous: f64,
    /// Coulomb (dry) friction (N m or N).
    #[serde(default)]
    pub coulomb: f64,
}

impl JointDrive {
    /// Checks that every parameter is finite and ≥ 0.
    pub fn check(&self, joint: &str) -> Result<(), CellError> {
        for (field, v) in [
            ("armature", self.armature),
            ("viscous", self.viscous),
            ("coulomb", self.coulomb),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(CellError::InvalidValue {
                    field: format!("joints.{joint}.{field}"),
                    value: v,
                    requirement: "must be finite and >= 0",
                });
            }
        }
        Ok(())
    }
}

/// A parsed inertia sidecar.
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InertiaFile {
    /// Mass properties by link name.
    #[serde(default)]
    pub links: BTreeMap<String, LinkInertia>,
    /// Drive parameters by joint name (missing joints: all zero).
    #[serde(default)]
    pub joints: BTreeMap<String, JointDrive>,
}

impl InertiaFile {
    /// Reads and checks an inertia sidecar.
    ///
    /// # Errors
    /// [`CellError::FileRead`], [`CellError::Parse`], or the first invalid entry.
    pub fn from_file(path: &Path) -> Result<Self, CellError> {
        let text = std::fs::read_to_string(path).map_err(|e| CellError::FileRead {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })?;
        let file: Self = serde_yaml_ng::from_str(&text).map_err(|e| CellError::Parse {
            path: path.to_path_buf(),
            what: "inertia file",
            reason: e.to_string(),
        })?;
        for (name, l) in &file.links {
            l.check(name)?;
        }
        for (name, j) in &file.joints {
            j.check(name)?;
        }
        Ok(file)
    }
}
