//! Multi-axis stepping (issue 29, item 3): what the axes do, judged from
//! the samples alone.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use kerf_stepping::{multi::MultiCourse, Limits, Rpro, RproSettings};

/// Checks a run from its samples: every point passed within the precision
/// by some sample, per-axis velocity, acceleration and jerk by finite
/// differences within the limits, rest at both ends.
fn judge(points: Vec<Vec<f64>>, limits: &[Limits], precision: f64) -> usize {
    let period = 0.002;
    let mc = MultiCourse::new(points.clone(), limits, precision, period).unwrap();
    let mut rpro = Rpro::new(&mc.course, RproSettings::default()).unwrap();
    let r = mc.run(&mut rpro, 2_000_000).unwrap();
    let x: Vec<&Vec<f64>> = r.samples.iter().map(|s| &s.position).collect();
    for (k, p) in points.iter().enumerate().skip(1) {
        let best = x
            .iter()
            .map(|s| {
                s.iter()
                    .zip(p)
                    .map(|(a, b)| (a - b).powi(2))
                    .sum::<f64>()
                    .sqrt()
            })
            .fold(f64::INFINITY, f64::min);
        assert!(best <= precision * (1.0 + 1e-9), "point {k}: {best}");
    }
    let end = x.last().unwrap();
    let last = points.last().unwrap();
    let d: f64 = end
        .iter()
        .zip(last)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        .sqrt();
    assert!(
        d <= precision * (1.0 + 1e-9),
        "rest {d} from the last point"
    );
    let dim = points[0].len();
    let lim = |i: usize| {
        if limits.len() == 1 {
            limits[0]
        } else {
            limits[i]
        }
    };
    for i in 0..dim {
        let l = lim(i);
        for w in x.windows(4) {
            let v = (w[1][i] - w[0][i]) / period;
            let a = (w[2][i] - 2.0 * w[1][i] + w[0][i]) / period.powi(2);
            let j = (w[3][i] - 3.0 * w[2][i] + 3.0 * w[1][i] - w[0][i]) / period.powi(3);
            assert!(v.abs() <= l.velocity * (1.0 + 1e-6), "axis {i}: v {v}");
            assert!(
                a.abs() <= l.acceleration * (1.0 + 1e-6) + 1e-9,
                "axis {i}: a {a}"
            );
            assert!(j.abs() <= l.jerk * (1.0 + 1e-6) + 1e-6, "axis {i}: j {j}");
        }
        assert!(r.samples[0].velocity[i] == 0.0);
        assert!(r.samples.last().unwrap().velocity[i].abs() < 1e-12);
    }
    for p in &r.passes {
        assert!(p.error <= precision * (1.0 + 1e-9));
    }
    r.run.steps()
}

#[test]
fn a_planar_arc_is_stepped_within_every_axis_limit() {
    let pts: Vec<Vec<f64>> = (0..12)
        .map(|k| {
            let t = k as f64 * 0.1;
            vec![0.02 * t.cos(), 0.02 * t.sin()]
        })
        .collect();
    let steps = judge(pts, &[Limits::new(0.1, 2.0, 20.0)], 1e-5);
    assert!(steps > 0);
}

#[test]
fn a_spatial_path_with_per_axis_limits_and_a_turn_back_is_stepped() {
    let pts = vec![
        vec![0.0, 0.0, 0.0],
        vec![0.004, 0.001, 0.0005],
        vec![0.008, 0.003, 0.001],
        vec![0.006, 0.007, 0.002],
        vec![0.002, 0.008, 0.001],
    ];
    let limits = [
        Limits::new(0.1, 2.0, 20.0),
        Limits::new(0.05, 1.0, 10.0),
        Limits::new(0.02, 0.5, 5.0),
    ];
    judge(pts, &limits, 1e-5);
}

#[test]
fn a_joint_path_of_six_axes_is_stepped() {
    let pts = vec![
        vec![0.0, -0.5, 0.5, 0.0, 0.3, 0.0],
        vec![0.02, -0.49, 0.51, 0.01, 0.31, -0.01],
        vec![0.05, -0.47, 0.53, 0.03, 0.33, -0.02],
        vec![0.07, -0.46, 0.52, 0.04, 0.32, -0.04],
    ];
    judge(pts, &[Limits::new(1.0, 5.0, 50.0)], 1e-4);
}

#[test]
fn one_increasing_axis_is_the_papers_course_exactly() {
    let pts: Vec<Vec<f64>> =
        kerf_stepping::database::path(15, kerf_stepping::database::Density::High, 2)
            .into_iter()
            .map(|p| vec![p])
            .collect();
    let l = Limits::new(0.1, 2.0, 20.0);
    let mc = MultiCourse::new(pts, &[l], 1e-5, 0.002).unwrap();
    // The same lattice as the single axis (the limits agree to rounding).
    let lat = kerf_stepping::Lattice::new(l, 0.002).unwrap();
    assert_eq!(
        (mc.course.lattice.max_n, mc.course.lattice.max_m),
        (lat.max_n, lat.max_m)
    );
    assert!((mc.course.lattice.unit_p / lat.unit_p - 1.0).abs() < 1e-12);
    assert!((mc.course.precision - 1e-5).abs() < 1e-15);
}

#[test]
fn bad_input_is_refused_with_a_reason() {
    let l = [Limits::new(0.1, 2.0, 20.0)];
    let e = MultiCourse::new(vec![vec![0.0, 0.0], vec![0.0, 0.0]], &l, 1e-5, 0.002).unwrap_err();
    assert!(e.to_string().contains("repeated"), "{e}");
    let e = MultiCourse::new(vec![vec![0.0], vec![f64::NAN]], &l, 1e-5, 0.002).unwrap_err();
    assert!(e.to_string().contains("not finite"), "{e}");
    let e = MultiCourse::new(vec![vec![0.0], vec![1.0]], &l, 0.0, 0.002).unwrap_err();
    assert!(e.to_string().contains("precision"), "{e}");
    let e = MultiCourse::new(vec![vec![0.0], vec![1.0]], &l, -1e-5, 0.002).unwrap_err();
    assert!(e.to_string().contains("precision"), "{e}");
    let two = [l[0], l[0]];
    assert!(MultiCourse::new(vec![vec![0.0; 3], vec![1.0; 3]], &two, 1e-5, 0.002).is_err());
}
