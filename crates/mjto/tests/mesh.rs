//! Mesh loading, writing, validation, resolution and caching.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::path::{Path, PathBuf};
use std::sync::Arc;

use kerf_mjto::mesh::{self, MeshCache, MeshData};
use kerf_mjto::PlanError;

/// A fresh scratch directory per test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kerf_mesh_test_{}_{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A non-trivial mesh: a box with a tilted plate, irregular coordinates.
fn sample_mesh() -> MeshData {
    let mut m = MeshData::cuboid([0.1, -0.2, 0.0], [0.7, 0.35, 0.0015]);
    m.append(&MeshData {
        vertices: vec![
            [0.123456789, 0.2, 0.3],
            [0.5, 0.21, 0.31],
            [0.5, 0.6, 0.45],
            [0.13, 0.58, 0.44],
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    })
    .unwrap();
    m
}

/// Triangles as coordinate triples, for comparisons independent of
/// vertex numbering.
fn triangle_coords(m: &MeshData) -> Vec<[[f64; 3]; 3]> {
    m.triangles
        .iter()
        .map(|t| t.map(|k| m.vertices[k as usize]))
        .collect()
}

fn assert_same_geometry(a: &MeshData, b: &MeshData, tol: f64) {
    let (ta, tb) = (triangle_coords(a), triangle_coords(b));
    assert_eq!(ta.len(), tb.len());
    for (x, y) in ta.iter().zip(&tb) {
        for (p, q) in x.iter().zip(y) {
            for (u, v) in p.iter().zip(q) {
                assert!((u - v).abs() <= tol, "{x:?} vs {y:?}");
            }
        }
    }
}

fn mesh_reason(r: Result<MeshData, PlanError>) -> String {
    match r {
        Err(PlanError::Mesh { reason, .. }) => reason,
        other => panic!("expected a mesh error, got {other:?}"),
    }
}

#[test]
fn obj_round_trip_is_exact() {
    let dir = scratch("obj");
    let m = sample_mesh();
    let path = dir.join("part.obj");
    mesh::write_obj(&path, &m).unwrap();
    let back = mesh::load(path.to_str().unwrap()).unwrap();
    assert_eq!(back, m, "OBJ keeps numbering and full f64 precision");
}

#[test]
fn binary_stl_round_trip_to_f32_precision() {
    let dir = scratch("stl_bin");
    let m = sample_mesh();
    let path = dir.join("part.STL"); // extension is case-insensitive
    mesh::write_stl(&path, &m).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(bytes.len(), 84 + 50 * m.triangles.len());
    let back = mesh::load(path.to_str().unwrap()).unwrap();
    assert_same_geometry(&back, &m, 1e-7);
    // Shared corners are merged again: 8 box corners + 4 plate corners.
    assert_eq!(back.vertices.len(), 12);
}

#[test]
fn binary_stl_whose_header_starts_with_solid_is_still_binary() {
    let dir = scratch("stl_solid_header");
    let m = sample_mesh();
    let path = dir.join("part.stl");
    mesh::write_stl(&path, &m).unwrap();
    let mut bytes = std::fs::read(&path).unwrap();
    bytes[..5].copy_from_slice(b"solid");
    std::fs::write(&path, &bytes).unwrap();
    let back = mesh::load(path.to_str().unwrap()).unwrap();
    assert_same_geometry(&back, &m, 1e-7);
}

#[test]
fn ascii_stl_round_trip_is_exact() {
    let dir = scratch("stl_ascii");
    let m = sample_mesh();
    let path = dir.join("part.stl");
    mesh::write_stl_ascii(&path, &m).unwrap();
    assert!(std::fs::read_to_string(&path)
        .unwrap()
        .starts_with("solid kerf"));
    let back = mesh::load(path.to_str().unwrap()).unwrap();
    assert_same_geometry(&back, &m, 0.0);
}

#[test]
fn obj_polygons_negative_indices_and_slash_forms() {
    let dir = scratch("obj_forms");
    let path = dir.join("quad.obj");
    std::fs::write(
        &path,
        "# a unit quad and a triangle with relative indices\n\
         mtllib x.mtl\no quad\n\
         v 0 0 0\nv 1 0 0\nv 1 1 0 1.0\nv 0 1 0\n\
         vt 0 0\nvn 0 0 1\n\
         f 1/1/1 2/1/1 3//1 4\n\
         v 0 0 1\nv 1 0 1\nv 0 1 1\n\
         f -3 -2 -1\n",
    )
    .unwrap();
    let m = mesh::load(path.to_str().unwrap()).unwrap();
    assert_eq!(m.vertices.len(), 7);
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [4, 5, 6]]);
}

