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

use std::path::{Path, PathBuf};

use crate::PlanError;

mod cache;
mod data;
mod parse;
mod write;

pub use cache::MeshCache;
pub use data::MeshData;
pub use write::{write_obj, write_stl, write_stl_ascii};

use parse::{parse_obj, parse_stl};

/// Largest accepted bounding-box extent of a workpiece mesh (m). A larger
/// mesh is almost certainly in millimetres.
pub const MAX_EXTENT: f64 = 20.0;

/// The directory `package://kerf/` refers to: the kerf data root of
/// [`kerf_robot::data`] (`KERF_DATA_DIR`, the share directory beside the binary, the
/// source tree — the repository root).
///
/// # Returns
/// The data root; when the search fails, the place it failed at
/// ([`kerf_robot::data::default_root`]), and [`resolve`] reports why.
pub fn package_root() -> PathBuf {
    kerf_robot::data::default_root()
}

/// Resolves a mesh reference to a file path, with the reader every file a request names goes
/// through ([`kerf_robot::file::resolve_uri`]).
///
/// # Arguments
/// * `reference` - one of
///   * a plain path (relative paths are relative to the process working
///     directory),
///   * a `file://` URI (`file:///abs/path`, `file://localhost/abs/path`;
///     `%XX` escapes are decoded),
///   * `package://kerf/<relative path>`, relative to the kerf data root
///     ([`package_root`], [`kerf_robot::data::resolve_package_uri`]).
///
/// # Returns
/// The mesh file's path (whether it exists is not checked).
///
/// # Errors
/// [`PlanError::Mesh`] for an empty reference, another package
/// (`package://kerf_msgs/...` and every package but `kerf`), another URI
/// scheme (`http://`, ...), a `file://` URI with a remote host, a
/// `package://kerf/` path that leaves the repository (`..`), or a
/// `package://kerf/` URI when no kerf data root is found.
pub fn resolve(reference: &str) -> Result<PathBuf, PlanError> {
    kerf_robot::file::resolve_uri(reference).map_err(|e| PlanError::Mesh {
        source_name: reference.to_owned(),
        reason: e.uri_reason(),
    })
}

/// Largest mesh file read (64 MiB: a binary STL of about 1.4 million triangles). A larger
/// file, a FIFO, a device or a directory named as a mesh is refused before it is read
/// ([`kerf_robot::file::read_regular`]).
pub const MAX_MESH_BYTES: u64 = 64 << 20;

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
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    if ext != "stl" && ext != "obj" {
        return Err(PlanError::Mesh {
            source_name: source_name.to_owned(),
            reason: format!(
                "unknown mesh format '.{ext}' of {}: expected .stl or .obj",
                path.display()
            ),
        });
    }
    let bytes =
        kerf_robot::file::read_regular(path, MAX_MESH_BYTES).map_err(|reason| PlanError::Mesh {
            source_name: source_name.to_owned(),
            reason,
        })?;
    parse(&bytes, &ext, source_name)
}

/// Parses and validates the contents of a mesh file, as [`load`] does after reading it.
///
/// # Arguments
/// * `bytes` - the file's contents.
/// * `format` - `stl` or `obj` (the file's extension, case-insensitive).
/// * `source_name` - the mesh reference, used in error messages.
///
/// # Errors
/// [`PlanError::Mesh`] naming `source_name`: an unknown format, the parse errors and the
/// failures of [`MeshData::validated`] listed at [`load`].
pub fn parse(bytes: &[u8], format: &str, source_name: &str) -> Result<MeshData, PlanError> {
    let err = |reason: String| PlanError::Mesh {
        source_name: source_name.to_owned(),
        reason,
    };
    let mesh = match format.to_ascii_lowercase().as_str() {
        "stl" => parse_stl(bytes),
        "obj" => std::str::from_utf8(bytes)
            .map_err(|e| format!("not UTF-8 text (OBJ is a text format): {e}"))
            .and_then(parse_obj),
        other => Err(format!(
            "unknown mesh format '{other}': expected stl or obj"
        )),
    }
    .map_err(err)?;
    mesh.validated(source_name)
}
