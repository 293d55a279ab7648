//! The quaternion-interpolation baseline (seed 001 ref. [3], section 3).
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests report failures by panicking

use std::f64::consts::PI;

use approx::assert_abs_diff_eq;
use kerf_mjto::baseline::{qi_pose, quaternion_interpolation, Rto};
use kerf_mjto::kinematics::{forward, tool_axis};
use kerf_mjto::orientation::PathFrames;
use kerf_mjto::timelaw::TimeLaw;
use kerf_mjto::{LaserMachine, PlanError};
use nalgebra::Vector3;

/// A 0.8 m cut along x at y = 0.5, z = 0.3, with a small bump in z so the
/// reference path is not a single straight segment.
fn path() -> PathFrames {
    let n = 41;
    let points: Vec<_> = (0..n)
        .map(|i| {
            let x = i as f64 / (n - 1) as f64;
            Vector3::new(0.2 + 0.8 * x, 0.5, 0.3 + 0.01 * (PI * x).sin())
        })
        .collect();
    let mut s = vec![0.0];
    for w in points.windows(2) {
        s.push(s.last().unwrap() + (w[1] - w[0]).norm());
    }
    let total = *s.last().unwrap();
    let u: Vec<f64> = s.iter().map(|v| v / total).collect();
    PathFrames::try_new(&points, &vec![Vector3::z(); n], &u).unwrap()
}

