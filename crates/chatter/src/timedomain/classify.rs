//! Classifying a simulation: the per-period growth factor of the
//! deviation and the stable / unstable / indeterminate verdict.

use super::{Growth, Simulation, Verdict, FACTOR_TOLERANCE, FLOOR_RATIO, SATURATION_RATIO};
use crate::error::{check_positive, ChatterError};

/// Measures the growth of the deviation from periodicity of a
/// [`Simulation`] and calls it stable, unstable or indeterminate.
///
/// The per-period factor is the exponential of the slope of a least-squares
/// line through `ln d_k`, over the periods after the first tenth (start
/// transient of the non-dominant multipliers) up to the first period where
/// `d_k` leaves `[1e-5, 10] × d_0` (noise floor / saturation by loss of
/// contact). Verdict: unstable if the factor exceeds 1 + 2e-3 or the run
/// ends saturated (mean deviation of the last fifth > 10 d_0); stable if
/// the factor is below 1 − 2e-3 (the fit then runs to the end of the run
/// or to the noise floor, so the deviation decays up to the end);
/// otherwise indeterminate.
///
/// # Errors
/// [`ChatterError::InvalidParameter`] for a run shorter than 8 periods or a
/// zero initial deviation; [`ChatterError::NonFinite`] for a non-finite
/// deviation.
pub fn classify(sim: &Simulation) -> Result<Growth, ChatterError> {
    let count = sim.periods.len();
    if count < 8 {
        return Err(ChatterError::InvalidParameter {
            name: "simulated periods".to_string(),
            value: count as f64,
            reason: "classification needs >= 8".to_string(),
        });
    }
    let d0 = check_positive("initial deviation [m]", sim.initial_deviation)?;
    let d: Vec<f64> = sim.periods.iter().map(|p| p.deviation).collect();
    if d.iter().any(|v| !v.is_finite()) {
        return Err(ChatterError::NonFinite {
            what: "deviation from periodicity".to_string(),
        });
    }
    let inside = |v: f64| v <= SATURATION_RATIO * d0 && v >= FLOOR_RATIO * d0 && v > 0.0;
    let mut first = (count / 10).max(1);
    let mut last = (first..count).find(|&k| !inside(d[k])).unwrap_or(count);
    if last < first + 3 {
        // Fast growth or decay: fit from the first period on.
        first = 0;
        last = (0..count).find(|&k| !inside(d[k])).unwrap_or(count);
    }
    let factor = if last >= 2 {
        log_linear_factor(&d[first..last])
    } else {
        // Left the band within one or two periods: use the first period that
        // left it.
        let k = last.min(count - 1);
        let v = d.get(k).copied().unwrap_or(d0).max(f64::MIN_POSITIVE);
        (v / d0).powf(1.0 / (k as f64 + 1.0))
    };
    let tail = (count / 5).max(1);
    let late = &sim.periods[count - tail..];
    let final_ratio = late.iter().map(|p| p.deviation).sum::<f64>() / (tail as f64 * d0);
    let late_contact_fraction = late.iter().map(|p| p.contact_fraction).sum::<f64>() / tail as f64;
    let amplification = d.iter().fold(0.0_f64, |a, &v| a.max(v)) / d0;
    let verdict = if factor > 1.0 + FACTOR_TOLERANCE || final_ratio > SATURATION_RATIO {
        Verdict::Unstable
    } else if factor < 1.0 - FACTOR_TOLERANCE {
        Verdict::Stable
    } else {
        Verdict::Indeterminate
    };
    Ok(Growth {
        factor,
        fit_range: (first, last),
        amplification,
        final_ratio,
        late_contact_fraction,
        orbit_contact_fraction: sim.orbit_contact_fraction,
        verdict,
    })
}

/// exp(slope) of the least-squares line through (k, ln d_k).
pub(super) fn log_linear_factor(d: &[f64]) -> f64 {
    let n = d.len() as f64;
    let (mut sx, mut sy, mut sxx, mut sxy) = (0.0, 0.0, 0.0, 0.0);
    for (k, v) in d.iter().enumerate() {
        let (x, y) = (k as f64, v.ln());
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
    }
    let den = n * sxx - sx * sx;
    if den <= 0.0 {
        return 1.0;
    }
    ((n * sxy - sx * sy) / den).exp()
}

pub(super) fn fraction(num: usize, den: usize) -> f64 {
    if den == 0 {
        1.0
    } else {
        num as f64 / den as f64
    }
}
