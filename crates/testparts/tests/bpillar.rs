//! The B-pillar test workpiece and the two cut requests of seed 001
//! section 3 (`kerf_testparts::bpillar`, `crates/mjto/cases/case{1,2}.yaml`,
//! `urdf/meshes/bpillar.obj`).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod support;
use support::{closest_on_triangle, repo_root, tri, v};

use std::collections::HashMap;

use kerf_mjto::mesh::{self, MeshData};
use kerf_mjto::{CutRequest, LaserMachine};
use kerf_testparts::bpillar::{self, BPillar, BPillarParams};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

fn committed_case(file: &str) -> CutRequest {
    let text = std::fs::read_to_string(repo_root().join(file))
        .unwrap_or_else(|e| panic!("{file}: {e} (run the gen_bpillar example)"));
    CutRequest::from_yaml(&text).unwrap_or_else(|e| panic!("{file}: {e}"))
}

fn committed_mesh() -> MeshData {
    mesh::load(bpillar::MESH_REFERENCE).expect("the committed bpillar.obj loads")
}

/// Distance from p to the mesh and the unit normal of the nearest triangle.
fn nearest(mesh: &MeshData, p: &Vector3<f64>) -> (f64, Vector3<f64>) {
    let mut best = (f64::INFINITY, Vector3::zeros());
    for t in &mesh.triangles {
        let abc = tri(mesh, t);
        let d = (closest_on_triangle(p, &abc) - p).norm();
        if d < best.0 {
            best = (d, (abc[1] - abc[0]).cross(&(abc[2] - abc[0])).normalize());
        }
    }
    best
}

/// Möller-Trumbore: distance along the unit ray (o, d) to the triangle.
fn ray_hit(o: &Vector3<f64>, d: &Vector3<f64>, [a, b, c]: &[Vector3<f64>; 3]) -> Option<f64> {
    let e1 = b - a;
    let e2 = c - a;
    let p = d.cross(&e2);
    let det = e1.dot(&p);
    if det.abs() < 1e-18 {
        return None;
    }
    let s = o - a;
    let u = s.dot(&p) / det;
    let q = s.cross(&e1);
    let w = d.dot(&q) / det;
    let t = e2.dot(&q) / det;
    (u >= 0.0 && w >= 0.0 && u + w <= 1.0 && t > 0.0).then_some(t)
}

#[test]
fn mesh_is_closed_and_consistently_oriented() {
    let g = bpillar::generate().unwrap();
    let mesh = g.pillar.mesh();
    assert!(
        (3000..8000).contains(&mesh.triangles.len()),
        "{} triangles: a few thousand expected",
        mesh.triangles.len()
    );
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    for t in &mesh.triangles {
        let abc = tri(mesh, t);
        let area = 0.5 * (abc[1] - abc[0]).cross(&(abc[2] - abc[0])).norm();
        assert!(area > 1e-8, "degenerate triangle {t:?} (area {area:e} m²)");
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        assert_eq!(n, 1, "directed edge {a}->{b} is used {n} times");
        assert_eq!(
            directed.get(&(b, a)),
            Some(&1),
            "edge {a}->{b} has no opposite: the surface is open or inconsistently oriented"
        );
    }
    // Every vertex is used.
    let mut used = vec![false; mesh.vertices.len()];
    for t in &mesh.triangles {
        for &k in t {
            used[k as usize] = true;
        }
    }
    assert!(used.iter().all(|&u| u), "unused vertices");
}

