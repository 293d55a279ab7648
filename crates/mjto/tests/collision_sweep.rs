//! The fast collision paths against the reference: the separating-axis
//! first stage ([`CollisionWorld::colliding_links`]) and conservative
//! advancement along a trajectory ([`CollisionWorld::colliding_links_along`])
//! must give, sample for sample and link for link, the verdicts of parry's
//! composite test on every shape ([`CollisionWorld::colliding_links_exhaustive`]):
//! on the planned trajectories of cases 1 and 2, on their QI baselines, and
//! on random perturbations of them that collide in many places. The skipped
//! samples are thereby shown to be clear, and the colliding-sample counts
//! (the QI metric) equal.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::{case, Rng};
use kerf_budget::Budget;
use kerf_mjto::baseline::{quaternion_interpolation_along, Rto};
use kerf_mjto::collision::{CollisionWorld, HeadModel};
use kerf_mjto::mesh::MeshCache;
use kerf_mjto::orientation::PathFrames;
use kerf_mjto::planner::Planner;
use kerf_mjto::{CutPlan, CutRequest, LaserMachine};

fn world(machine: &LaserMachine, request: &CutRequest, clearance: f64) -> CollisionWorld {
    let v = request.validate().unwrap();
    let mesh = MeshCache::new().get(&request.mesh).unwrap();
    let head = HeadModel::from_urdf(machine.robot().urdf()).unwrap();
    CollisionWorld::new(head, &mesh, &v.workpiece_pose, clearance).unwrap()
}

/// The QI baseline's samples on the plan's RTOs and along the plan's s(t), as the planner
/// samples it for its metrics.
fn qi_samples(machine: &LaserMachine, request: &CutRequest, plan: &CutPlan) -> Vec<[f64; 6]> {
    let v = request.validate().unwrap();
    let frames = PathFrames::new(&v.points, &v.axes, &v.u);
    let rtos: Vec<Rto> = plan.rtos.iter().map(Rto::from).collect();
    quaternion_interpolation_along(
        &frames,
        &rtos,
        &plan.path_positions,
        v.sigma,
        machine.limits(),
        &Budget::unlimited(),
    )
    .unwrap()
}

/// Smooth random perturbations of a trajectory (every joint offset by a
/// slowly varying amount, as a different solution would be), and a few
/// non-finite samples.
fn perturbed(q: &[[f64; 6]], seed: u64) -> Vec<[f64; 6]> {
    let mut rng = Rng(seed);
    let scale = [0.004, 0.004, 0.006, 0.15, 0.15, 0.004];
    let mut offset = [0.0; 6];
    let mut out = Vec::with_capacity(q.len());
    for (k, q) in q.iter().enumerate() {
        if k % 40 == 0 {
            for (o, s) in offset.iter_mut().zip(scale) {
                *o = s * rng.signed();
            }
        }
        let mut p = *q;
        for (x, o) in p.iter_mut().zip(offset) {
            // Vary within the 40-sample run too.
            *x += o * (1.0 + 0.5 * ((k % 40) as f64 / 40.0));
        }
        if k % 97 == 50 {
            p[3] = f64::NAN;
        }
        out.push(p);
    }
    out
}

/// Every path against the reference on one trajectory; returns the number
/// of colliding samples.
fn assert_same_verdicts(label: &str, w: &CollisionWorld, qs: &[[f64; 6]]) -> usize {
    let reference: Vec<Vec<&str>> = qs.iter().map(|q| w.colliding_links_exhaustive(q)).collect();
    let single: Vec<Vec<&str>> = qs.iter().map(|q| w.colliding_links(q)).collect();
    let free: Vec<bool> = qs.iter().map(|q| w.is_free(q)).collect();
    // Whole trajectory at once, and in the planner's runs of 256 samples.
    let along = w.colliding_links_along(qs);
    let chunked: Vec<Vec<&str>> = qs
        .chunks(kerf_mjto::planner::BUDGET_STRIDE)
        .flat_map(|c| w.colliding_links_along(c))
        .collect();
    for k in 0..qs.len() {
        assert_eq!(single[k], reference[k], "{label}: sample {k} (first stage)");
        assert_eq!(along[k], reference[k], "{label}: sample {k} (advancement)");
        assert_eq!(
            chunked[k], reference[k],
            "{label}: sample {k} (runs of 256)"
        );
        assert_eq!(
            free[k],
            reference[k].is_empty(),
            "{label}: sample {k} (is_free)"
        );
    }
    reference.iter().filter(|l| !l.is_empty()).count()
}

fn check_case(name: &str, seeds: &[u64]) {
    let machine = LaserMachine::default_machine().unwrap();
    let request = case(name);
    let mut planner = Planner::new(machine.clone()).unwrap();
    let plan = planner.plan(&request).unwrap();
    let w = world(&machine, &request, request.options.clearance);

    assert_eq!(assert_same_verdicts(name, &w, &plan.positions), 0);
    let qi = qi_samples(&machine, &request, &plan);
    let qi_colliding = assert_same_verdicts(&format!("{name} QI"), &w, &qi);
    assert_eq!(
        qi_colliding, plan.qi_metrics.colliding_samples,
        "{name}: QI count"
    );

    let mut colliding = 0;
    for &seed in seeds {
        let p = perturbed(&plan.positions, seed);
        colliding += assert_same_verdicts(&format!("{name} seed {seed}"), &w, &p);
    }
    // The perturbations reach the workpiece (else the comparison is empty)
    // and leave most samples clear.
    let total = seeds.len() * plan.positions.len();
    assert!(
        colliding * 20 > total,
        "{name}: {colliding} of {total} collide"
    );
    assert!(colliding < total, "{name}: {colliding} of {total} collide");

    // A clearance makes every shape's margin thinner: verdicts still agree.
    let wide = world(&machine, &request, 0.003);
    let p = perturbed(&plan.positions, seeds[0] + 100);
    assert!(assert_same_verdicts(&format!("{name} clearance 3 mm"), &wide, &p) > 0);
}

#[test]
fn case1_fast_paths_match_the_exhaustive_check() {
    check_case("case1", &[1, 2, 3, 4]);
}

#[test]
fn case2_fast_paths_match_the_exhaustive_check() {
    check_case("case2", &[5, 6, 7]);
}
