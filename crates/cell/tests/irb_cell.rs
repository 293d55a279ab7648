//! The IRB 6660 milling cell: the tool sits where kerf_mill's tool tip is, the cutter's
//! engagement in the stock is not a contact, the holder in the stock and the cutter in the
//! fixture plate are.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::shipped;
use kerf_cell::Mode;
use kerf_mill::MillCell;
use nalgebra::{Point3, Translation3, Vector3};

#[test]
fn tool_tip_is_kerf_mills_tcp_and_engagement_is_not_a_contact() {
    let mut cell = shipped("irb6660_plate", Mode::Kinematic);
    // The start is clear of everything.
    assert!(
        cell.state().contacts.is_empty(),
        "{:?}",
        cell.state().contacts
    );
    let mill = MillCell::default_cell().unwrap();
    let (body, off) = cell.chain().link("tool0").unwrap();
    let body = body.unwrap();
    for i in 0..=20 {
        let u = i as f64 / 20.0;
        let q = mill.joints_at_parameter(u, 0.0, None).unwrap();
        let tip = mill.tool_pose_at_parameter(u, 0.0).unwrap();
        cell.reset(&q).unwrap();
        // tool0 of the cell's bodies, with the tcp of irb6660_milling.yaml.
        let tool0 = cell.body_poses()[body] * off;
        let p = tool0 * Point3::new(0.30, 0.0, 0.15);
        assert!(
            (p.coords - tip.translation.vector).norm() < 1e-9,
            "u {u}: {p} vs {}",
            tip.translation.vector
        );
        assert!((p.z - 1.7).abs() < 1e-9);
        // On the path the cutter is 3 mm deep in the stock: engaged, not a contact.
        assert!(
            cell.state().contacts.is_empty(),
            "u {u}: {:?}",
            cell.state().contacts
        );
        // 30 mm deeper the holder enters the stock: a contact naming it.
        let deeper = Translation3::from(Vector3::new(0.0, 0.0, -0.030)) * tip;
        let q = mill.kinematics().ik_nearest(&deeper, &q).unwrap();
        let state = cell.reset(&q).unwrap();
        assert!(
            state
                .contacts
                .iter()
                .any(|c| c.shape == "holder" && c.object == "stock" && c.link == "tool0"),
            "u {u}: {:?}",
            state.contacts
        );
        // 52 mm deeper the cutter's end face is below the fixture plate's top (z 1.653).
        let deepest = Translation3::from(Vector3::new(0.0, 0.0, -0.052)) * tip;
        let q = mill.kinematics().ik_nearest(&deepest, &q).unwrap();
        let state = cell.reset(&q).unwrap();
        let c = state
            .contacts
            .iter()
            .find(|c| c.shape == "cutter" && c.object == "fixture_plate")
            .unwrap_or_else(|| panic!("u {u}: {:?}", state.contacts));
        assert!((c.depth - 0.005).abs() < 1e-6, "{c:?}");
    }
}
