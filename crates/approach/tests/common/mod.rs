//! A 2-link planar arm with capsule links and circle obstacles: exact distances for the
//! integration tests.
#![allow(dead_code)]

use kerf_approach::{ApproachPlanner, ApproachSettings, Clearance, JointLimit, Sample};

/// Link lengths (m).
pub const L1: f64 = 1.0;
pub const L2: f64 = 0.8;
/// Capsule radius of both links (m).
pub const LINK_RADIUS: f64 = 0.05;
/// The clearance of the tests (m).
pub const CLEARANCE: f64 = 0.05;
/// The executor's control period (s).
pub const PERIOD: f64 = 0.004;

/// A circular obstacle in the arm's plane.
#[derive(Debug, Clone)]
pub struct Circle {
    pub name: &'static str,
    pub center: [f64; 2],
    pub radius: f64,
}

/// Elbow and tip positions.
pub fn fk(q: &[f64]) -> ([f64; 2], [f64; 2]) {
    let elbow = [L1 * q[0].cos(), L1 * q[0].sin()];
    let a = q[0] + q[1];
    let tip = [elbow[0] + L2 * a.cos(), elbow[1] + L2 * a.sin()];
    (elbow, tip)
}

/// Distance from `p` to the segment `a`–`b`.
pub fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let ab = [b[0] - a[0], b[1] - a[1]];
    let ap = [p[0] - a[0], p[1] - a[1]];
    let len2 = ab[0] * ab[0] + ab[1] * ab[1];
    let s = if len2 > 0.0 {
        ((ap[0] * ab[0] + ap[1] * ab[1]) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let d = [ap[0] - s * ab[0], ap[1] - s * ab[1]];
    (d[0] * d[0] + d[1] * d[1]).sqrt()
}

/// Exact signed distance from the arm (two capsules) to the nearest circle, and its name.
pub fn clearance(circles: &[Circle], q: &[f64]) -> Clearance {
    let (elbow, tip) = fk(q);
    let mut best = Clearance::new(f64::INFINITY, "none");
    for c in circles {
        let d = segment_distance(c.center, [0.0, 0.0], elbow)
            .min(segment_distance(c.center, elbow, tip))
            - c.radius
            - LINK_RADIUS;
        if d < best.distance {
            best = Clearance::new(d, c.name);
        }
    }
    best
}

/// Lipschitz bounds: any capsule point is at most `L1 + L2 + r` from the shoulder axis and
/// `L2 + r` from the elbow axis.
pub fn lipschitz() -> Vec<f64> {
    vec![L1 + L2 + LINK_RADIUS, L2 + LINK_RADIUS]
}

pub fn limits() -> Vec<JointLimit> {
    vec![
        JointLimit {
            name: "shoulder".into(),
            min_position: -3.0,
            max_position: 3.0,
            max_velocity: 1.5,
            max_acceleration: 4.0,
            max_jerk: 30.0,
        },
        JointLimit {
            name: "elbow".into(),
            min_position: -3.0,
            max_position: 3.0,
            max_velocity: 2.0,
            max_acceleration: 6.0,
            max_jerk: 50.0,
        },
    ]
}

/// Start and goal on either side of angle 0 (the arm stretched out).
pub const START: [f64; 2] = [-1.2, 0.0];
pub const GOAL: [f64; 2] = [1.2, 0.0];
/// The arm folded, elbow at (1, 0), tip back towards the base.
pub const SAFE: [f64; 2] = [0.0, 2.6];

/// A fixture at angle 0 that the stretched arm hits but the folded arm clears.
pub fn fixture() -> Vec<Circle> {
    vec![Circle {
        name: "fixture",
        center: [1.7, 0.0],
        radius: 0.08,
    }]
}

/// A post at angle 0 next to the elbow: every move across angle 0 hits it.
pub fn post() -> Vec<Circle> {
    vec![Circle {
        name: "post",
        center: [1.05, 0.0],
        radius: 0.05,
    }]
}

/// Far away: nothing is in the way.
pub fn far() -> Vec<Circle> {
    vec![Circle {
        name: "far",
        center: [-3.0, -3.0],
        radius: 0.1,
    }]
}

pub fn settings(safe_poses: Vec<Vec<f64>>) -> ApproachSettings {
    ApproachSettings::builder()
        .clearance(CLEARANCE)
        .control_period(PERIOD)
        .lipschitz(lipschitz())
        .safe_poses(safe_poses)
        .build()
        .unwrap()
}

pub fn planner<'w>(
    world: &'w dyn Fn(&[f64]) -> Clearance,
    safe_poses: Vec<Vec<f64>>,
) -> ApproachPlanner<'w> {
    ApproachPlanner::new(settings(safe_poses), limits(), world).unwrap()
}

