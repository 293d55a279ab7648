//! Finite-difference derivatives, peaks, RMS jerk and limit violations of
//! sampled joint trajectories.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use approx::assert_abs_diff_eq;
use kerf_mjto::metrics::{finite_differences, kinematic_metrics, limit_violations, LIMIT_REL_TOL};
use kerf_mjto::{AxisLimits, LaserMachine};

/// Times 0, dt, …, and an uneven last interval ending at `total`.
fn grid(dt: f64, total: f64) -> Vec<f64> {
    let mut t: Vec<f64> = (0..)
        .map(|i| i as f64 * dt)
        .take_while(|&t| t < total - dt * 1e-6)
        .collect();
    t.push(total);
    t
}

/// Joint j follows `f(t) * (j + 1)` so that the joints differ.
fn sample(times: &[f64], f: impl Fn(f64) -> f64) -> Vec<[f64; 6]> {
    times
        .iter()
        .map(|&t| std::array::from_fn(|j| f(t) * (j as f64 + 1.0)))
        .collect()
}

#[test]
fn quartic_is_differentiated_exactly_even_on_the_uneven_last_interval() {
    let times = grid(0.01, 0.5337);
    let p = |t: f64| 0.3 - 0.2 * t + 1.5 * t * t - 4.0 * t.powi(3) + 2.5 * t.powi(4);
    let v = |t: f64| -0.2 + 3.0 * t - 12.0 * t * t + 10.0 * t.powi(3);
    let a = |t: f64| 3.0 - 24.0 * t + 30.0 * t * t;
    let j = |t: f64| -24.0 + 60.0 * t;
    let (fv, fa, fj) = finite_differences(&times, &sample(&times, p));
    assert_eq!(fv.len(), times.len());
    for (i, &t) in times.iter().enumerate() {
        for k in 0..6 {
            let s = k as f64 + 1.0;
            assert_abs_diff_eq!(fv[i][k], s * v(t), epsilon = 1e-9);
            assert_abs_diff_eq!(fa[i][k], s * a(t), epsilon = 1e-7);
            assert_abs_diff_eq!(fj[i][k], s * j(t), epsilon = 1e-6);
        }
    }
}

#[test]
fn smooth_motion_converges_at_second_order() {
    // x = sin(5t): the jerk error must fall ~4× when dt halves; velocity
    // and acceleration are more accurate still.
    let w = 5.0;
    let errors = |dt: f64| {
        // The last interval is 0.7 dt on both grids.
        let times = grid(dt, 1.0 - 0.3 * dt);
        let (fv, fa, fj) = finite_differences(&times, &sample(&times, |t| (w * t).sin()));
        let mut e = [0.0_f64; 3];
        for (i, &t) in times.iter().enumerate() {
            e[0] = e[0].max((fv[i][0] - w * (w * t).cos()).abs());
            e[1] = e[1].max((fa[i][0] + w * w * (w * t).sin()).abs());
            e[2] = e[2].max((fj[i][0] + w.powi(3) * (w * t).cos()).abs());
        }
        e
    };
    let coarse = errors(0.004);
    let fine = errors(0.002);
    for (c, f) in coarse.iter().zip(&fine) {
        assert!(c / f > 3.5, "order below 2: {c:e} → {f:e}");
    }
    // Absolute: jerk error ~ dt² · w⁵ / 4 at the ends.
    assert!(coarse[2] < 0.02 * w.powi(3), "jerk error {:e}", coarse[2]);
    assert!(coarse[0] < 1e-6 * w, "velocity error {:e}", coarse[0]);
}

/// Limits far from the test motions.
fn wide_limits() -> [AxisLimits; 6] {
    [AxisLimits {
        min: -10.0,
        max: 10.0,
        vel: 100.0,
        acc: 100.0,
        jerk: 100.0,
    }; 6]
}

#[test]
fn rms_and_peak_jerk_are_exact_on_a_constant_jerk_profile() {
    let jerk = 3.0;
    let times = grid(0.004, 0.3);
    let pos = sample(&times, |t| 0.1 + jerk * t.powi(3) / 6.0);
    let (v, a, j) = finite_differences(&times, &pos);
    let metrics = kinematic_metrics(&times, &pos, &v, &a, &j, &wide_limits());
    for k in 0..6 {
        let s = k as f64 + 1.0;
        assert_abs_diff_eq!(metrics.rms_jerk[k], s * jerk, epsilon = 1e-6);
        assert_abs_diff_eq!(metrics.peak_jerk[k], s * jerk, epsilon = 1e-6);
        assert_abs_diff_eq!(metrics.peak_acceleration[k], s * jerk * 0.3, epsilon = 1e-9);
        assert_abs_diff_eq!(
            metrics.peak_velocity[k],
            s * jerk * 0.09 / 2.0,
            epsilon = 1e-9
        );
    }
    assert!(metrics.within_limits, "{:?}", metrics.limit_violations);
    assert!(metrics.limit_violations.is_empty());
    assert_eq!(metrics.max_cl_error, 0.0);
    assert_eq!(metrics.colliding_samples, 0);
}