#[test]
fn volume_is_area_times_thickness_and_normals_point_outward() {
    let g = bpillar::generate().unwrap();
    let mesh = g.pillar.mesh();
    let n_outer = (g.pillar.stations().len() * g.pillar.profile_len()) as u32;
    // Divergence theorem: V = Σ a · (b × c) / 6 over outward triangles.
    let volume: f64 = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = tri(mesh, t);
            a.dot(&b.cross(&c)) / 6.0
        })
        .sum();
    let outer_area: f64 = mesh
        .triangles
        .iter()
        .filter(|t| t.iter().all(|&k| k < n_outer))
        .map(|t| {
            let [a, b, c] = tri(mesh, t);
            0.5 * (b - a).cross(&(c - a)).norm()
        })
        .sum();
    let t = g.pillar.params().thickness;
    assert!(volume > 0.0, "signed volume {volume} must be positive");
    let rel = volume / (outer_area * t) - 1.0;
    assert!(
        rel.abs() < 0.01,
        "volume {volume:e} m³ vs area {outer_area:.4} m² x thickness {t}: {:.3}% off",
        rel * 100.0
    );
    // The outer triangles face the head side: their normals agree with
    // the analytic surface normals of their first vertex.
    let outer = g.pillar.outer_vertices();
    for tr in mesh
        .triangles
        .iter()
        .filter(|t| t.iter().all(|&k| k < n_outer))
    {
        let [a, b, c] = tri(mesh, tr);
        let n = (b - a).cross(&(c - a)).normalize();
        let analytic = outer[tr[0] as usize].normal;
        assert!(
            n.dot(&analytic) > 0.95,
            "outer triangle {tr:?} faces {n:?}, the surface normal is {analytic:?}"
        );
    }
}

#[test]
fn sheet_is_1_5_mm_thick() {
    let g = bpillar::generate().unwrap();
    let mesh = g.pillar.mesh();
    let n_outer = g.pillar.stations().len() * g.pillar.profile_len();
    assert_eq!(mesh.vertices.len(), 2 * n_outer);
    assert_eq!(g.pillar.params().thickness, 0.0015);
    for k in 0..n_outer {
        let d = (v(&mesh.vertices[k]) - v(&mesh.vertices[n_outer + k])).norm();
        assert!((d - 0.0015).abs() < 1e-8, "vertex {k}: inner offset {d}");
    }
    // Independent of the construction: from every CL point, a ray into
    // the sheet (against the tool axis) leaves it through the inner
    // surface after 1.5 mm, wherever the point is (flange, fillets, wall,
    // top, curved body).
    for file in [bpillar::CASE1_FILE, bpillar::CASE2_FILE] {
        let req = committed_case(file);
        for (i, (p, a)) in req.points.iter().zip(&req.axes).enumerate().step_by(7) {
            let dir = -v(a);
            let origin = v(p) + dir * 1e-4;
            let hit = mesh
                .triangles
                .iter()
                .filter_map(|t| ray_hit(&origin, &dir, &tri(mesh, t)))
                .fold(f64::INFINITY, f64::min);
            let depth = hit + 1e-4;
            assert!(
                (depth - 0.0015).abs() < 2e-5,
                "{file} point {i}: sheet depth along -axis {depth} m"
            );
        }
    }
}

