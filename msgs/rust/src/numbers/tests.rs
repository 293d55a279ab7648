//! Every numeric leaf of every request message, probed with hostile values.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use serde::{de::DeserializeOwned, Serialize};

use super::probe::{probe_values, rule_of, with_value};
use super::*;
use crate::builtin_interfaces::{Duration, Time};
use crate::control_msgs::{FollowJointTrajectoryGoal, JointComponentTolerance, JointTolerance};
use crate::geometry_msgs::{Point, Pose, Quaternion, Transform, Twist, Vector3};
use crate::msg::{CutRequest, GcodeRequest, MillRequest};
use crate::srv::ValidateTrajectoryRequest;
use crate::std_msgs::Header;
use crate::trajectory_msgs::{
    JointTrajectory, JointTrajectoryPoint, MultiDOFJointTrajectory, MultiDOFJointTrajectoryPoint,
};

fn p(x: f64, y: f64, z: f64) -> Point {
    Point { x, y, z }
}

fn cut() -> CutRequest {
    CutRequest {
        request_id: "c".into(),
        points: vec![p(0.1, 0.2, 0.3), p(0.2, 0.2, 0.3)],
        axes: vec![
            Vector3 {
                x: 0.0,
                y: 0.0,
                z: 1.0
            };
            2
        ],
        feedrate: 0.3,
        feed_acceleration: 8.0,
        feed_jerk: 80.0,
        sample_period: 0.004,
        max_lead_angle: 0.1,
        max_tilt_angle: 0.1,
        mesh: "m.stl".into(),
        workpiece_pose: Pose {
            position: p(0.5, 0.0, 0.1),
            orientation: Quaternion::IDENTITY,
        },
        control_points: 6,
        max_iterations: 10,
        gfd_q4_steps: 13,
        gfd_q5_steps: 9,
        gfd_q6_steps: 5,
        gfd_q4_half_range: 0.35,
        gfd_q5_half_range: 0.3,
        rto_indices: vec![0, 1],
        rto_spacing: 0.15,
        rto_angle: 0.35,
        has_reference_standoff: true,
        reference_standoff: -0.07,
        clearance: 0.001,
        cl_tolerance: 1.5e-4,
        time_budget: 10.0,
        start: "given".into(),
        start_positions: vec![0.8, 0.7, 1.5, 0.0, 0.0, -0.05],
        ..Default::default()
    }
}

fn mill() -> MillRequest {
    MillRequest {
        points: vec![p(1.4, -0.3, 1.7), p(2.1, 0.3, 1.7)],
        segments: 100,
        has_process: true,
        teeth: 2,
        tool_radius: 0.04,
        axial_depth: 0.003,
        kt: 6.44e8,
        kn: 2.37e8,
        entry_angle: 2.356,
        exit_angle: 3.0,
        has_limits: true,
        spindle_min_rpm: 2000.0,
        spindle_max_rpm: 4000.0,
        feed_min: 0.0,
        feed_max: 0.06,
        g_min: -3.0,
        g_max: 3.0,
        max_spindle_step_rpm: 20.0,
        max_feed_step: 1e-3,
        max_g_step: 0.2,
        has_initial_state: true,
        initial_spindle_rpm: 2000.0,
        initial_feed: 0.04,
        initial_g: 0.0,
        time_budget: 10.0,
        has_tolerances: true,
        path_tolerance: 5e-5,
        min_condition_indicator: 0.01,
        start: "given".into(),
        start_positions: vec![0.0; 6],
        ..Default::default()
    }
}

fn gcode() -> GcodeRequest {
    GcodeRequest {
        program: "G1 X10 F600".into(),
        tolerance: 1e-4,
        has_limits: true,
        max_feed: 0.1,
        tangential_acceleration: 8.0,
        tangential_jerk: 80.0,
        normal_acceleration: 8.0,
        normal_jerk: 80.0,
        chord_error: 1e-5,
        contour_error: 5e-5,
        rapid_feed: 0.5,
        has_placement: true,
        origin: p(0.3, 0.3, 0.5),
        redundancy_angle: 0.1,
        standoff_axis: -0.08,
        time_budget: 10.0,
        start: "given".into(),
        start_positions: vec![0.8, 0.7, 1.5, 0.0, 0.0, -0.05],
        ..Default::default()
    }
}

fn stamp() -> Header {
    Header {
        stamp: Time {
            sec: 100,
            nanosec: 5,
        },
        frame_id: String::new(),
    }
}

fn trajectory() -> JointTrajectory {
    let point = |t: i32| JointTrajectoryPoint {
        positions: vec![0.1, 0.2],
        velocities: vec![0.0, 0.1],
        accelerations: vec![0.0, 0.0],
        effort: vec![1.0, 2.0],
        time_from_start: Duration { sec: t, nanosec: 7 },
    };
    JointTrajectory {
        header: stamp(),
        joint_names: vec!["a".into(), "b".into()],
        points: vec![point(0), point(2)],
    }
}

