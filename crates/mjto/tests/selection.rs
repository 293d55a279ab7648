//! Initial RTO selection (seed 001 eq. 56): lazy vs eager, optimality by
//! brute force, and the error of a layer without a free candidate.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use kerf_budget::Budget;
use kerf_mjto::collision::{CollisionWorld, HeadModel};
use kerf_mjto::gfd::Gfd;
use kerf_mjto::mesh::MeshData;
use kerf_mjto::request::{GfdGrid, Weights};
use kerf_mjto::selection::{select_rtos, select_rtos_eager, selection_cost};
use kerf_mjto::{LaserMachine, PlanError};
use nalgebra::{Isometry3, Vector3};

const Y: f64 = 0.7;
const Z: f64 = 0.3;

/// Lead/tilt against the frame of a cut along +x on a horizontal sheet.
fn lead_tilt(o: &Vector3<f64>) -> (f64, f64) {
    (o.x.atan2(o.z), o.y.atan2(o.z))
}

/// A 2 mm sheet with its top face at z = Z, and a 10 cm high wall across
/// the path at x = 0.895 (a flange the cut approaches): at the last CL
/// point (x = 0.85) the fork arms (x in M.x +- 0.05) touch it unless the
/// head leans away (q5 <= -0.075 moves M by 5 mm in -x).
fn world() -> CollisionWorld {
    let machine = LaserMachine::default_machine().unwrap();
    let head = HeadModel::from_urdf(machine.robot().urdf()).unwrap();
    let mut mesh = MeshData::cuboid([0.4, Y - 0.3, Z - 0.002], [1.0, Y + 0.3, Z]);
    mesh.append(&MeshData::cuboid(
        [0.895, Y - 0.3, Z],
        [0.899, Y + 0.3, Z + 0.1],
    ))
    .unwrap();
    CollisionWorld::new(head, &mesh, &Isometry3::identity(), 0.0).unwrap()
}

/// GFDs at CL points (x, Y, Z) with a reference standoff of -0.05 m,
/// where the fork arms touch the sheet: every reference collides.
fn layers(xs: &[f64], grid: &GfdGrid) -> (Vec<Gfd>, Vec<f64>) {
    let machine = LaserMachine::default_machine().unwrap();
    let gfds = xs
        .iter()
        .enumerate()
        .map(|(i, &x)| {
            Gfd::build(
                i * 10,
                x,
                &Vector3::new(x, Y, Z),
                [0.0, 0.0, -0.05],
                grid,
                &Weights::default(),
                0.3,
                0.3,
                &lead_tilt,
                machine.limits(),
            )
        })
        .collect();
    let sigma = xs.windows(2).map(|w| w[1] - w[0]).collect();
    (gfds, sigma)
}

#[test]
fn lazy_equals_eager_with_fewer_queries() {
    let xs = [0.6, 0.7, 0.8, 0.85];
    let (mut lazy, sigma) = layers(&xs, &GfdGrid::default());
    let mut eager = lazy.clone();
    let w = Weights::default();

    let lazy_world = world();
    let a = select_rtos(&mut lazy, &sigma, &w, &lazy_world, &Budget::unlimited()).unwrap();
    let eager_world = world();
    let b = select_rtos_eager(&mut eager, &sigma, &w, &eager_world).unwrap();

    assert_eq!(a, b);
    let cost_a = selection_cost(&lazy, &a, &sigma, &w).unwrap();
    let cost_b = selection_cost(&eager, &b, &sigma, &w).unwrap();
    assert_eq!(cost_a, cost_b);
    // Every chosen candidate is free, and moved away from the colliding
    // reference standoff.
    for (g, &p) in lazy.iter().zip(&a) {
        assert!(eager_world.is_free(&g.joint_vector(p)));
        assert!(g.candidates[p].q[2] < -0.06, "{:?}", g.candidates[p]);
    }
    let total: usize = eager.iter().map(|g| g.candidates.len()).sum();
    assert_eq!(eager_world.queries(), total + a.len());
    assert!(
        lazy_world.queries() * 5 < total,
        "lazy {} vs eager {} queries",
        lazy_world.queries(),
        total
    );
    // The lazy search did need several rounds (the references collide).
    assert!(lazy_world.queries() > xs.len());
}

#[test]
fn selection_is_the_brute_force_optimum() {
    // A small grid: 3 x 5 (q4, q5) x (3 + 1) q6 per layer, 3 layers.
    let grid = GfdGrid {
        q4_steps: 3,
        q5_steps: 5,
        q6_steps: 3,
        q4_half_range: 0.3,
        q5_half_range: 0.1,
    };
    let w = Weights {
        k2: 0.5,
        ..Weights::default()
    };
    let (mut gfds, sigma) = layers(&[0.7, 0.8, 0.85], &grid);
    let world = world();
    let choice = select_rtos(&mut gfds, &sigma, &w, &world, &Budget::unlimited()).unwrap();
    let best = selection_cost(&gfds, &choice, &sigma, &w).unwrap();

    let free: Vec<Vec<usize>> = gfds
        .iter_mut()
        .map(|g| {
            (0..g.candidates.len())
                .filter(|&p| g.is_free(p, &world))
                .collect()
        })
        .collect();
    assert!(free.iter().all(|f| !f.is_empty()));
    let mut brute = f64::INFINITY;
    let mut paths = 0;
    for &a in &free[0] {
        for &b in &free[1] {
            for &c in &free[2] {
                let cost = selection_cost(&gfds, &[a, b, c], &sigma, &w).unwrap();
                brute = brute.min(cost);
                paths += 1;
            }
        }
    }
    assert!(paths > 100, "{paths} paths");
    assert_eq!(best, brute);
    // The chosen path is itself free.
    for (f, p) in free.iter().zip(&choice) {
        assert!(f.contains(p));
    }
}

