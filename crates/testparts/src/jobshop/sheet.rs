//! A closed thin solid from a grid of points on the head-side surface of a sheet: the outer
//! surface, the inner surface one thickness below it along the normals, and strips closing
//! every free edge (the construction of `bpillar`, for any grid).

use kerf_mjto::mesh::MeshData;
use nalgebra::Vector3;

use super::MAX_TRIANGLES;
use crate::rounding::round_point;
use crate::TestPartError;

/// The head-side surface of a sheet sampled on a `nu × nv` grid (u-major: vertex `(i, j)` is
/// element `i * nv + j`), with unit normals pointing towards the head.
#[derive(Debug, Clone)]
pub struct SheetGrid {
    /// Samples along u.
    pub nu: usize,
    /// Samples along v.
    pub nv: usize,
    /// True when u wraps around (a tube): vertex `nu` is vertex 0.
    pub periodic_u: bool,
    /// Points (m).
    pub points: Vec<Vector3<f64>>,
    /// Unit head-side normals.
    pub normals: Vec<Vector3<f64>>,
}

/// The closed, outward-oriented thin solid of a sheet.
///
/// # Arguments
/// * `grid` - the head-side surface.
/// * `thickness` - sheet thickness (m); the inner vertex is `p - thickness · n`.
///
/// # Returns
/// Outer vertices `0..nu·nv`, inner vertices `nu·nv..2·nu·nv` (same order), coordinates rounded
/// to 1 nm; the outer triangles face along the normals, the inner ones away from them, and
/// two triangles per free edge close the rim. Every directed edge has exactly one opposite.
///
/// # Errors
/// [`TestPartError::Invalid`] for a grid smaller than 2 × 2, mismatched lengths, a
/// non-positive thickness, quads whose winding disagrees with the normals, or more than
/// [`MAX_TRIANGLES`] triangles.
pub fn thick_sheet(grid: &SheetGrid, thickness: f64) -> Result<MeshData, TestPartError> {
    let (nu, nv) = (grid.nu, grid.nv);
    if nu < 2 || nv < 2 || grid.points.len() != nu * nv || grid.normals.len() != nu * nv {
        return Err(TestPartError::invalid(
            "sheet grid",
            format!(
                "{nu} × {nv} grid with {} points and {} normals",
                grid.points.len(),
                grid.normals.len()
            ),
        ));
    }
    if !(thickness.is_finite() && thickness > 0.0) {
        return Err(TestPartError::invalid(
            "sheet thickness",
            format!("{thickness} must be finite and > 0"),
        ));
    }
    let quads_u = if grid.periodic_u { nu } else { nu - 1 };
    let outer_count = 2 * quads_u * (nv - 1);
    let total = 2 * outer_count + 4 * (quads_u + if grid.periodic_u { 0 } else { nv - 1 });
    if total > MAX_TRIANGLES {
        return Err(TestPartError::invalid(
            "sheet grid",
            format!("{total} triangles, over the limit of {MAX_TRIANGLES}"),
        ));
    }
    let n = nu * nv;
    let idx = |i: usize, j: usize| ((i % nu) * nv + j) as u32;
    // Winding: (a, b, c), (a, c, d) must face along the normals for every quad.
    let mut outer = Vec::with_capacity(outer_count);
    let mut flips = 0usize;
    for i in 0..quads_u {
        for j in 0..nv - 1 {
            let (a, b, c, d) = (idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1));
            let p = |k: u32| grid.points[k as usize];
            let face = (p(b) - p(a)).cross(&(p(c) - p(a)));
            let normal = grid.normals[a as usize] + grid.normals[c as usize];
            if face.dot(&normal) < 0.0 {
                flips += 1;
                outer.push([a, c, b]);
                outer.push([a, d, c]);
            } else {
                outer.push([a, b, c]);
                outer.push([a, c, d]);
            }
        }
    }
    if flips != 0 && flips != quads_u * (nv - 1) {
        return Err(TestPartError::invalid(
            "sheet grid",
            format!(
                "{flips} of {} quads wind against the others",
                quads_u * (nv - 1)
            ),
        ));
    }
    let mut triangles = outer.clone();
    triangles.extend(
        outer
            .iter()
            .map(|t| [t[0] + n as u32, t[2] + n as u32, t[1] + n as u32]),
    );
    // Free edges: directed outer edges whose reverse no outer triangle uses. For the edge
    // x→y the strip is (y, x, x'), (y, x', y') (x' the inner copy of x).
    let mut directed = std::collections::HashSet::new();
    for t in &outer {
        for k in 0..3 {
            directed.insert((t[k], t[(k + 1) % 3]));
        }
    }
    let mut rim: Vec<(u32, u32)> = directed
        .iter()
        .filter(|(x, y)| !directed.contains(&(*y, *x)))
        .copied()
        .collect();
    rim.sort_unstable();
    for (x, y) in rim {
        let (xi, yi) = (x + n as u32, y + n as u32);
        triangles.push([y, x, xi]);
        triangles.push([y, xi, yi]);
    }
    let mut vertices: Vec<[f64; 3]> = grid.points.iter().map(round_point).collect();
    for (p, nrm) in grid.points.iter().zip(&grid.normals) {
        vertices.push(round_point(&(p - nrm * thickness)));
    }
    Ok(MeshData {
        vertices,
        triangles,
    })
}
