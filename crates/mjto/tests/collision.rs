//! Collision checking of the laser head of `urdf/laser_cutter.urdf` against
//! real meshes (parry3d, no mocks).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::f64::consts::FRAC_PI_2;

use kerf_mjto::collision::{CollisionWorld, HeadLink, HeadModel, Primitive};
use kerf_mjto::mesh::MeshData;
use kerf_mjto::{LaserMachine, PlanError};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

/// The CL point of the tests: on the top surface of the sheet.
const C: [f64; 3] = [0.8, 0.7, 0.3];

fn head() -> HeadModel {
    let machine = LaserMachine::default_machine().unwrap();
    HeadModel::from_urdf(machine.robot().urdf()).unwrap()
}

/// A 2 mm sheet, 0.6 m x 0.6 m, whose top face is z = C.z.
fn sheet() -> MeshData {
    MeshData::cuboid(
        [C[0] - 0.3, C[1] - 0.3, C[2] - 0.002],
        [C[0] + 0.3, C[1] + 0.3, C[2]],
    )
}

/// Vertical tool axis (q4 = q5 = 0) with the CL point at `c` and standoff
/// q6: M = C - q6 * z (seed 001 eq. 3).
fn vertical(c: [f64; 3], q4: f64, q6: f64) -> [f64; 6] {
    [c[0], c[1], c[2] - q6, q4, 0.0, q6]
}

fn world(mesh: &MeshData, clearance: f64) -> CollisionWorld {
    CollisionWorld::new(head(), mesh, &Isometry3::identity(), clearance).unwrap()
}

#[test]
fn head_model_has_the_urdf_primitives() {
    let machine = LaserMachine::default_machine().unwrap();
    let h = HeadModel::from_urdf(machine.robot().urdf()).unwrap();
    assert_eq!(h.links(), vec!["nozzle", "a_axis", "c_axis", "z_ram"]);
    // One primitive per <collision> element of those links.
    let urdf = machine.robot().urdf();
    let count = |name: &str| {
        urdf.links
            .iter()
            .find(|l| l.name == name)
            .map_or(0, |l| l.collision.len())
    };
    for link in HeadLink::ALL {
        let n = h.shapes().iter().filter(|s| s.link == link).count();
        assert_eq!(n, count(link.name()), "{link:?}");
    }
    assert_eq!(count("c_axis"), 3, "motor housing and two fork arms");
    let housing = h
        .shapes()
        .iter()
        .find(|s| s.link == HeadLink::AAxis)
        .unwrap();
    assert_eq!(
        housing.primitive,
        Primitive::Cylinder {
            radius: 0.045,
            half_length: 0.085
        }
    );
    // rpy = (pi/2, 0, 0): the cylinder's z axis becomes the link's -y axis.
    let axis = housing.origin.rotation * Vector3::z();
    assert!(
        (axis - Vector3::new(0.0, -1.0, 0.0)).norm() < 1e-12,
        "{axis}"
    );
}

