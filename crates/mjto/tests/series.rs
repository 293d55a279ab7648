//! The joint series drawn by `kerf plan cut --plots`: the plan's, and the QI baseline's (seed
//! 001 eq. 2) on the straight cut of `kerf_testparts::straight`.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_mjto::{series::JointSeries, timelaw::TimeLaw, LaserMachine};
use kerf_testparts::straight::straight_cut;

#[test]
fn qi_baseline_of_a_straight_cut() {
    let (request, plan) = straight_cut().unwrap();
    let machine = LaserMachine::default_machine().unwrap();
    let qi = JointSeries::qi_baseline(&request, &plan, machine.limits()).unwrap();
    let law = TimeLaw::new(0.1, 0.2, 8.0, 80.0).unwrap();
    let want = law.sample_times(0.01);
    assert_eq!(qi.times.len(), want.len());
    assert!(qi
        .times
        .iter()
        .zip(&want)
        .all(|(a, b)| (a - b).abs() < 1e-12));
    assert!(qi.times.len() > 50, "{}", qi.times.len());
    let first = qi.positions.first().unwrap();
    let last = qi.positions.last().unwrap();
    // The workpiece frame is 0.2 m above the machine frame; M = C + 0.05 ẑ.
    for (q, x) in [(first, 0.5), (last, 0.6)] {
        assert!((q[0] - x).abs() < 1e-9, "{q:?}");
        assert!((q[1] - 0.7).abs() < 1e-9, "{q:?}");
        assert!((q[2] - 1.25).abs() < 1e-9, "{q:?}");
        assert!(q[3].abs() < 1e-9 && q[4].abs() < 1e-9, "{q:?}");
        assert!((q[5] + 0.05).abs() < 1e-12, "{q:?}");
    }
    // Along x at the feed: the finite-difference velocity of q1 peaks at the time law's
    // peak feed (within the estimator's error at the ramp joints, 0.1 %).
    let peak = qi.velocities.iter().map(|v| v[0]).fold(0.0, f64::max);
    assert!((peak / law.peak_feed() - 1.0).abs() < 1e-3, "{peak}");
    assert!(qi.jerks.iter().all(|j| j[3] == 0.0 && j[4] == 0.0));
}

#[test]
fn the_plan_series_is_the_plan_with_its_jerk() {
    let (_, plan) = straight_cut().unwrap();
    let s = JointSeries::of_plan(&plan);
    assert_eq!(s.times, plan.times);
    assert_eq!(s.positions, plan.positions);
    assert_eq!(s.velocities, plan.velocities);
    assert_eq!(s.accelerations, plan.accelerations);
    // Constant positions: zero jerk.
    assert_eq!(s.jerks.len(), plan.times.len());
    assert!(s.jerks.iter().flatten().all(|j| *j == 0.0));
}

#[test]
fn an_invalid_request_has_no_baseline() {
    let (mut request, plan) = straight_cut().unwrap();
    request.feedrate = -1.0;
    let machine = LaserMachine::default_machine().unwrap();
    assert!(JointSeries::qi_baseline(&request, &plan, machine.limits()).is_err());
}
