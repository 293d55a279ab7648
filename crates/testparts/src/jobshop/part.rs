//! A generated job-shop workpiece: its mesh and how closely the mesh follows the true surface.

use kerf_mjto::mesh::MeshData;

/// A workpiece: closed thin-solid mesh and its tolerances against the true surface.
#[derive(Debug, Clone)]
pub struct Part {
    /// Short name; the mesh file is `urdf/meshes/jobshop_<name>.obj`.
    pub name: &'static str,
    /// The closed mesh in the workpiece frame (m).
    pub mesh: MeshData,
    /// Sheet or wall thickness (m).
    pub thickness: f64,
    /// Largest distance between a point of the true head-side surface and the mesh (m): the
    /// chordal sag of the facets, `r (1 − cos(Δφ/2))` for a facet spanning Δφ on radius r,
    /// plus the 1 nm rounding; CL points lie on the true surface.
    pub surface_tolerance: f64,
    /// Largest angle between the true surface normal at a CL point and the normal of the
    /// nearest facet (rad): the angle one facet spans (0 on flat faces, plus rounding).
    pub axis_tolerance: f64,
}

impl Part {
    /// Repository-relative path of the mesh file.
    pub fn mesh_file(&self) -> String {
        format!("urdf/meshes/jobshop_{}.obj", self.name)
    }

    /// The `package://` reference of the mesh written into requests.
    pub fn mesh_reference(&self) -> String {
        format!("package://kerf/{}", self.mesh_file())
    }
}

/// Chordal sag of a facet spanning `angle` (rad) on radius `radius` (m), plus 1 nm rounding.
pub(super) fn sag(radius: f64, angle: f64) -> f64 {
    radius * (1.0 - (angle / 2.0).cos()) + 1e-9
}