#[test]
fn committed_files_equal_the_generator_output() {
    let dir = std::env::temp_dir().join(format!("kerf_bpillar_test_{}", std::process::id()));
    let (_, written) = bpillar::write_files(&dir).unwrap();
    for (rel, path) in [bpillar::MESH_FILE, bpillar::CASE1_FILE, bpillar::CASE2_FILE]
        .iter()
        .zip(&written)
    {
        let fresh = std::fs::read(path).unwrap();
        let committed = std::fs::read(repo_root().join(rel)).unwrap_or_default();
        assert!(
            fresh == committed,
            "{rel} is stale: regenerate it with `{}`",
            bpillar::REGENERATE_COMMAND
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn both_requests_validate_with_the_parameters_of_table_1() {
    let c1 = committed_case(bpillar::CASE1_FILE);
    let c2 = committed_case(bpillar::CASE2_FILE);
    let v1 = c1.validate().unwrap();
    let v2 = c2.validate().unwrap();
    for c in [&c1, &c2] {
        assert_eq!(c.mesh, "package://kerf/urdf/meshes/bpillar.obj");
        assert_eq!(c.feed_acceleration, 8.0);
        assert_eq!(c.feed_jerk, 80.0);
        assert_eq!(c.options.control_points, 0);
        assert_eq!(c.options.max_iterations, 10);
    }
    // Case 1: 20 m/min, 10 ms, 5°/5°, 0.8 m, six RTOs.
    assert!((c1.feedrate - 20.0 / 60.0).abs() < 1e-12);
    assert_eq!(c1.sample_period, 0.01);
    assert!((c1.max_lead_angle - 5f64.to_radians()).abs() < 1e-12);
    assert!((c1.max_tilt_angle - 5f64.to_radians()).abs() < 1e-12);
    assert!((v1.sigma - 0.8).abs() < 1e-3, "case 1 path {} m", v1.sigma);
    assert_eq!(c1.options.rto_indices.len(), 6);
    // Case 2: 15 m/min, 4 ms, 15°/10°, about 628 points, ten RTOs.
    assert_eq!(c2.feedrate, 0.25);
    assert_eq!(c2.sample_period, 0.004);
    assert!((c2.max_lead_angle - 15f64.to_radians()).abs() < 1e-12);
    assert!((c2.max_tilt_angle - 10f64.to_radians()).abs() < 1e-12);
    assert!(
        (600..=660).contains(&c2.points.len()),
        "case 2 has {} points",
        c2.points.len()
    );
    assert!(
        (v2.sigma - 0.627).abs() < 2e-3,
        "case 2 path {} m",
        v2.sigma
    );
    assert_eq!(c2.options.rto_indices.len(), 10);
}

#[test]
fn cl_points_lie_on_the_outer_surface_with_outward_axes() {
    let mesh = committed_mesh();
    for file in [bpillar::CASE1_FILE, bpillar::CASE2_FILE] {
        let req = committed_case(file);
        let mut worst: f64 = 0.0;
        let mut worst_angle: f64 = 0.0;
        for (i, (p, a)) in req.points.iter().zip(&req.axes).enumerate() {
            let (d, n) = nearest(&mesh, &v(p));
            worst = worst.max(d);
            // The nearest facet is an outer one facing the tool: within
            // half a fillet chord (6.4° / 2) of the interpolated normal.
            let angle = n.dot(&v(a)).clamp(-1.0, 1.0).acos();
            worst_angle = worst_angle.max(angle);
            assert!(d < 1e-6, "{file} point {i} is {d:e} m off the mesh");
            assert!(
                angle < 3.5f64.to_radians(),
                "{file} point {i}: axis {a:?} is {:.2}° from the facet normal",
                angle.to_degrees()
            );
        }
        println!(
            "{file}: worst distance {worst:e} m, worst axis-facet angle {:.2}°",
            worst_angle.to_degrees()
        );
    }
}

#[test]
fn axes_are_unit_and_points_are_spaced_at_feedrate_times_period() {
    for file in [bpillar::CASE1_FILE, bpillar::CASE2_FILE] {
        let req = committed_case(file);
        let h = req.feedrate * req.sample_period;
        for (i, a) in req.axes.iter().enumerate() {
            assert!((v(a).norm() - 1.0).abs() < 1e-9, "{file} axis {i}");
        }
        for (i, w) in req.points.windows(2).enumerate() {
            let d = (v(&w[1]) - v(&w[0])).norm();
            // A chord across a polyline vertex is shorter than the path
            // step by at most 1 - cos(6.4°/2).
            assert!(
                d <= h * (1.0 + 1e-6) && d >= h * 3.3f64.to_radians().cos(),
                "{file} step {i}: {d} m, expected {h} m"
            );
        }
    }
}

#[test]
fn case2_turns_the_tool_axis_twice_by_77_degrees_between_adjacent_rtos() {
    let c2 = committed_case(bpillar::CASE2_FILE);
    let changes = bpillar::rto_angle_changes(&c2).unwrap();
    let big: Vec<usize> = (0..changes.len())
        .filter(|&k| (changes[k].to_degrees() - 77.0).abs() <= 3.0)
        .collect();
    assert_eq!(big.len(), 2, "changes {changes:?}");
    for (k, c) in changes.iter().enumerate() {
        if !big.contains(&k) {
            assert!(c.to_degrees() < 3.0, "RTO pair {k}: {c} rad");
        }
    }
    // Each turn happens over a short distance (a 0.1 m fillet, 0.134 m).
    let r = &c2.options.rto_indices;
    for &k in &big {
        let d = (r[k + 1] - r[k]) as f64 * c2.feedrate * c2.sample_period;
        assert!((0.12..0.16).contains(&d), "turn {k} spans {d} m");
    }
    // Flange at the start, top at the end: both nominal axes are the
    // workpiece's +z.
    let first = v(&c2.axes[0]);
    let last = v(c2.axes.last().unwrap());
    assert!(first.z > 1.0 - 1e-12 && last.z > 1.0 - 1e-12);
    let depth = BPillarParams::default().foot.depth;
    assert!((c2.points[0][2]).abs() < 1e-9);
    assert!((c2.points.last().unwrap()[2] - depth).abs() < 1e-9);
}

#[test]
fn case1_is_a_near_vertical_side_trim_where_q4_is_ill_defined() {
    let c1 = committed_case(bpillar::CASE1_FILE);
    let p = BPillarParams::default();
    // On the flange, 75 mm from the fillet, parallel to the spine.
    let y = p.body.flange_tangent_y() - 0.075;
    for (i, q) in c1.points.iter().enumerate() {
        assert!((q[1] - y).abs() < 1e-9, "point {i} y = {}", q[1]);
    }
    let x_first = c1.points[0][0];
    let x_last = c1.points.last().unwrap()[0];
    assert!(x_first > p.curved_start() && x_last < p.kink_start());
    // The flange normal turns by a few degrees (gentle spine curvature),
    // never by the kink's 20°.
    let a0 = v(&c1.axes[0]);
    let a1 = v(c1.axes.last().unwrap());
    let total = a0.angle(&a1).to_degrees();
    assert!((3.0..8.0).contains(&total), "total turn {total}°");
    let changes = bpillar::rto_angle_changes(&c1).unwrap();
    assert!(changes.iter().all(|c| c.to_degrees() < 5.0));
    // In the machine frame the axis stays within 4° of the vertical, and
    // q4 = atan2(O_y, O_x) swings by more than 90°.
    let val = c1.validate().unwrap();
    let q4: Vec<f64> = val.axes.iter().map(|o| o.y.atan2(o.x)).collect();
    assert!(val.axes.iter().all(|o| o.z > 4f64.to_radians().cos()));
    let swing = q4.iter().fold(f64::NEG_INFINITY, |m, &x| m.max(x))
        - q4.iter().fold(f64::INFINITY, |m, &x| m.min(x));
    assert!(
        swing.to_degrees() > 90.0,
        "q4 swing {}°",
        swing.to_degrees()
    );
}

#[test]
fn nominal_m_points_are_inside_the_strokes_and_tilts_inside_q5() {
    let machine = LaserMachine::default_machine().unwrap();
    let lim = machine.limits();
    for file in [bpillar::CASE1_FILE, bpillar::CASE2_FILE] {
        let req = committed_case(file);
        let val = req.validate().unwrap();
        let q6 = -0.07;
        for (i, (c, o)) in val.points.iter().zip(&val.axes).enumerate() {
            let m = c - o * q6;
            for k in 0..3 {
                assert!(
                    m[k] > lim[k].min + 0.1 && m[k] < lim[k].max - 0.1,
                    "{file} point {i}: M[{k}] = {} outside [{}, {}] with 0.1 m margin",
                    m[k],
                    lim[k].min,
                    lim[k].max
                );
            }
            assert!(
                o.z > 80f64.to_radians().cos(),
                "{file} point {i}: O_z = {}",
                o.z
            );
        }
    }
}

#[test]
fn invalid_parameters_are_rejected_by_name() {
    let mut p = BPillarParams::default();
    p.foot.top_fillet_radius = f64::NAN;
    let e = BPillar::new(p).unwrap_err().to_string();
    assert!(e.contains("bpillar.foot.top_fillet_radius"), "{e}");
    let mut p = BPillarParams::default();
    p.foot.depth = 0.15; // too shallow for two 0.1 m fillets at 77°
    let e = BPillar::new(p).unwrap_err().to_string();
    assert!(e.contains("bpillar.foot.depth"), "{e}");
    let mut p = BPillarParams::default();
    p.body.flange_fillet_radius = 0.001; // below the thickness
    let e = BPillar::new(p).unwrap_err().to_string();
    assert!(e.contains("flange_fillet_radius"), "{e}");
    let pillar = BPillar::new(BPillarParams::default()).unwrap();
    // A cut plane outside the uniform foot, a path that does not end on
    // the top, a trim line off the flange.
    assert!(pillar.section_path(0.4, 0.1, 0.001, 628).is_err());
    assert!(pillar.section_path(0.125, 0.1, 0.001, 900).is_err());
    assert!(pillar.flange_trim_path(0.5, 0.6, 0.001, 100).is_err());
    assert!(pillar.flange_trim_path(0.075, 0.6, f64::NAN, 100).is_err());
    assert!(pillar
        .flange_trim_path(0.075, 0.6, 0.001, usize::MAX)
        .is_err());
    // Case parameters: NaN roll, absurd length, lead angle of 90°.
    let t = bpillar::TrimCaseParams {
        roll: f64::NAN,
        ..Default::default()
    };
    assert!(bpillar::trim_case(&pillar, &t).is_err());
    let t = bpillar::TrimCaseParams {
        length: 1e9,
        ..Default::default()
    };
    assert!(bpillar::trim_case(&pillar, &t).is_err());
    let c = bpillar::CornerCaseParams {
        max_lead_angle: std::f64::consts::FRAC_PI_2,
        ..Default::default()
    };
    let e = bpillar::corner_case(&pillar, &c).unwrap_err().to_string();
    assert!(e.contains("max_lead_angle"), "{e}");
}

/// The head of `urdf/laser_cutter.urdf` as convex polyhedra, posed by the
/// robot model's forward kinematics, tested against the workpiece
/// triangles with the separating axis theorem (Ericson, Real-Time
/// Collision Detection, section 5.2.1: two convex polyhedra are disjoint
/// iff their projections are disjoint on a face normal of either or on a
/// cross product of an edge of each).
///
/// parry3d 0.31 is not used here: its GJK distance and intersection tests
/// misreport a flat-capped cylinder parallel to a triangle 1 mm away as
/// touching, which is exactly the nozzle over a flange.
mod head {
    use super::*;

    /// Sides of the prisms circumscribing the URDF cylinders (their faces
    /// stand at most r (1/cos(π/n) - 1) = 0.2 % of r outside the cylinder:
    /// "no contact" holds for the real cylinder too).
    const PRISM_SIDES: usize = 32;

    /// A convex polyhedron in its link frame.
    struct Solid {
        vertices: Vec<Vector3<f64>>,
        normals: Vec<Vector3<f64>>,
        edges: Vec<Vector3<f64>>,
    }

    impl Solid {
        fn cuboid(half: Vector3<f64>) -> Self {
            let mut vertices = Vec::new();
            for sx in [-1.0, 1.0] {
                for sy in [-1.0, 1.0] {
                    for sz in [-1.0, 1.0] {
                        vertices.push(Vector3::new(sx * half.x, sy * half.y, sz * half.z));
                    }
                }
            }
            let axes = vec![Vector3::x(), Vector3::y(), Vector3::z()];
            Self {
                vertices,
                normals: axes.clone(),
                edges: axes,
            }
        }

        /// Prism around the z axis circumscribing the cylinder (r, length).
        fn cylinder(r: f64, length: f64) -> Self {
            let n = PRISM_SIDES;
            let step = 2.0 * std::f64::consts::PI / n as f64;
            let rc = r / (step / 2.0).cos();
            let mut vertices = Vec::new();
            let mut normals = vec![Vector3::z()];
            let mut edges = vec![Vector3::z()];
            for k in 0..n {
                let a = step * k as f64;
                for z in [-length / 2.0, length / 2.0] {
                    vertices.push(Vector3::new(rc * a.cos(), rc * a.sin(), z));
                }
                let mid = a + step / 2.0;
                normals.push(Vector3::new(mid.cos(), mid.sin(), 0.0));
                edges.push(Vector3::new(-mid.sin(), mid.cos(), 0.0));
            }
            Self {
                vertices,
                normals,
                edges,
            }
        }

        fn posed(&self, iso: &Isometry3<f64>) -> Posed {
            let vertices: Vec<Vector3<f64>> = self
                .vertices
                .iter()
                .map(|p| iso.transform_point(&(*p).into()).coords)
                .collect();
            let centre = vertices.iter().sum::<Vector3<f64>>() / vertices.len() as f64;
            let radius = vertices
                .iter()
                .map(|p| (p - centre).norm())
                .fold(0.0, f64::max);
            Posed {
                vertices,
                normals: self.normals.iter().map(|n| iso.rotation * n).collect(),
                edges: self.edges.iter().map(|e| iso.rotation * e).collect(),
                centre,
                radius,
            }
        }
    }

    /// A solid in the machine frame with its bounding sphere.
    struct Posed {
        vertices: Vec<Vector3<f64>>,
        normals: Vec<Vector3<f64>>,
        edges: Vec<Vector3<f64>>,
        centre: Vector3<f64>,
        radius: f64,
    }

    fn interval<'a>(
        pts: impl Iterator<Item = &'a Vector3<f64>>,
        axis: &Vector3<f64>,
    ) -> (f64, f64) {
        pts.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            let d = p.dot(axis);
            (lo.min(d), hi.max(d))
        })
    }

    impl Posed {
        /// SAT: true unless some axis separates the solid and the triangle.
        fn touches(&self, t: &[Vector3<f64>; 3]) -> bool {
            let te = [t[1] - t[0], t[2] - t[1], t[0] - t[2]];
            let mut axes: Vec<Vector3<f64>> = self.normals.clone();
            axes.push(te[0].cross(&te[1]));
            for e in &self.edges {
                for f in &te {
                    axes.push(e.cross(f));
                }
            }
            !axes.iter().any(|axis| {
                let len = axis.norm();
                if len < 1e-12 {
                    return false;
                }
                let axis = axis / len;
                let (a0, a1) = interval(self.vertices.iter(), &axis);
                let (b0, b1) = interval(t.iter(), &axis);
                a1 < b0 || b1 < a0
            })
        }
    }

    /// The separating-axis test itself: a 20 mm box and a 25 mm-radius
    /// prism against a triangle 1 mm below, touching and 1 mm into it.
    #[test]
    fn separating_axis_test_resolves_a_1_mm_gap() {
        let t = [
            Vector3::new(-0.1, -0.1, 0.0),
            Vector3::new(0.2, -0.1, 0.0),
            Vector3::new(-0.1, 0.2, 0.0),
        ];
        let tilt = UnitQuaternion::from_euler_angles(0.0, 0.3, 0.2);
        for solid in [
            Solid::cuboid(Vector3::new(0.01, 0.01, 0.01)),
            Solid::cylinder(0.025, 0.02),
        ] {
            // Lowest point of the tilted solid, relative to its centre.
            let low = solid
                .vertices
                .iter()
                .map(|p| (tilt * p).z)
                .fold(f64::INFINITY, f64::min);
            for (gap, expect) in [(1e-3, false), (0.0, true), (-1e-3, true)] {
                let iso = Isometry3::from_parts(Translation3::new(0.0, 0.0, gap - low), tilt);
                assert_eq!(solid.posed(&iso).touches(&t), expect, "gap {gap}");
            }
            // Beside the triangle (beyond its hypotenuse) nothing touches.
            let iso = Isometry3::from_parts(Translation3::new(0.2, 0.2, -low - 0.01), tilt);
            assert!(!solid.posed(&iso).touches(&t));
        }
    }

    pub struct Scene {
        machine: LaserMachine,
        parts: Vec<(String, Isometry3<f64>, Solid)>,
        /// Workpiece triangles in the machine frame, with bounding spheres.
        triangles: Vec<([Vector3<f64>; 3], Vector3<f64>, f64)>,
    }

    impl Scene {
        pub fn new(mesh: &MeshData, placement: &Isometry3<f64>) -> Self {
            let machine = LaserMachine::default_machine().unwrap();
            let mut parts = Vec::new();
            for link in &machine.robot().urdf().links {
                for c in &link.collision {
                    let o = &c.origin;
                    let origin = Isometry3::from_parts(
                        Translation3::new(o.xyz[0], o.xyz[1], o.xyz[2]),
                        UnitQuaternion::from_euler_angles(o.rpy[0], o.rpy[1], o.rpy[2]),
                    );
                    let solid = match &c.geometry {
                        urdf_rs::Geometry::Box { size } => {
                            Solid::cuboid(Vector3::new(size[0], size[1], size[2]) / 2.0)
                        }
                        urdf_rs::Geometry::Cylinder { radius, length } => {
                            Solid::cylinder(*radius, *length)
                        }
                        other => panic!("unexpected collision geometry {other:?}"),
                    };
                    parts.push((link.name.clone(), origin, solid));
                }
            }
            let triangles = mesh
                .triangles
                .iter()
                .map(|t| {
                    let abc = tri(mesh, t).map(|p| placement.transform_point(&p.into()).coords);
                    let centre = (abc[0] + abc[1] + abc[2]) / 3.0;
                    let radius = abc.iter().map(|p| (p - centre).norm()).fold(0.0, f64::max);
                    (abc, centre, radius)
                })
                .collect();
            Self {
                machine,
                parts,
                triangles,
            }
        }

        /// Links touching the workpiece with the tool at CL point `c`
        /// (machine frame), rotary axes (q4, q5) and standoff q6.
        pub fn contacts(&self, c: &Vector3<f64>, q4: f64, q5: f64, q6: f64) -> Vec<String> {
            let o = Vector3::new(q4.cos() * q5.sin(), q4.sin() * q5.sin(), q5.cos());
            let m = c - o * q6;
            let q = [m.x, m.y, m.z, q4, q5, q6];
            let poses: HashMap<String, Isometry3<f64>> = self
                .machine
                .robot()
                .link_poses(&q)
                .unwrap()
                .into_iter()
                .collect();
            let mut hits: Vec<String> = Vec::new();
            for (link, origin, solid) in &self.parts {
                if hits.contains(link) {
                    continue;
                }
                let posed = solid.posed(&(poses[link] * origin));
                let touching = self.triangles.iter().any(|(t, centre, radius)| {
                    (centre - posed.centre).norm() <= radius + posed.radius && posed.touches(t)
                });
                if touching {
                    hits.push(link.clone());
                }
            }
            hits
        }
    }
}

