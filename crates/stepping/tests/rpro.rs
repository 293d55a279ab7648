//! RPRO over the database of seed 002 Table 1: every process passes every
//! point within the precision, inside the limits, and stops on the last.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use kerf_stepping::{
    database::{self, Density},
    run, Course, Lattice, Rpro, RproSettings,
};

fn check(points: &[f64], limits: kerf_stepping::Limits) -> kerf_stepping::Run {
    let lat = Lattice::new(limits, database::PERIOD).unwrap();
    let course = Course::new(lat, points.to_vec(), database::PRECISION).unwrap();
    let mut rpro = Rpro::new(&course, RproSettings::default()).unwrap();
    let r = run(&course, &mut rpro, 1_000_000).unwrap();
    // Independent replay in floating point: positions from the jerks.
    let dt = database::PERIOD;
    let (mut p, mut v, mut a) = (0.0f64, 0.0f64, 0.0f64);
    let mut samples = vec![0.0];
    for act in &r.actions {
        let j = act.sign() as f64 * limits.jerk;
        p += v * dt + a * dt * dt / 2.0 + j * dt.powi(3) / 6.0;
        v += a * dt + j * dt * dt / 2.0;
        a += j * dt;
        assert!(
            v >= -1e-12 && v <= limits.velocity * (1.0 + 1e-9),
            "v = {v}"
        );
        assert!(a.abs() <= limits.acceleration * (1.0 + 1e-9), "a = {a}");
        samples.push(p);
    }
    assert!(v.abs() < 1e-12 && a.abs() < 1e-12, "ends at rest");
    for (k, target) in points.iter().enumerate().skip(1) {
        let rel = target - points[0];
        let best = samples
            .iter()
            .map(|s| (s - rel).abs())
            .fold(f64::INFINITY, f64::min);
        assert!(best <= database::PRECISION + 1e-12, "point {k}: {best}");
    }
    assert!((p - (points.last().unwrap() - points[0])).abs() <= database::PRECISION + 1e-12);
    r
}

#[test]
fn every_table_1_limit_passes_every_point_of_dense_and_medium_paths() {
    // High-density path 3 ends with a last point closer than the crawl's stopping distance:
    // a first version of the look-ahead found no action there at every jerk of 10 m/s³.
    for (density, path) in [(Density::High, 0), (Density::High, 3), (Density::Medium, 0)] {
        let points = database::path(15, density, path);
        let mut steps = Vec::new();
        for limits in database::limit_grid() {
            steps.push(check(&points, limits).steps());
        }
        steps.sort_unstable();
        eprintln!(
            "{}: median steps {}",
            density.name(),
            steps[steps.len() / 2]
        );
    }
}

#[test]
fn a_sparse_path_and_a_long_dense_path_are_passed() {
    check(
        &database::path(15, Density::Low, 3),
        database::limit_grid()[59],
    );
    check(
        &database::path(100, Density::High, 1),
        database::limit_grid()[0],
    );
}
