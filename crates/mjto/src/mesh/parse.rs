//! Reading binary and ASCII STL and Wavefront OBJ.

use std::collections::HashMap;

use super::MeshData;

/// Size of the header plus triangle count of a binary STL file (bytes).
const STL_HEADER: usize = 84;
/// Size of one binary STL triangle record (bytes).
const STL_RECORD: usize = 50;

/// Parses an STL file, binary or ASCII.
///
/// Binary when the size is exactly 84 + 50 · (the triangle count in bytes
/// 80..84), even if the header starts with "solid" (some exporters do
/// that); ASCII when the text starts with `solid`; otherwise an error
/// describing the size mismatch.
pub(super) fn parse_stl(bytes: &[u8]) -> Result<MeshData, String> {
    let binary_count = bytes
        .get(80..84)
        .and_then(|b| <[u8; 4]>::try_from(b).ok())
        .map(|b| u32::from_le_bytes(b) as usize);
    if let Some(n) = binary_count {
        if n.checked_mul(STL_RECORD)
            .and_then(|s| s.checked_add(STL_HEADER))
            == Some(bytes.len())
        {
            return parse_stl_binary(bytes, n);
        }
    }
    let head = bytes
        .iter()
        .skip_while(|b| b.is_ascii_whitespace())
        .take(5)
        .copied()
        .collect::<Vec<u8>>();
    if head.eq_ignore_ascii_case(b"solid") {
        let text =
            std::str::from_utf8(bytes).map_err(|e| format!("ASCII STL is not valid text: {e}"))?;
        return parse_stl_ascii(text);
    }
    match binary_count {
        Some(n) => Err(format!(
            "binary STL header announces {n} triangles ({} bytes) but the file has {} bytes \
             (truncated or not an STL file)",
            n.saturating_mul(STL_RECORD).saturating_add(STL_HEADER),
            bytes.len()
        )),
        None => Err(format!(
            "{} bytes: too short for a binary STL (84-byte header) and not an ASCII STL \
             (no 'solid' keyword)",
            bytes.len()
        )),
    }
}

/// Merges bit-identical vertices while building a mesh.
#[derive(Default)]
struct VertexPool {
    mesh: MeshData,
    index: HashMap<[u64; 3], u32>,
}

impl VertexPool {
    fn add(&mut self, v: [f64; 3]) -> Result<u32, String> {
        let key = [v[0].to_bits(), v[1].to_bits(), v[2].to_bits()];
        if let Some(&i) = self.index.get(&key) {
            return Ok(i);
        }
        let i = u32::try_from(self.mesh.vertices.len())
            .map_err(|_| "more than 2^32 vertices".to_owned())?;
        self.mesh.vertices.push(v);
        self.index.insert(key, i);
        Ok(i)
    }
}

fn parse_stl_binary(bytes: &[u8], n: usize) -> Result<MeshData, String> {
    let mut pool = VertexPool::default();
    pool.mesh.triangles.reserve(n);
    for t in 0..n {
        let start = STL_HEADER + t * STL_RECORD;
        let rec = bytes
            .get(start..start + STL_RECORD)
            .ok_or_else(|| format!("triangle {t}: truncated record"))?;
        let f = |k: usize| -> f64 {
            let o = 12 + 4 * k; // skip the normal (3 x f32)
            let b = [rec[o], rec[o + 1], rec[o + 2], rec[o + 3]];
            f64::from(f32::from_le_bytes(b))
        };
        let mut tri = [0u32; 3];
        for (c, slot) in tri.iter_mut().enumerate() {
            let v = [f(3 * c), f(3 * c + 1), f(3 * c + 2)];
            if v.iter().any(|x| !x.is_finite()) {
                return Err(format!("triangle {t}: vertex {c} is not finite: {v:?}"));
            }
            *slot = pool.add(v)?;
        }
        pool.mesh.triangles.push(tri);
    }
    Ok(pool.mesh)
}

