//! `derivatives_at`: the path's first and second arc-length derivatives
//! against central differences of `point_at`.

use kerf_toolpath::{derivatives_at, point_at, sample_path, smooth_polyline};

#[test]
fn derivatives_match_central_differences_on_lines_and_corners() {
    let polyline = [
        [0.0, 0.0, 0.0],
        [0.01, 0.0, 0.0],
        [0.01, 0.01, 0.0],
        [0.0, 0.012, 0.001],
    ];
    let path = smooth_polyline(&polyline, 1e-4).unwrap();
    let samples = sample_path(&path, 1e-5);
    let length = samples.last().unwrap().s;
    // Steps: truncation (h²/6 |p‴|, |p‴| ~ κ² ~ 1e8) against rounding (1e-16 / h per difference).
    let (h1, h2) = (1e-7, 2e-6);
    let mut corner_points = 0;
    for k in 1..400 {
        let s = length * k as f64 / 400.0;
        let (p, d1, d2) = derivatives_at(&path, &samples, s);
        assert_eq!(p, point_at(&path, &samples, s));
        let at = |x: f64| point_at(&path, &samples, x);
        let (pm1, pp1, pm2, pp2) = (at(s - h1), at(s + h1), at(s - h2), at(s + h2));
        for d in 0..3 {
            let first = (pp1[d] - pm1[d]) / (2.0 * h1);
            let second = (pp2[d] - 2.0 * p[d] + pm2[d]) / (h2 * h2);
            assert!(
                (first - d1[d]).abs() < 1e-5,
                "s {s}: d1 {first} vs {}",
                d1[d]
            );
            assert!(
                (second - d2[d]).abs() < 2e-2 * (1.0 + d2[d].abs()),
                "s {s}: d2 {second} vs {}",
                d2[d]
            );
        }
        let unit = d1.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!((unit - 1.0).abs() < 1e-12);
        if d2.iter().any(|v| *v != 0.0) {
            corner_points += 1;
        }
    }
    assert!(corner_points > 10, "the corners were sampled");
}
