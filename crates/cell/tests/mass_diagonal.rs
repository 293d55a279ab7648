//! The mass-matrix diagonal of the servo gains (`kerf_cell::dynamics::mass_diagonal`) against
//! the inverse dynamics with a unit acceleration (Walker and Orin's method 1), on both robots at
//! random positions.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::{shipped, Rng};
use kerf_cell::dynamics::{inverse_dynamics, mass_diagonal, Workspace};
use kerf_cell::Mode;
use nalgebra::Vector3;

#[test]
fn mass_diagonal_equals_the_unit_acceleration_inverse_dynamics() {
    for name in ["laser_bpillar", "irb6660_plate"] {
        let cell = shipped(name, Mode::Dynamic);
        let chain = cell.chain();
        let n = chain.joints.len();
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let mut ws = Workspace::default();
        let mut diagonal = vec![0.0; n];
        let mut tau = vec![0.0; n];
        for _ in 0..50 {
            let q: Vec<f64> = cell
                .model()
                .joints()
                .iter()
                .map(|j| rng.range(j.min_position.max(-3.0), j.max_position.min(3.0)))
                .collect();
            mass_diagonal(chain, &q, &mut ws, &mut diagonal);
            for j in 0..n {
                let mut unit = vec![0.0; n];
                unit[j] = 1.0;
                inverse_dynamics(
                    chain,
                    &q,
                    &vec![0.0; n],
                    &unit,
                    &Vector3::zeros(),
                    &mut ws,
                    &mut tau,
                );
                assert!(
                    (diagonal[j] - tau[j]).abs() <= 1e-9 * tau[j].abs().max(1.0),
                    "{name} joint {j}: diagonal {} against {} at {q:?}",
                    diagonal[j],
                    tau[j]
                );
                assert!(diagonal[j] > 0.0, "{name} joint {j}: no inertia at {q:?}");
            }
        }
    }
}
