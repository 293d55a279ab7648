//! The Ruckig reference (`kerf_stepping::ruckig_ref`): it passes every
//! point, keeps every limit at every sample (checked by finite differences
//! of the sampled positions, not by rsruckig's own velocities), starts and
//! ends at rest, and compares with RPRO on database paths.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use kerf_stepping::{
    database::{self, Density},
    ruckig_ref::{self, Method, Reference},
    run, Course, Lattice, Limits, Rpro, RproSettings,
};

const DT: f64 = database::PERIOD;

/// Largest ratio of a finite-difference derivative to its limit, over all
/// axes and samples: (velocity, acceleration, jerk).
///
/// The first difference is the mean velocity over a period, the second
/// (central) a triangle-weighted mean acceleration over two periods, the
/// third a B-spline-weighted mean jerk over three: each is bounded by its
/// limit whenever the continuous motion is.
fn fd_ratios(r: &Reference, limits: &[Limits]) -> (f64, f64, f64) {
    let n = r.samples();
    let (mut rv, mut ra, mut rj) = (0.0f64, 0.0f64, 0.0f64);
    for (j, l) in limits.iter().enumerate() {
        let p: Vec<f64> = (0..n).map(|i| r.position(i)[j]).collect();
        for w in p.windows(2) {
            rv = rv.max(((w[1] - w[0]) / DT).abs() / l.velocity);
        }
        for w in p.windows(3) {
            ra = ra.max(((w[2] - 2.0 * w[1] + w[0]) / (DT * DT)).abs() / l.acceleration);
        }
        for w in p.windows(4) {
            let d3 = w[3] - 3.0 * w[2] + 3.0 * w[1] - w[0];
            rj = rj.max((d3 / (DT * DT * DT)).abs() / l.jerk);
        }
    }
    (rv, ra, rj)
}

/// Every check that does not depend on the method; returns the reference.
fn check(points: &[Vec<f64>], limits: &[Limits], method: Method, max_miss: f64) -> Reference {
    let r = ruckig_ref::reference(points, limits, DT, method).unwrap();
    let axes = limits.len();
    assert_eq!(r.axes, axes);
    assert_eq!(r.hits.len(), points.len());
    // Start and end at rest, on the first and last point.
    let last = r.samples() - 1;
    assert_eq!(r.position(0), &points[0][..]);
    let end = &points[points.len() - 1];
    for (j, goal) in end.iter().enumerate().take(axes) {
        assert_eq!(r.velocity(0)[j], 0.0);
        assert_eq!(r.acceleration(0)[j], 0.0);
        assert!(r.velocity(last)[j].abs() < 1e-9, "{method:?} end v");
        assert!(r.acceleration(last)[j].abs() < 1e-9, "{method:?} end a");
        assert!((r.position(last)[j] - goal).abs() < 1e-8);
    }
    // Passes every point, in order.
    for (k, h) in r.hits.iter().enumerate() {
        assert!(
            h.distance <= max_miss,
            "{method:?}: point {k} missed by {} (> {max_miss})",
            h.distance
        );
        if k > 0 {
            assert!(
                h.step >= r.hits[k - 1].step,
                "{method:?}: point {k} out of order"
            );
        }
    }
    // Limits by finite differences. Slack: 1e-6 relative (Ruckig's own
    // 1e-12 absolute limit tolerance and ~1e-12 m position noise amplified
    // by 1/Δt³ = 1.25e8 in the third difference; measured ≤ 1 + 5e-7).
    let (rv, ra, rj) = fd_ratios(&r, limits);
    eprintln!(
        "{:>16}: {} steps, max miss {:.3e} m, fd/limit v {rv:.6} a {ra:.6} j {rj:.6}",
        method.name(),
        r.steps(),
        r.max_error()
    );
    assert!(rv <= 1.0 + 1e-6, "{method:?}: velocity {rv} × limit");
    assert!(ra <= 1.0 + 1e-6, "{method:?}: acceleration {ra} × limit");
    assert!(rj <= 1.0 + 1e-5, "{method:?}: jerk {rj} × limit");
    r
}

