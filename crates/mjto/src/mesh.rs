//! Workpiece meshes: resolving a mesh reference, reading STL (binary and
//! ASCII) and Wavefront OBJ, validating, writing, and caching.
//!
//! Meshes are in metres, in the workpiece frame. Readers are strict about
//! what makes a mesh unusable for collision checking (no triangles,
//! non-finite coordinates, indices out of range, millimetre-sized bounding
//! boxes) and tolerant about the rest (OBJ texture/normal indices, groups,
//! materials; STL normals, which are ignored and recomputed on writing).
//!
//! # Example
//!
//! ```
//! use kerf_mjto::mesh::{self, MeshData};
//!
//! let dir = std::env::temp_dir().join(format!("kerf_mesh_doc_{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! let sheet = MeshData::cuboid([0.0, 0.0, -0.002], [0.5, 0.3, 0.0]);
//! let path = dir.join("sheet.stl");
//! mesh::write_stl(&path, &sheet).unwrap();
//! let back = mesh::load(path.to_str().unwrap())?;
//! assert_eq!(back.triangles.len(), 12);
//! # std::fs::remove_dir_all(&dir).ok();
//! # Ok::<(), kerf_mjto::PlanError>(())
//! ```

use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::SystemTime;

use crate::PlanError;

/// Largest accepted bounding-box extent of a workpiece mesh (m). A larger
/// mesh is almost certainly in millimetres.
pub const MAX_EXTENT: f64 = 20.0;

/// Size of the header plus triangle count of a binary STL file (bytes).
const STL_HEADER: usize = 84;
/// Size of one binary STL triangle record (bytes).
const STL_RECORD: usize = 50;

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
    /// # Panics
    /// If the merged vertex count exceeds `u32::MAX` (a mesh of more than
    /// four billion vertices).
    pub fn append(&mut self, other: &MeshData) {
        let offset = u32::try_from(self.vertices.len()).expect("mesh larger than u32 indices");
        self.vertices.extend_from_slice(&other.vertices);
        self.triangles.extend(
            other
                .triangles
                .iter()
                .map(|t| [t[0] + offset, t[1] + offset, t[2] + offset]),
        );
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

fn sub(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The repository root, the directory `package://kerf/` refers to.
pub fn package_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Resolves a mesh reference to a file path.
///
/// # Arguments
/// * `reference` - one of
///   * a plain path (relative paths are relative to the process working
///     directory),
///   * a `file://` URI (`file:///abs/path`, `file://localhost/abs/path`;
///     `%XX` escapes are decoded),
///   * `package://kerf/<relative path>`, relative to the repository root
///     ([`package_root`]).
///
/// # Errors
/// [`PlanError::Mesh`] for an empty reference, another package
/// (`package://kerf_msgs/...` and every package but `kerf`), another URI
/// scheme (`http://`, ...), a `file://` URI with a remote host, or a
/// `package://kerf/` path that leaves the repository (`..`).
pub fn resolve(reference: &str) -> Result<PathBuf, PlanError> {
    let err = |reason: String| PlanError::Mesh {
        source_name: reference.to_owned(),
        reason,
    };
    let r = reference.trim();
    if r.is_empty() {
        return Err(err("empty mesh reference".into()));
    }
    if let Some(rest) = r.strip_prefix("package://") {
        let (package, rel) = rest.split_once('/').unwrap_or((rest, ""));
        if package != "kerf" {
            return Err(err(format!(
                "package '{package}' is not supported: only package://kerf/<path> (the kerf \
                 repository root) is resolved"
            )));
        }
        let rel = Path::new(rel);
        if rel.as_os_str().is_empty() {
            return Err(err("package://kerf/ needs a file path".into()));
        }
        if rel.components().any(|c| {
            !matches!(
                c,
                std::path::Component::Normal(_) | std::path::Component::CurDir
            )
        }) {
            return Err(err(
                "a package://kerf/ path must be relative and stay inside the repository".into(),
            ));
        }
        return Ok(package_root().join(rel));
    }
    if let Some(rest) = r.strip_prefix("file://") {
        let path = if rest.starts_with('/') {
            rest
        } else if let Some(p) = rest.strip_prefix("localhost") {
            p
        } else {
            return Err(err(
                "file:// URIs must name a local absolute path (file:///path)".into(),
            ));
        };
        return Ok(PathBuf::from(percent_decode(path).map_err(err)?));
    }
    if let Some((scheme, _)) = r.split_once("://") {
        if !scheme.is_empty()
            && scheme
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '+')
        {
            return Err(err(format!(
                "URI scheme '{scheme}://' is not supported (use a path, file:// or package://kerf/)"
            )));
        }
    }
    Ok(PathBuf::from(r))
}

/// Decodes `%XX` escapes of a URI path.
fn percent_decode(s: &str) -> Result<String, String> {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while let Some(&b) = bytes.get(i) {
        if b == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| format!("bad percent escape at byte {i} of the URI path"))?;
            out.push(hex);
            i += 3;
        } else {
            out.push(b);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| "the URI path is not UTF-8 after decoding".to_owned())
}

