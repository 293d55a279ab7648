//! The geometric Jacobian against finite differences of FK, the condition
//! number of seed 004 eq. 14 against a second formula, singular poses, and
//! the characteristic length stored in the cell YAML.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

mod common;

use common::{random_q, robot, Rng};
use kerf_mill::{
    characteristic_length, condition_indicator, condition_number, Kinematics, MillCell,
};
use nalgebra::{Isometry3, Matrix6, Translation3, UnitQuaternion, Vector3};

/// Jacobian by central differences of the TCP pose (linear rows: position;
/// angular rows: the rotation vector of R(q + h e_i) R(q - h e_i)^T / 2h).
fn jacobian_fd(kin: &Kinematics, q: &[f64; 6]) -> Matrix6<f64> {
    let h = 1e-6;
    let mut j = Matrix6::zeros();
    for i in 0..6 {
        let (mut qp, mut qm) = (*q, *q);
        qp[i] += h;
        qm[i] -= h;
        let (tp, tm) = (
            kin.tcp_pose(&qp).expect("fk"),
            kin.tcp_pose(&qm).expect("fk"),
        );
        let v = (tp.translation.vector - tm.translation.vector) / (2.0 * h);
        let w = (tp.rotation * tm.rotation.inverse()).scaled_axis() / (2.0 * h);
        j.fixed_view_mut::<3, 1>(0, i).copy_from(&v);
        j.fixed_view_mut::<3, 1>(3, i).copy_from(&w);
    }
    j
}

fn offset_kinematics() -> Kinematics {
    let tcp = Isometry3::from_parts(
        Translation3::new(0.3, -0.05, 0.15),
        UnitQuaternion::from_axis_angle(&Vector3::y_axis(), 1.2),
    );
    Kinematics::from_robot(&robot(), tcp, [1.0; 6]).expect("kin")
}

#[test]
fn jacobian_matches_finite_differences_of_fk() {
    let mut rng = Rng(0xA076_1D64_78BD_642F);
    let mut worst = 0.0f64;
    for kin in [common::kinematics(), offset_kinematics()] {
        for _ in 0..200 {
            let q = random_q(&mut rng, &kin);
            let j = kin.jacobian(&q).expect("J");
            let fd = jacobian_fd(&kin, &q);
            worst = worst.max((j - fd).abs().max());
        }
    }
    println!("worst |J - J_fd| = {worst:.3e}");
    assert!(worst < 1e-6);
}

#[test]
fn condition_number_agrees_with_the_trace_formula_and_is_at_least_one() {
    let kin = offset_kinematics();
    let mut rng = Rng(99);
    for _ in 0..200 {
        let q = random_q(&mut rng, &kin);
        let j = kin.jacobian(&q).expect("J");
        for l in [0.3, 1.0, 2.5] {
            let k = condition_number(&j, l).expect("K");
            // Second method: explicit inverse.
            let mut jn = j;
            for r in 0..3 {
                for c in 0..6 {
                    jn[(r, c)] /= l;
                }
            }
            let a = jn * jn.transpose();
            let ainv = a.try_inverse().expect("regular at random q");
            let k2 = (a.trace() * ainv.trace()).sqrt() / 6.0;
            assert!((k - k2).abs() < 1e-8 * k2, "{k} vs {k2}");
            assert!(k >= 1.0);
            let ind = condition_indicator(&j, l).expect("1/K");
            assert!(ind > 0.0 && ind <= 1.0 && (ind * k - 1.0).abs() < 1e-15);
        }
    }
    // An isotropic Jacobian gives K = 1 exactly: J = diag(L I3, I3).
    let l = 1.7;
    let j = Matrix6::from_diagonal(&nalgebra::Vector6::new(l, l, l, 1.0, 1.0, 1.0));
    assert!((condition_number(&j, l).expect("K") - 1.0).abs() < 1e-14);
    // K scales as expected for a diagonal J: eigenvalues d_i^2.
    let d = nalgebra::Vector6::new(1.0, 2.0, 3.0, 4.0, 5.0, 6.0);
    let j = Matrix6::from_diagonal(&d);
    let s: f64 = d.iter().map(|x| x * x).sum();
    let si: f64 = d.iter().map(|x| 1.0 / (x * x)).sum();
    assert!((condition_number(&j, 1.0).expect("K") - (s * si).sqrt() / 6.0).abs() < 1e-13);
}

#[test]
fn singular_poses_give_infinity_never_nan() {
    for kin in [common::kinematics(), offset_kinematics()] {
        // Wrist singularity: q5 = 0 aligns the axes of joints 4 and 6.
        let j = kin.jacobian(&[0.3, 0.2, 0.4, 0.5, 0.0, 0.7]).expect("J");
        let k = condition_number(&j, 1.0).expect("K");
        assert!(k.is_infinite() && k > 0.0, "wrist: {k}");
        assert_eq!(condition_indicator(&j, 1.0).expect("ind"), 0.0);
        // Elbow singularity: forearm in line with the lower arm,
        // sin(beta - q3) = 1, i.e. q3 = beta - pi/2.
        let g = kin.geometry();
        let beta = g.a3.atan2(g.d4);
        let j = kin
            .jacobian(&[0.1, 0.3, beta - std::f64::consts::FRAC_PI_2, 0.2, 0.6, 0.1])
            .expect("J");
        let k = condition_number(&j, 1.0).expect("K");
        assert!(k.is_infinite(), "elbow: {k}");
    }
    let mut j = Matrix6::identity();
    j[(2, 2)] = f64::NAN;
    assert!(condition_number(&j, 1.0).is_err());
    assert!(condition_number(&Matrix6::identity(), 0.0).is_err());
}

#[test]
fn characteristic_length_in_the_yaml_minimizes_the_mean_condition_number() {
    let cell = MillCell::default_cell().expect("cell");
    let mut js = Vec::new();
    for gi in 0..9 {
        let g = -std::f64::consts::PI + gi as f64 * std::f64::consts::FRAC_PI_4;
        for s in 0..cell.path().segments().len() {
            if let Ok(state) = cell.evaluate(s, g, None) {
                js.push(cell.kinematics().jacobian(&state.joints).expect("J"));
            }
        }
    }
    let (l, mean) = characteristic_length(&js, 0.01, 100.0).expect("search");
    let stored = cell.characteristic_length();
    let mean_at = |l: f64| {
        js.iter()
            .map(|j| condition_number(j, l).expect("K"))
            .sum::<f64>()
            / js.len() as f64
    };
    println!(
        "{} reachable samples: L* = {l:.4} m (mean K {mean:.4}, 1/mean K {:.3}); stored L = \
         {stored} m (mean K {:.4}); mean K at L/2: {:.4}, at 2L: {:.4}",
        js.len(),
        1.0 / mean,
        mean_at(stored),
        mean_at(0.5 * l),
        mean_at(2.0 * l)
    );
    assert!(
        (stored - l).abs() < 1e-3 * l,
        "stored L {stored} vs minimizer {l}"
    );
    assert!(mean_at(stored) < mean_at(0.5 * l) && mean_at(stored) < mean_at(2.0 * l));
}