fn one_axis(points: &[f64]) -> Vec<Vec<f64>> {
    points.iter().map(|x| vec![*x]).collect()
}

#[test]
fn every_method_passes_every_point_within_the_limits_on_one_axis() {
    let grid = database::limit_grid();
    for density in [Density::High, Density::Medium] {
        let pts = one_axis(&database::path(15, density, 0));
        for li in [0, 59] {
            let limits = [grid[li]];
            let bound = ruckig_ref::lower_bound(&pts, &limits, DT).unwrap();
            for method in Method::ALL {
                // Discrete sections end on the point itself; the one-call
                // waypoint trajectory is sampled where it falls, at most
                // half a period of travel from the point.
                let miss = if method == Method::Waypoints {
                    limits[0].velocity * DT / 2.0
                } else {
                    1e-7
                };
                let r = check(&pts, &limits, method, miss);
                assert!(
                    r.steps() >= bound,
                    "{method:?}: {} < bound {bound}",
                    r.steps()
                );
            }
        }
    }
}

#[test]
fn three_axes_turning_corners_pass_every_point_within_the_limits() {
    let pts = vec![
        vec![0.0, 0.0, 0.0],
        vec![0.01, 0.0, 0.0],
        vec![0.01, 0.01, 0.002],
        vec![0.0, 0.01, 0.004],
        vec![0.005, 0.005, 0.004],
        vec![0.0051, 0.0052, 0.0041],
    ];
    let limits = [
        Limits::new(0.1, 2.0, 20.0),
        Limits::new(0.08, 1.5, 30.0),
        Limits::new(0.05, 1.0, 10.0),
    ];
    let vmax = 0.1f64.hypot(0.08).hypot(0.05);
    let mut steps = Vec::new();
    for method in Method::ALL {
        let miss = if method == Method::Waypoints {
            vmax * DT / 2.0
        } else {
            1e-7
        };
        steps.push(check(&pts, &limits, method, miss).steps());
    }
    // Resting on every point is the slowest way through them.
    let rest = steps[3];
    assert!(steps.iter().all(|s| *s <= rest), "{steps:?}");
}

fn rpro_steps(points: &[f64], limits: Limits) -> usize {
    let lat = Lattice::new(limits, DT).unwrap();
    let course = Course::new(lat, points.to_vec(), database::PRECISION).unwrap();
    let mut rpro = Rpro::new(&course, RproSettings::default()).unwrap();
    run(&course, &mut rpro, 1_000_000).unwrap().steps()
}

#[test]
fn ruckig_is_close_to_rpro_on_medium_and_low_density_paths_and_both_above_the_bound() {
    // Measured (held-out bench, 40 processes a row): the default reference
    // needs 0–11 % more periods than RPRO look-ahead 1 at medium and low
    // density (every point hit exactly rather than within ±10 µm), and
    // ~1.7× at high density, where a gap is only 1–10 periods of travel.
    let grid = database::limit_grid();
    for (density, index) in [(Density::Medium, 1), (Density::Low, 2)] {
        let path = database::path(15, density, index);
        let pts = one_axis(&path);
        for li in [0, 29, 59] {
            let limits = grid[li];
            let bound = ruckig_ref::lower_bound(&pts, &[limits], DT).unwrap();
            let rpro = rpro_steps(&path, limits);
            let r = ruckig_ref::reference(&pts, &[limits], DT, Method::default()).unwrap();
            eprintln!(
                "{} limits {li}: bound {bound}, RPRO {rpro}, Ruckig {} (max miss {:.1e} m)",
                density.name(),
                r.steps(),
                r.max_error()
            );
            assert!(
                rpro >= bound,
                "RPRO {rpro} below the time-optimal bound {bound}"
            );
            assert!(r.steps() >= bound);
            assert!(
                r.steps() as f64 <= 1.2 * rpro as f64 + 5.0,
                "Ruckig {} vs RPRO {rpro}",
                r.steps()
            );
            assert!(r.max_error() < 1e-7);
        }
    }
}
