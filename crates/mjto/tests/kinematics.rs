//! Forward and inverse kinematics of the laser cutting machine (seed 001
//! eq. 2 and 3) against the URDF chain and along paths.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use approx::assert_abs_diff_eq;
use kerf_mjto::kinematics::{
    forward, inverse, m_point, rotary_ikt, tool_axis, IktError, STROKE_TOLERANCE,
};
use kerf_mjto::{LaserMachine, PlanError};
use nalgebra::Vector3;

mod common;
use common::Rng;

fn machine() -> LaserMachine {
    LaserMachine::default_machine().expect("the repository's laser cutter loads")
}

fn random_q(rng: &mut Rng, m: &LaserMachine) -> [f64; 6] {
    let mut q = [0.0; 6];
    for (v, l) in q.iter_mut().zip(m.limits()) {
        *v = rng.range(l.min, l.max);
    }
    q
}

const Q4_LIMITS: (f64, f64) = (-TAU, TAU);
const Q5_LIMITS: (f64, f64) = (-FRAC_PI_2, FRAC_PI_2);

#[test]
fn forward_equals_urdf_tool0_pose() {
    let m = machine();
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    for _ in 0..500 {
        let q = random_q(&mut rng, &m);
        let (c, o) = forward(&q);
        let pose = m.robot().forward_kinematics(&q).expect("finite q");
        let z = pose.rotation * Vector3::z();
        assert_abs_diff_eq!(c, pose.translation.vector, epsilon = 1e-12);
        assert_abs_diff_eq!(o, z, epsilon = 1e-12);
        assert_abs_diff_eq!(o.norm(), 1.0, epsilon = 1e-15);
        // M is the origin of the rotary-axes centre, (q1, q2, q3).
        assert_abs_diff_eq!(
            m_point(&c, &o, q[5]),
            Vector3::new(q[0], q[1], q[2]),
            epsilon = 1e-12
        );
    }
}

#[test]
fn tool_axis_components_follow_eq2() {
    // O_x = cos q4 sin q5, O_y = sin q4 sin q5: q4 = π/2 tilts toward +y.
    assert_abs_diff_eq!(tool_axis(0.0, FRAC_PI_2), Vector3::x(), epsilon = 1e-15);
    assert_abs_diff_eq!(
        tool_axis(FRAC_PI_2, FRAC_PI_2),
        Vector3::y(),
        epsilon = 1e-15
    );
    assert_abs_diff_eq!(tool_axis(1.234, 0.0), Vector3::z(), epsilon = 1e-15);
    let o = tool_axis(0.3, 0.4);
    assert_abs_diff_eq!(o.x, 0.3f64.cos() * 0.4f64.sin(), epsilon = 1e-15);
    assert_abs_diff_eq!(o.y, 0.3f64.sin() * 0.4f64.sin(), epsilon = 1e-15);
    assert_abs_diff_eq!(o.z, 0.4f64.cos(), epsilon = 1e-15);
}

#[test]
fn q4_is_atan2_of_oy_ox_not_the_printed_order() {
    // Eq. 3 prints atan2(O_x, O_y); for O = (0, sin 0.5, cos 0.5) that
    // would give 0, but eq. 2 needs q4 = π/2.
    let o = Vector3::new(0.0, 0.5f64.sin(), 0.5f64.cos());
    let (q4, q5) = rotary_ikt(&o, None, Q4_LIMITS, Q5_LIMITS).unwrap();
    assert_abs_diff_eq!(q4, FRAC_PI_2, epsilon = 1e-15);
    assert_abs_diff_eq!(q5, 0.5, epsilon = 1e-15);
    let o = Vector3::new(-(0.7f64.sin()), -1e-3, 0.7f64.cos()).normalize();
    let (q4, q5) = rotary_ikt(&o, None, Q4_LIMITS, Q5_LIMITS).unwrap();
    // k = 0 preferred without a previous value: q4 = atan2(O_y, O_x) ≈ -π.
    assert_abs_diff_eq!(q4, o.y.atan2(o.x), epsilon = 1e-15);
    assert!(q4 < -3.0 && q5 > 0.0);
    assert_abs_diff_eq!(tool_axis(q4, q5), o, epsilon = 1e-15);
}

