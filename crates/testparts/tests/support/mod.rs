//! Geometry shared by the fixture tests of the test parts (bpillar, jobshop).
#![allow(dead_code)] // each test file uses a subset

use std::path::PathBuf;

use kerf_mjto::mesh::MeshData;
use nalgebra::Vector3;

/// The repository root (the committed files are relative to it).
pub fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A point as a vector.
pub fn v(p: &[f64; 3]) -> Vector3<f64> {
    Vector3::new(p[0], p[1], p[2])
}

/// The corners of triangle `t` of `mesh`.
pub fn tri(mesh: &MeshData, t: &[u32; 3]) -> [Vector3<f64>; 3] {
    t.map(|k| v(&mesh.vertices[k as usize]))
}

/// Closest point of triangle (a, b, c) to p (Ericson, Real-Time Collision Detection,
/// section 5.1.5, by Voronoi regions).
pub fn closest_on_triangle(p: &Vector3<f64>, [a, b, c]: &[Vector3<f64>; 3]) -> Vector3<f64> {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(&ap);
    let d2 = ac.dot(&ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return *a;
    }
    let bp = p - b;
    let d3 = ab.dot(&bp);
    let d4 = ac.dot(&bp);
    if d3 >= 0.0 && d4 <= d3 {
        return *b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let d5 = ab.dot(&cp);
    let d6 = ac.dot(&cp);
    if d6 >= 0.0 && d5 <= d6 {
        return *c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}
