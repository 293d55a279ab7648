//! The 3D GFD of one RTO (seed 001 section 2.4, eq. 55) on a real sheet.

use kerf_mjto::collision::{CollisionWorld, HeadModel};
use kerf_mjto::gfd::{tool_axis, weighted_distance, Gfd};
use kerf_mjto::mesh::MeshData;
use kerf_mjto::request::{GfdGrid, Weights};
use kerf_mjto::LaserMachine;
use nalgebra::{Isometry3, Vector3};

/// CL point on the top face of the sheet.
const C: [f64; 3] = [0.8, 0.7, 0.3];

/// Lead and tilt of a tool axis against the path frame of a straight cut
/// along +x on a horizontal sheet: t = x, n = z, b = n × t = y;
/// lead = atan2(O·t, O·n), tilt = atan2(O·b, O·n).
fn lead_tilt(o: &Vector3<f64>) -> (f64, f64) {
    (o.x.atan2(o.z), o.y.atan2(o.z))
}

fn machine() -> LaserMachine {
    LaserMachine::default_machine().unwrap()
}

fn sheet_world() -> CollisionWorld {
    let m = machine();
    let head = HeadModel::from_urdf(m.robot().urdf()).unwrap();
    let sheet = MeshData::cuboid(
        [C[0] - 0.3, C[1] - 0.3, C[2] - 0.002],
        [C[0] + 0.3, C[1] + 0.3, C[2]],
    );
    CollisionWorld::new(head, &sheet, &Isometry3::identity(), 0.0).unwrap()
}

fn build(point: [f64; 3], reference: [f64; 3], max_angle: f64) -> Gfd {
    let m = machine();
    Gfd::build(
        4,
        0.25,
        &Vector3::from(point),
        reference,
        &GfdGrid::default(),
        &Weights::default(),
        max_angle,
        max_angle,
        &lead_tilt,
        m.limits(),
    )
}

#[test]
fn candidates_respect_the_lead_and_tilt_limits() {
    let g = build(C, [0.0, 0.0, -0.08], 0.2);
    // 9 x 9 q4/q5 samples, q6: 5 over [-0.1, 0.02] plus the reference.
    assert_eq!(g.total, 9 * 9 * 6);
    assert_eq!(
        g.candidates.len() + g.angle_rejected + g.range_rejected + g.stroke_rejected,
        g.total
    );
    // q5 spans +-0.3 > 0.2: some samples must be rejected.
    assert!(g.angle_rejected > 0);
    assert!(!g.candidates.is_empty());
    for c in &g.candidates {
        let (lead, tilt) = lead_tilt(&tool_axis(c.q[0], c.q[1]));
        assert!(lead.abs() <= 0.2 && tilt.abs() <= 0.2, "{c:?}");
        assert_eq!((c.lead, c.tilt), (lead, tilt));
    }
    // Every rejected (q4, q5) really violates a limit: count them.
    let mut rejected = 0;
    for j in 0..9 {
        for k in 0..9 {
            let q4 = -0.35 + 0.7 * j as f64 / 8.0;
            let q5 = -0.3 + 0.6 * k as f64 / 8.0;
            let (lead, tilt) = lead_tilt(&tool_axis(q4, q5));
            if lead.abs() > 0.2 || tilt.abs() > 0.2 {
                rejected += 6;
            }
        }
    }
    assert_eq!(g.angle_rejected, rejected);
    // With limits wider than the grid nothing is rejected for its angle.
    assert_eq!(build(C, [0.0, 0.0, -0.08], 1.5).angle_rejected, 0);
}

