//! Derived cells (`MillCell::with_path`, `with_process`,
//! `with_state_limits`) and the tool pose / joints at an arc length
//! (`tool_pose_at`, `joints_at`): what a planner request changes, checked
//! against the default cell and analytic references.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_mill::{MillCell, MillError, PathSpec, StateLimits};
use nalgebra::Vector3;

fn cell() -> MillCell {
    MillCell::default_cell().expect("default cell")
}

/// The seed 004 points of `PathSpec::default()` are the cell file's: the
/// derived cell has the identical path and evaluates identically.
#[test]
fn with_path_of_the_default_spec_reproduces_the_cell() {
    let cell = cell();
    let same = cell.with_path(&PathSpec::default()).expect("same path");
    assert_eq!(same.path(), cell.path());
    assert_eq!(same.characteristic_length(), cell.characteristic_length());
    for k in [0, 37, 99] {
        let a = cell.evaluate(k, 0.5, None).expect("evaluate");
        let b = same.evaluate(k, 0.5, None).expect("evaluate");
        assert_eq!(a, b);
    }
}

/// Translating the points translates every segment (midpoints, ends) by
/// the same vector and leaves lengths and cutting frames unchanged; the
/// characteristic length stays the cell's (documented).
#[test]
fn with_path_of_translated_points_translates_the_segments() {
    let cell = cell();
    let shift = Vector3::new(0.05, 0.02, -0.1);
    let spec = PathSpec {
        points: PathSpec::default()
            .points
            .iter()
            .map(|p| [p[0] + shift.x, p[1] + shift.y, p[2] + shift.z])
            .collect(),
        ..PathSpec::default()
    };
    let moved = cell.with_path(&spec).expect("moved path");
    assert_eq!(moved.characteristic_length(), cell.characteristic_length());
    assert_eq!(moved.path().segments().len(), 100);
    let mut worst = 0.0f64;
    for (a, b) in cell.path().segments().iter().zip(moved.path().segments()) {
        worst = worst
            .max((b.mid - a.mid - shift).norm())
            .max((b.start - a.start - shift).norm())
            .max((b.end - a.end - shift).norm())
            .max((b.length - a.length).abs())
            .max((b.cutting_frame.x - a.cutting_frame.x).norm())
            .max((b.cutting_frame.z - a.cutting_frame.z).norm());
    }
    println!("translated path: worst deviation {worst:.2e}");
    assert!(worst < 1e-9, "{worst}");
    // The moved path is still reachable at g = 0.5 rad everywhere.
    let mut prev = None;
    for k in 0..100 {
        let s = moved.evaluate(k, 0.5, prev.as_ref()).expect("reachable");
        prev = Some(s.joints);
    }
}

/// Four corners of a square in z = 1.7 and the centre lifted by h: the
/// best-fit plane is z = 1.7 + h/5 by symmetry (the centre carries no x/y
/// lever), so the worst point is the centre (index 2) at 4h/5.
#[test]
fn with_path_not_coplanar_names_the_worst_point_and_its_distance() {
    let cell = cell();
    let h = 1e-3;
    let spec = PathSpec {
        points: vec![
            [1.5, -0.1, 1.7],
            [1.7, -0.1, 1.7],
            [1.6, 0.0, 1.7 + h],
            [1.7, 0.1, 1.7],
            [1.5, 0.1, 1.7],
        ],
        ..PathSpec::default()
    };
    match cell.with_path(&spec) {
        Err(MillError::NotCoplanar {
            worst_point,
            distance,
            ..
        }) => {
            assert_eq!(worst_point, 2);
            assert!((distance - 0.8 * h).abs() < 1e-12, "{distance}");
        }
        other => panic!("expected NotCoplanar, got {other:?}"),
    }
    // One point: refused by name.
    let one = PathSpec {
        points: vec![[1.5, 0.0, 1.7]],
        ..PathSpec::default()
    };
    assert!(matches!(
        cell.with_path(&one),
        Err(MillError::InvalidParameter { ref name, .. }) if name.contains("points")
    ));
}

/// The process is replaced and validated; nothing else changes.
#[test]
fn with_process_replaces_only_the_process() {
    let cell = cell();
    let mut process = cell.milling_process();
    process.radius = 0.02;
    process.teeth = 4;
    let derived = cell.with_process(process).expect("process");
    assert_eq!(derived.milling_process(), process);
    assert_eq!(derived.path(), cell.path());
    assert_eq!(derived.state_limits(), cell.state_limits());
    assert_eq!(
        derived.evaluate(50, 0.0, None).expect("evaluate"),
        cell.evaluate(50, 0.0, None).expect("evaluate")
    );
    process.teeth = 0;
    assert!(matches!(
        cell.with_process(process),
        Err(MillError::Chatter(_))
    ));
    let mut nan = cell.milling_process();
    nan.kt = f64::NAN;
    assert!(cell.with_process(nan).is_err());
}