/// Checks velocity, acceleration and jerk at every step of `samples` (sampled every `h`)
/// against `limits`, by finite differences of positions, velocities and accelerations and on
/// the analytic values, with a relative tolerance `tol`. Returns the peak ratios
/// (v, a, j) of sample value to limit over all joints.
pub fn assert_within_limits(
    samples: &[Sample],
    h: f64,
    limits: &[JointLimit],
    tol: f64,
) -> [f64; 3] {
    let mut peak = [0.0f64; 3];
    for (j, l) in limits.iter().enumerate() {
        let (v, a, jerk) = (l.max_velocity, l.max_acceleration, l.max_jerk);
        for s in samples {
            assert!(
                s.qd[j].abs() <= v * (1.0 + tol),
                "{}: qd {} at {}",
                l.name,
                s.qd[j],
                s.t
            );
            assert!(
                s.qdd[j].abs() <= a * (1.0 + tol),
                "{}: qdd {} at {}",
                l.name,
                s.qdd[j],
                s.t
            );
            assert!(s.q[j] >= l.min_position && s.q[j] <= l.max_position);
            peak[0] = peak[0].max(s.qd[j].abs() / v);
            peak[1] = peak[1].max(s.qdd[j].abs() / a);
        }
        for w in samples.windows(2) {
            let dt = w[1].t - w[0].t;
            assert!(
                dt > 0.0 && dt <= h * (1.0 + 1e-9),
                "step {dt} at {}",
                w[0].t
            );
            // Mean-value bounds: a difference quotient is a mean of the derivative.
            let fd_v = (w[1].q[j] - w[0].q[j]) / dt;
            let fd_a = (w[1].qd[j] - w[0].qd[j]) / dt;
            let fd_j = (w[1].qdd[j] - w[0].qdd[j]) / dt;
            assert!(
                fd_v.abs() <= v * (1.0 + tol),
                "{}: fd v {fd_v} at {}",
                l.name,
                w[0].t
            );
            assert!(
                fd_a.abs() <= a * (1.0 + tol),
                "{}: fd a {fd_a} at {}",
                l.name,
                w[0].t
            );
            assert!(
                fd_j.abs() <= jerk * (1.0 + tol),
                "{}: fd j {fd_j} at {}",
                l.name,
                w[0].t
            );
            peak[2] = peak[2].max(fd_j.abs() / jerk);
            // The analytic velocity is consistent with the positions (trapezoid rule).
            let mean_v = 0.5 * (w[0].qd[j] + w[1].qd[j]);
            assert!(
                (fd_v - mean_v).abs() <= 1e-3 * v + 1e-9,
                "{}: {fd_v} vs {mean_v}",
                l.name
            );
        }
        // Second and third differences of the positions alone (uniform steps only).
        for w in samples.windows(4) {
            let uniform = w.windows(2).all(|p| ((p[1].t - p[0].t) - h).abs() < 1e-12);
            if !uniform {
                continue;
            }
            let d2 = (w[2].q[j] - 2.0 * w[1].q[j] + w[0].q[j]) / (h * h);
            let d3 = (w[3].q[j] - 3.0 * w[2].q[j] + 3.0 * w[1].q[j] - w[0].q[j]) / (h * h * h);
            assert!(
                d2.abs() <= a * (1.0 + tol),
                "{}: d2 {d2} at {}",
                l.name,
                w[0].t
            );
            assert!(
                d3.abs() <= jerk * (1.0 + tol),
                "{}: d3 {d3} at {}",
                l.name,
                w[0].t
            );
        }
    }
    peak
}
