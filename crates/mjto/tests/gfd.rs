//! The 3D GFD of one RTO (seed 001 section 2.4, eq. 55) on a real sheet.
//!
//! The grid of [`GfdGrid::default`]: 13 q4 samples over reference ±
//! `q4_half_span(0.35, q̂5)` (the full circle, ± π, when |q̂5| is below
//! asin(0.35 / π) ≈ 0.1116 rad), 9 q5 samples over reference ± 0.3 rad
//! (0.075 apart) and 5 q6 samples over `q6_span(q̂6, stroke)`.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_budget::Budget;
use std::f64::consts::{FRAC_PI_2, PI};

use kerf_mjto::collision::{CollisionWorld, HeadModel};
use kerf_mjto::gfd::{q4_half_span, q6_span, tool_axis, weighted_distance, Gfd};
use kerf_mjto::mesh::MeshData;
use kerf_mjto::request::{GfdGrid, Weights};
use kerf_mjto::{AxisLimits, LaserMachine};
use nalgebra::{Isometry3, Vector3};

/// CL point on the top face of the sheet.
const C: [f64; 3] = [0.8, 0.7, 0.3];

/// The preferred standoff of `CutOptions::default()`: on the q6 stroke
/// [-0.1, 0.02] its q6 span is [-0.1, -0.04], sampled 0.015 apart.
const STANDOFF: f64 = -0.07;

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

