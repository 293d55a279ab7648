//! The cell YAML: the default file loads with the seed 004 Table 1 values,
//! evaluate() is consistent with the path and the kinematics, and bad
//! fields are reported by name.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use kerf_mill::{MillCell, MillError};

#[test]
fn default_cell_has_the_table_1_values() {
    let cell = MillCell::default_cell().expect("default cell");
    let p = cell.milling_process();
    assert_eq!(p.teeth, 2);
    assert_eq!(
        (p.radius, p.axial_depth, p.kt, p.kn),
        (0.04, 0.003, 6.44e8, 2.37e8)
    );
    assert!((p.entry_angle - 0.75 * std::f64::consts::PI).abs() < 1e-15);
    assert!((p.exit_angle - std::f64::consts::PI).abs() < 1e-15);
    let l = cell.state_limits();
    assert_eq!(l.spindle_rpm, [2000.0, 4000.0]);
    assert_eq!(l.feed, [0.0, 0.06]);
    assert_eq!(
        (
            l.max_feed_step,
            l.max_spindle_step_rpm,
            l.max_redundancy_step
        ),
        (1e-3, 20.0, 0.2)
    );
    assert_eq!(cell.path().segments().len(), 100);
    assert_eq!(cell.robot().dof(), 6);
}

#[test]
fn evaluate_is_consistent_with_path_kinematics_and_dynamics() {
    let cell = MillCell::default_cell().expect("cell");
    let mut prev: Option<[f64; 6]> = None;
    let mut worst_step = 0.0f64;
    for s in 0..100 {
        let st = cell
            .evaluate(s, 1.0, prev.as_ref())
            .expect("g = 1 reachable");
        let pose = cell.path().tool_pose(s, 1.0).expect("pose");
        let tcp = cell.kinematics().tcp_pose(&st.joints).expect("fk");
        assert!((tcp.translation.vector - pose.translation.vector).norm() < 1e-9);
        assert!(tcp.rotation.angle_to(&pose.rotation) < 1e-7);
        cell.kinematics()
            .check_limits(&st.joints)
            .expect("within limits");
        assert!((st.condition_indicator * st.condition_number - 1.0).abs() < 1e-15);
        assert!(st.condition_indicator > 0.0 && st.condition_indicator <= 1.0);
        st.modal.validate().expect("valid Modal2");
        if let Some(p) = prev {
            for (a, b) in st.joints.iter().zip(&p) {
                worst_step = worst_step.max((a - b).abs());
            }
        }
        prev = Some(st.joints);
    }
    println!("largest joint step between segments at g = 1: {worst_step:.4} rad");
    assert!(worst_step < cell.branch_jump_threshold());
}

#[test]
fn unreachable_or_limited_states_name_segment_g_and_joint() {
    let cell = MillCell::default_cell().expect("cell");
    let err = cell
        .evaluate(10, 3.0, None)
        .expect_err("g = 3 is outside the band");
    let msg = err.to_string();
    println!("{msg}");
    match err {
        MillError::JointLimit {
            segment, g, excess, ..
        } => {
            assert_eq!(segment, Some(10));
            assert_eq!(g, Some(3.0));
            assert!(excess > 0.0);
        }
        other => panic!("expected JointLimit, got {other}"),
    }
    assert!(msg.contains("segment 10") && msg.contains("joint_"));
    assert!(cell.evaluate(100, 0.0, None).is_err());
    assert!(cell.evaluate(0, 4.0, None).is_err());
    assert!(cell.evaluate(0, f64::NAN, None).is_err());
}

#[test]
fn bad_fields_are_reported_by_name() {
    let text = common::default_cell_text();
    let cases = [
        (
            "  damping_ratio: 0.05\n",
            "  damping_ratio: 1.5\n",
            "damping_ratio",
        ),
        (
            "3.0e6, 3.0e6, 2.0e6",
            "3.0e6, -3.0e6, 2.0e6",
            "joint_stiffness[1]",
        ),
        ("model: compliance", "model: gaussian", "dynamics.model"),
        (
            "engagement_over_pi: [0.75, 1.0]",
            "engagement_over_pi: [0.75, 1.5]",
            "engagement_over_pi[1]",
        ),
        (
            "spindle_rpm: [2000.0, 4000.0]",
            "spindle_rpm: [4000.0, 2000.0]",
            "process.spindle_rpm",
        ),
        (
            "characteristic_length: 1.2799",
            "characteristic_length: 0.0",
            "characteristic_length",
        ),
        ("segments: 100", "segments: 0", "path.segments"),
        (
            "z_axis: [1.0, 0.0, 0.0]",
            "z_axis: [1.0, 0.0, 1.0]",
            "tcp.z_axis",
        ),
        (
            "branch_jump_threshold: 0.5",
            "branch_jump_threshold: .nan",
            "branch_jump_threshold",
        ),
        (
            "    - [1.6, -0.1, 1.7]",
            "    - [1.6, -0.1, 1.75]",
            "not coplanar",
        ),
        ("  teeth: 2", "  teeth: 2\n  helix: 30", "unknown field"),
        ("urdf: irb6660.urdf", "urdf: missing.urdf", "missing.urdf"),
    ];
    for (from, to, expect) in cases {
        assert!(text.contains(from), "fixture: {from}");
        let Err(err) = common::load_cell_text(&text.replacen(from, to, 1)) else {
            panic!("{expect}: accepted")
        };
        let msg = err.to_string();
        println!("{expect}: {msg}");
        assert!(msg.contains(expect), "{msg}");
    }
    // `measured` without modes, then the measured model loading fine.
    let measured = text.replacen("model: compliance", "model: measured", 1);
    let cell = common::load_cell_text(&measured).expect("measured model");
    let st = cell.evaluate(0, 0.0, None).expect("state");
    let w = 2.0 * std::f64::consts::PI * 20.0;
    assert!((st.modal.stiffness[(0, 0)] - 60.0 * w * w).abs() < 1e-6);
}
