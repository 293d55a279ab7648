//! The exact head-to-workpiece distance ([`CollisionWorld::distance`],
//! [`CollisionWorld::distance_up_to`]) and the per-joint Lipschitz bounds
//! ([`HeadModel::lipschitz`]) on the shipped machine and B-pillar mesh
//! (`package://kerf/urdf/meshes/bpillar.obj`, 4 964 triangles): against a
//! brute force over every shape-triangle pair built independently from the
//! public head model, against the boolean check at the clearance, and the
//! Lipschitz bound against finite differences of sampled head points.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use std::f64::consts::{FRAC_PI_2, TAU};
use std::time::Instant;

use common::{case, Rng};
use kerf_mjto::collision::{CollisionWorld, HeadLink, HeadModel, Primitive};
use kerf_mjto::mesh::{MeshCache, MeshData};
use kerf_mjto::LaserMachine;
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use parry3d_f64::math::{Pose, Rotation, Vector};
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::{Ball, Cuboid, Cylinder, Shape, Triangle};

fn head() -> HeadModel {
    let machine = LaserMachine::default_machine().unwrap();
    HeadModel::from_urdf(machine.robot().urdf()).unwrap()
}

/// The B-pillar of case 1 placed as the request places it, its CL points
/// and tool axes (machine frame).
struct Part {
    mesh: MeshData,
    pose: Isometry3<f64>,
    points: Vec<Vector3<f64>>,
    axes: Vec<Vector3<f64>>,
}

fn part() -> Part {
    let request = case("case1");
    assert!(request.mesh.ends_with("bpillar.obj"), "{}", request.mesh);
    let v = request.validate().unwrap();
    Part {
        mesh: (*MeshCache::new().get(&request.mesh).unwrap()).clone(),
        pose: v.workpiece_pose,
        points: v.points,
        axes: v.axes,
    }
}

fn world(p: &Part, clearance: f64) -> CollisionWorld {
    CollisionWorld::new(head(), &p.mesh, &p.pose, clearance).unwrap()
}

/// A configuration near the part: the CL point on or off a path point
/// (along the tool axis from 5 mm inside to 5 cm outside, 2 cm sideways),
/// the tool axis leaning up to 0.43 rad off the path's, q6 over its range
/// (seed 001 eq. 2 and 3: M = C - q6 O). `far` lifts the head 0.3 m.
fn near(p: &Part, rng: &mut Rng, far: bool) -> [f64; 6] {
    let i = (rng.next() * p.points.len() as f64) as usize % p.points.len();
    let axis = p.axes[i];
    let lean = Vector3::new(rng.signed(), rng.signed(), rng.signed()) * 0.25;
    let o = (UnitQuaternion::from_scaled_axis(lean - axis * axis.dot(&lean)) * axis).normalize();
    let side = Vector3::new(rng.signed(), rng.signed(), rng.signed()) * 0.02;
    let lift = if far { 0.3 } else { rng.range(-0.005, 0.05) };
    let c = p.points[i] + side + o * lift;
    // Mostly with the nozzle out of the tilt housing (q6 < -0.045; above it
    // the housing reaches the CL point, urdf/laser_cutter.urdf).
    let q6 = if rng.next() < 0.8 {
        rng.range(-0.1, -0.045)
    } else {
        rng.range(-0.1, 0.02)
    };
    let m = c - o * q6;
    let q4 = o.y.atan2(o.x);
    let q5 = o.z.clamp(-1.0, 1.0).acos();
    [m.x, m.y, m.z, q4, q5, q6]
}

/// The head's shapes at `q` as parry shapes in the machine frame, built
/// from the public model (parry cylinders are along y: the URDF z-cylinder
/// turned by Rx(pi/2)).
fn placed_shapes(h: &HeadModel, q: &[f64; 6]) -> Vec<(&'static str, Box<dyn Shape>, Pose)> {
    let z_to_y = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2);
    h.shapes()
        .iter()
        .map(|s| {
            let (shape, fix): (Box<dyn Shape>, _) = match s.primitive {
                Primitive::Box { half_extents: e } => (
                    Box::new(Cuboid::new(Vector::new(e[0], e[1], e[2]))),
                    UnitQuaternion::identity(),
                ),
                Primitive::Cylinder {
                    radius,
                    half_length,
                } => (Box::new(Cylinder::new(half_length, radius)), z_to_y),
                Primitive::Sphere { radius } => {
                    (Box::new(Ball::new(radius)), UnitQuaternion::identity())
                }
            };
            let iso =
                s.link.pose(q) * s.origin * Isometry3::from_parts(Translation3::identity(), fix);
            let t = iso.translation.vector;
            let r = iso.rotation.quaternion();
            let pose = Pose::from_parts(
                Vector::new(t.x, t.y, t.z),
                Rotation::from_xyzw(r.i, r.j, r.k, r.w),
            );
            (s.link.name(), shape, pose)
        })
        .collect()
}

