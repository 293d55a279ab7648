//! Case 1's plan in the shipped laser cell, and a hand-made trajectory that drives the head
//! into the B-pillar: the contact is reported at the first control period whose end
//! configuration the exact checker calls touching, it is named, and its depth is bounded by
//! the motion of one physics step.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::{case1, case1_plan, plan_at, shipped, urdf_dir};
use kerf_cell::Mode;
use kerf_executor::JointSample;
use kerf_mjto::collision::{CollisionWorld, HeadModel};
use kerf_mjto::LaserMachine;
use nalgebra::Vector3;

#[test]
fn head_driven_into_the_part_is_reported_at_the_first_touching_period() {
    // The shipped cell: the nozzle tip is a contact when it touches (standoff allowance),
    // the other shapes within 2 mm.
    let mut cell = shipped("laser_bpillar", Mode::Kinematic);
    let request = case1();
    let pose = request.workpiece_pose.isometry().unwrap();
    let bytes = std::fs::read(urdf_dir().join("meshes/bpillar.obj")).unwrap();
    let mesh = kerf_mjto::mesh::parse(&bytes, "obj", "bpillar").unwrap();
    let machine = LaserMachine::default_machine().unwrap();
    let head = HeadModel::from_urdf(machine.robot().urdf()).unwrap();
    let exact = CollisionWorld::new(head, &mesh, &pose, 0.0).unwrap();
    let plan = case1_plan();

    for k in [0, plan.positions.len() / 3, 2 * plan.positions.len() / 3] {
        // The planned configuration at sample k; the whole head moved back 10 mm along the
        // tool axis, then driven along it into the part at 20 mm/s.
        let base = plan.positions[k];
        let o = cell.model().forward_kinematics(&base).unwrap().rotation * Vector3::z();
        let speed = 0.02;
        let at = |t: f64| {
            let d = o * (0.010 - speed * t);
            [
                base[0] + d.x,
                base[1] + d.y,
                base[2] + d.z,
                base[3],
                base[4],
                base[5],
            ]
        };
        let vel = [-o.x * speed, -o.y * speed, -o.z * speed, 0.0, 0.0, 0.0];
        cell.reset(&at(0.0)).unwrap();
        assert!(
            cell.state().contacts.is_empty(),
            "{:?}",
            cell.state().contacts
        );
        let dt = 1.0 / cell.settings().control_rate_hz;
        let mut first_exact = None;
        let mut first_cell = None;
        for i in 1..=400 {
            let q = at(i as f64 * dt);
            let command = JointSample {
                positions: q.to_vec(),
                velocities: vel.to_vec(),
                accelerations: vec![0.0; 6],
            };
            let state = cell.step(&command, dt).unwrap();
            if first_exact.is_none() && !exact.is_free(&q) {
                first_exact = Some(i);
            }
            if first_cell.is_none() && !state.contacts.is_empty() {
                first_cell = Some((i, state.contacts.clone()));
            }
            if first_exact.is_some() && first_cell.is_some() {
                break;
            }
        }
        let (i, contacts) = first_cell.expect("no contact reported");
        assert_eq!(
            Some(i),
            first_exact,
            "sample {k}: cell period {i}, exact {first_exact:?}"
        );
        // Nothing else came within its threshold first: only the tip is reported.
        assert_eq!(contacts.len(), 1, "{contacts:?}");
        let contact = &contacts[0];
        assert_eq!(contact.link, "nozzle");
        assert_eq!(contact.shape, "nozzle/0");
        assert_eq!(contact.object, "bpillar");
        // Depth bound: in the previous control period no physics step was in contact
        // (distance >= 0 at its end), and the reported contact is the deepest of this
        // period's sub-steps: the head moved at most speed * dt = 80 um since then.
        let bound = speed * dt * 1.01;
        assert!(
            contact.distance < 0.0 && contact.depth <= bound,
            "depth {} m, bound {bound} m",
            contact.depth
        );
        // The position is on the tip: within its radius of the tool axis, 1..5 mm from C.
        let q = at(i as f64 * dt);
        let c = cell
            .model()
            .forward_kinematics(&q)
            .unwrap()
            .translation
            .vector;
        let from_c = Vector3::from(contact.position) - c;
        let radial = (from_c - o * from_c.dot(&o)).norm();
        assert!(radial <= 0.0025 + 1e-6, "{radial}");
        let along = from_c.dot(&o);
        assert!((0.001 - 1e-6..=0.005).contains(&along), "{along}");
        println!("sample {k}: first contact at period {i}: {contact:?}");
    }
}

#[test]
fn case_1_plan_runs_in_the_cell_without_contact() {
    let plan = case1_plan();
    let duration = *plan.times.last().unwrap();
    for mode in [Mode::Kinematic, Mode::Dynamic] {
        let mut cell = shipped("laser_bpillar", mode);
        cell.reset(&plan.positions[0]).unwrap();
        let dt = 1.0 / cell.settings().control_rate_hz;
        let steps = (duration / dt).ceil() as usize;
        let mut nearest_tip = f64::INFINITY;
        let mut max_error = [0.0f64; 6];
        for i in 1..=steps {
            let state = cell.step(&plan_at(&plan, i as f64 * dt), dt).unwrap();
            assert!(
                state.contacts.is_empty(),
                "{mode:?} period {i}: {:?}",
                state.contacts
            );
            for (m, e) in max_error.iter_mut().zip(&state.tracking_error) {
                *m = m.max(e.abs());
            }
            if i % 5 == 0 {
                let d = cell
                    .distances()
                    .into_iter()
                    .find(|(s, _, _)| s == "nozzle/0")
                    .and_then(|(_, _, d)| d)
                    .unwrap();
                nearest_tip = nearest_tip.min(d);
            }
        }
        println!("{mode:?}: {steps} periods, nearest tip {nearest_tip} m, max tracking error {max_error:?}");
        // The tip runs at its ~1 mm standoff, inside the 2 mm threshold: only the standoff
        // allowance keeps it from being a contact.
        assert!(nearest_tip > 0.0 && nearest_tip < 0.002, "{nearest_tip}");
    }
}