#[test]
fn violations_name_joint_quantity_value_and_time() {
    let m = LaserMachine::default_machine().unwrap();
    let n = 8;
    let times: Vec<f64> = (0..n).map(|i| 0.01 * i as f64).collect();
    let mut pos = vec![[0.5, 0.5, 0.5, 0.0, 0.0, -0.05]; n];
    let mut vel = vec![[0.0; 6]; n];
    let mut acc = vec![[0.0; 6]; n];
    let mut jerk = vec![[0.0; 6]; n];
    // q2 velocity over 2 m/s twice: the worst (−2.5 at t = 0.03) is kept.
    vel[5][1] = 2.2;
    vel[3][1] = -2.5;
    // q6 below its stroke at t = 0.01.
    pos[1][5] = -0.12;
    // q4 jerk over 200 rad/s³ at t = 0.07.
    jerk[7][3] = -250.0;
    // NaN acceleration of q5 at t = 0.02.
    acc[2][4] = f64::NAN;
    // q1 velocity within the relative tolerance: not a violation.
    vel[4][0] = 2.0 * (1.0 + 0.5 * LIMIT_REL_TOL);
    // q3 above its 3 m stroke by less than the tolerance.
    pos[6][2] = 3.0 + 1e-7;

    let v = limit_violations(&times, &pos, &vel, &acc, &jerk, m.limits(), LIMIT_REL_TOL);
    let found: Vec<(&str, &str, f64, f64, f64)> = v
        .iter()
        .map(|x| (x.joint.as_str(), x.quantity, x.value, x.limit, x.time))
        .collect();
    assert_eq!(found.len(), 4, "{found:?}");
    assert_eq!(found[0], ("q2", "velocity", -2.5, 2.0, 0.03));
    assert_eq!(found[1], ("q4", "jerk", -250.0, 200.0, 0.07));
    assert_eq!(
        (found[2].0, found[2].1, found[2].3, found[2].4),
        ("q5", "acceleration", 80.0, 0.02)
    );
    assert!(found[2].2.is_nan());
    assert_eq!(found[3], ("q6", "position", -0.12, -0.1, 0.01));

    // With no tolerance the q1 and q3 samples count too.
    let strict = limit_violations(&times, &pos, &vel, &acc, &jerk, m.limits(), 0.0);
    assert_eq!(strict.len(), 6);
    assert_eq!(
        (strict[0].joint.as_str(), strict[0].quantity),
        ("q1", "velocity")
    );
    assert_eq!(
        (
            strict[2].joint.as_str(),
            strict[2].quantity,
            strict[2].limit
        ),
        ("q3", "position", 3.0)
    );

    let metrics = kinematic_metrics(&times, &pos, &vel, &acc, &jerk, m.limits());
    assert!(!metrics.within_limits);
    assert_eq!(metrics.limit_violations.len(), 4);
    assert_eq!(
        metrics.limit_violations[0],
        "q2 velocity -2.500000 exceeds 2.000000 at t = 0.030 s"
    );
    assert!(metrics.limit_violations[3].starts_with("q6 position -0.120000"));
    assert!(
        metrics.peak_acceleration[4].is_nan(),
        "NaN is not hidden by max"
    );
    assert_eq!(metrics.peak_velocity[1], 2.5);
    assert_eq!(metrics.peak_jerk[3], 250.0);
}

#[test]
fn short_and_degenerate_inputs() {
    // One sample: zero derivatives; two: the divided difference.
    let (v, a, j) = finite_differences(&[0.0], &[[1.0; 6]]);
    assert_eq!((v[0], a[0], j[0]), ([0.0; 6], [0.0; 6], [0.0; 6]));
    let (v, a, _) = finite_differences(&[0.0, 0.5], &[[1.0; 6], [2.0; 6]]);
    assert_eq!(v, vec![[2.0; 6]; 2]);
    assert_eq!(a, vec![[0.0; 6]; 2]);
    // Three: the parabola.
    let (v, a, j) = finite_differences(&[0.0, 1.0, 3.0], &[[0.0; 6], [1.0; 6], [9.0; 6]]);
    for (i, t) in [0.0, 1.0, 3.0].iter().enumerate() {
        assert_abs_diff_eq!(v[i][0], 2.0 * t, epsilon = 1e-12);
        assert_abs_diff_eq!(a[i][0], 2.0, epsilon = 1e-12);
        assert_abs_diff_eq!(j[i][0], 0.0, epsilon = 1e-12);
    }
    // Mismatched lengths: the shorter one.
    let (v, _, _) = finite_differences(&[0.0, 1.0, 2.0], &[[0.0; 6], [1.0; 6]]);
    assert_eq!(v.len(), 2);
    // Repeated times: non-finite derivatives, reported, never hidden.
    let m = LaserMachine::default_machine().unwrap();
    let times = [0.0, 0.1, 0.1, 0.2];
    let pos = vec![[0.5, 0.5, 0.5, 0.0, 0.0, -0.05]; 4];
    let (v, a, j) = finite_differences(&times, &pos);
    let metrics = kinematic_metrics(&times, &pos, &v, &a, &j, m.limits());
    assert!(!metrics.within_limits);
}