/// Case 1 (seed 001 Figure 9): near the wall, q4 decides. With the fork
/// arms along the cut the head clears the part at every CL point; turned
/// across the cut they hit the wall; the QI orientation (q4 from atan2 of
/// the nominal axis) hits it at the ends of the path.
#[test]
fn case1_head_clears_the_wall_only_with_the_forks_along_the_cut() {
    let req = committed_case(bpillar::CASE1_FILE);
    let val = req.validate().unwrap();
    let scene = head::Scene::new(&committed_mesh(), &val.workpiece_pose);
    let q6 = -0.07;
    let lead = req.max_lead_angle;
    for (i, (c, o)) in val.points.iter().zip(&val.axes).enumerate() {
        // Forks along the cut (machine x): q4 = 90°, O in the y-z plane.
        let along = Vector3::new(0.0, o.y, o.z).normalize();
        assert!(
            along.angle(o) < lead,
            "point {i}: not within the lead angle"
        );
        let hits = scene.contacts(c, std::f64::consts::FRAC_PI_2, along.y.atan2(along.z), q6);
        assert!(
            hits.is_empty(),
            "point {i}: forks along the cut touch {hits:?}"
        );
        // Forks across the cut, towards the wall: q4 = 0, O in the x-z plane.
        let across = Vector3::new(o.x, 0.0, o.z).normalize();
        assert!(across.angle(o) < lead);
        let hits = scene.contacts(c, 0.0, across.x.atan2(across.z), q6);
        assert!(
            hits.iter().any(|l| l == "c_axis"),
            "point {i}: forks across the cut should hit the wall, contacts {hits:?}"
        );
    }
    let qi = |i: usize| {
        let o = val.axes[i];
        scene.contacts(
            &val.points[i],
            o.y.atan2(o.x),
            o.z.clamp(-1.0, 1.0).acos(),
            q6,
        )
    };
    let n = val.points.len();
    assert!(
        !qi(0).is_empty(),
        "QI orientation at the start should collide"
    );
    assert!(
        !qi(n - 1).is_empty(),
        "QI orientation at the end should collide"
    );
    assert!(
        qi(n / 2).is_empty(),
        "QI orientation in the middle: {:?}",
        qi(n / 2)
    );
}