/// Limits are validated by the rules of the YAML and then enforced by
/// `evaluate` (g outside the range is refused).
#[test]
fn with_state_limits_is_validated_like_the_yaml() {
    let cell = cell();
    let base = *cell.state_limits();
    let narrow = StateLimits {
        spindle_rpm: [2500.0, 3000.0],
        feed: [0.01, 0.05],
        redundancy_angle: [-1.0, 1.0],
        max_feed_step: 2e-3,
        max_spindle_step_rpm: 10.0,
        max_redundancy_step: 0.1,
    };
    let derived = cell.with_state_limits(narrow).expect("limits");
    assert_eq!(*derived.state_limits(), narrow);
    assert_eq!(derived.path(), cell.path());
    assert!(derived.evaluate(10, 0.9, None).is_ok());
    assert!(matches!(
        derived.evaluate(10, 1.5, None),
        Err(MillError::InvalidParameter { .. })
    ));
    let bad: Vec<(StateLimits, &str)> = vec![
        (
            StateLimits {
                feed: [0.05, 0.01],
                ..base
            },
            "state_limits.feed [m/s][1]",
        ),
        (
            StateLimits {
                spindle_rpm: [f64::NAN, 3000.0],
                ..base
            },
            "state_limits.spindle_rpm [rpm][0]",
        ),
        (
            StateLimits {
                spindle_rpm: [0.0, 3000.0],
                ..base
            },
            "state_limits.spindle_rpm[0] [rpm]",
        ),
        (
            StateLimits {
                feed: [-0.01, 0.06],
                ..base
            },
            "state_limits.feed [m/s][0]",
        ),
        (
            StateLimits {
                redundancy_angle: [-1.0, 4.0],
                ..base
            },
            "state_limits.redundancy_angle [rad][1]",
        ),
        (
            StateLimits {
                max_feed_step: 0.0,
                ..base
            },
            "state_limits.max_feed_step [m/s]",
        ),
        (
            StateLimits {
                max_redundancy_step: -0.1,
                ..base
            },
            "state_limits.max_redundancy_step [rad]",
        ),
    ];
    for (limits, field) in bad {
        match cell.with_state_limits(limits) {
            Err(MillError::InvalidParameter { name, .. }) => assert_eq!(name, field),
            other => panic!("{field}: expected InvalidParameter, got {other:?}"),
        }
    }
}

/// At a segment's arc-length midpoint `joints_at` is `evaluate`'s IK; at
/// the path ends the forward kinematics of `joints_at` puts the tool tip on
/// the path's end points with the tool axis along the approach direction
/// and the tool x axis at angle g from the tangent (finite-difference
/// tangent, an independent reference).
#[test]
fn joints_at_matches_evaluate_and_the_forward_kinematics() {
    let cell = cell();
    let path = cell.path();
    let total = path.total_length();
    let n = path.segments().len() as f64;
    let g = 0.7;
    let mut prev: Option<[f64; 6]> = None;
    for k in 0..100 {
        let s = total * (k as f64 + 0.5) / n;
        let q = cell.joints_at(s, g, prev.as_ref()).expect("joints");
        let e = cell.evaluate(k, g, prev.as_ref()).expect("evaluate");
        let d = q
            .iter()
            .zip(&e.joints)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(d < 1e-9, "segment {k}: {d}");
        prev = Some(q);
    }
    let approach = path.approach();
    for (s, u, sign) in [(0.0, 0.0, 1.0), (total, 1.0, -1.0)] {
        let q = cell.joints_at(s, g, None).expect("end joints");
        let pose = cell.kinematics().tcp_pose(&q).expect("fk");
        let p = path.point(u).expect("point");
        assert!((pose.translation.vector - p).norm() < 1e-9);
        let r = pose.rotation.to_rotation_matrix();
        let z = r.matrix().column(2).into_owned();
        let x = r.matrix().column(0).into_owned();
        assert!((z - approach).norm() < 1e-9);
        let step = 1e-7 * sign;
        let t = (path.point(u + step).expect("point") - p).normalize() * sign;
        let expected_x = t * g.cos() + approach.cross(&t) * g.sin();
        assert!(
            (x - expected_x).norm() < 1e-5,
            "{}",
            (x - expected_x).norm()
        );
    }
    assert!(matches!(
        cell.joints_at(total * 1.01, g, None),
        Err(MillError::InvalidParameter { .. })
    ));
    assert!(matches!(
        cell.joints_at(0.0, f64::NAN, None),
        Err(MillError::InvalidParameter { .. })
    ));
    // 5 m away from the base: unreachable, with g in the error.
    let far = cell
        .with_path(&PathSpec {
            points: vec![[6.0, 0.0, 1.7], [6.2, 0.1, 1.7]],
            ..PathSpec::default()
        })
        .expect("far path");
    assert!(matches!(
        far.joints_at(0.0, 0.0, None),
        Err(MillError::Unreachable {
            g: Some(_),
            segment: None,
            ..
        })
    ));
}
