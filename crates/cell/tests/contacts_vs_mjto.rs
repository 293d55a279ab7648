//! Kinematic-mode contacts against kerf_mjto's exact head-vs-workpiece checker, on the
//! B-pillar at case 1's pose, around case 1's path and near the surface.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::{case1, case1_plan, laser_with, urdf_dir, Rng};
use kerf_cell::Mode;
use kerf_executor::JointSample;
use kerf_mjto::collision::{CollisionWorld, HeadModel};
use kerf_mjto::LaserMachine;
use nalgebra::Vector3;

/// The shipped scene without allowances: every shape keeps the threshold, as in kerf_mjto.
const CELL: &str = "
robot:
  name: laser_cutter
  inertia: ../laser_cutter_inertia.yaml
  initial_positions: [0.40, 0.70, 1.20, 0.0, 0.0, -0.07]
objects:
  - name: bpillar
    kind: workpiece
    geometry: {mesh: {path: ../meshes/bpillar.obj}}
    pose:
      position: [-0.199, 0.879, 0.895]
      orientation: [0.008723084313, -0.028120221488, -0.000245401455, 0.999566456381]
contact:
  threshold: 0.002
";

const THRESHOLD: f64 = 0.002;

#[test]
fn kinematic_contacts_agree_with_the_exact_checker_around_case_1() {
    let mut cell = laser_with(CELL, Mode::Kinematic).unwrap();
    let request = case1();
    let pose = request.workpiece_pose.isometry().unwrap();
    let bytes = std::fs::read(urdf_dir().join("meshes/bpillar.obj")).unwrap();
    let mesh = kerf_mjto::mesh::parse(&bytes, "obj", "bpillar").unwrap();
    let machine = LaserMachine::default_machine().unwrap();
    let head = HeadModel::from_urdf(machine.robot().urdf()).unwrap();
    let touching = CollisionWorld::new(head.clone(), &mesh, &pose, 0.0).unwrap();
    let within = CollisionWorld::new(head, &mesh, &pose, THRESHOLD).unwrap();

    let plan = case1_plan();
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let (mut colliding, mut clear, mut between) = (0, 0, 0);
    let dt = 1.0 / cell.settings().control_rate_hz;
    for i in 0..1500 {
        // Around case 1's planned (collision-free) configurations: the head moved along the
        // tool axis by -8..+6 mm (into or off the sheet) and sideways by up to 5 mm, the
        // rotary axes turned by up to 0.3 rad (C) and 0.2 rad (A), the standoff axis moved
        // by up to 30 mm.
        let k = (i * 7) % plan.positions.len();
        let base = plan.positions[k];
        let tool0 = cell.model().forward_kinematics(&base).unwrap();
        let o = tool0.rotation * Vector3::z();
        let shift = o * rng.range(-0.008, 0.006)
            + Vector3::new(rng.range(-0.005, 0.005), rng.range(-0.005, 0.005), 0.0);
        let q = [
            base[0] + shift.x,
            base[1] + shift.y,
            base[2] + shift.z,
            base[3] + rng.range(-0.3, 0.3),
            base[4] + rng.range(-0.2, 0.2),
            (base[5] + rng.range(-0.03, 0.03)).clamp(-0.1, 0.02),
        ];
        // Place the head with one control period from rest at q (state = command).
        cell.reset(&q).unwrap();
        let state = cell.step(&JointSample::at_rest(q.to_vec()), dt).unwrap();
        let reported = !state.contacts.is_empty();
        let exact = !touching.is_free(&q);
        let near = !within.is_free(&q);
        if exact {
            colliding += 1;
            assert!(reported, "{q:?}: kerf_mjto finds contact, the cell none");
            // Every link the exact checker names is among the cell's contacts.
            for link in touching.colliding_links(&q) {
                assert!(
                    state.contacts.iter().any(|c| c.link == link),
                    "{q:?}: link {link} not reported: {:?}",
                    state.contacts
                );
            }
        } else if !near {
            clear += 1;
            assert!(
                !reported,
                "{q:?}: clear by more than {THRESHOLD} m, the cell reports {:?}",
                state.contacts
            );
        } else {
            between += 1;
            // Within the threshold but not touching: a contact with distance in [0, t).
            assert!(reported, "{q:?}: within the threshold, not reported");
            for c in &state.contacts {
                assert!(c.distance < THRESHOLD && c.distance > -1e-9, "{c:?}");
            }
        }
    }
    println!("colliding {colliding}, within the threshold {between}, clear {clear}");
    assert!(
        colliding >= 200 && clear >= 200 && between >= 20,
        "{colliding} {between} {clear}"
    );
}