#[test]
fn single_layer_is_the_nearest_free_candidate() {
    let (mut gfds, sigma) = layers(&[0.7], &GfdGrid::default());
    assert!(sigma.is_empty());
    let world = world();
    let w = Weights::default();
    let choice = select_rtos(&mut gfds, &sigma, &w, &world, &Budget::unlimited()).unwrap();
    let mut g = gfds[0].clone();
    // The GFD's distances (eq. 55 to the reference) weight q4 by sin²q̂5.
    let reference_w = Weights {
        k4: w.k4 * g.reference[1].sin().powi(2),
        ..w
    };
    let nearest = g
        .nearest_free(g.reference, &reference_w, &world, &Budget::unlimited())
        .unwrap()
        .unwrap();
    assert_eq!(choice, vec![nearest]);
}

#[test]
fn all_colliding_layer_is_no_feasible_orientation() {
    // Layer 1 has its CL point 5 mm below the sheet's top face: the nozzle
    // crosses the sheet for every sample.
    let (mut gfds, sigma) = layers(&[0.6, 0.7, 0.8], &GfdGrid::default());
    let machine = LaserMachine::default_machine().unwrap();
    gfds[1] = Gfd::build(
        10,
        0.5,
        &Vector3::new(0.7, Y, Z - 0.005),
        [0.0, 0.0, -0.08],
        &GfdGrid::default(),
        &Weights::default(),
        0.3,
        0.3,
        &lead_tilt,
        machine.limits(),
    );
    let n = gfds[1].candidates.len();
    assert!(n > 0);
    let err = select_rtos(
        &mut gfds,
        &sigma,
        &Weights::default(),
        &world(),
        &Budget::unlimited(),
    )
    .unwrap_err();
    match &err {
        PlanError::NoFeasibleOrientation { index, u, reason } => {
            assert_eq!((*index, *u), (10, 0.5));
            assert!(
                reason.contains(&format!("{n} of the {n} remaining candidates collide")),
                "{reason}"
            );
        }
        other => panic!("expected NoFeasibleOrientation, got {other:?}"),
    }
    assert_eq!(err.status(), kerf_mjto::error::status::COLLISION);
    // The eager version reports the same layer.
    let (mut again, _) = layers(&[0.6, 0.7, 0.8], &GfdGrid::default());
    again[1] = gfds[1].clone();
    assert!(matches!(
        select_rtos_eager(&mut again, &sigma, &Weights::default(), &world()),
        Err(PlanError::NoFeasibleOrientation { index: 10, .. })
    ));
}

#[test]
fn empty_layer_and_bad_inputs() {
    let (mut gfds, sigma) = layers(&[0.6, 0.7], &GfdGrid::default());
    let world = world();
    let w = Weights::default();
    // Wrong number of path lengths, non-positive length, NaN weight.
    assert!(matches!(
        select_rtos(&mut gfds, &[], &w, &world, &Budget::unlimited()),
        Err(PlanError::InvalidRequest { .. })
    ));
    assert!(matches!(
        select_rtos(&mut gfds, &[0.0], &w, &world, &Budget::unlimited()),
        Err(PlanError::InvalidRequest { .. })
    ));
    let nan_w = Weights { k2: f64::NAN, ..w };
    assert!(matches!(
        select_rtos(&mut gfds, &sigma, &nan_w, &world, &Budget::unlimited()),
        Err(PlanError::InvalidRequest { .. })
    ));
    assert!(matches!(
        select_rtos(&mut [], &[], &w, &world, &Budget::unlimited()),
        Err(PlanError::InvalidRequest { .. })
    ));
    assert_eq!(world.queries(), 0);
    // A GFD emptied by its lead/tilt limits (a NaN limit rejects all).
    let machine = LaserMachine::default_machine().unwrap();
    gfds[0] = Gfd::build(
        0,
        0.0,
        &Vector3::new(0.6, Y, Z),
        [0.0, 0.0, -0.08],
        &GfdGrid::default(),
        &w,
        f64::NAN,
        0.3,
        &lead_tilt,
        machine.limits(),
    );
    match select_rtos(&mut gfds, &sigma, &w, &world, &Budget::unlimited()) {
        Err(PlanError::NoFeasibleOrientation {
            index: 0, reason, ..
        }) => {
            assert!(
                reason.starts_with("585 grid samples: 585 outside the lead/tilt limits"),
                "{reason}"
            );
        }
        other => panic!("{other:?}"),
    }
}