#[test]
fn inverse_round_trips_forward() {
    let m = machine();
    let mut rng = Rng(42);
    let mut n = 0;
    while n < 500 {
        let q = random_q(&mut rng, &m);
        if q[4].abs() < 1e-6 {
            continue;
        }
        n += 1;
        let (c, o) = forward(&q);
        // With the true q4 as previous value, the same branch comes back.
        let back = inverse(&c, &o, q[5], Some(q[3]), m.limits()).unwrap();
        for (a, b) in back.iter().zip(&q) {
            assert_abs_diff_eq!(a, b, epsilon = 1e-9);
        }
        // Without one, some branch that reproduces the pose.
        let other = inverse(&c, &o, q[5], None, m.limits()).unwrap();
        let (c2, o2) = forward(&other);
        assert_abs_diff_eq!(c2, c, epsilon = 1e-12);
        assert_abs_diff_eq!(o2, o, epsilon = 1e-12);
        assert!(
            other[3].abs() <= PI + 1e-12,
            "k = 0 branch first: {}",
            other[3]
        );
        assert!(other[4] >= 0.0);
    }
}

#[test]
fn branch_stays_continuous_circling_the_vertical() {
    // The axis circles the vertical on a cone of half angle 0.05 rad for
    // 1.9 turns, starting next to the lower q4 limit: q4 must follow the
    // circle (−1.9π → 1.9π) without π or 2π jumps, q5 constant.
    let tilt = 0.05;
    let steps = 4000;
    let mut prev = Some(-1.9 * PI);
    let mut q4s = Vec::new();
    for i in 0..=steps {
        let phi = -1.9 * PI + 3.8 * PI * i as f64 / steps as f64;
        let o = tool_axis(phi, tilt);
        let (q4, q5) = rotary_ikt(&o, prev, Q4_LIMITS, Q5_LIMITS).unwrap();
        assert_abs_diff_eq!(q4, phi, epsilon = 1e-9);
        assert_abs_diff_eq!(q5, tilt, epsilon = 1e-9);
        prev = Some(q4);
        q4s.push(q4);
    }
    let max_step = q4s
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0, f64::max);
    assert!(
        max_step < 3.8 * PI / steps as f64 + 1e-9,
        "max step {max_step}"
    );
}

#[test]
fn branch_stays_continuous_passing_near_the_vertical() {
    // O_xy = (x, 1e-3) with x from 0.05 to −0.05: the true q4 sweeps
    // ≈ π quickly near x = 0 but smoothly; the branch must not flip.
    let steps = 20_000;
    let mut prev = None;
    let mut q4s = Vec::new();
    for i in 0..=steps {
        let x = 0.05 - 0.1 * i as f64 / steps as f64;
        let o = Vector3::new(x, 1e-3, 1.0).normalize();
        let (q4, q5) = rotary_ikt(&o, prev, Q4_LIMITS, Q5_LIMITS).unwrap();
        assert!(q5 > 0.0, "q5 keeps its sign: {q5}");
        assert_abs_diff_eq!(tool_axis(q4, q5), o, epsilon = 1e-12);
        prev = Some(q4);
        q4s.push(q4);
    }
    let max_step = q4s
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0, f64::max);
    // Largest true step: dx / 1e-3 = 5e-6 / 1e-3 = 5e-3 rad.
    assert!(max_step < 6e-3, "max step {max_step}");
    let total = q4s.last().unwrap() - q4s.first().unwrap();
    let expected = PI - 2.0 * (1e-3f64 / 0.05).atan();
    assert_abs_diff_eq!(total, expected, epsilon = 1e-9);
}

