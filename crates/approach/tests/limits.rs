//! Velocity, acceleration and jerk limits at every 1 ms sample of planned moves.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::*;
use kerf_approach::{JointLimit, JointMove, Route, WaypointMove};

/// Relative tolerance on the limits (rounding only: the bounds are exact).
const TOL: f64 = 1e-9;
const H: f64 = 0.001;

#[test]
fn direct_approach_respects_every_limit_at_1ms() {
    let circles = far();
    let world = |q: &[f64]| clearance(&circles, q);
    let a = planner(&world, vec![]).approach(&START, &GOAL).unwrap();
    assert_eq!(a.route, Route::Direct);
    let samples = a.path.samples(H).unwrap();
    let peak = assert_within_limits(&samples, H, &limits(), TOL);
    // Minimal time: the binding limit is nearly reached (the duration is only rounded up to
    // a whole control period).
    assert!(peak.iter().any(|&p| p > 0.98), "{peak:?}");
}

#[test]
fn via_approach_respects_every_limit_at_1ms() {
    let circles = fixture();
    let world = |q: &[f64]| clearance(&circles, q);
    let a = planner(&world, vec![SAFE.to_vec()])
        .approach(&START, &GOAL)
        .unwrap();
    assert_eq!(a.route, Route::ViaSafePose(0));
    let samples = a.path.samples(H).unwrap();
    assert_within_limits(&samples, H, &limits(), TOL);
    // The via pose is a sample, at rest.
    let via = a.path.leg_offsets()[1];
    let s = samples.iter().find(|s| (s.t - via).abs() < 1e-9).unwrap();
    assert_eq!(s.q, SAFE.to_vec());
    assert!(s.qd.iter().all(|v| *v == 0.0));
}

#[test]
fn each_limit_can_be_the_binding_one() {
    let q0 = [0.0, 0.0];
    // Small moves are jerk-bound, long ones velocity-bound; with a high velocity limit, a
    // long move is acceleration-bound.
    for (target, max_velocity, index) in [
        ([0.001, 0.0], 1.5, 2),
        ([2.0, 0.0], 100.0, 1),
        ([2.9, 0.0], 1.5, 0),
    ] {
        let mut base = limits();
        base[0].max_velocity = max_velocity;
        let m = JointMove::new(&q0, &target, &base).unwrap();
        let path = WaypointMove::from_legs(vec![m]).unwrap();
        let h = path.duration() / 2000.0;
        let samples = path.samples(h).unwrap();
        let peak = assert_within_limits(&samples, h, &base, 1e-6);
        assert!(peak[index] > 0.99, "{target:?}: {peak:?}");
    }
}

#[test]
fn many_random_moves_respect_the_limits() {
    // A small deterministic generator: no dependency.
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..40 {
        let limits: Vec<JointLimit> = (0..3)
            .map(|j| JointLimit {
                name: format!("j{j}"),
                min_position: -3.0,
                max_position: 3.0,
                max_velocity: 0.1 + 3.0 * next(),
                max_acceleration: 0.1 + 10.0 * next(),
                max_jerk: 1.0 + 100.0 * next(),
            })
            .collect();
        let waypoints: Vec<Vec<f64>> = (0..3)
            .map(|_| (0..3).map(|_| -3.0 + 6.0 * next()).collect())
            .collect();
        let path = WaypointMove::through(&waypoints, &limits).unwrap();
        let samples = path.samples(H).unwrap();
        assert_within_limits(&samples, H, &limits, TOL);
    }
}