fn goal() -> FollowJointTrajectoryGoal {
    let tol = |v: f64| JointTolerance {
        name: "a".into(),
        position: v,
        velocity: v,
        acceleration: v,
    };
    let ctol = JointComponentTolerance {
        joint_name: "base".into(),
        component: JointComponentTolerance::ROTATION,
        position: 0.1,
        velocity: -1.0,
        acceleration: 0.0,
    };
    let twist = Twist {
        linear: Vector3 {
            x: 0.1,
            y: 0.0,
            z: 0.0,
        },
        angular: Vector3 {
            x: 0.0,
            y: 0.0,
            z: 0.2,
        },
    };
    FollowJointTrajectoryGoal {
        trajectory: trajectory(),
        multi_dof_trajectory: MultiDOFJointTrajectory {
            header: stamp(),
            joint_names: vec!["base".into()],
            points: vec![MultiDOFJointTrajectoryPoint {
                transforms: vec![Transform {
                    translation: Vector3 {
                        x: 1.0,
                        y: 2.0,
                        z: 0.0,
                    },
                    rotation: Quaternion::IDENTITY,
                }],
                velocities: vec![twist],
                accelerations: vec![twist],
                time_from_start: Duration { sec: 1, nanosec: 0 },
            }],
        },
        path_tolerance: vec![tol(0.1)],
        component_path_tolerance: vec![ctol.clone()],
        goal_tolerance: vec![tol(-1.0)],
        component_goal_tolerance: vec![ctol],
        goal_time_tolerance: Duration {
            sec: 0,
            nanosec: 500_000_000,
        },
    }
}

/// The leaves of `example` whose key no declared rule of `T` matches.
fn undeclared<T: NumberRules + Serialize>(example: &T) -> Vec<String> {
    leaves(example)
        .into_iter()
        .filter(|l| rule_of::<T>(&l.key).is_none())
        .map(|l| l.key)
        .collect()
}

/// Sets every numeric leaf of `example` to every probe value in turn and checks the answer of
/// `check_numbers` against the leaf's declared rule. Returns the number of probes.
fn probe_every_leaf<T>(example: &T) -> usize
where
    T: NumberFields + NumberRules + Serialize + DeserializeOwned,
{
    assert_eq!(example.check_numbers(), Ok(()), "the example is valid");
    let missing = undeclared(example);
    assert!(
        missing.is_empty(),
        "numeric fields without a rule: {missing:?}"
    );
    let all = leaves(example);
    // No stale rule: every rule matches a leaf of the example (arrays are non-empty).
    for section in T::SECTIONS {
        for rule in section.rules {
            assert!(
                all.iter().any(|l| l
                    .key
                    .strip_prefix(section.prefix)
                    .is_some_and(|k| rule.matches(k))),
                "rule {}{} matches no field",
                section.prefix,
                rule.field
            );
        }
    }
    let mut probes = 0;
    for leaf in &all {
        let rule = rule_of::<T>(&leaf.key).expect("declared");
        for value in probe_values(leaf.value) {
            probes += 1;
            let mutated = with_value(example, &leaf.path, value).unwrap();
            let got = mutated.check_numbers();
            match rule.check(value, true) {
                Ok(()) => assert_eq!(got, Ok(()), "{} = {value}", leaf.path),
                Err(text) => {
                    let e = got.expect_err(&format!("{} = {value} accepted", leaf.path));
                    assert_eq!(e.field, leaf.path, "{e}");
                    assert_eq!(e.value, value.to_string(), "{e}");
                    assert_eq!(e.rule, text, "{e}");
                }
            }
            // NaN and the infinities are refused by every rule.
            if !value.as_f64().is_finite() {
                assert!(rule.check(value, true).is_err(), "{}", leaf.path);
            }
        }
    }
    probes
}

#[test]
fn every_numeric_field_of_every_request_is_probed() {
    let counts = [
        probe_every_leaf(&cut()),
        probe_every_leaf(&mill()),
        probe_every_leaf(&gcode()),
        probe_every_leaf(&trajectory()),
        probe_every_leaf(&goal()),
        probe_every_leaf(&ValidateTrajectoryRequest {
            trajectory: trajectory(),
        }),
        probe_every_leaf(&crate::msg::ReferencePoint {
            header: stamp(),
            id: 7,
            joint_names: vec!["a".into(), "b".into()],
            positions: vec![0.1, -0.2],
            precision: 1e-4,
        }),
    ];
    assert!(counts.iter().all(|c| *c > 20), "{counts:?}");
}

