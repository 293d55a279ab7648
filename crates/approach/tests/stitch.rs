//! Approach + process + retract stitched into one timeline.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::*;
use kerf_approach::{ApproachError, Boundary, Sample, Stitched, WaypointMove};

/// A process from GOAL to `end`: a slow minimum-jerk move sampled every 2 ms, its clock
/// starting at 100 s (any origin).
fn process(end: [f64; 2]) -> Vec<Sample> {
    let m = WaypointMove::through(&[GOAL, end], &limits()).unwrap();
    let m = WaypointMove::from_legs(vec![m.legs()[0].with_duration(1.0).unwrap()]).unwrap();
    m.samples(0.002)
        .unwrap()
        .into_iter()
        .map(|s| Sample {
            t: s.t + 100.0,
            ..s
        })
        .collect()
}

fn parts() -> Stitched {
    let circles = fixture();
    let world = |q: &[f64]| clearance(&circles, q);
    let p = planner(&world, vec![SAFE.to_vec()]);
    let end = [1.3, -0.2];
    let approach = p.approach(&START, &GOAL).unwrap().path;
    let retract = p.retract(&end, &[SAFE]).unwrap().path;
    Stitched {
        approach,
        process: process(end),
        retract,
    }
}

#[test]
fn stitched_timeline_is_time_ordered_with_the_process_unchanged() {
    let parts = parts();
    let tl = parts.timeline(PERIOD).unwrap();
    assert_eq!(tl.process_start, parts.approach.duration());
    assert!((tl.process_end - tl.process_start - 1.0).abs() < 1e-12);
    assert!(tl.samples.windows(2).all(|w| w[1].t > w[0].t));
    assert_eq!(tl.samples[0].t, 0.0);
    assert_eq!(tl.samples[0].q, START.to_vec());
    let last = tl.samples.last().unwrap();
    assert_eq!(last.q, SAFE.to_vec());
    assert!((last.t - tl.process_end - parts.retract.duration()).abs() < 1e-9);
    // The process part: the same samples, shifted.
    let i0 = tl
        .samples
        .iter()
        .position(|s| s.t == tl.process_start)
        .unwrap();
    let shift = tl.process_start - parts.process[0].t;
    for (k, p) in parts.process.iter().enumerate() {
        let s = &tl.samples[i0 + k];
        assert_eq!((&s.q, &s.qd, &s.qdd), (&p.q, &p.qd, &p.qdd));
        assert!((s.t - (p.t + shift)).abs() < 1e-9);
    }
    assert_eq!(tl.samples[i0 + parts.process.len() - 1].t, tl.process_end);
    // Nothing jumps: the whole timeline respects the limits at its own steps.
    assert_within_limits(&tl.samples, PERIOD, &limits(), 1e-9);
    // Counts: approach without its end, process, retract without its start.
    let n_a = (parts.approach.duration() / PERIOD).round() as usize;
    let n_r = (parts.retract.duration() / PERIOD).round() as usize;
    assert_eq!(tl.samples.len(), n_a + parts.process.len() + n_r);
}

#[test]
fn discontinuities_are_refused() {
    let mut parts = parts();
    parts.process[0].q[1] += 1e-6;
    let e = parts.timeline(PERIOD).unwrap_err();
    assert!(
        matches!(
            e,
            ApproachError::Discontinuity {
                boundary: Boundary::ProcessStart,
                joint: 1,
                quantity: "position",
                ..
            }
        ),
        "{e}"
    );
    let mut parts = self::parts();
    parts.process.last_mut().unwrap().qd[0] = 0.1;
    let e = parts.timeline(PERIOD).unwrap_err();
    assert!(
        matches!(
            e,
            ApproachError::Discontinuity {
                boundary: Boundary::ProcessEnd,
                quantity: "velocity",
                ..
            }
        ),
        "{e}"
    );
}

#[test]
fn malformed_processes_are_refused() {
    let mut parts = parts();
    parts.process[5].t = parts.process[4].t;
    assert!(matches!(
        parts.timeline(PERIOD),
        Err(ApproachError::InvalidProcess { index: 5, .. })
    ));
    let mut parts = self::parts();
    parts.process[3].qdd.pop();
    assert!(matches!(
        parts.timeline(PERIOD),
        Err(ApproachError::InvalidProcess { index: 3, .. })
    ));
    let mut parts = self::parts();
    parts.process[7].qd[0] = f64::INFINITY;
    assert!(matches!(
        parts.timeline(PERIOD),
        Err(ApproachError::InvalidProcess { index: 7, .. })
    ));
    let mut parts = self::parts();
    parts.process.clear();
    assert_eq!(parts.timeline(PERIOD), Err(ApproachError::EmptyProcess));
    let parts = self::parts();
    for period in [0.0, -1.0, f64::NAN] {
        assert!(matches!(
            parts.timeline(period),
            Err(ApproachError::InvalidPeriod { .. })
        ));
    }
}

#[test]
fn tuple_samples_convert() {
    let s: Sample = (0.5, vec![1.0], vec![0.0], vec![0.0]).into();
    assert_eq!(s, Sample::at_rest(0.5, vec![1.0]));
}
