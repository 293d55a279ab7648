//! The contact checker skips a pair while the shape's motion since its last test cannot have
//! closed the clearance that test proved (`kerf_cell::motion`), and tests mesh triangles
//! deepest-first (`kerf_cell::mesh_contact`). Along case 1's plan moved in and out of the
//! B-pillar, and along the IRB 6660 through its fixture, it reports exactly the contacts of a
//! checker that tests every pair every time.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::{case1_plan, shipped, Rng};
use kerf_cell::geometry::to_pose;
use kerf_cell::Mode;
use nalgebra::Vector3;

/// Feeds the same poses to a checker that keeps its clearances and to fresh copies of it (no
/// clearance: every pair tested), and compares the contacts. Returns (poses with a contact,
/// pair tests the persistent checker skipped).
fn compare(name: &str, configurations: &[Vec<f64>]) -> (usize, u64) {
    let mut cell = shipped(name, Mode::Kinematic);
    let pristine = cell.checker().clone();
    let mut persistent = pristine.clone();
    let mut touching = 0;
    for (k, q) in configurations.iter().enumerate() {
        cell.reset(q).unwrap();
        let poses: Vec<_> = cell.body_poses().iter().map(to_pose).collect();
        let mut ours = Vec::new();
        persistent.check(&poses, 0.0, &mut ours);
        let mut all = Vec::new();
        pristine.clone().check(&poses, 0.0, &mut all);
        assert_eq!(
            ours.len(),
            all.len(),
            "{name} pose {k}: {ours:?} against {all:?}"
        );
        for (a, b) in ours.iter().zip(&all) {
            assert_eq!(
                (&a.shape, &a.object),
                (&b.shape, &b.object),
                "{name} pose {k}"
            );
            assert!(
                (a.distance - b.distance).abs() < 1e-12,
                "{name} pose {k}: {a:?} against {b:?}"
            );
        }
        if !all.is_empty() {
            touching += 1;
        }
    }
    (touching, persistent.counts().skipped)
}

#[test]
fn skipping_pairs_reports_the_contacts_of_testing_every_pair() {
    // Case 1's samples, the head moved along its tool axis by 4 mm sin(t / 0.3 s): in and out
    // of the part and through the 2 mm threshold many times.
    let plan = case1_plan();
    let cell = shipped("laser_bpillar", Mode::Kinematic);
    let laser: Vec<Vec<f64>> = plan
        .positions
        .iter()
        .zip(&plan.times)
        .map(|(q, &t)| {
            let o = cell.model().forward_kinematics(q).unwrap().rotation * Vector3::z();
            let d = o * 0.004 * (t / 0.3).sin();
            vec![q[0] + d.x, q[1] + d.y, q[2] + d.z, q[3], q[4], q[5]]
        })
        .collect();
    let (touching, skipped) = compare("laser_bpillar", &laser);
    assert!(
        touching > laser.len() / 5 && touching < laser.len() * 4 / 5,
        "{touching} of {} poses touch: the path should go in and out",
        laser.len()
    );
    assert!(skipped > 0, "nothing skipped");

    // The IRB 6660: a random walk of small steps near the plate and big jumps.
    let cell = shipped("irb6660_plate", Mode::Kinematic);
    let mut rng = Rng(0x0123_4567_89ab_cdef);
    let mut q = cell.state().positions.clone();
    let joints = cell.model().joints().to_vec();
    let mut irb = Vec::new();
    for k in 0..2000 {
        let step = if k % 200 == 0 { 0.5 } else { 0.01 };
        for (x, j) in q.iter_mut().zip(&joints) {
            *x = (*x + rng.range(-step, step)).clamp(j.min_position, j.max_position);
        }
        irb.push(q.clone());
    }
    let (touching, skipped) = compare("irb6660_plate", &irb);
    println!(
        "IRB 6660: {touching} of {} poses touch, {skipped} pair tests skipped",
        irb.len()
    );
    assert!(skipped > 0, "nothing skipped");
}