/// The workpiece triangles in the machine frame.
fn triangles(p: &Part) -> Vec<Triangle> {
    let v: Vec<Vector> = p
        .mesh
        .vertices
        .iter()
        .map(|v| {
            let w = p.pose * Point3::new(v[0], v[1], v[2]);
            Vector::new(w.x, w.y, w.z)
        })
        .collect();
    p.mesh
        .triangles
        .iter()
        .map(|t| Triangle::new(v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]))
        .collect()
}

/// The brute force: parry's distance of every shape to every triangle.
fn brute_force(h: &HeadModel, tris: &[Triangle], q: &[f64; 6]) -> (f64, &'static str) {
    let mut best = (f64::INFINITY, "");
    for (link, shape, pose) in placed_shapes(h, q) {
        for t in tris {
            let d = parry3d_f64::query::distance(&Pose::IDENTITY, t, &pose, shape.as_ref())
                .unwrap()
                .distance;
            if d < best.0 {
                best = (d, link);
            }
        }
    }
    best
}

#[test]
fn distance_equals_the_brute_force_over_every_triangle() {
    let p = part();
    let tris = triangles(&p);
    assert_eq!(tris.len(), 4964);
    let w = world(&p, 0.002);
    let h = head();
    let mut rng = Rng(0x5eed_d157);
    let (mut zero, mut positive) = (0, 0);
    for k in 0..24 {
        // Clear configurations near the part (the fork arms meet the hat's
        // wall at most C-axis angles: rejection-sampled), some colliding,
        // some far.
        let q = match k % 6 {
            0..=3 => loop {
                let q = near(&p, &mut rng, false);
                if w.is_free(&q) {
                    break q;
                }
            },
            4 => near(&p, &mut rng, false),
            _ => near(&p, &mut rng, true),
        };
        let d = w.distance(&q).unwrap();
        let (reference, link) = brute_force(&h, &tris, &q);
        assert!(
            (d.distance - reference).abs() <= 1e-9,
            "q = {q:?}: {d:?} vs brute force {reference} ({link})"
        );
        if reference > 1e-9 {
            positive += 1;
            assert_eq!(d.link, link, "q = {q:?}");
            // The points realise the distance, the head point is on the
            // nearest link's shapes, the workpiece point on the mesh.
            let gap = (d.head_point - d.workpiece_point).norm();
            assert!((gap - d.distance).abs() <= 1e-7, "{gap} vs {d:?}");
            let on_link = placed_shapes(&h, &q)
                .into_iter()
                .filter(|(l, _, _)| *l == d.link)
                .map(|(_, s, pose)| {
                    let x = d.head_point;
                    s.distance_to_point(&pose, Vector::new(x.x, x.y, x.z), true)
                })
                .fold(f64::INFINITY, f64::min);
            assert!(on_link <= 1e-7, "head point {on_link} m off {}", d.link);
            let x = d.workpiece_point;
            let off_mesh = tris
                .iter()
                .map(|t| t.distance_to_point(&Pose::IDENTITY, Vector::new(x.x, x.y, x.z), true))
                .fold(f64::INFINITY, f64::min);
            assert!(
                off_mesh <= 1e-7,
                "workpiece point {off_mesh} m off the mesh"
            );
        } else {
            zero += 1;
            assert_eq!(d.distance, 0.0, "q = {q:?}");
        }
    }
    assert!(positive >= 20, "{positive} clear configurations");
    assert!(zero >= 1, "{zero} intersecting configurations");
}