#[test]
fn candidates_are_sorted_by_eq55_and_reproduce_the_cl_point() {
    let reference = [0.1, 0.05, -0.08];
    let g = build(C, reference, 1.0);
    let w = Weights::default();
    // The reference itself is a candidate, at distance 0.
    assert_eq!(g.candidates[0].q, reference);
    assert_eq!(g.candidates[0].distance, 0.0);
    for (p, c) in g.candidates.iter().enumerate() {
        let d = reference;
        let expected = (w.k4 * (c.q[0] - d[0]).powi(2)
            + w.k5 * (c.q[1] - d[1]).powi(2)
            + w.k6 * (c.q[2] - d[2]).powi(2))
        .sqrt();
        assert!((c.distance - expected).abs() < 1e-15);
        assert_eq!(c.distance, weighted_distance(&c.q, &reference, &w));
        if p > 0 {
            assert!(g.candidates[p - 1].distance <= c.distance);
        }
        // Forward kinematics (eq. 2) of the joint vector gives back C.
        let q = g.joint_vector(p);
        let o = Vector3::new(q[3].cos() * q[4].sin(), q[3].sin() * q[4].sin(), q[4].cos());
        let c_fk = Vector3::new(q[0], q[1], q[2]) + q[5] * o;
        assert!((c_fk - Vector3::from(C)).norm() < 1e-14);
    }
    // q4 samples are 0.0875 apart: the two nearest neighbours of the
    // reference in q4 (k4 = 1) come right after the q5 ones (0.075).
    assert!((g.candidates[1].distance - 0.075).abs() < 1e-12);
    assert!((g.candidates[3].distance - 0.0875).abs() < 1e-12);
}

#[test]
fn translational_stroke_rejects_samples() {
    // C 1 cm above the lower q3 limit (q3 >= 0): q6 > 0.01 puts M below it.
    let g = build([0.8, 0.7, 0.01], [0.0, 0.0, -0.08], 1.0);
    assert!(g.stroke_rejected > 0);
    let limits = *machine().limits();
    for p in 0..g.candidates.len() {
        let q = g.joint_vector(p);
        for j in 0..6 {
            assert!(limits[j].min <= q[j] && q[j] <= limits[j].max, "{q:?}");
        }
    }
    // q5 = +-0.3 and q6 = 0.02: M.z = 0.01 - 0.02 cos q5 < 0; every sample
    // with q6 = 0.02 (9 x 9) goes.
    assert_eq!(g.stroke_rejected, 81);
}

#[test]
fn non_finite_input_gives_an_empty_gfd() {
    let g = build([f64::NAN, 0.7, 0.3], [0.0, 0.0, -0.08], 0.2);
    assert!(g.candidates.is_empty());
    let g = build(C, [0.0, f64::NAN, -0.08], 0.2);
    assert!(g.candidates.is_empty());
    let g = build(C, [0.0, 0.0, -0.08], f64::NAN);
    assert!(g.candidates.is_empty());
}

#[test]
fn collision_status_is_lazy_and_memoised() {
    let world = sheet_world();
    let mut g = build(C, [0.0, 0.0, -0.08], 0.2);
    assert_eq!(g.collision_checked(), 0);
    // The reference (tip 1 mm above the sheet) is free.
    assert!(g.is_free(0, &world));
    assert!(g.is_free(0, &world));
    assert_eq!((g.collision_checked(), world.queries()), (1, 1));
    // A candidate with q6 = 0.02 (M below the surface) collides.
    let high = g.candidates.iter().position(|c| c.q[2] == 0.02).unwrap();
    assert!(!g.is_free(high, &world));
    assert_eq!(g.known_status(high), Some(false));
    assert_eq!(world.queries(), 2);
}

#[test]
fn nearest_free_equals_brute_force() {
    let world = sheet_world();
    let w = Weights::default();
    // Targets that collide (standoff too small, tilted tip) and one free.
    for target in [[0.0, 0.0, -0.01], [0.2, 0.25, -0.04], [0.0, 0.0, -0.1]] {
        let mut lazy = build(C, [0.0, 0.0, -0.08], 0.3);
        let mut eager = lazy.clone();
        let free: Vec<usize> = (0..eager.candidates.len())
            .filter(|&p| eager.is_free(p, &world))
            .collect();
        let brute = free.into_iter().min_by(|&a, &b| {
            let da = weighted_distance(&eager.candidates[a].q, &target, &w);
            let db = weighted_distance(&eager.candidates[b].q, &target, &w);
            da.total_cmp(&db).then(a.cmp(&b))
        });
        let got = lazy.nearest_free(target, &w, &world);
        assert_eq!(got, brute, "target {target:?}");
        let p = got.unwrap();
        assert!(
            lazy.candidates[p].q[2] <= -0.061,
            "the fork needs q6 < -0.06"
        );
        assert!(lazy.collision_checked() < eager.collision_checked());
    }
}