fn sigma(f: &PathFrames) -> f64 {
    f.points().windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

fn rtos() -> Vec<Rto> {
    vec![
        Rto {
            u: 0.0,
            q4: 0.3,
            q5: 0.2,
            q6: -0.07,
        },
        Rto {
            u: 0.45,
            q4: 0.8,
            q5: 0.4,
            q6: -0.05,
        },
        Rto {
            u: 1.0,
            q4: 0.5,
            q5: 0.1,
            q6: -0.08,
        },
    ]
}

#[test]
fn passes_exactly_through_the_rtos() {
    let m = LaserMachine::default_machine().unwrap();
    let f = path();
    for r in rtos() {
        let q = qi_pose(&f, &rtos(), r.u, Some(r.q4), m.limits()).unwrap();
        assert_abs_diff_eq!(q[3], r.q4, epsilon = 1e-12);
        assert_abs_diff_eq!(q[4], r.q5, epsilon = 1e-12);
        assert_abs_diff_eq!(q[5], r.q6, epsilon = 1e-15);
        let (c, o) = forward(&q);
        assert_abs_diff_eq!(o, tool_axis(r.q4, r.q5), epsilon = 1e-12);
        assert_abs_diff_eq!(c, f.cl_point(r.u), epsilon = 1e-12);
    }
}

#[test]
fn sampled_trajectory_follows_the_path_on_great_circles() {
    let m = LaserMachine::default_machine().unwrap();
    let f = path();
    let sigma = sigma(&f);
    let law = TimeLaw::new(sigma, 0.25, 8.0, 80.0).unwrap();
    let dt = 0.004;
    let r = rtos();
    let (times, q) = quaternion_interpolation(&f, &r, &law, sigma, dt, m.limits()).unwrap();
    assert_eq!(times, law.sample_times(dt));
    assert_eq!(q.len(), times.len());
    // Ends: exactly the first and last RTO.
    assert_abs_diff_eq!(q[0][3], 0.3, epsilon = 1e-12);
    assert_abs_diff_eq!(q[0][4], 0.2, epsilon = 1e-12);
    let last = q.last().unwrap();
    assert_abs_diff_eq!(forward(last).1, tool_axis(0.5, 0.1), epsilon = 1e-12);
    assert_abs_diff_eq!(last[5], -0.08, epsilon = 1e-15);

    let axes: Vec<_> = r.iter().map(|x| tool_axis(x.q4, x.q5)).collect();
    let mut max_step = 0.0_f64;
    for (k, (t, qk)) in times.iter().zip(&q).enumerate() {
        let u = law.eval(*t)[0] / sigma;
        let (c, o) = forward(qk);
        assert_abs_diff_eq!(o.norm(), 1.0, epsilon = 1e-14);
        assert_abs_diff_eq!(c, f.cl_point(u), epsilon = 1e-12);
        // On the great circle between the two RTOs, at the fraction of u.
        let seg = if u < r[1].u { 0 } else { 1 };
        let s = (u - r[seg].u) / (r[seg + 1].u - r[seg].u);
        let (a, b) = (axes[seg], axes[seg + 1]);
        let total = a.angle(&b);
        assert_abs_diff_eq!(a.angle(&o), s * total, epsilon = 1e-7);
        assert_abs_diff_eq!(o.angle(&b), (1.0 - s) * total, epsilon = 1e-7);
        assert_abs_diff_eq!(o.dot(&a.cross(&b)), 0.0, epsilon = 1e-12);
        // q6 linear in u.
        let q6 = r[seg].q6 + s * (r[seg + 1].q6 - r[seg].q6);
        assert_abs_diff_eq!(qk[5], q6, epsilon = 1e-14);
        if k > 0 {
            max_step = max_step.max((qk[3] - q[k - 1][3]).abs());
        }
    }
    // q4 continuous: the whole move is 0.5 rad over ~900 samples.
    assert!(max_step < 0.01, "q4 step {max_step}");
}

#[test]
fn constant_orientation_keeps_the_rotary_axes_still() {
    let m = LaserMachine::default_machine().unwrap();
    let f = path();
    let sigma = sigma(&f);
    let law = TimeLaw::new(sigma, 0.25, 8.0, 80.0).unwrap();
    let r: Vec<Rto> = [0.0, 0.3, 0.7, 1.0]
        .iter()
        .map(|&u| Rto {
            u,
            q4: -2.0,
            q5: 0.35,
            q6: -0.06,
        })
        .collect();
    let (_, q) = quaternion_interpolation(&f, &r, &law, sigma, 0.01, m.limits()).unwrap();
    for qk in &q {
        assert_abs_diff_eq!(qk[3], -2.0, epsilon = 1e-12);
        assert_abs_diff_eq!(qk[4], 0.35, epsilon = 1e-12);
        assert_abs_diff_eq!(qk[5], -0.06, epsilon = 1e-15);
    }
}

#[test]
fn great_circle_through_the_vertical_keeps_q4_and_flips_q5() {
    // From 0.2 rad toward +x to 0.2 rad toward −x: the great circle passes
    // through the vertical; q4 must stay 0 and q5 sweep 0.2 → −0.2.
    let m = LaserMachine::default_machine().unwrap();
    let f = path();
    let r = [
        Rto {
            u: 0.0,
            q4: 0.0,
            q5: 0.2,
            q6: -0.07,
        },
        Rto {
            u: 1.0,
            q4: PI,
            q5: 0.2,
            q6: -0.07,
        },
    ];
    let mut prev = Some(0.0);
    let mut last_q5 = f64::INFINITY;
    for i in 0..=1000 {
        let u = i as f64 / 1000.0;
        let q = qi_pose(&f, &r, u, prev, m.limits()).unwrap();
        assert_abs_diff_eq!(q[3], 0.0, epsilon = 1e-12);
        assert_abs_diff_eq!(q[4], 0.2 - 0.4 * u, epsilon = 1e-9);
        assert!(q[4] < last_q5);
        last_q5 = q[4];
        prev = Some(q[3]);
    }
}

#[test]
fn bad_rtos_and_unreachable_samples_are_errors() {
    let m = LaserMachine::default_machine().unwrap();
    let f = path();
    let sigma = sigma(&f);
    let law = TimeLaw::new(sigma, 0.25, 8.0, 80.0).unwrap();
    let invalid = |r: Result<(Vec<f64>, Vec<[f64; 6]>), PlanError>| match r {
        Err(PlanError::InvalidRequest { field, .. }) => field,
        other => panic!("{other:?}"),
    };
    assert_eq!(
        invalid(quaternion_interpolation(
            &f,
            &[],
            &law,
            sigma,
            0.004,
            m.limits()
        )),
        "rtos"
    );
    let mut r = rtos();
    r[1].u = 0.0;
    assert_eq!(
        invalid(quaternion_interpolation(
            &f,
            &r,
            &law,
            sigma,
            0.004,
            m.limits()
        )),
        "rtos[1]"
    );
    let mut r = rtos();
    r[2].q5 = f64::NAN;
    assert_eq!(
        invalid(quaternion_interpolation(
            &f,
            &r,
            &law,
            sigma,
            0.004,
            m.limits()
        )),
        "rtos[2]"
    );
    assert_eq!(
        invalid(quaternion_interpolation(
            &f,
            &rtos(),
            &law,
            sigma * 1.1,
            0.004,
            m.limits()
        )),
        "sigma"
    );
    assert_eq!(
        invalid(quaternion_interpolation(
            &f,
            &rtos(),
            &law,
            sigma,
            0.0,
            m.limits()
        )),
        "sample_period"
    );
    // A period that would need more than MAX_SAMPLES samples.
    assert_eq!(
        invalid(quaternion_interpolation(
            &f,
            &rtos(),
            &law,
            sigma,
            1e-9,
            m.limits()
        )),
        "sample_period"
    );
    // q6 of the last RTO outside [−0.1, 0.02]: unreachable near the end.
    let mut r = rtos();
    r[2].q6 = 0.06;
    match quaternion_interpolation(&f, &r, &law, sigma, 0.004, m.limits()) {
        Err(PlanError::Unreachable { index, reason }) => {
            assert!(index > 20, "index {index}");
            assert!(reason.contains("q6"), "{reason}");
        }
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        qi_pose(&f, &rtos(), f64::NAN, None, m.limits()),
        Err(PlanError::InvalidRequest { .. })
    ));
}