#[test]
fn errors_name_the_problem() {
    let dir = scratch("errors");
    // Missing file.
    let missing = dir.join("nope.stl");
    let r = mesh_reason(mesh::load(missing.to_str().unwrap()));
    assert!(r.contains("cannot read"), "{r}");
    // Unknown extension.
    let ply = dir.join("part.ply");
    std::fs::write(&ply, "ply\n").unwrap();
    let r = mesh_reason(mesh::load(ply.to_str().unwrap()));
    assert!(r.contains("unknown mesh format"), "{r}");
    // Bad index, with its line number.
    let bad = dir.join("bad_index.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n").unwrap();
    let r = mesh_reason(mesh::load(bad.to_str().unwrap()));
    assert!(r.contains("line 4") && r.contains("out of range"), "{r}");
    // NaN vertex in OBJ, with its line number.
    let nan = dir.join("nan.obj");
    std::fs::write(&nan, "v 0 0 0\nv NaN 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let r = mesh_reason(mesh::load(nan.to_str().unwrap()));
    assert!(r.contains("line 2") && r.contains("not finite"), "{r}");
    // NaN vertex in binary STL, with its triangle number.
    let nan_stl = dir.join("nan.stl");
    let mut m = sample_mesh();
    mesh::write_stl(&nan_stl, &m).unwrap();
    let mut bytes = std::fs::read(&nan_stl).unwrap();
    let off = 84 + 50 * 3 + 12; // triangle 3, first vertex x
    bytes[off..off + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    std::fs::write(&nan_stl, &bytes).unwrap();
    let r = mesh_reason(mesh::load(nan_stl.to_str().unwrap()));
    assert!(r.contains("triangle 3") && r.contains("not finite"), "{r}");
    // Empty: no triangles.
    let empty = dir.join("empty.obj");
    std::fs::write(&empty, "v 0 0 0\n").unwrap();
    let r = mesh_reason(mesh::load(empty.to_str().unwrap()));
    assert!(r.contains("no triangles"), "{r}");
    // ASCII STL parse error, with its line number.
    let ascii = dir.join("bad.stl");
    std::fs::write(
        &ascii,
        "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 zero\n",
    )
    .unwrap();
    let r = mesh_reason(mesh::load(ascii.to_str().unwrap()));
    // Issue 11, row 9: the line and the coordinate, never the file's own text.
    assert!(
        r.contains("line 5") && r.contains("coordinate 3 is not a number") && !r.contains("zero"),
        "{r}"
    );
    // Truncated binary STL.
    let trunc = dir.join("trunc.stl");
    mesh::write_stl(&trunc, &m).unwrap();
    let bytes = std::fs::read(&trunc).unwrap();
    std::fs::write(&trunc, &bytes[..bytes.len() - 7]).unwrap();
    let r = mesh_reason(mesh::load(trunc.to_str().unwrap()));
    assert!(r.contains("announces 14 triangles"), "{r}");
    // Millimetres.
    for v in &mut m.vertices {
        *v = v.map(|c| c * 1000.0);
    }
    let mm = dir.join("mm.obj");
    mesh::write_obj(&mm, &m).unwrap();
    let r = mesh_reason(mesh::load(mm.to_str().unwrap()));
    assert!(r.contains("millimetres"), "{r}");
}

#[test]
fn validation_of_in_memory_meshes() {
    let m = MeshData {
        vertices: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [2.0, 0.0, 0.0]],
        // One good, one repeated index, one collinear (zero area).
        triangles: vec![[0, 1, 2], [0, 0, 1], [0, 1, 3]],
    };
    let v = m.clone().validated("mem").unwrap();
    assert_eq!(v.triangles, vec![[0, 1, 2]]);
    let all_bad = MeshData {
        triangles: vec![[0, 1, 3]],
        ..m.clone()
    };
    assert!(mesh_reason(all_bad.validated("mem")).contains("degenerate"));
    let out_of_range = MeshData {
        triangles: vec![[0, 1, 4]],
        ..m
    };
    assert!(mesh_reason(out_of_range.validated("mem")).contains("beyond the 4 vertices"));
}

#[test]
fn references_resolve() {
    let root = mesh::package_root();
    assert_eq!(
        mesh::resolve("package://kerf/urdf/laser_cutter.urdf").unwrap(),
        root.join("urdf/laser_cutter.urdf")
    );
    assert!(root.join("urdf/laser_cutter.urdf").is_file());
    assert_eq!(
        mesh::resolve("file:///tmp/a%20b.stl").unwrap(),
        Path::new("/tmp/a b.stl")
    );
    assert_eq!(
        mesh::resolve("file://localhost/tmp/x.obj").unwrap(),
        Path::new("/tmp/x.obj")
    );
    assert_eq!(
        mesh::resolve("parts/x.obj").unwrap(),
        Path::new("parts/x.obj")
    );
    for bad in [
        "package://kerf_msgs/meshes/x.stl",
        "package://kerf/../etc/passwd",
        "http://example.com/x.stl",
        "file://host/x.stl",
        "",
    ] {
        assert!(
            matches!(mesh::resolve(bad), Err(PlanError::Mesh { .. })),
            "{bad} should not resolve"
        );
    }
}

#[test]
fn package_uri_loads_a_mesh_inside_the_repository() {
    // A mesh written under the repository's target dir, loaded by URI.
    let rel = format!("target/kerf_mesh_test_{}.obj", std::process::id());
    let abs = mesh::package_root().join(&rel);
    std::fs::create_dir_all(abs.parent().unwrap()).unwrap();
    let m = sample_mesh();
    mesh::write_obj(&abs, &m).unwrap();
    let back = mesh::load(&format!("package://kerf/{rel}"));
    std::fs::remove_file(&abs).ok();
    assert_eq!(back.unwrap(), m);
}

#[test]
fn cache_loads_once_and_reloads_on_change() {
    let dir = scratch("cache");
    let path = dir.join("part.obj");
    let m = sample_mesh();
    mesh::write_obj(&path, &m).unwrap();
    let mut cache = MeshCache::new();
    let a = cache.get(path.to_str().unwrap()).unwrap();
    let b = cache.get(&format!("file://{}", path.display())).unwrap();
    assert!(Arc::ptr_eq(&a, &b), "same file by two references: one load");
    assert_eq!((cache.loads(), cache.len()), (1, 1));
    // A changed file (different length) is reloaded.
    let mut m2 = m.clone();
    m2.append(&MeshData::cuboid([0.0; 3], [0.1; 3])).unwrap();
    mesh::write_obj(&path, &m2).unwrap();
    let c = cache.get(path.to_str().unwrap()).unwrap();
    assert_eq!(*c, m2);
    assert_eq!(cache.loads(), 2);
    assert!(cache
        .get(dir.join("missing.obj").to_str().unwrap())
        .is_err());
}

/// Runs `f` on a thread and fails the test if it does not end within 10 s (a request file
/// must never hang the planner).
fn within_10_s<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(std::time::Duration::from_secs(10))
        .expect("the call hung (a FIFO opened for reading blocks)")
}

