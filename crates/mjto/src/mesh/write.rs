//! Writing meshes as Wavefront OBJ and binary or ASCII STL.

use std::io::Write;
use std::path::Path;

use super::data::{cross, dot, sub};
use super::MeshData;

/// Writes a Wavefront OBJ file (`v` lines with shortest round-trip
/// decimals, `f` lines with 1-based indices).
///
/// # Errors
/// Any I/O error of creating or writing the file.
pub fn write_obj(path: &Path, mesh: &MeshData) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(
        w,
        "# kerf workpiece mesh, metres: {} vertices, {} triangles",
        mesh.vertices.len(),
        mesh.triangles.len()
    )?;
    for v in &mesh.vertices {
        writeln!(w, "v {:?} {:?} {:?}", v[0], v[1], v[2])?;
    }
    for t in &mesh.triangles {
        writeln!(w, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
    }
    w.flush()
}

/// Unit normal of a triangle (right-hand rule), or zero when degenerate or
/// an index is out of range.
fn facet_normal(mesh: &MeshData, t: &[u32; 3]) -> [f64; 3] {
    let (Some(a), Some(b), Some(c)) = (
        mesh.vertices.get(t[0] as usize),
        mesh.vertices.get(t[1] as usize),
        mesh.vertices.get(t[2] as usize),
    ) else {
        return [0.0; 3];
    };
    let n = cross(&sub(b, a), &sub(c, a));
    let len = dot(&n, &n).sqrt();
    if len > 0.0 && len.is_finite() {
        [n[0] / len, n[1] / len, n[2] / len]
    } else {
        [0.0; 3]
    }
}

/// The vertices of triangle `t`, or an `InvalidInput` error when an index
/// is out of range.
fn triangle_vertices(mesh: &MeshData, t: &[u32; 3]) -> std::io::Result<[[f64; 3]; 3]> {
    let get = |k: u32| {
        mesh.vertices.get(k as usize).copied().ok_or_else(|| {
            std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!(
                    "triangle {t:?} refers to vertex {k} of {}",
                    mesh.vertices.len()
                ),
            )
        })
    };
    Ok([get(t[0])?, get(t[1])?, get(t[2])?])
}

/// Writes a binary STL file (80-byte header, little-endian f32 normals and
/// vertices; coordinates are rounded to f32).
///
/// # Errors
/// I/O errors, an index out of range, or more than `u32::MAX` triangles
/// (`InvalidInput`).
pub fn write_stl(path: &Path, mesh: &MeshData) -> std::io::Result<()> {
    let count = u32::try_from(mesh.triangles.len()).map_err(|_| {
        std::io::Error::new(std::io::ErrorKind::InvalidInput, "more than 2^32 triangles")
    })?;
    let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
    let mut header = [b' '; 80];
    let tag = b"kerf binary STL, metres";
    header[..tag.len()].copy_from_slice(tag);
    w.write_all(&header)?;
    w.write_all(&count.to_le_bytes())?;
    for t in &mesh.triangles {
        let vs = triangle_vertices(mesh, t)?;
        for c in facet_normal(mesh, t) {
            w.write_all(&(c as f32).to_le_bytes())?;
        }
        for v in vs {
            for c in v {
                w.write_all(&(c as f32).to_le_bytes())?;
            }
        }
        w.write_all(&0u16.to_le_bytes())?;
    }
    w.flush()
}

/// Writes an ASCII STL file (`solid kerf` ... `endsolid kerf`, full f64
/// precision).
///
/// # Errors
/// I/O errors, or an index out of range (`InvalidInput`).
pub fn write_stl_ascii(path: &Path, mesh: &MeshData) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(w, "solid kerf")?;
    for t in &mesh.triangles {
        let vs = triangle_vertices(mesh, t)?;
        let n = facet_normal(mesh, t);
        writeln!(w, "  facet normal {:e} {:e} {:e}", n[0], n[1], n[2])?;
        writeln!(w, "    outer loop")?;
        for v in vs {
            writeln!(w, "      vertex {:?} {:?} {:?}", v[0], v[1], v[2])?;
        }
        writeln!(w, "    endloop")?;
        writeln!(w, "  endfacet")?;
    }
    writeln!(w, "endsolid kerf")?;
    w.flush()
}
