//! `check_executable`: the executor's validation from rest at the first point, the check
//! every planner runs on its output.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::{names, pt, robot};
use kerf_executor::{check_executable, ExecutorConfig, ExecutorError, TrajectoryRequest};

/// Two joints at 0.5 / −0.5, then a cubic move of `d` in 1 s back to rest.
fn planned(d: f64, reversed: bool) -> TrajectoryRequest {
    let limits = robot(2, 3.0, 2.0, 10.0);
    let mut joint_names = names(&limits);
    let (mut p0, mut p1) = (vec![0.5, -0.5], vec![0.5 + d, -0.5]);
    if reversed {
        joint_names.reverse();
        p0.reverse();
        p1.reverse();
    }
    TrajectoryRequest {
        joint_names,
        points: vec![
            pt(0.0, &p0, &[0.0, 0.0], &[]),
            pt(1.0, &p1, &[0.0, 0.0], &[]),
        ],
        start_time: None,
    }
}

#[test]
fn a_plan_from_rest_at_its_first_point_is_executable_in_any_joint_order() {
    let limits = robot(2, 3.0, 2.0, 10.0);
    let cfg = ExecutorConfig::default();
    for reversed in [false, true] {
        // Cubic rest to rest: peak velocity 1.5 d / T, peak acceleration 6 d / T².
        let v = check_executable(&limits, &cfg, &planned(1.0, reversed)).expect("executable");
        assert_eq!(v.final_positions(), &[1.5, -0.5]);
        assert!((v.duration() - 1.0).abs() < 1e-12);
        // A start time is taken as now: the same answer.
        let mut stamped = planned(1.0, reversed);
        stamped.start_time = Some(1.7e9);
        assert!(check_executable(&limits, &cfg, &stamped).is_ok());
    }
}

#[test]
fn limits_on_the_interpolated_curve_and_empty_plans_are_refused() {
    let limits = robot(2, 3.0, 2.0, 10.0);
    let cfg = ExecutorConfig::default();
    // d = 1.8: peak acceleration 10.8 > 10 at the first point (velocity 2.7 > 2 too; the
    // acceleration at t = 0 is found first).
    let e = check_executable(&limits, &cfg, &planned(1.8, false)).unwrap_err();
    assert!(
        matches!(
            e,
            ExecutorError::AccelerationLimit { .. } | ExecutorError::VelocityLimit { .. }
        ),
        "{e}"
    );
    // Beyond the position limit 3.
    let e = check_executable(&limits, &cfg, &planned(2.6, false)).unwrap_err();
    assert!(e.to_string().contains("joint 'j1'"), "{e}");
    let empty = TrajectoryRequest {
        joint_names: names(&limits),
        points: Vec::new(),
        start_time: None,
    };
    assert!(matches!(
        check_executable(&limits, &cfg, &empty),
        Err(ExecutorError::EmptyTrajectory)
    ));
}