fn parse_stl_ascii(text: &str) -> Result<MeshData, String> {
    let mut pool = VertexPool::default();
    let mut facet: Option<(usize, Vec<u32>)> = None;
    for (i, line) in text.lines().enumerate() {
        let ln = i + 1;
        let mut tok = line.split_whitespace();
        let Some(kw) = tok.next() else { continue };
        match kw.to_ascii_lowercase().as_str() {
            "solid" | "endsolid" | "outer" | "endloop" => {}
            "facet" => {
                if facet.is_some() {
                    return Err(format!("line {ln}: 'facet' inside an open facet"));
                }
                facet = Some((ln, Vec::with_capacity(3)));
            }
            "vertex" => {
                let Some((_, verts)) = facet.as_mut() else {
                    return Err(format!("line {ln}: 'vertex' outside a facet"));
                };
                let v = parse_xyz(&mut tok).map_err(|e| format!("line {ln}: {e}"))?;
                verts.push(pool.add(v).map_err(|e| format!("line {ln}: {e}"))?);
            }
            "endfacet" => {
                let Some((start, verts)) = facet.take() else {
                    return Err(format!("line {ln}: 'endfacet' without 'facet'"));
                };
                match verts.as_slice() {
                    [a, b, c] => pool.mesh.triangles.push([*a, *b, *c]),
                    _ => {
                        return Err(format!(
                            "line {start}: facet has {} vertices, expected 3",
                            verts.len()
                        ))
                    }
                }
            }
            _ => return Err(format!("line {ln}: unexpected keyword (expected facet, outer loop, vertex, endloop, endfacet or endsolid)")),
        }
    }
    if let Some((start, _)) = facet {
        return Err(format!("line {start}: facet is not closed (no 'endfacet')"));
    }
    Ok(pool.mesh)
}

/// Parses three finite coordinates; extra tokens are not allowed.
fn parse_xyz<'a>(tok: &mut impl Iterator<Item = &'a str>) -> Result<[f64; 3], String> {
    let mut v = [0.0; 3];
    for (k, slot) in v.iter_mut().enumerate() {
        let s = tok
            .next()
            .ok_or_else(|| format!("expected 3 coordinates, got {k}"))?;
        let x: f64 = s
            .parse()
            .map_err(|_| format!("coordinate {} is not a number", k + 1))?;
        if !x.is_finite() {
            return Err(format!("coordinate {} is not finite", k + 1));
        }
        *slot = x;
    }
    Ok(v)
}

pub(super) fn parse_obj(text: &str) -> Result<MeshData, String> {
    let mut mesh = MeshData::default();
    for (i, line) in text.lines().enumerate() {
        let ln = i + 1;
        let line = line.split('#').next().unwrap_or("");
        let mut tok = line.split_whitespace();
        match tok.next() {
            Some("v") => {
                // x y z [w] or x y z r g b: the first three are the position.
                let v = parse_xyz(&mut tok).map_err(|e| format!("line {ln}: {e}"))?;
                mesh.vertices.push(v);
            }
            Some("f") => {
                let n = mesh.vertices.len();
                let idx = tok
                    .map(|t| obj_index(t, n).map_err(|e| format!("line {ln}: {e}")))
                    .collect::<Result<Vec<u32>, String>>()?;
                if idx.len() < 3 {
                    return Err(format!(
                        "line {ln}: face with {} vertices, at least 3 are required",
                        idx.len()
                    ));
                }
                // Fan triangulation of a (convex, planar) polygon.
                for k in 1..idx.len() - 1 {
                    mesh.triangles.push([idx[0], idx[k], idx[k + 1]]);
                }
            }
            _ => {} // vt, vn, g, o, s, usemtl, mtllib, l, p, blank: not geometry we use
        }
    }
    Ok(mesh)
}

/// One OBJ face vertex `i`, `i/t`, `i//n` or `i/t/n`: 1-based, or
/// negative relative to the `n` vertices read so far.
fn obj_index(token: &str, n: usize) -> Result<u32, String> {
    let s = token.split('/').next().unwrap_or("");
    let i: i64 = s
        .parse()
        .map_err(|_| "a face index is not an integer".to_string())?;
    let zero_based = match i {
        0 => return Err("face index 0 (OBJ indices start at 1)".into()),
        i if i > 0 => i - 1,
        i => n as i64 + i,
    };
    if zero_based < 0 || zero_based >= n as i64 {
        return Err(format!(
            "face index {i} is out of range: {n} vertices defined so far"
        ));
    }
    u32::try_from(zero_based).map_err(|_| format!("face index {i} exceeds u32"))
}