/// The distinct values of wrist coordinate `i` among the candidates,
/// ascending.
fn distinct(g: &Gfd, i: usize) -> Vec<f64> {
    let mut v: Vec<f64> = g.candidates.iter().map(|c| c.q[i]).collect();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

fn stroke(min: f64, max: f64) -> AxisLimits {
    AxisLimits {
        min,
        max,
        vel: 1.0,
        acc: 1.0,
        jerk: 1.0,
    }
}

#[test]
fn candidates_respect_the_lead_and_tilt_limits() {
    let g = build(C, [0.0, 0.0, STANDOFF], 0.2);
    // 13 x 9 q4/q5 samples, q6: 5 over [-0.1, -0.04] (the reference is
    // the middle one, not added again).
    assert_eq!(g.total, 13 * 9 * 5);
    assert_eq!(
        g.candidates.len() + g.angle_rejected + g.range_rejected + g.stroke_rejected,
        g.total
    );
    assert_eq!((g.range_rejected, g.stroke_rejected), (0, 0));
    // q̂5 = 0: q4 every 30 deg over [-180, 180] deg. |lead| and |tilt| are
    // at most |q5|, so |q5| <= 0.15 always passes. At |q5| = 0.225,
    // tan(lead) = cos q4 tan q5 (tilt: sin q4) <= tan 0.2 needs
    // |cos q4|, |sin q4| <= 0.8856: q4 = 0, +-90, +-180 deg (5) fail. At
    // |q5| = 0.3 that needs both <= 0.6553: no multiple of 30 deg passes
    // (13). (2 * 5 + 2 * 13) pairs of 5 q6 samples each.
    assert_eq!(g.angle_rejected, (2 * 5 + 2 * 13) * 5);
    assert_eq!(g.candidates.len(), (13 * 9 - 36) * 5);
    for c in &g.candidates {
        let (lead, tilt) = lead_tilt(&tool_axis(c.q[0], c.q[1]));
        assert!(lead.abs() <= 0.2 && tilt.abs() <= 0.2, "{c:?}");
        assert_eq!((c.lead, c.tilt), (lead, tilt));
    }
    // Every rejected (q4, q5) really violates a limit: count them.
    let mut rejected = 0;
    for j in 0..13 {
        for k in 0..9 {
            let q4 = PI * (j as f64 - 6.0) / 6.0;
            let q5 = 0.3 * (k as f64 - 4.0) / 4.0;
            let (lead, tilt) = lead_tilt(&tool_axis(q4, q5));
            if lead.abs() > 0.2 || tilt.abs() > 0.2 {
                rejected += 5;
            }
        }
    }
    assert_eq!(g.angle_rejected, rejected);
    // With limits wider than the grid (|q5| <= 0.3) nothing is rejected
    // for its angle.
    let wide = build(C, [0.0, 0.0, STANDOFF], 1.5);
    assert_eq!(wide.angle_rejected, 0);
    assert_eq!(wide.candidates.len(), 13 * 9 * 5);
}

/// Eq. 55 as `Gfd::build` applies it: the q4 term weighted by sin²q̂5 (the
/// q4 offset δ moves the tool axis by about δ sin|q̂5|, eq. 2).
fn eq55(q: &[f64; 3], reference: &[f64; 3], w: &Weights) -> f64 {
    let k4 = w.k4 * reference[1].sin().powi(2);
    (k4 * (q[0] - reference[0]).powi(2)
        + w.k5 * (q[1] - reference[1]).powi(2)
        + w.k6 * (q[2] - reference[2]).powi(2))
    .sqrt()
}

#[test]
fn candidates_are_sorted_by_eq55_and_reproduce_the_cl_point() {
    let reference = [0.1, 0.05, STANDOFF];
    let g = build(C, reference, 1.0);
    let w = Weights::default();
    let reference_weights = Weights {
        k4: w.k4 * 0.05f64.sin().powi(2),
        ..w
    };
    assert_eq!(g.candidates.len(), 13 * 9 * 5);
    // The reference itself is a candidate, at distance 0.
    assert_eq!(g.candidates[0].q, reference);
    assert_eq!(g.candidates[0].distance, 0.0);
    for (p, c) in g.candidates.iter().enumerate() {
        assert!((c.distance - eq55(&c.q, &reference, &w)).abs() < 1e-15);
        assert_eq!(
            c.distance,
            weighted_distance(&c.q, &reference, &reference_weights)
        );
        if p > 0 {
            assert!(g.candidates[p - 1].distance <= c.distance);
        }
        // Forward kinematics (eq. 2) of the joint vector gives back C.
        let q = g.joint_vector(p);
        let o = Vector3::new(q[3].cos() * q[4].sin(), q[3].sin() * q[4].sin(), q[4].cos());
        let c_fk = Vector3::new(q[0], q[1], q[2]) + q[5] * o;
        assert!((c_fk - Vector3::from(C)).norm() < 1e-14);
    }
    // The whole sorted list of distances, from the grid enumerated here:
    // q4 = 0.1 + j pi/6 (|j| <= 6), q5 = 0.05 + 0.075 a (|a| <= 4), q6 =
    // -0.1 + 0.015 b (b = 0..4).
    let mut expected: Vec<f64> = Vec::new();
    for j in -6..=6 {
        for a in -4..=4 {
            for b in 0..5 {
                let q = [
                    0.1 + PI * j as f64 / 6.0,
                    0.05 + 0.075 * a as f64,
                    -0.1 + 0.015 * b as f64,
                ];
                expected.push(eq55(&q, &reference, &w));
            }
        }
    }
    expected.sort_by(f64::total_cmp);
    for (c, e) in g.candidates.iter().zip(&expected) {
        assert!((c.distance - e).abs() < 1e-12, "{} {e}", c.distance);
    }
    // sin(0.05) * pi < 0.35: q4 spans the full circle, 30 deg apart, and a
    // q4 step of pi/6 costs sin(0.05) pi/6 = 0.026169 only: the q4
    // neighbours come before the q5 neighbours (0.075 away; q6 samples,
    // 0.015 m apart, cost sqrt(k6) 0.015 = 0.15). The order (ties in grid
    // order, q4 ascending):
    //   1, 2: q4 -+ pi/6 (0.026169); 3, 4: q4 -+ pi/3 (0.052338);
    //   5, 6: q5 -+ 0.075; 7, 8: q4 -+ pi/2 (0.078507);
    //   9..12: q4 -+ pi/6 with q5 -+ 0.075 (0.079434);
    //   13..16: q4 -+ pi/3 with q5 -+ 0.075 (0.091457).
    let step = 0.05f64.sin() * PI / 6.0;
    assert!((step - 0.026_169).abs() < 1e-6);
    let offsets = |p: usize| {
        let q = g.candidates[p].q;
        (
            ((q[0] - reference[0]) / (PI / 6.0)).round() as i32,
            ((q[1] - reference[1]) / 0.075).round() as i32,
            ((q[2] - reference[2]) / 0.015).round() as i32,
        )
    };
    let order: Vec<(i32, i32, i32)> = (0..17).map(offsets).collect();
    assert_eq!(
        order,
        vec![
            (0, 0, 0),
            (-1, 0, 0),
            (1, 0, 0),
            (-2, 0, 0),
            (2, 0, 0),
            (0, -1, 0),
            (0, 1, 0),
            (-3, 0, 0),
            (3, 0, 0),
            (-1, -1, 0),
            (-1, 1, 0),
            (1, -1, 0),
            (1, 1, 0),
            (-2, -1, 0),
            (-2, 1, 0),
            (2, -1, 0),
            (2, 1, 0),
        ]
    );
    let want = [
        0.0,
        step,
        step,
        2.0 * step,
        2.0 * step,
        0.075,
        0.075,
        3.0 * step,
        3.0 * step,
    ];
    for (p, d) in want.iter().enumerate() {
        assert!((g.candidates[p].distance - d).abs() < 1e-12, "{p}");
    }
    assert!((3.0 * step - 0.078_507).abs() < 1e-6);
    for p in 9..13 {
        let d = (step * step + 0.075 * 0.075).sqrt();
        assert!((g.candidates[p].distance - d).abs() < 1e-12, "{p}");
        assert!((d - 0.079_434).abs() < 1e-6);
    }
    for p in 13..17 {
        let d = (4.0 * step * step + 0.075 * 0.075).sqrt();
        assert!((g.candidates[p].distance - d).abs() < 1e-12, "{p}");
        assert!((d - 0.091_457).abs() < 1e-6);
    }
    // The q4 term is the tool-axis displacement: the axes of the q4
    // neighbours are 2 asin(sin(0.05) sin(pi/12)) = 0.025872 rad from the
    // reference axis, 1.2 % below the weighted q4 step.
    let o_ref = tool_axis(reference[0], reference[1]);
    let angle = tool_axis(g.candidates[1].q[0], g.candidates[1].q[1]).angle(&o_ref);
    assert!((angle - 0.025_872).abs() < 1e-6, "{angle}");
    assert!((g.candidates[1].distance / angle - 1.0).abs() < 0.013);
    let q4s = distinct(&g, 0);
    assert_eq!(q4s.len(), 13);
    assert!((q4s[0] - (reference[0] - PI)).abs() < 1e-12);
    assert!((q4s[12] - (reference[0] + PI)).abs() < 1e-12);
    for pair in q4s.windows(2) {
        assert!((pair[1] - pair[0] - PI / 6.0).abs() < 1e-12);
    }
}

#[test]
fn eq55_q4_weight_is_sin_squared_of_the_reference_q5() {
    let w = Weights::default();
    // Vertical reference (q̂5 = 0): q4 is undefined (eq. 3) and costs
    // nothing; candidates differing only in q4 have the same distance,
    // sqrt(k5 dq5² + k6 dq6²).
    for q5_ref in [0.0, -0.0] {
        let reference = [0.4, q5_ref, STANDOFF];
        let g = build(C, reference, 0.3);
        assert_eq!(distinct(&g, 0).len(), 13);
        let mut groups = 0;
        for c in &g.candidates {
            let same: Vec<_> = g
                .candidates
                .iter()
                .filter(|d| d.q[1] == c.q[1] && d.q[2] == c.q[2])
                .collect();
            if same.len() > 1 {
                groups += 1;
            }
            for d in &same {
                assert_eq!(d.distance, c.distance, "{:?} {:?}", c.q, d.q);
            }
            let plain =
                (w.k5 * (c.q[1] - q5_ref).powi(2) + w.k6 * (c.q[2] - STANDOFF).powi(2)).sqrt();
            assert!((c.distance - plain).abs() < 1e-15);
        }
        assert!(groups > 0);
        // So the 13 q4 samples at the reference q5, q6 all tie at 0 and
        // keep grid order (q4 ascending, from 0.4 - pi).
        for (j, c) in g.candidates[..13].iter().enumerate() {
            assert_eq!(c.distance, 0.0);
            assert_eq!((c.q[1], c.q[2]), (q5_ref, STANDOFF));
            assert!((c.q[0] - (0.4 - PI + PI * j as f64 / 6.0)).abs() < 1e-12);
        }
        assert!(g.candidates[13].distance > 0.0);
    }

    // A horizontal reference axis (q̂5 = pi/2, sin² = 1): the plain k4 of
    // eq. 55, here a non-default k4 = 2.5. The lead/tilt test is switched
    // off (every axis accepted) to keep the whole grid.
    let m = machine();
    let weights = Weights { k4: 2.5, ..w };
    let accept = |_: &Vector3<f64>| (0.0, 0.0);
    let build_with = |reference: [f64; 3]| {
        Gfd::build(
            2,
            0.5,
            &Vector3::from(C),
            reference,
            &GfdGrid::default(),
            &weights,
            0.2,
            0.2,
            &accept,
            m.limits(),
        )
    };
    let reference = [0.2, FRAC_PI_2, STANDOFF];
    let g = build_with(reference);
    // q5 above pi/2 is out of range: 4 of the 9 q5 samples.
    assert_eq!(g.range_rejected, 13 * 4 * 5);
    assert_eq!(g.candidates.len(), 13 * 5 * 5);
    for c in &g.candidates {
        assert_eq!(c.distance, weighted_distance(&c.q, &reference, &weights));
    }
    // q4 samples 0.35 / 6 apart (q4_half_span(0.35, pi/2) = 0.35): the
    // two q4 neighbours, sqrt(2.5) 0.35 / 6 = 0.092233, come right after
    // the single q5 neighbour at 0.075 (the other one is above pi/2).
    assert_eq!(g.candidates[0].q, reference);
    assert_eq!(g.candidates[1].q[0], reference[0]);
    assert!((g.candidates[1].q[1] - (FRAC_PI_2 - 0.075)).abs() < 1e-12);
    assert!((g.candidates[1].distance - 0.075).abs() < 1e-12);
    for p in [2, 3] {
        let c = g.candidates[p];
        assert_eq!((c.q[1], c.q[2]), (reference[1], reference[2]));
        assert!(((c.q[0] - reference[0]).abs() - 0.35 / 6.0).abs() < 1e-12);
        assert!((c.distance - 2.5f64.sqrt() * 0.35 / 6.0).abs() < 1e-12);
    }
    // In between: k4 sin²(q̂5), e.g. q̂5 = 0.5: 2.5 * 0.229849 = 0.574623.
    let reference = [0.2, 0.5, STANDOFF];
    let g = build_with(reference);
    let k4 = 2.5 * 0.5f64.sin().powi(2);
    assert!((k4 - 0.574_623).abs() < 1e-6);
    for c in &g.candidates {
        let expected = (k4 * (c.q[0] - 0.2).powi(2)
            + (c.q[1] - 0.5).powi(2)
            + 100.0 * (c.q[2] - STANDOFF).powi(2))
        .sqrt();
        assert!((c.distance - expected).abs() < 1e-15, "{:?}", c.q);
    }
}

#[test]
fn translational_stroke_rejects_samples() {
    let limits = *machine().limits();
    // C 1 cm above the lower q3 limit (q3 >= 0): only q6 > 0.01 would put
    // M below it, and the q6 span of the preferred standoff, [-0.1, -0.04],
    // never gets there.
    let low = build([0.8, 0.7, 0.01], [0.0, 0.0, STANDOFF], 1.0);
    assert_eq!(low.stroke_rejected, 0);
    assert_eq!(low.candidates.len(), low.total);
    // C 7.5 cm below the upper q3 limit (q3 <= 3): M.z = 2.925 + |q6| cos q5
    // leaves the stroke for |q6| cos q5 > 0.075. |q5| <= 0.3 (cos >= 0.955):
    // every sample with q6 = -0.1 or -0.085 goes (cos q5 > 0.882), none with
    // |q6| <= 0.07.
    let g = build([0.8, 0.7, 2.925], [0.0, 0.0, STANDOFF], 1.0);
    assert_eq!(g.stroke_rejected, 2 * 13 * 9);
    assert_eq!(g.candidates.len(), 3 * 13 * 9);
    assert_eq!(distinct(&g, 2).len(), 3);
    assert!(g.candidates.iter().all(|c| c.q[2] > -0.08));
    for p in 0..g.candidates.len() {
        let q = g.joint_vector(p);
        for j in 0..6 {
            assert!(limits[j].min <= q[j] && q[j] <= limits[j].max, "{q:?}");
        }
    }
    // The reference standoff 0 spans [-0.02, 0.02] (0.01 apart) on the
    // stroke [-0.1, 0.02]. With C 1.5 cm above q3 = 0, q6 = 0.02 puts
    // M.z = 0.015 - 0.02 cos q5 below it for every |q5| <= 0.3 (cos > 0.75):
    // all 13 x 9 of them go; q6 = 0.01 keeps M.z >= 0.005.
    let g = build([0.8, 0.7, 0.015], [0.0, 0.0, 0.0], 1.0);
    assert_eq!(distinct(&g, 2).len(), 4);
    assert_eq!(g.stroke_rejected, 13 * 9);
    assert!(g.candidates.iter().all(|c| c.q[2] < 0.015));
}

#[test]
fn non_finite_input_gives_an_empty_gfd() {
    let g = build([f64::NAN, 0.7, 0.3], [0.0, 0.0, STANDOFF], 0.2);
    assert!(g.candidates.is_empty());
    let g = build(C, [0.0, f64::NAN, STANDOFF], 0.2);
    assert!(g.candidates.is_empty());
    let g = build(C, [0.0, 0.0, STANDOFF], f64::NAN);
    assert!(g.candidates.is_empty());
}

#[test]
fn collision_status_is_lazy_and_memoised() {
    let world = sheet_world();
    let mut g = build(C, [0.0, 0.0, STANDOFF], 0.2);
    assert_eq!(g.collision_checked(), 0);
    // q̂5 = 0: the q4 term of eq. 55 has weight sin²(0) = 0, so the 13 q4
    // samples at the reference q5, q6 tie at distance 0 in grid order
    // (q4 = -pi, -5 pi/6, ..., pi); the reference itself (q4 = 0) is the
    // seventh. It (M 7 cm above the sheet, fork arms 1 cm above it) is
    // free.
    assert!(g.candidates[..13].iter().all(|c| c.distance == 0.0));
    assert_eq!(g.candidates[0].q, [-PI, 0.0, STANDOFF]);
    assert_eq!(g.candidates[6].q, [0.0, 0.0, STANDOFF]);
    assert!(g.is_free(6, &world));
    assert!(g.is_free(6, &world));
    assert_eq!((g.collision_checked(), world.queries()), (1, 1));
    // A candidate with q6 = -0.04 (M 4 cm above C: the tilt housing,
    // radius 4.5 cm, contains C and the fork arms reach 2 cm into the
    // sheet) collides.
    let high = g
        .candidates
        .iter()
        .position(|c| (c.q[2] + 0.04).abs() < 1e-12)
        .unwrap();
    assert!(!g.is_free(high, &world));
    assert!(!g.is_free(high, &world));
    assert_eq!(g.known_status(high), Some(false));
    assert_eq!(g.known_status(1), None);
    assert_eq!((g.collision_checked(), g.known_colliding()), (2, 1));
    assert_eq!(world.queries(), 2);
}

#[test]
fn nearest_free_equals_brute_force() {
    let world = sheet_world();
    let w = Weights::default();
    // Targets that collide (standoff too small, tilted tip) and one free.
    let expected = [Some([0.0, 0.0, STANDOFF]), None, Some([0.0, 0.0, -0.1])];
    for (target, want) in [[0.0, 0.0, -0.01], [0.2, 0.25, -0.04], [0.0, 0.0, -0.1]]
        .into_iter()
        .zip(expected)
    {
        let mut lazy = build(C, [0.0, 0.0, STANDOFF], 0.3);
        let mut eager = lazy.clone();
        let free: Vec<usize> = (0..eager.candidates.len())
            .filter(|&p| eager.is_free(p, &world))
            .collect();
        let brute = free.into_iter().min_by(|&a, &b| {
            let da = weighted_distance(&eager.candidates[a].q, &target, &w);
            let db = weighted_distance(&eager.candidates[b].q, &target, &w);
            da.total_cmp(&db).then(a.cmp(&b))
        });
        let got = lazy
            .nearest_free(target, &w, &world, &Budget::unlimited())
            .unwrap();
        assert_eq!(got, brute, "target {target:?}");
        let p = got.unwrap();
        let [_, q5, q6] = lazy.candidates[p].q;
        // The fork arms (bottom 6 cm below M, not tilted by q5) stay above
        // the sheet: M.z - C.z = -q6 cos q5 > 0.06. Of the q6 samples
        // -0.1, -0.085, -0.07, -0.055, -0.04 only the first three can.
        assert!(-q6 * q5.cos() > 0.06, "the fork needs q6 < -0.06");
        if let Some(q) = want {
            assert_eq!(lazy.candidates[p].q, q, "target {target:?}");
        }
        assert!(lazy.collision_checked() < eager.collision_checked());
    }
}

#[test]
fn q4_half_span_is_the_axis_sweep_over_sin_q5() {
    // Vertical reference: q4 is undefined, the grid spans the full circle.
    assert_eq!(q4_half_span(0.35, 0.0), PI);
    assert_eq!(q4_half_span(0.35, -0.0), PI);
    // Small tilt: 0.35 / sin(0.05) = 7.0 > pi, capped.
    assert_eq!(q4_half_span(0.35, 0.05), PI);
    assert_eq!(q4_half_span(0.35, -0.05), PI);
    // The cap starts where sin|q5| = 0.35 / pi (q5 = 0.11164): continuous.
    let edge = (0.35 / PI).asin();
    assert!((edge - 0.111_640_2).abs() < 1e-7);
    assert_eq!(q4_half_span(0.35, edge * (1.0 - 1e-9)), PI);
    assert!((q4_half_span(0.35, edge * (1.0 + 1e-9)) - PI).abs() < 1e-7);
    assert!(q4_half_span(0.35, edge * (1.0 + 1e-9)) < PI);
    // Above it: 0.35 / sin|q5|, e.g. 0.35 / sin 0.2 = 1.761721,
    // 0.35 / sin 0.5 = 0.730040.
    assert!((q4_half_span(0.35, 0.2) - 1.761_721_3).abs() < 1e-6);
    assert!((q4_half_span(0.35, 0.5) - 0.730_040_4).abs() < 1e-6);
    assert_eq!(q4_half_span(0.35, -0.5), q4_half_span(0.35, 0.5));
    // Horizontal axis: q4 moves the axis at full rate, span = half range.
    assert_eq!(q4_half_span(0.35, FRAC_PI_2), 0.35);
    assert_eq!(q4_half_span(0.35, -FRAC_PI_2), 0.35);
    assert!((q4_half_span(0.1, FRAC_PI_2) - 0.1).abs() < 1e-15);
    // The axis really sweeps about 2 sin(q5) sin(span / 2) ~ the half range
    // for small spans: at q5 = pi/2 and 0.5 the chord between the reference
    // axis and the end of the q4 span.
    for q5 in [0.5, 1.0, FRAC_PI_2] {
        let span = q4_half_span(0.1, q5);
        let chord = (tool_axis(span, q5) - tool_axis(0.0, q5)).norm();
        assert!((chord - 2.0 * (0.05f64).sin()).abs() < 1e-3, "{q5} {chord}");
    }
    // In the GFD: 13 q4 samples over 0.2 +- 0.35 / sin 0.5.
    let g = build(C, [0.2, 0.5, STANDOFF], 1.0);
    let q4s = distinct(&g, 0);
    assert_eq!(q4s.len(), 13);
    let half = 0.35 / 0.5f64.sin();
    assert!((q4s[0] - (0.2 - half)).abs() < 1e-12);
    assert!((q4s[12] - (0.2 + half)).abs() < 1e-12);
    assert!(q4s.contains(&0.2));
}

#[test]
fn q6_span_is_symmetric_and_reaches_the_nearer_stroke_end() {
    let s = stroke(-0.1, 0.02);
    let close = |(a, b): (f64, f64), (x, y): (f64, f64)| {
        assert!((a - x).abs() < 1e-15 && (b - y).abs() < 1e-15, "{a} {b}");
    };
    // The doc's example and the middle of the stroke (both ends reached).
    close(q6_span(-0.07, &s), (-0.1, -0.04));
    close(q6_span(-0.04, &s), (-0.1, 0.02));
    // Nearer the upper end.
    close(q6_span(0.0, &s), (-0.02, 0.02));
    close(q6_span(-0.08, &s), (-0.1, -0.06));
    // At an end: a single value.
    close(q6_span(-0.1, &s), (-0.1, -0.1));
    close(q6_span(0.02, &s), (0.02, 0.02));
    // Outside the stroke: zero width at the reference.
    assert_eq!(q6_span(-0.15, &s), (-0.15, -0.15));
    assert_eq!(q6_span(0.05, &s), (0.05, 0.05));
    // Symmetric on another stroke.
    close(q6_span(0.3, &stroke(0.0, 1.0)), (0.0, 0.6));
    close(q6_span(0.9, &stroke(0.0, 1.0)), (0.8, 1.0));

    // In the GFD, the q6 samples are q6_span split in 4, the reference the
    // middle one.
    let g = build(C, [0.0, 0.0, -0.08], 1.5);
    let q6s = distinct(&g, 2);
    assert_eq!(q6s.len(), 5);
    for (k, v) in q6s.iter().enumerate() {
        assert!((v - (-0.1 + 0.01 * k as f64)).abs() < 1e-12, "{q6s:?}");
    }
    assert_eq!(g.total, 13 * 9 * 5);
    // At the stroke end the grid has the reference alone.
    let g = build(C, [0.0, 0.0, -0.1], 1.5);
    assert_eq!(distinct(&g, 2), vec![-0.1]);
    assert_eq!((g.total, g.candidates.len()), (13 * 9, 13 * 9));
    // Outside the stroke: the reference alone, which is out of range.
    let g = build(C, [0.0, 0.0, -0.15], 1.5);
    assert_eq!((g.total, g.range_rejected), (13 * 9, 13 * 9));
    assert!(g.candidates.is_empty());
}

#[test]
fn near_the_vertical_q4_spreads_over_the_full_circle() {
    // q̂5 = 0.02 rad: sin(0.02) pi = 0.063 < 0.35, so q4 spans ref +- pi.
    let reference = [0.3, 0.02, STANDOFF];
    assert_eq!(q4_half_span(GfdGrid::default().q4_half_range, 0.02), PI);
    let g = build(C, reference, 0.3);
    let q4s = distinct(&g, 0);
    assert_eq!(q4s.len(), 13);
    assert!((q4s[0] - (0.3 - PI)).abs() < 1e-12);
    assert!((q4s[12] - (0.3 + PI)).abs() < 1e-12);
    // 30 deg apart, so the head's orientation about the vertical (q4 mod
    // 2 pi) leaves no gap over 30 deg around the circle.
    let mut around: Vec<f64> = q4s.iter().map(|q| q.rem_euclid(2.0 * PI)).collect();
    around.sort_by(f64::total_cmp);
    around.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    assert_eq!(around.len(), 12);
    let mut gaps: Vec<f64> = around.windows(2).map(|p| p[1] - p[0]).collect();
    gaps.push(around[0] + 2.0 * PI - around[11]);
    for gap in gaps {
        assert!((gap - PI / 6.0).abs() < 1e-9, "{gap}");
    }
    // Each q4 has candidates at the reference q5 and q6, whose axes stay
    // within 2 sin(0.02) = 0.04 of the reference axis: the whole circle of
    // q4 is a small cone of tool axes.
    let o_ref = tool_axis(reference[0], reference[1]);
    for &q4 in &q4s {
        let c = g
            .candidates
            .iter()
            .find(|c| c.q == [q4, reference[1], reference[2]])
            .unwrap_or_else(|| panic!("q4 = {q4}"));
        let angle = tool_axis(c.q[0], c.q[1]).angle(&o_ref);
        assert!(angle <= 0.04 + 1e-12, "{angle}");
        assert!(c.lead.abs() <= 0.02 + 1e-12 && c.tilt.abs() <= 0.02 + 1e-12);
    }
}