#[test]
fn passing_exactly_through_the_vertical_keeps_q4() {
    // O = Rz(0.7) (sin θ, 0, cos θ), θ from 0.1 to −0.1 through exactly 0:
    // q4 stays 0.7 and q5 = θ changes sign smoothly (odd branch after the
    // singular sample).
    let mut prev = Some(0.7);
    for i in 0..=20 {
        let theta = 0.1 - 0.01 * i as f64;
        let theta = if i == 10 { 0.0 } else { theta };
        let o = tool_axis(0.7, theta);
        let (q4, q5) = rotary_ikt(&o, prev, Q4_LIMITS, Q5_LIMITS).unwrap();
        assert_abs_diff_eq!(q4, 0.7, epsilon = 1e-12);
        assert_abs_diff_eq!(q5, theta, epsilon = 1e-12);
        prev = Some(q4);
    }
    // Singular without a previous value: q4 = 0; keeps any previous one.
    let (q4, q5) = rotary_ikt(&Vector3::z(), None, Q4_LIMITS, Q5_LIMITS).unwrap();
    assert_eq!((q4, q5), (0.0, 0.0));
    let (q4, _) = rotary_ikt(&Vector3::z(), Some(-5.5), Q4_LIMITS, Q5_LIMITS).unwrap();
    assert_eq!(q4, -5.5);
}

#[test]
fn continuity_picks_the_nearest_of_all_branches() {
    let o = tool_axis(0.4, 0.3);
    let cases = [
        (0.4, 0.4, 0.3),
        (0.4 - TAU + 0.2, 0.4 - TAU, 0.3),
        (0.4 + PI - 0.1, 0.4 + PI, -0.3),
        (0.4 - PI + 0.1, 0.4 - PI, -0.3),
    ];
    for (previous, q4_expected, q5_expected) in cases {
        let (q4, q5) = rotary_ikt(&o, Some(previous), Q4_LIMITS, Q5_LIMITS).unwrap();
        assert_abs_diff_eq!(q4, q4_expected, epsilon = 1e-12);
        assert_abs_diff_eq!(q5, q5_expected, epsilon = 1e-12);
    }
    // The 2π unwrap upward (0.4 + 2π is beyond the limit, −0.4 + 2π is not).
    let (q4, q5) = rotary_ikt(&tool_axis(-0.4, 0.3), Some(5.8), Q4_LIMITS, Q5_LIMITS).unwrap();
    assert_abs_diff_eq!(q4, TAU - 0.4, epsilon = 1e-12);
    assert_abs_diff_eq!(q5, 0.3, epsilon = 1e-12);
    // Previous beyond the limit: the nearest branch inside it.
    let (q4, _) = rotary_ikt(&o, Some(0.4 + TAU), Q4_LIMITS, Q5_LIMITS).unwrap();
    assert_abs_diff_eq!(q4, 0.4 + PI, epsilon = 1e-12);
    // A previous value far outside the stroke: still the nearest branch
    // inside it (−0.4 + 2π), not an error.
    let (q4, _) = rotary_ikt(&tool_axis(-0.4, 0.3), Some(100.0), Q4_LIMITS, Q5_LIMITS).unwrap();
    assert_abs_diff_eq!(q4, TAU - 0.4, epsilon = 1e-12);
    // Only negative q5 allowed: the odd branch with the smallest |q4|.
    let (q4, q5) = rotary_ikt(&o, None, Q4_LIMITS, (-FRAC_PI_2, 0.0)).unwrap();
    assert_abs_diff_eq!(q4, 0.4 - PI, epsilon = 1e-12);
    assert_abs_diff_eq!(q5, -0.3, epsilon = 1e-12);
}

fn out_of_stroke(e: &IktError) -> (&'static str, f64) {
    match e {
        IktError::OutOfStroke { joint, .. } => (joint, e.excess()),
        other => panic!("expected OutOfStroke, got {other:?}"),
    }
}