/// Issue 11, rows 6 and 9: a FIFO named as a mesh is refused at once (directly or through a
/// symbolic link), an oversized file by its size, and parse errors quote no file contents.
#[test]
fn fifos_oversized_files_and_secrets_are_not_read() {
    let dir = scratch("unsafe");
    let fifo = dir.join("pipe.stl");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: mkfifo(3) on a NUL-terminated path we own.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    let link = dir.join("link.obj");
    std::os::unix::fs::symlink(&fifo, &link).unwrap();
    for p in [fifo.clone(), link] {
        let shown = p.display().to_string();
        let e = within_10_s(move || mesh::load(&shown)).unwrap_err();
        assert!(matches!(e, PlanError::Mesh { .. }), "{e}");
        assert!(e.to_string().contains("FIFO"), "{e}");
        let shown = p.display().to_string();
        let e = within_10_s(move || MeshCache::new().get(&shown).map(|_| ())).unwrap_err();
        assert!(e.to_string().contains("FIFO"), "{e}");
    }
    let big = dir.join("big.stl");
    std::fs::File::create(&big)
        .unwrap()
        .set_len(mesh::MAX_MESH_BYTES + 1)
        .unwrap();
    let e = mesh::load(big.to_str().unwrap()).unwrap_err().to_string();
    assert!(e.contains("over the limit"), "{e}");
    let secret = dir.join("secret.obj");
    for (text, needle) in [
        ("v 0 0 0\nv 1 TOPSECRET 0\n", "coordinate 2 is not a number"),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 TOPSECRET\n",
            "not an integer",
        ),
    ] {
        std::fs::write(&secret, text).unwrap();
        let e = mesh::load(secret.to_str().unwrap())
            .unwrap_err()
            .to_string();
        assert!(e.contains(needle) && !e.contains("TOPSECRET"), "{e}");
    }
    let stl = dir.join("secret.stl");
    std::fs::write(&stl, "solid x\nTOPSECRET 1 2 3\nendsolid\n").unwrap();
    let e = mesh::load(stl.to_str().unwrap()).unwrap_err().to_string();
    assert!(
        e.contains("unexpected keyword") && !e.contains("TOPSECRET"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
