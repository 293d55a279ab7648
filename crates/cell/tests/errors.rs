//! Bad input: each is refused with a clear error naming what is wrong.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::{laser_with, settings, shipped, urdf_dir};
use kerf_cell::{load_robot, Cell, CellError, CellFile, CellSettings, Mode};
use kerf_executor::JointSample;

const ROBOT: &str = "
robot:
  name: laser_cutter
  inertia: ../laser_cutter_inertia.yaml
  initial_positions: [0.40, 0.70, 1.20, 0.0, 0.0, -0.07]
";

#[test]
fn a_cell_file_naming_a_missing_mesh_is_refused() {
    let text = format!(
        "{ROBOT}objects:\n  - name: part\n    kind: workpiece\n    geometry: {{mesh: {{path: \
         ../meshes/no_such_part.obj}}}}\ncontact: {{threshold: 0.002}}\n"
    );
    let err = laser_with(&text, Mode::Kinematic).unwrap_err();
    match &err {
        CellError::MissingMesh { object, path } => {
            assert_eq!(object, "part");
            assert!(path.ends_with("meshes/no_such_part.obj"), "{path:?}");
        }
        other => panic!("{other:?}"),
    }
    assert!(err.to_string().contains("no_such_part.obj"), "{err}");
}

#[test]
fn an_effort_limit_of_zero_or_below_is_refused() {
    let urdf = std::fs::read_to_string(urdf_dir().join("laser_cutter.urdf")).unwrap();
    for bad in ["0.0", "-60.0"] {
        let text = urdf.replacen("effort=\"60.0\"", &format!("effort=\"{bad}\""), 1);
        assert_ne!(text, urdf);
        match load_robot(&text).unwrap_err() {
            CellError::EffortLimit { joint, effort } => {
                assert_eq!(joint, "q4");
                assert_eq!(effort, bad.parse::<f64>().unwrap());
            }
            other => panic!("{other:?}"),
        }
    }
    // The shipped URDF passes.
    assert_eq!(load_robot(&urdf).unwrap().dof(), 6);
}

#[test]
fn a_physics_rate_that_is_not_a_multiple_of_the_control_rate_is_refused() {
    let model = load_robot(&std::fs::read_to_string(urdf_dir().join("laser_cutter.urdf")).unwrap())
        .unwrap();
    let dir = urdf_dir().join("cells");
    let file = CellFile::from_file(&dir.join("laser_bpillar.yaml")).unwrap();
    for (physics, control) in [(1000.0, 300.0), (900.0, 250.0), (100.0, 250.0)] {
        let s = CellSettings {
            physics_rate_hz: physics,
            control_rate_hz: control,
            ..settings(Mode::Dynamic)
        };
        match Cell::new(model.clone(), &file, s).unwrap_err() {
            CellError::RateRatio {
                physics_hz,
                control_hz,
                ratio,
            } => {
                assert_eq!((physics_hz, control_hz), (physics, control));
                assert!((ratio - physics / control).abs() < 1e-12);
            }
            other => panic!("{physics}/{control}: {other:?}"),
        }
    }
    // 2 kHz under 500 Hz is 4 sub-steps.
    let s = CellSettings {
        physics_rate_hz: 2000.0,
        control_rate_hz: 500.0,
        ..settings(Mode::Dynamic)
    };
    assert_eq!(Cell::new(model, &file, s).unwrap().substeps(), 4);
}

#[test]
fn a_command_with_the_wrong_joints_is_refused() {
    let mut cell = shipped("laser_bpillar", Mode::Kinematic);
    let before = cell.state().clone();
    let dt = 0.004;
    let err = cell
        .step(&JointSample::at_rest(vec![0.0; 5]), dt)
        .unwrap_err();
    match &err {
        CellError::JointMismatch {
            what,
            reason,
            expected,
        } => {
            assert_eq!(*what, "command positions");
            assert!(reason.contains("5 values for 6 joints"), "{reason}");
            assert_eq!(expected, "q1, q2, q3, q4, q5, q6");
        }
        other => panic!("{other:?}"),
    }
    // Velocities of the wrong length.
    let mut command = JointSample::at_rest(before.positions.clone());
    command.velocities.pop();
    assert!(matches!(
        cell.step(&command, dt).unwrap_err(),
        CellError::JointMismatch {
            what: "command velocities",
            ..
        }
    ));
    // Joint names: the executor's list against the URDF.
    cell.check_joint_names(&["q1", "q2", "q3", "q4", "q5", "q6"])
        .unwrap();
    match cell
        .check_joint_names(&["q1", "q2", "q3", "q5", "q4", "q6"])
        .unwrap_err()
    {
        CellError::JointMismatch { reason, .. } => {
            assert!(
                reason.contains("joint 3 is 'q5', expected 'q4'"),
                "{reason}"
            )
        }
        other => panic!("{other:?}"),
    }
    assert!(cell.check_joint_names(&["joint_1"]).is_err());
    // A control period other than the configured one.
    assert!(matches!(
        cell.step(&JointSample::at_rest(before.positions.clone()), 0.001)
            .unwrap_err(),
        CellError::ControlPeriod { .. }
    ));
    // Nothing changed.
    assert_eq!(cell.state(), &before);
}

