//! The triangle mesh of a workpiece and its validation.

use super::MAX_EXTENT;
use crate::PlanError;

/// A triangle mesh: vertex positions (m) and triangles as vertex indices.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MeshData {
    /// Vertex positions (m).
    pub vertices: Vec<[f64; 3]>,
    /// Triangles, three 0-based indices into `vertices` each.
    pub triangles: Vec<[u32; 3]>,
}

impl MeshData {
    /// The closed surface of the axis-aligned box `[min, max]`: 8 vertices,
    /// 12 outward-facing triangles.
    ///
    /// # Arguments
    /// * `min`, `max` - opposite corners (m); a zero extent gives a
    ///   degenerate (flat) box whose side triangles [`MeshData::validated`]
    ///   would drop.
    pub fn cuboid(min: [f64; 3], max: [f64; 3]) -> Self {
        let v = |x: usize, y: usize, z: usize| -> [f64; 3] {
            [
                if x == 0 { min[0] } else { max[0] },
                if y == 0 { min[1] } else { max[1] },
                if z == 0 { min[2] } else { max[2] },
            ]
        };
        let vertices = vec![
            v(0, 0, 0),
            v(1, 0, 0),
            v(1, 1, 0),
            v(0, 1, 0),
            v(0, 0, 1),
            v(1, 0, 1),
            v(1, 1, 1),
            v(0, 1, 1),
        ];
        let triangles = vec![
            [0, 2, 1],
            [0, 3, 2], // bottom, -z
            [4, 5, 6],
            [4, 6, 7], // top, +z
            [0, 1, 5],
            [0, 5, 4], // -y
            [2, 3, 7],
            [2, 7, 6], // +y
            [1, 2, 6],
            [1, 6, 5], // +x
            [3, 0, 4],
            [3, 4, 7], // -x
        ];
        Self {
            vertices,
            triangles,
        }
    }

    /// Appends the vertices and triangles of `other` (indices shifted).
    ///
    /// # Errors
    /// [`PlanError::InvalidRequest`] (field `mesh`) when the merged vertex count would not fit the `u32`
    /// triangle indices (a mesh of more than four billion vertices); nothing is appended.
    pub fn append(&mut self, other: &MeshData) -> Result<(), PlanError> {
        let too_large = || {
            PlanError::invalid(
                "mesh",
                format!(
                    "{} + {} vertices do not fit u32 triangle indices",
                    self.vertices.len(),
                    other.vertices.len()
                ),
            )
        };
        let offset = u32::try_from(self.vertices.len()).map_err(|_| too_large())?;
        if u32::try_from(self.vertices.len() + other.vertices.len()).is_err() {
            return Err(too_large());
        }
        self.vertices.extend_from_slice(&other.vertices);
        self.triangles.extend(
            other
                .triangles
                .iter()
                .map(|t| [t[0] + offset, t[1] + offset, t[2] + offset]),
        );
        Ok(())
    }

    /// Axis-aligned bounding box `(min, max)` of the vertices, or `None`
    /// for a mesh without vertices.
    pub fn bounds(&self) -> Option<([f64; 3], [f64; 3])> {
        let first = *self.vertices.first()?;
        Some(self.vertices.iter().fold((first, first), |(lo, hi), v| {
            (
                [lo[0].min(v[0]), lo[1].min(v[1]), lo[2].min(v[2])],
                [hi[0].max(v[0]), hi[1].max(v[1]), hi[2].max(v[2])],
            )
        }))
    }

    /// Checks the mesh and drops degenerate triangles.
    ///
    /// A triangle is degenerate when two of its indices are equal or its
    /// area is zero up to rounding (`|e1 × e2| <= 1e-12 · longest edge²`);
    /// those are dropped and counted in a `log::warn!`.
    ///
    /// # Arguments
    /// * `source_name` - the mesh reference, used in error messages.
    ///
    /// # Errors
    /// [`PlanError::Mesh`] for: a non-finite vertex coordinate (with its
    /// index), a triangle index out of range (with the triangle), no
    /// triangles (before or after dropping degenerate ones), or a bounding
    /// box larger than [`MAX_EXTENT`] in some direction (probably
    /// millimetres).
    ///
    /// # Performance
    /// O(vertices + triangles), in place.
    pub fn validated(mut self, source_name: &str) -> Result<Self, PlanError> {
        let err = |reason: String| PlanError::Mesh {
            source_name: source_name.to_owned(),
            reason,
        };
        if let Some((i, v)) = self
            .vertices
            .iter()
            .enumerate()
            .find(|(_, v)| v.iter().any(|c| !c.is_finite()))
        {
            return Err(err(format!("vertex {i} is not finite: {v:?}")));
        }
        let n = self.vertices.len();
        if let Some((i, t)) = self
            .triangles
            .iter()
            .enumerate()
            .find(|(_, t)| t.iter().any(|&k| k as usize >= n))
        {
            return Err(err(format!(
                "triangle {i} {t:?} refers to a vertex beyond the {n} vertices"
            )));
        }
        if self.triangles.is_empty() {
            return Err(err("the mesh has no triangles".into()));
        }
        let before = self.triangles.len();
        let vertices = &self.vertices;
        self.triangles.retain(|t| !is_degenerate(vertices, t));
        let dropped = before - self.triangles.len();
        if dropped > 0 {
            log::warn!(
                "workpiece mesh '{source_name}': dropped {dropped} degenerate triangle(s) of {before}"
            );
        }
        if self.triangles.is_empty() {
            return Err(err(format!(
                "all {before} triangles are degenerate (zero area)"
            )));
        }
        if let Some((lo, hi)) = self.bounds() {
            let ext = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
            if ext.iter().any(|&e| e > MAX_EXTENT) {
                return Err(err(format!(
                    "bounding box {:.3} x {:.3} x {:.3} m is larger than {MAX_EXTENT} m: the mesh is \
                     probably in millimetres (kerf meshes are in metres; scale it by 0.001)",
                    ext[0], ext[1], ext[2]
                )));
            }
        }
        Ok(self)
    }
}

/// True when the triangle repeats an index or has (numerically) zero area.
fn is_degenerate(vertices: &[[f64; 3]], t: &[u32; 3]) -> bool {
    if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
        return true;
    }
    let (Some(a), Some(b), Some(c)) = (
        vertices.get(t[0] as usize),
        vertices.get(t[1] as usize),
        vertices.get(t[2] as usize),
    ) else {
        return true;
    };
    let e1 = sub(b, a);
    let e2 = sub(c, a);
    let e3 = sub(c, b);
    let cr = cross(&e1, &e2);
    let longest = dot(&e1, &e1).max(dot(&e2, &e2)).max(dot(&e3, &e3));
    dot(&cr, &cr).sqrt() <= 1e-12 * longest
}

pub(super) fn sub(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(super) fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(super) fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
