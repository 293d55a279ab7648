//! CPU cost of one 1 kHz rapier step of the laser cutter's multibody (no efforts applied,
//! gravity on), with the cell's integration parameters (one substep, 4 PGS iterations) and
//! with rapier's defaults (4 substeps, 1 PGS iteration each).
//!
//! Run: `cargo run --release -p kerf_cell --example step_cost`.
#![allow(clippy::unwrap_used, clippy::expect_used)] // an example reports failures by panicking

use std::time::Instant;

use kerf_cell::chain::Chain;
use kerf_cell::inertia::InertiaFile;
use kerf_cell::world::World;
use nalgebra::Vector3;

fn main() {
    let dir = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../urdf");
    let urdf = std::fs::read_to_string(dir.join("laser_cutter.urdf")).unwrap();
    let model = kerf_cell::load_robot(&urdf).unwrap();
    let inertia = InertiaFile::from_file(&dir.join("laser_cutter_inertia.yaml")).unwrap();
    let chain = Chain::build(&model, &inertia).unwrap();
    let q0 = [0.4, 0.7, 1.2, 0.0, 0.0, -0.07];
    for (name, substeps, pgs) in [("kerf_cell", 1, 4), ("rapier defaults", 4, 1)] {
        let mut world = World::new(&chain, &q0, &Vector3::new(0.0, 0.0, -9.81), 0.001).unwrap();
        world.physics.integration_parameters.num_solver_iterations = substeps;
        world
            .physics
            .integration_parameters
            .num_internal_pgs_iterations = pgs;
        let tau = vec![0.0; chain.joints.len()];
        let mut times = Vec::new();
        for _ in 0..5000 {
            let start = Instant::now();
            world.apply_efforts(&chain, &tau);
            world.step();
            times.push(start.elapsed().as_secs_f64() * 1e6);
        }
        times.sort_by(f64::total_cmp);
        println!(
            "{name:<16} ({substeps} substeps x {pgs} PGS): median {:.1} us, p99 {:.1} us",
            times[times.len() / 2],
            times[times.len() * 99 / 100]
        );
    }
}