#[test]
fn nan_commands_are_refused() {
    for mode in [Mode::Kinematic, Mode::Dynamic] {
        let mut cell = shipped("laser_bpillar", mode);
        let before = cell.state().clone();
        let mut command = JointSample::at_rest(before.positions.clone());
        command.positions[2] = f64::NAN;
        match cell.step(&command, 0.004).unwrap_err() {
            CellError::NonFinite { what, joint, value } => {
                assert_eq!(what, "command positions");
                assert_eq!(joint, "q3");
                assert!(value.is_nan());
            }
            other => panic!("{other:?}"),
        }
        let mut command = JointSample::at_rest(before.positions.clone());
        command.accelerations[5] = f64::INFINITY;
        assert!(matches!(
            cell.step(&command, 0.004).unwrap_err(),
            CellError::NonFinite {
                what: "command accelerations",
                ..
            }
        ));
        assert_eq!(cell.state(), &before);
    }
}

#[test]
fn other_bad_cell_files_are_refused() {
    // Another robot's cell file.
    let irb = CellFile::from_file(&urdf_dir().join("cells/irb6660_plate.yaml")).unwrap();
    let model = load_robot(&std::fs::read_to_string(urdf_dir().join("laser_cutter.urdf")).unwrap())
        .unwrap();
    let err = Cell::new(model, &irb, settings(Mode::Kinematic)).unwrap_err();
    assert!(err.to_string().contains("abb_irb6660_130_3_1"), "{err}");
    // An allowance on a fixture.
    let text = format!(
        "{ROBOT}objects:\n  - name: table\n    kind: fixture\n    geometry: {{box: {{size: [1, 1, \
         0.1]}}}}\ncontact:\n  threshold: 0.002\n  allowances:\n    - {{shape: nozzle/0, object: \
         table, allow: engagement}}\n"
    );
    let err = laser_with(&text, Mode::Kinematic).unwrap_err();
    assert!(err.to_string().contains("fixture"), "{err}");
    // A standoff above the threshold.
    let text = format!(
        "{ROBOT}objects:\n  - name: part\n    kind: workpiece\n    geometry: {{box: {{size: [1, 1, \
         0.1]}}}}\n    pose: {{position: [0.4, 0.7, 0.0]}}\ncontact:\n  threshold: 0.002\n  \
         allowances:\n    - {{shape: nozzle/0, object: part, allow: standoff, \
         min_distance: 0.005}}\n"
    );
    assert!(matches!(
        laser_with(&text, Mode::Kinematic).unwrap_err(),
        CellError::InvalidValue { .. }
    ));
    // An unknown shape name.
    let text = format!(
        "{ROBOT}objects:\n  - name: part\n    kind: workpiece\n    geometry: {{box: {{size: [1, 1, \
         0.1]}}}}\ncontact:\n  threshold: 0.002\n  allowances:\n    - {{shape: laser, object: \
         part, allow: engagement}}\n"
    );
    let err = laser_with(&text, Mode::Kinematic).unwrap_err();
    assert!(err.to_string().contains("'laser'"), "{err}");
    // Wrong number of initial positions.
    let text = ROBOT.replace("-0.07]", "-0.07, 0.0]") + "contact: {threshold: 0.002}\n";
    assert!(matches!(
        laser_with(&text, Mode::Kinematic).unwrap_err(),
        CellError::JointMismatch { .. }
    ));
    // A servo bandwidth the explicit PD cannot run at 1 kHz.
    let s = CellSettings {
        bandwidth_hz: 200.0,
        ..settings(Mode::Dynamic)
    };
    assert!(matches!(
        s.substeps().unwrap_err(),
        CellError::InvalidValue { .. }
    ));
}