#[test]
fn a_field_without_a_rule_is_found() {
    #[derive(Serialize)]
    struct Two {
        declared: f64,
        forgotten: Vec<u32>,
    }
    impl NumberRules for Two {
        const SECTIONS: &'static [Section] = &[Section {
            prefix: "",
            rules: &[Rule::closed("declared", 0.0, 1.0, "m")],
        }];
    }
    let two = Two {
        declared: 0.5,
        forgotten: vec![3],
    };
    assert_eq!(undeclared(&two), vec!["forgotten[]".to_string()]);
    // At run time an undeclared leaf is still checked finite.
    #[derive(Serialize)]
    struct Loose {
        x: f64,
    }
    let e = check(&Loose { x: f64::NAN }, &[]).unwrap_err();
    assert_eq!(e.to_string(), "field `x` = NaN: must be finite");
}

#[test]
fn errors_name_the_field_path_with_indices() {
    let mut m = cut();
    m.points[1].y = f64::NAN;
    assert_eq!(
        m.check_numbers().unwrap_err().to_string(),
        "field `points[1].y` = NaN: must be finite"
    );
    let mut m = goal();
    m.trajectory.points[1].velocities[0] = 1e308;
    let e = m.check_numbers().unwrap_err();
    assert_eq!(e.field, "trajectory.points[1].velocities[0]");
    assert_eq!(e.value, "1e308");
    assert_eq!(e.rule, "must be in [-10000, 10000] rad/s or m/s");
    let mut m = mill();
    m.spindle_max_rpm = 1e308;
    assert_eq!(
        m.check_numbers().unwrap_err().to_string(),
        "field `spindle_max_rpm` = 1e308: must be in (0, 100000] rpm (when has_limits is true; \
         else only finite)"
    );
    let mut m = gcode();
    m.max_feed = 5e-324;
    let e = m.check_numbers().unwrap_err();
    assert!(e.rule.contains("must not be denormal"), "{e}");
}

#[test]
fn a_field_that_does_not_apply_is_only_checked_finite() {
    // The probe's case: a NaN redundancy_angle on the laser cutter (no placement given).
    let mut m = gcode();
    m.has_placement = false;
    m.redundancy_angle = f64::NAN;
    assert_eq!(m.check_numbers().unwrap_err().field, "redundancy_angle");
    m.redundancy_angle = 1e308;
    assert_eq!(m.check_numbers(), Ok(()));
    let mut m = mill();
    m.has_process = false;
    m.tool_radius = 0.0;
    m.teeth = 0;
    assert_eq!(m.check_numbers(), Ok(()));
    m.kt = f64::INFINITY;
    assert_eq!(m.check_numbers().unwrap_err().field, "kt");
    for budget in [f64::NAN, f64::INFINITY, -1.0, 1e308] {
        let mut g = gcode();
        g.time_budget = budget;
        assert_eq!(g.check_numbers().unwrap_err().field, "time_budget");
    }
}

#[test]
fn values_are_printed_short() {
    let cases = [
        (f64::NAN, "NaN"),
        (f64::NEG_INFINITY, "-inf"),
        (-0.0, "-0"),
        (5e-324, "5e-324"),
        (1e308, "1e308"),
        (0.25, "0.25"),
    ];
    for (v, text) in cases {
        assert_eq!(format_value(v), text);
    }
}

#[test]
fn text_values_are_checked_by_the_message_field() {
    let e = check_value(
        <GcodeRequest as NumberRules>::SECTIONS,
        "max_feed",
        Number::Float(5e-324),
    )
    .unwrap_err();
    assert_eq!(e.field, "max_feed");
    let e = check_value(
        <CutRequest as NumberRules>::SECTIONS,
        "points[4].z",
        Number::Float(f64::INFINITY),
    )
    .unwrap_err();
    assert_eq!(e.to_string(), "field `points[4].z` = inf: must be finite");
    assert_eq!(
        check_value(
            <CutRequest as NumberRules>::SECTIONS,
            "points[4].z",
            Number::Float(0.5)
        ),
        Ok(())
    );
}

/// The cost of a check on a 10^6-point, 6-joint trajectory (positions and velocities).
#[test]
#[ignore = "a measurement: cargo test --release -p kerf_msgs numbers_speed -- --ignored --nocapture"]
fn numbers_speed() {
    let point = JointTrajectoryPoint {
        positions: vec![0.1; 6],
        velocities: vec![0.2; 6],
        time_from_start: Duration { sec: 1, nanosec: 0 },
        ..Default::default()
    };
    let t = JointTrajectory {
        points: vec![point; 1_000_000],
        ..Default::default()
    };
    for _ in 0..3 {
        let start = std::time::Instant::now();
        t.check_numbers().unwrap();
        println!(
            "check_numbers, 10^6 points x 6 joints: {:?}",
            start.elapsed()
        );
    }
}