/// Loads and validates a workpiece mesh.
///
/// # Arguments
/// * `reference` - a path or URI, see [`resolve`]. The format is chosen by
///   the extension (case-insensitive): `.stl` (binary or ASCII, told apart
///   by the content: a binary file has exactly 84 + 50 · n bytes) or
///   `.obj` (`v` and `f` lines; polygons are fan-triangulated; negative,
///   relative indices and `v/t/n` forms are accepted; other statements are
///   ignored). Coordinates are metres.
///
/// # Errors
/// [`PlanError::Mesh`] naming the reference: unresolvable reference,
/// missing or unreadable file, unknown extension, parse errors (with the
/// line number for text formats, the triangle number for binary STL), and
/// every failure of [`MeshData::validated`].
///
/// # Performance
/// One read of the file; binary STL vertices are merged when bit-identical
/// (O(n) with a hash map). Use [`MeshCache`] to load a mesh once.
pub fn load(reference: &str) -> Result<MeshData, PlanError> {
    let path = resolve(reference)?;
    load_path(&path, reference)
}

/// Loads the file at `path` (already resolved); errors name `source_name`.
fn load_path(path: &Path, source_name: &str) -> Result<MeshData, PlanError> {
    let err = |reason: String| PlanError::Mesh {
        source_name: source_name.to_owned(),
        reason,
    };
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    if ext != "stl" && ext != "obj" {
        return Err(err(format!(
            "unknown mesh format '.{ext}' of {}: expected .stl or .obj",
            path.display()
        )));
    }
    let bytes =
        std::fs::read(path).map_err(|e| err(format!("cannot read {}: {e}", path.display())))?;
    let mesh = if ext == "stl" {
        parse_stl(&bytes)
    } else {
        let text = std::str::from_utf8(&bytes)
            .map_err(|e| format!("not UTF-8 text (OBJ is a text format): {e}"))
            .map_err(&err)?;
        parse_obj(text)
    }
    .map_err(&err)?;
    mesh.validated(source_name)
}

/// Parses an STL file, binary or ASCII.
///
/// Binary when the size is exactly 84 + 50 · (the triangle count in bytes
/// 80..84), even if the header starts with "solid" (some exporters do
/// that); ASCII when the text starts with `solid`; otherwise an error
/// describing the size mismatch.
fn parse_stl(bytes: &[u8]) -> Result<MeshData, String> {
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
            other => return Err(format!("line {ln}: unexpected keyword '{other}'")),
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
        let x: f64 = s.parse().map_err(|_| format!("'{s}' is not a number"))?;
        if !x.is_finite() {
            return Err(format!("coordinate '{s}' is not finite"));
        }
        *slot = x;
    }
    Ok(v)
}

fn parse_obj(text: &str) -> Result<MeshData, String> {
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
        .map_err(|_| format!("face index '{token}' is not an integer"))?;
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

/// Identity of a file version: length and modification time.
type FileStamp = (u64, Option<SystemTime>);

/// A cache of loaded meshes, so a planner node loads each mesh once.
///
/// Keyed by the resolved (canonical when possible) path; an entry is
/// reused while the file's length and modification time are unchanged,
/// and reloaded otherwise.
#[derive(Debug, Default)]
pub struct MeshCache {
    entries: HashMap<PathBuf, (FileStamp, Arc<MeshData>)>,
    loads: usize,
}

impl MeshCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// The mesh of `reference`, loaded on first use or when the file
    /// changed.
    ///
    /// # Errors
    /// As [`load`]; a file whose metadata cannot be read is a
    /// [`PlanError::Mesh`] ("cannot read").
    ///
    /// # Performance
    /// A cache hit costs one `stat` of the file and an `Arc` clone.
    pub fn get(&mut self, reference: &str) -> Result<Arc<MeshData>, PlanError> {
        let path = resolve(reference)?;
        let key = std::fs::canonicalize(&path).unwrap_or_else(|_| path.clone());
        let meta = std::fs::metadata(&key).map_err(|e| PlanError::Mesh {
            source_name: reference.to_owned(),
            reason: format!("cannot read {}: {e}", path.display()),
        })?;
        let stamp = (meta.len(), meta.modified().ok());
        if let Some((s, mesh)) = self.entries.get(&key) {
            if *s == stamp {
                return Ok(Arc::clone(mesh));
            }
        }
        let mesh = Arc::new(load_path(&key, reference)?);
        self.loads += 1;
        self.entries.insert(key, (stamp, Arc::clone(&mesh)));
        Ok(mesh)
    }

    /// Number of meshes held.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// True when no mesh is held.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Number of file loads so far (misses, including reloads of changed
    /// files).
    pub fn loads(&self) -> usize {
        self.loads
    }
}