#[test]
fn specialised_kinematics_equals_kerf_robot() {
    let machine = LaserMachine::default_machine().unwrap();
    let robot = machine.robot();
    let limits = machine.limits();
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = || {
        // xorshift64*: deterministic pseudo-random numbers in [0, 1).
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        (state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..200 {
        let q: [f64; 6] =
            std::array::from_fn(|j| limits[j].min + (limits[j].max - limits[j].min) * next());
        let reference = robot.link_poses(&q).unwrap();
        for link in HeadLink::ALL {
            let (_, expected) = reference
                .iter()
                .find(|(name, _)| name == link.name())
                .unwrap();
            let got = link.pose(&q);
            let dt = (got.translation.vector - expected.translation.vector).norm();
            let dr = got.rotation.angle_to(&expected.rotation);
            assert!(
                dt < 1e-12 && dr < 1e-12,
                "{link:?} at {q:?}: {dt} m, {dr} rad"
            );
        }
        // tool0 = C of eq. 2.
        let (_, tool0) = reference.iter().find(|(n, _)| n == "tool0").unwrap();
        let o = Vector3::new(q[3].cos() * q[4].sin(), q[3].sin() * q[4].sin(), q[4].cos());
        let c = Vector3::new(q[0], q[1], q[2]) + q[5] * o;
        assert!((tool0.translation.vector - c).norm() < 1e-12);
        assert!((tool0.rotation * Vector3::z() - o).norm() < 1e-12);
    }
}

#[test]
fn vertical_head_on_a_sheet() {
    let w = world(&sheet(), 0.0);
    // q6 = -0.08: tip 1 mm above the surface, fork arms 20 mm, housing
    // 35 mm: free.
    assert!(w.is_free(&vertical(C, 0.0, -0.08)));
    assert!(w.colliding_links(&vertical(C, 0.0, -0.08)).is_empty());
    // q6 = -0.02: the tilt housing (radius 45 mm around M, 20 mm above C)
    // and the fork arms (60 mm below M) reach into the sheet; the nozzle
    // (above C) does not.
    let links = w.colliding_links(&vertical(C, 0.0, -0.02));
    assert_eq!(links, vec!["a_axis", "c_axis"]);
    assert!(!w.is_free(&vertical(C, 0.0, -0.02)));
    // q6 = -0.05: the housing clears by 5 mm, the fork arms reach 10 mm
    // below C.
    assert_eq!(w.colliding_links(&vertical(C, 0.0, -0.05)), vec!["c_axis"]);
    // The free/colliding boundary of the fork arms is at q6 = -0.06.
    assert!(w.is_free(&vertical(C, 0.0, -0.0605)));
    assert!(!w.is_free(&vertical(C, 0.0, -0.0595)));
    // One query per colliding_links / is_free call above.
    assert_eq!(w.queries(), 7);
}

#[test]
fn nozzle_below_the_surface_collides() {
    let w = world(&sheet(), 0.0);
    // C 5 mm below the top face of the 2 mm sheet: the nozzle tip, from
    // 1 mm to 30 mm above C, crosses both faces; the fork arms end 15 mm
    // above the sheet.
    let c = [C[0], C[1], C[2] - 0.005];
    assert_eq!(w.colliding_links(&vertical(c, 0.0, -0.08)), vec!["nozzle"]);
}

#[test]
fn clearance_is_a_distance_threshold() {
    // The nozzle tip is 1 mm above the surface at q6 = -0.08.
    let q = vertical(C, 0.0, -0.08);
    assert!(world(&sheet(), 0.0005).is_free(&q));
    assert_eq!(world(&sheet(), 0.0015).colliding_links(&q), vec!["nozzle"]);
    assert!(matches!(
        CollisionWorld::new(head(), &sheet(), &Isometry3::identity(), -0.001),
        Err(PlanError::InvalidRequest { .. })
    ));
    assert!(CollisionWorld::new(head(), &sheet(), &Isometry3::identity(), f64::NAN).is_err());
}

#[test]
fn wall_beside_the_path_depends_on_q4() {
    // A vertical wall 70 mm beside C in +x, 150 mm tall, 50 mm thick.
    let mut mesh = sheet();
    mesh.append(&MeshData::cuboid(
        [C[0] + 0.07, C[1] - 0.3, C[2]],
        [C[0] + 0.12, C[1] + 0.3, C[2] + 0.15],
    ))
    .unwrap();
    let w = world(&mesh, 0.0);
    // q4 = 0: fork arms at y = +-0.10 span x in [-0.05, 0.05]; the housing
    // spans x in [-0.045, 0.045]; the nozzle body radius 0.025: free.
    assert!(w.is_free(&vertical(C, 0.0, -0.08)));
    // q4 = pi/2: one fork arm turns to x in [0.085, 0.115], inside the
    // wall, through its top face; the housing axis turns along x and
    // reaches x = 0.085 through the wall's near face at x = 0.07.
    assert_eq!(
        w.colliding_links(&vertical(C, FRAC_PI_2, -0.08)),
        vec!["a_axis", "c_axis"]
    );
    // q4 = pi: symmetric to q4 = 0.
    assert!(w.is_free(&vertical(C, std::f64::consts::PI, -0.08)));
}

#[test]
fn tilting_towards_a_wall_collides() {
    // The wall alone (on the sheet, a nozzle tilted by 0.5 rad digs its
    // tip into the surface, see below).
    let wall = MeshData::cuboid(
        [C[0] + 0.07, C[1] - 0.3, C[2]],
        [C[0] + 0.12, C[1] + 0.3, C[2] + 0.15],
    );
    let w = world(&wall, 0.0);
    let q6 = -0.08;
    let tilted = |q5: f64| {
        // O = (sin q5, 0, cos q5) for q4 = 0; M = C - q6 O (eq. 3).
        let m = Vector3::from(C) - q6 * Vector3::new(q5.sin(), 0.0, q5.cos());
        [m.x, m.y, m.z, 0.0, q5, q6]
    };
    // q5 = 0.5 moves M 38 mm towards the wall: the housing (radius 45 mm)
    // reaches x = 83 mm > 70 mm.
    assert!(w.colliding_links(&tilted(0.5)).contains(&"a_axis"));
    assert!(w.is_free(&tilted(-0.5)));
    assert!(w.is_free(&tilted(0.0)));
    // On the sheet, the nozzle tip (radius 2.5 mm, 1 mm above C) limits
    // the lean to atan(1 / 2.5) = 0.3805 rad (the URDF's 21 deg).
    let s = world(&sheet(), 0.0);
    assert!(s.is_free(&tilted(0.36)));
    assert_eq!(s.colliding_links(&tilted(0.40)), vec!["nozzle"]);
}

#[test]
fn workpiece_pose_places_the_mesh() {
    // The sheet defined around the origin, moved to C by the pose.
    let local = MeshData::cuboid([-0.3, -0.3, -0.002], [0.3, 0.3, 0.0]);
    let pose = Isometry3::from_parts(
        Translation3::new(C[0], C[1], C[2]),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.3),
    );
    let w = CollisionWorld::new(head(), &local, &pose, 0.0).unwrap();
    assert!(w.is_free(&vertical(C, 0.0, -0.08)));
    assert!(!w.is_free(&vertical(C, 0.0, -0.02)));
    // Far from the sheet (0.5 m away in x) nothing collides at any q6.
    let away = [C[0] + 0.5, C[1], C[2]];
    assert!(w.is_free(&vertical(away, 0.0, -0.02)));
    assert_eq!(w.triangles(), 12);
}

#[test]
fn non_finite_configurations_are_never_free() {
    let w = world(&sheet(), 0.0);
    let mut q = vertical(C, 0.0, -0.08);
    q[3] = f64::NAN;
    assert!(!w.is_free(&q));
    assert_eq!(w.colliding_links(&q).len(), 4);
}

#[test]
fn world_is_sync_and_shared_between_threads() {
    fn assert_sync<T: Sync + Send>(_: &T) {}
    let w = world(&sheet(), 0.0);
    assert_sync(&w);
    let results: Vec<bool> = std::thread::scope(|s| {
        let hs: Vec<_> = [-0.08, -0.02]
            .into_iter()
            .map(|q6| {
                let w = &w;
                s.spawn(move || (0..50).all(|_| w.is_free(&vertical(C, 0.0, q6))))
            })
            .collect();
        hs.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert_eq!(results, vec![true, false]);
    // 50 free queries, and the colliding thread stops at its first false.
    assert_eq!(w.queries(), 51);
}

#[test]
fn unsupported_head_geometry_is_an_error() {
    let path = LaserMachine::urdf_dir().join("laser_cutter.urdf");
    let xml = std::fs::read_to_string(path).unwrap();
    // Mesh geometry in the first <collision> of the nozzle.
    let nozzle = xml.find("<link name=\"nozzle\">").unwrap();
    let start = nozzle + xml[nozzle..].find("<collision>").unwrap();
    let cyl = start + xml[start..].find("<cylinder").unwrap();
    let end = cyl + xml[cyl..].find("/>").unwrap() + 2;
    let with_mesh = format!(
        "{}<mesh filename=\"package://kerf/urdf/meshes/nozzle.stl\"/>{}",
        &xml[..cyl],
        &xml[end..]
    );
    let robot = urdf_rs::read_from_string(&with_mesh).unwrap();
    let err = HeadModel::from_urdf(&robot).unwrap_err().to_string();
    assert!(err.contains("not supported"), "{err}");
    // A joint origin that the specialised kinematics would ignore.
    let moved = xml.replacen(
        "<child link=\"c_axis\"/>\n    <origin xyz=\"0 0 0\"",
        "<child link=\"c_axis\"/>\n    <origin xyz=\"0 0 0.1\"",
        1,
    );
    assert_ne!(moved, xml);
    let robot = urdf_rs::read_from_string(&moved).unwrap();
    let err = HeadModel::from_urdf(&robot).unwrap_err().to_string();
    assert!(err.contains("joint q4"), "{err}");
}

/// Regression: the nozzle tip 0.86 mm above the flange of the committed
/// case 1 part, tilted 3° (a configuration of a real plan). parry3d's f32
/// build reported a contact here (its cylinder–triangle GJK fails once the
/// triangle is a centimetre off the query origin); the f64 build used by
/// `CollisionWorld` does not.
#[test]
fn nozzle_just_above_the_case1_flange_is_free() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(dir.join("cases/case1.yaml")).unwrap();
    let request = kerf_mjto::CutRequest::from_yaml(&text).unwrap();
    let mesh = kerf_mjto::mesh::load(&request.mesh).unwrap();
    let machine = kerf_mjto::LaserMachine::default_machine().unwrap();
    let head = kerf_mjto::collision::HeadModel::from_urdf(machine.robot().urdf()).unwrap();
    let pose = request.workpiece_pose.isometry().unwrap();
    let q = [
        0.4897333565133044,
        0.6939036470371193,
        1.0252331286216727,
        -1.8632834220568073,
        0.0743563372540371,
        -0.09611768730387765,
    ];
    let free = kerf_mjto::collision::CollisionWorld::new(head.clone(), &mesh, &pose, 0.0).unwrap();
    assert!(free.is_free(&q), "{:?}", free.colliding_links(&q));
    // The same pose with 1 mm clearance required touches: the gap is below 1 mm.
    let tight = kerf_mjto::collision::CollisionWorld::new(head, &mesh, &pose, 0.001).unwrap();
    assert_eq!(tight.colliding_links(&q), ["nozzle"]);
}
