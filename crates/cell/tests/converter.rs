//! The URDF-to-rapier converter: rapier's multibody places every link where kerf_robot's
//! forward kinematics does, in kinematic mode and after dynamic steps.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::{shipped, Rng};
use kerf_cell::Mode;

#[test]
fn multibody_link_poses_equal_kerf_robot_forward_kinematics() {
    for name in ["laser_bpillar", "irb6660_plate"] {
        let mut cell = shipped(name, Mode::Kinematic);
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        let joints: Vec<(f64, f64)> = cell
            .model()
            .joints()
            .iter()
            .map(|j| (j.min_position.max(-3.0), j.max_position.min(3.0)))
            .collect();
        for _ in 0..100 {
            let q: Vec<f64> = joints.iter().map(|&(lo, hi)| rng.range(lo, hi)).collect();
            cell.reset(&q).unwrap();
            let reference = cell.model().link_poses(&q).unwrap();
            let bodies = cell.body_poses();
            for (j, joint) in cell.chain().joints.iter().enumerate() {
                let (_, expected) = reference.iter().find(|(l, _)| *l == joint.link).unwrap();
                let got = bodies[j];
                let dt = (got.translation.vector - expected.translation.vector).norm();
                let dr = got.rotation.angle_to(&expected.rotation);
                assert!(
                    dt < 1e-9 && dr < 1e-9,
                    "{name} {}: {dt} m, {dr} rad at {q:?}",
                    joint.link
                );
            }
            // The state reads back the positions set.
            assert_eq!(cell.state().positions, q);
        }
    }
}

#[test]
fn every_moving_body_has_the_sidecar_mass() {
    let laser = shipped("laser_bpillar", Mode::Dynamic);
    let masses: Vec<f64> = laser.chain().joints.iter().map(|j| j.mass.mass).collect();
    assert_eq!(masses, vec![70.0, 40.0, 35.0, 12.0, 5.0, 1.5]);
    let irb = shipped("irb6660_plate", Mode::Dynamic);
    let masses: Vec<f64> = irb.chain().joints.iter().map(|j| j.mass.mass).collect();
    // link_6 carries the tool shapes' masses (bracket 8, spindle 45, holder 3, cutter 1.5).
    assert_eq!(&masses[..5], &[620.0, 280.0, 330.0, 200.0, 70.0]);
    assert!((masses[5] - (10.0 + 57.5)).abs() < 1e-9, "{masses:?}");
    // Robot (moving links) + fixed base = 1 910 kg.
    let robot: f64 = masses.iter().sum::<f64>() - 57.5 + 400.0;
    assert!((robot - 1910.0).abs() < 1e-9, "{robot}");
}

#[test]
fn a_cell_can_move_to_the_control_thread() {
    fn send<T: Send>(_: &T) {}
    let cell = shipped("laser_bpillar", Mode::Dynamic);
    send(&cell);
    let handle = std::thread::spawn(move || cell.state().positions.len());
    assert_eq!(handle.join().unwrap(), 6);
}
