//! Tube-to-tube saddle cuts: the hole in the main tube where a branch tube meets it.

use nalgebra::Vector3;

use super::case::{Expectation, JobShopCase, Process};
use super::part::Part;
use super::tube::TubeParams;
use crate::TestPartError;

/// The saddle curve where a branch tube of radius r (axis z) meets the main tube of radius R
/// (axis x), as a closed curve over t in [0, 1], θ = 2πt:
/// `(r cos θ, r sin θ, √(R² − r² sin² θ))`, with the main tube's outward normal
/// `(0, y, z) / R` as the tool axis. The axis is vertical at θ = 0 and π (twice per loop)
/// and tilts by asin(r/R) at θ = ±π/2.
///
/// # Errors
/// [`TestPartError::Invalid`] unless 0 < r < R.
pub fn saddle_curve(
    tube: &TubeParams,
    r: f64,
) -> Result<impl Fn(f64) -> (Vector3<f64>, Vector3<f64>), TestPartError> {
    let big = tube.radius;
    if !(r > 0.0 && r < big) {
        return Err(TestPartError::invalid(
            "saddle branch radius",
            format!("{r} m must be in (0, {big}) m"),
        ));
    }
    Ok(move |t: f64| {
        let theta = std::f64::consts::TAU * t;
        let y = r * theta.sin();
        let z = (big * big - y * y).sqrt();
        (
            Vector3::new(r * theta.cos(), y, z),
            Vector3::new(0.0, y / big, z / big),
        )
    })
}

/// The saddle cases: branch-to-main radius ratios 0.4, 0.7 and 0.95 on the Ø100 × 3 main
/// tube, 10 m/min, Δt 4 ms, lead and tilt allowances 10° (the measurement of issue 16).
///
/// # Errors
/// Only for inconsistent defaults.
pub(super) fn saddle_cases(
    tube: &TubeParams,
    part: &Part,
) -> Result<Vec<JobShopCase>, TestPartError> {
    let process = Process::shop(10.0, 4.0, 10.0, 10.0);
    [
        ("saddle_r040", 0.4),
        ("saddle_r070", 0.7),
        ("saddle_r095", 0.95),
    ]
    .into_iter()
    .map(|(name, ratio)| {
        let r = ratio * tube.radius;
        let curve = saddle_curve(tube, r)?;
        JobShopCase::cut(
            name,
            format!(
                "saddle cut of a Ø{:.0} mm branch in the Ø{:.0} mm main tube (r/R = {ratio}), \
                     tool axis the main tube's normal, vertical twice per loop; 10 m/min, 10°/10°",
                2e3 * r,
                2e3 * tube.radius
            ),
            part,
            &curve,
            true,
            process,
            Expectation::Plan,
        )
    })
    .collect()
}
