//! The conservative-advancement bound never accepts a motion that comes closer than the
//! clearance (random worlds, dense scans), and no input makes the crate panic.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::*;
use kerf_approach::{
    ApproachPlanner, ApproachSettings, Clearance, JointLimit, JointMove, Sample, Stitched,
    WaypointMove,
};

/// xorshift64: deterministic, no dependency.
struct Rng(u64);

impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }
}

#[test]
fn accepted_moves_keep_the_clearance_between_samples() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let (mut accepted, mut refused) = (0, 0);
    for _ in 0..60 {
        let circles: Vec<Circle> = (0..3)
            .map(|_| Circle {
                name: "c",
                center: [rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0)],
                radius: rng.uniform(0.02, 0.3),
            })
            .collect();
        let world = |q: &[f64]| clearance(&circles, q);
        let p = planner(&world, vec![]);
        let start = [rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0)];
        let goal = [rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0)];
        match p.approach(&start, &goal) {
            Ok(a) => {
                accepted += 1;
                for s in a.path.samples(2e-4).unwrap() {
                    let d = world(&s.q).distance;
                    assert!(d >= CLEARANCE - 1e-12, "t = {} d = {d}", s.t);
                }
            }
            Err(_) => refused += 1,
        }
    }
    // Both outcomes occur, or the test proves nothing.
    assert!(
        accepted > 5 && refused > 5,
        "{accepted} accepted, {refused} refused"
    );
}

#[test]
fn hostile_inputs_never_panic() {
    let odd = [
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        0.0,
        -0.0,
        -1.0,
        1e-300,
        1e300,
        f64::MAX,
        f64::MIN_POSITIVE,
    ];
    for &x in &odd {
        let limit = JointLimit {
            name: "j".into(),
            min_position: x.min(-x),
            max_position: x.max(-x),
            max_velocity: x,
            max_acceleration: x.abs(),
            max_jerk: 1.0,
        };
        let _ = limit.check();
        let _ = JointMove::new(&[x], &[-x], std::slice::from_ref(&limit));
        let _ = WaypointMove::through(&[[0.0], [x]], &[limit]);
        let _ = ApproachSettings::builder()
            .clearance(x)
            .control_period(x)
            .lipschitz(vec![x])
            .max_duration(x)
            .safe_pose(vec![x])
            .build();
        // A world that answers the odd value everywhere.
        let world = |_: &[f64]| Clearance::new(x, "odd");
        let p = planner(&world, vec![SAFE.to_vec()]);
        let _ = p.approach(&[x, 0.0], &GOAL);
        let _ = p.approach(&START, &GOAL);
        let _ = p.retract(&GOAL, &[[x, x]]);
        let m = JointMove::new(&[0.0, 0.0], &[1.0, 1.0], &limits()).unwrap();
        let _ = m.with_duration(x);
        let _ = m.sample(x);
        let path = WaypointMove::from_legs(vec![m]).unwrap();
        let _ = path.sample(x);
        let _ = path.samples(x);
        let stitched = Stitched {
            approach: path.clone(),
            process: vec![Sample {
                t: x,
                q: vec![1.0, x],
                qd: vec![0.0; 2],
                qdd: vec![],
            }],
            retract: path.clone(),
        };
        let _ = stitched.timeline(x);
        let _ = stitched.timeline(PERIOD);
    }
    // Wrong joint counts everywhere.
    let world = |q: &[f64]| clearance(&far(), q);
    let settings = ApproachSettings::builder()
        .clearance(0.01)
        .lipschitz(vec![1.0; 2])
        .build()
        .unwrap();
    let p = ApproachPlanner::new(settings, limits(), &world).unwrap();
    let _ = p.approach(&[], &[]);
    let _ = p.retract(&[0.0; 3], &[[0.0; 1]]);
    let _ = JointMove::new(&[0.0], &[0.0, 1.0], &limits());
    let _ = WaypointMove::from_legs(vec![]);
}