#[test]
fn distance_agrees_with_the_boolean_check_at_the_clearance() {
    let p = part();
    for clearance in [0.0, 0.003] {
        let w = world(&p, clearance);
        let mut rng = Rng(77 + clearance.to_bits());
        let (mut inside, mut outside) = (0, 0);
        for _ in 0..300 {
            let q = near(&p, &mut rng, false);
            let d = w.distance(&q).unwrap().distance;
            let colliding = !w.colliding_links(&q).is_empty();
            if d < clearance - 1e-9 || (clearance == 0.0 && d == 0.0) {
                assert!(
                    colliding,
                    "clearance {clearance}: d = {d} but free at {q:?}"
                );
                inside += 1;
            } else if d > clearance + 1e-9 {
                assert!(
                    !colliding,
                    "clearance {clearance}: d = {d} but colliding at {q:?}"
                );
                outside += 1;
            }
            // The cut-off variant: exact below the cut-off, None above.
            for cutoff in [clearance, 0.01, 0.05] {
                match w.distance_up_to(&q, cutoff).unwrap() {
                    Some(e) => {
                        assert!(e.distance < cutoff, "{e:?} not below {cutoff}");
                        assert!((e.distance - d).abs() <= 1e-12, "{e:?} vs {d}");
                    }
                    None => assert!(d >= cutoff - 1e-12, "None below the cut-off: {d}"),
                }
            }
        }
        assert!(
            inside >= 30 && outside >= 30,
            "{inside} inside, {outside} outside"
        );
    }
}

/// Points on the surface of each shape at `q` (machine frame), by link.
fn surface_points(h: &HeadModel, q: &[f64; 6]) -> Vec<(HeadLink, Vector3<f64>)> {
    let mut out = Vec::new();
    for s in h.shapes() {
        let place = s.link.pose(q) * s.origin;
        let mut local = Vec::new();
        match s.primitive {
            Primitive::Box { half_extents: e } => {
                for k in 0..27 {
                    let c = [
                        (k % 3) as f64 - 1.0,
                        ((k / 3) % 3) as f64 - 1.0,
                        (k / 9) as f64 - 1.0,
                    ];
                    local.push(Point3::new(c[0] * e[0], c[1] * e[1], c[2] * e[2]));
                }
            }
            Primitive::Cylinder {
                radius,
                half_length,
            } => {
                for k in 0..24 {
                    let a = TAU * k as f64 / 24.0;
                    for z in [-half_length, 0.0, half_length] {
                        local.push(Point3::new(radius * a.cos(), radius * a.sin(), z));
                    }
                }
            }
            Primitive::Sphere { radius } => {
                for d in [Vector3::x(), Vector3::y(), Vector3::z()] {
                    local.push(Point3::from(d * radius));
                    local.push(Point3::from(-d * radius));
                }
            }
        }
        out.extend(local.into_iter().map(|x| (s.link, (place * x).coords)));
    }
    out
}

#[test]
fn lipschitz_bounds_every_sampled_point_motion() {
    let h = head();
    let l = h.lipschitz();
    assert_eq!(h.standoff_range(), [-0.1, 0.02]);
    assert_eq!([l[0], l[1], l[2], l[5]], [1.0; 4], "prismatic joints");
    // The fork arm's outer corner (0.05, 0.115) about the C axis; the nozzle
    // tip's rim (0.0025, 0.099 below M at q6 = -0.1) about the A axis.
    assert!((l[3] - 0.05f64.hypot(0.115)).abs() < 1e-12, "{l:?}");
    assert!(
        l[4] >= 0.0025f64.hypot(0.099) && l[4] < 0.0025f64.hypot(0.099) + 1e-6,
        "{l:?}"
    );

    let mut rng = Rng(2718);
    let mut worst = [0.0f64; 6];
    for k in 0..400 {
        let q6 = if k % 10 == 0 {
            -0.1
        } else {
            rng.range(-0.1, 0.02)
        };
        let q = [
            rng.range(0.0, 1.6),
            rng.range(0.0, 1.4),
            rng.range(0.0, 3.0),
            rng.range(-TAU, TAU),
            rng.range(-FRAC_PI_2, FRAC_PI_2),
            q6,
        ];
        let before = surface_points(&h, &q);
        for j in 0..6 {
            let dq = rng.range(1e-4, 1e-2) * if rng.next() < 0.5 { -1.0 } else { 1.0 };
            let mut b = q;
            b[j] += dq;
            // Keep q6 in the range the bound holds over.
            if j == 5 && !(-0.1..=0.02).contains(&b[5]) {
                b[5] = q[5] - dq;
            }
            for ((link, x), (_, y)) in before.iter().zip(surface_points(&h, &b)) {
                let ratio = (y - x).norm() / dq.abs();
                assert!(
                    ratio <= l[j] * (1.0 + 1e-9),
                    "joint {}: {link:?} point moved {ratio} m per unit > {}",
                    j + 1,
                    l[j]
                );
                worst[j] = worst[j].max(ratio);
            }
        }
    }
    // The bounds are nearly attained (not vacuous).
    for j in 0..6 {
        assert!(
            worst[j] >= 0.98 * l[j],
            "joint {}: {} vs {}",
            j + 1,
            worst[j],
            l[j]
        );
    }
    // A wider standoff range only widens the rotary bounds; a non-finite
    // one voids them.
    let wide = h.lipschitz_within([-0.3, 0.1]);
    assert!(wide[3] > l[3] && wide[4] > l[4], "{wide:?}");
    let void = h.lipschitz_within([f64::NAN, 0.0]);
    assert!(void[3].is_infinite() && void[4].is_infinite(), "{void:?}");
}