/// Case 2 is feasible for this head: at every CL point the nominal tool
/// axis has a collision-free standoff q6 in [-0.1, -0.07]. (The fork arms
/// hang 0.06 m below M, so inclined parts of the path need q6 below the
/// default -0.07: the redundant axis is what makes the corner cuttable.)
#[test]
fn case2_nominal_axes_are_collision_free_with_some_standoff() {
    let req = committed_case(bpillar::CASE2_FILE);
    let val = req.validate().unwrap();
    let scene = head::Scene::new(&committed_mesh(), &val.workpiece_pose);
    // q4 of the inclined part (constant: the cut is planar); the vertical
    // flange and top keep it.
    let wall = val
        .axes
        .iter()
        .find(|o| o.z < 0.5)
        .copied()
        .expect("case 2 reaches the wall");
    let q4 = wall.y.atan2(wall.x);
    let mut retracted = 0;
    for (i, (c, o)) in val.points.iter().zip(&val.axes).enumerate() {
        let xy = o.xy().norm();
        let q4_here = if xy > 1e-9 { o.y.atan2(o.x) } else { q4 };
        assert!(
            (q4_here - q4).abs() < 1e-6,
            "point {i}: the axis leaves the cut plane"
        );
        let q5 = xy.atan2(o.z);
        let free = [-0.07, -0.08, -0.09, -0.1]
            .into_iter()
            .find(|&q6| scene.contacts(c, q4, q5, q6).is_empty());
        match free {
            Some(q6) => retracted += usize::from(q6 < -0.07),
            None => panic!(
                "point {i}: the nominal axis collides at every standoff: {:?}",
                scene.contacts(c, q4, q5, -0.1)
            ),
        }
    }
    println!(
        "case 2: {retracted} of {} points need q6 < -0.07",
        val.points.len()
    );
}
