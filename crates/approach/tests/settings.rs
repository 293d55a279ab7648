//! Settings validation: every number finite and > 0.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::*;
use kerf_approach::{ApproachError, ApproachPlanner, ApproachSettings, ClearanceCheck};

const BAD: [f64; 5] = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 0.0, -1.0];

fn valid() -> kerf_approach::ApproachSettingsBuilder {
    ApproachSettings::builder()
        .clearance(0.01)
        .lipschitz(vec![1.0, 0.5])
}

fn field_of(e: &ApproachError) -> &str {
    match e {
        ApproachError::InvalidSetting { field, .. } => field,
        other => panic!("{other}"),
    }
}

#[test]
fn defaults() {
    let s = valid().build().unwrap();
    assert_eq!(s.control_period(), 0.004);
    assert_eq!(s.max_duration(), 600.0);
    assert!(s.safe_poses().is_empty());
    assert_eq!(s.lipschitz(), &[1.0, 0.5]);
}

#[test]
fn every_number_must_be_finite_and_positive() {
    for v in BAD {
        let e = valid().clearance(v).build().unwrap_err();
        assert_eq!(field_of(&e), "clearance", "{v}");
        let e = valid().control_period(v).build().unwrap_err();
        assert_eq!(field_of(&e), "control_period", "{v}");
        let e = valid().max_duration(v).build().unwrap_err();
        assert_eq!(field_of(&e), "max_duration", "{v}");
        let e = valid().lipschitz(vec![1.0, v]).build().unwrap_err();
        assert_eq!(field_of(&e), "lipschitz[1]", "{v}");
        assert!(e.to_string().contains("finite and > 0"), "{e}");
    }
    for v in [f64::NAN, f64::INFINITY] {
        let e = valid().safe_pose(vec![0.0, v]).build().unwrap_err();
        assert_eq!(field_of(&e), "safe_poses[0][1]");
    }
    let e = valid().lipschitz(vec![]).build().unwrap_err();
    assert_eq!(field_of(&e), "lipschitz");
    // Bounded sample count per move.
    let e = valid()
        .control_period(1e-6)
        .max_duration(10.0)
        .build()
        .unwrap_err();
    assert_eq!(field_of(&e), "max_duration");
}

#[test]
fn required_settings_and_lengths() {
    let e = ApproachSettings::builder()
        .lipschitz(vec![1.0])
        .build()
        .unwrap_err();
    assert_eq!(e, ApproachError::MissingSetting { field: "clearance" });
    let e = ApproachSettings::builder()
        .clearance(0.1)
        .build()
        .unwrap_err();
    assert_eq!(e, ApproachError::MissingSetting { field: "lipschitz" });
    assert!(matches!(
        valid().safe_pose(vec![0.0]).build(),
        Err(ApproachError::JointCount {
            expected: 2,
            found: 1,
            ..
        })
    ));
    // Three Lipschitz bounds for a 2-joint robot.
    let world = |q: &[f64]| clearance(&far(), q);
    let s = valid().lipschitz(vec![1.0, 1.0, 1.0]).build().unwrap();
    assert!(matches!(
        ApproachPlanner::new(s, limits(), &world),
        Err(ApproachError::JointCount {
            expected: 2,
            found: 3,
            ..
        })
    ));
    let mut l = limits();
    l[1].max_jerk = f64::NAN;
    let e = ApproachPlanner::new(valid().build().unwrap(), l, &world).unwrap_err();
    assert!(
        matches!(&e, ApproachError::InvalidJointLimit { joint, field: "max_jerk", .. } if joint == "elbow"),
        "{e}"
    );
    assert_eq!(
        ApproachPlanner::new(valid().build().unwrap(), vec![], &world).unwrap_err(),
        ApproachError::NoJoints
    );
}

#[test]
fn clearance_check_validates_too() {
    for v in BAD {
        assert!(ClearanceCheck::new(v, 0.004, vec![1.0]).is_err());
        assert!(ClearanceCheck::new(0.01, v, vec![1.0]).is_err());
        assert!(ClearanceCheck::new(0.01, 0.004, vec![v]).is_err());
    }
    assert!(ClearanceCheck::new(0.01, 0.004, vec![]).is_err());
}