#[test]
fn non_finite_configurations_are_errors_not_panics() {
    let p = part();
    let w = world(&p, 0.001);
    let mut rng = Rng(5);
    let good = near(&p, &mut rng, false);
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        for j in 0..6 {
            let mut q = good;
            q[j] = bad;
            let err = w.distance(&q).unwrap_err().to_string();
            assert!(err.contains(&format!("q{}", j + 1)), "{err}");
            assert!(w.distance_up_to(&q, 0.01).is_err());
        }
    }
    assert!(w.distance_up_to(&good, f64::NAN).is_err());
    // Degenerate cut-offs are fine: +inf is the plain query, <= 0 finds nothing.
    let exact = w.distance(&good).unwrap();
    assert_eq!(w.distance_up_to(&good, f64::INFINITY).unwrap(), Some(exact));
    assert_eq!(w.distance_up_to(&good, 0.0).unwrap(), None);
    assert_eq!(w.distance_up_to(&good, -1.0).unwrap(), None);
}

/// Timing of one query (printed; no assertion): run with `--nocapture`.
/// Three regimes: clear of the part within a few centimetres (where a
/// clearance check spends its queries), colliding, and 0.3 m above it.
#[test]
fn distance_query_cost() {
    let p = part();
    let w = world(&p, 0.001);
    let mut rng = Rng(99);
    let (mut clear, mut colliding) = (Vec::new(), Vec::new());
    while clear.len() < 300 || colliding.len() < 300 {
        let q = near(&p, &mut rng, false);
        if w.is_free(&q) {
            clear.push(q);
        } else {
            colliding.push(q);
        }
    }
    clear.truncate(300);
    colliding.truncate(300);
    let far: Vec<[f64; 6]> = (0..300).map(|_| near(&p, &mut rng, true)).collect();
    let per_query = |f: &dyn Fn(&[f64; 6]) -> f64, qs: &[[f64; 6]]| -> (f64, f64) {
        let t = Instant::now();
        let sum: f64 = qs.iter().map(f).sum();
        (
            t.elapsed().as_secs_f64() / qs.len() as f64 * 1e6,
            sum / qs.len() as f64,
        )
    };
    for (label, qs) in [
        ("clear, near the part", &clear),
        ("colliding", &colliding),
        ("0.3 m above the part", &far),
    ] {
        let (exact, mean) = per_query(&|q| w.distance(q).unwrap().distance, qs);
        let (capped, _) = per_query(
            &|q| {
                w.distance_up_to(q, 0.01)
                    .unwrap()
                    .map_or(0.01, |d| d.distance)
            },
            qs,
        );
        let (boolean, _) = per_query(&|q| f64::from(u8::from(w.is_free(q))), qs);
        println!(
            "{label}: distance {exact:.1} us, distance_up_to(1 cm) {capped:.1} us, \
             is_free {boolean:.1} us per query (mean distance {mean:.4} m, {} queries)",
            qs.len()
        );
    }
}