#[test]
fn unreachable_poses_name_the_joint_and_the_amount() {
    let m = machine();
    let l = m.limits();
    // Axis below the horizontal: |q5| = 1.8 rad > π/2.
    let o = tool_axis(0.2, 1.8);
    let e = rotary_ikt(&o, None, Q4_LIMITS, Q5_LIMITS).unwrap_err();
    let (joint, excess) = out_of_stroke(&e);
    assert_eq!(joint, "q5");
    assert_abs_diff_eq!(excess, 1.8 - FRAC_PI_2, epsilon = 1e-12);
    assert!(
        e.to_string().contains(&format!("{:.6}", 1.8 - FRAC_PI_2)),
        "{e}"
    );
    // Straight down is singular and unreachable too.
    let e = rotary_ikt(&-Vector3::z(), Some(1.0), Q4_LIMITS, Q5_LIMITS).unwrap_err();
    assert_abs_diff_eq!(out_of_stroke(&e).1, FRAC_PI_2, epsilon = 1e-12);

    // q1 beyond 1.6 m: C = (1.65, 0.5, 0.5), vertical axis, q6 = −0.07
    // puts M at x = 1.65.
    let e = inverse(&Vector3::new(1.65, 0.5, 0.5), &Vector3::z(), -0.07, None, l).unwrap_err();
    let (joint, excess) = out_of_stroke(&e);
    assert_eq!(joint, "q1");
    assert_abs_diff_eq!(excess, 0.05, epsilon = 1e-12);
    // q3 below 0 through the standoff: C_z = −0.1, q6 = −0.05 → M_z = −0.05.
    let e = inverse(&Vector3::new(0.5, 0.5, -0.1), &Vector3::z(), -0.05, None, l).unwrap_err();
    let (joint, excess) = out_of_stroke(&e);
    assert_eq!(joint, "q3");
    assert_abs_diff_eq!(excess, 0.05, epsilon = 1e-12);
    // q6 beyond its stroke [−0.1, 0.02].
    let e = inverse(&Vector3::new(0.5, 0.5, 0.5), &Vector3::z(), 0.05, None, l).unwrap_err();
    let (joint, excess) = out_of_stroke(&e);
    assert_eq!(joint, "q6");
    assert_abs_diff_eq!(excess, 0.03, epsilon = 1e-12);
    // A narrow q4 stroke that no branch reaches.
    let e = rotary_ikt(&tool_axis(1.0, 0.3), None, (-0.2, 0.2), Q5_LIMITS).unwrap_err();
    let (joint, excess) = out_of_stroke(&e);
    assert_eq!(joint, "q4");
    assert_abs_diff_eq!(excess, 0.8, epsilon = 1e-12);

    // The planner's error carries the CL index and the message.
    match e.clone().into_plan_error(17) {
        PlanError::Unreachable { index, reason } => {
            assert_eq!(index, 17);
            assert_eq!(reason, e.to_string());
            assert!(
                reason.contains("q4") && reason.contains("0.800000"),
                "{reason}"
            );
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn rounding_at_a_limit_is_accepted_and_clamped() {
    let m = machine();
    // C on the q1 upper limit within the tolerance.
    let c = Vector3::new(1.6 + 0.5 * STROKE_TOLERANCE, 0.5, 0.5);
    let q = inverse(&c, &Vector3::z(), 0.0, None, m.limits()).unwrap();
    assert_eq!(q[0], 1.6);
    // Horizontal axis: q5 = π/2 exactly.
    let (_, q5) = rotary_ikt(&Vector3::x(), None, Q4_LIMITS, Q5_LIMITS).unwrap();
    assert_eq!(q5, FRAC_PI_2);
}

#[test]
fn invalid_inputs_are_errors_not_nan() {
    let m = machine();
    let l = m.limits();
    let nan = Vector3::new(f64::NAN, 0.0, 1.0);
    assert!(matches!(
        rotary_ikt(&nan, None, Q4_LIMITS, Q5_LIMITS),
        Err(IktError::InvalidInput {
            what: "tool axis",
            ..
        })
    ));
    assert!(matches!(
        rotary_ikt(&Vector3::new(0.0, 0.0, 1.1), None, Q4_LIMITS, Q5_LIMITS),
        Err(IktError::InvalidInput {
            what: "tool axis",
            ..
        })
    ));
    assert!(matches!(
        rotary_ikt(&Vector3::z(), Some(f64::NAN), Q4_LIMITS, Q5_LIMITS),
        Err(IktError::InvalidInput {
            what: "previous q4",
            ..
        })
    ));
    assert!(matches!(
        inverse(
            &Vector3::new(0.5, f64::INFINITY, 0.5),
            &Vector3::z(),
            -0.05,
            None,
            l
        ),
        Err(IktError::InvalidInput {
            what: "CL point",
            ..
        })
    ));
    assert!(matches!(
        inverse(
            &Vector3::new(0.5, 0.5, 0.5),
            &Vector3::z(),
            f64::NAN,
            None,
            l
        ),
        Err(IktError::InvalidInput { what: "q6", .. })
    ));
}
