//! The classic constant-delay milling model (Insperger & Stépán 2004, Int.
//! J. Numer. Meth. Eng. 61:117, §5, eq. 44–45; Altintas & Budak 1995):
//!
//! ```text
//! M p̈ + C ṗ + K p = −a_p H(t) (p(t) − p(t − T)),
//! H(t) = Σ_j g(φ_j(t)) b(φ_j) c(φ_j)ᵀ,   φ_j(t) = Ω t + 2π j / N_t,
//! ```
//!
//! with [`crate::model::force_direction`] `b` and
//! [`crate::model::chip_direction`] `c` (see [`crate::model`] for the frame),
//! and the screen function `g(φ) = 1` inside the engagement
//! `[φ_en, φ_ex]` (mod 2π), 0 outside. Multiplying out,
//!
//! ```text
//! H = Σ_j g [ K_t sc + K_n s²,   K_t c² + K_n sc ;
//!            −K_t s² + K_n sc,  −K_t sc + K_n c² ],   s = sin φ_j, c = cos φ_j,
//! ```
//!
//! which is Insperger & Stépán 2004 eq. 45 (h_xx = g (K_t cos φ + K_n sin φ) sin φ, …).
//!
//! # Sub-interval averages, exactly
//!
//! The discretization ([`crate::fdm`]) needs `H̄_i = (1/Δt) ∫_{t_i}^{t_{i+1}} H dt`.
//! Since `dφ = Ω dt`, `H̄_i = (1/Δφ) Σ_j ∫ g H_j dφ` over the tooth's angle
//! interval `[Ω t_i + 2πj/N_t, Ω t_{i+1} + 2πj/N_t]`, `Δφ = Ω Δt = 2π/(N_t m)`.
//! The screen function only cuts the interval at φ_en and φ_ex, so the
//! integral is the antiderivative difference over the intersection with the
//! engagement (and with its copy shifted by 2π), using
//! `∫ sc dφ = s²/2`, `∫ s² dφ = φ/2 − sin 2φ/4`, `∫ c² dφ = φ/2 + sin 2φ/4`.
//! No quadrature error, and entry/exit discontinuities inside a sub-interval
//! are honoured exactly.

use std::f64::consts::PI;

use nalgebra::Matrix2;

use crate::error::ChatterError;
use crate::model::{DdeSample, DelayTerm, MillingProcess, PeriodicDde};

/// Sub-interval averages `H̄_i` [N/m²] of the directional matrix over the
/// m sub-intervals of one tooth period (module documentation; Insperger &
/// Stépán 2004 eq. 45), exact.
///
/// # Arguments
/// * `process` — teeth, K_t, K_n, engagement (axial depth unused).
/// * `steps` — number of sub-intervals m ≥ 1.
///
/// # Errors
/// [`ChatterError::InvalidParameter`] for an invalid process or m = 0.
pub fn directional_averages(
    process: &MillingProcess,
    steps: usize,
) -> Result<Vec<Matrix2<f64>>, ChatterError> {
    process.validate()?;
    if steps == 0 {
        return Err(ChatterError::InvalidParameter {
            name: "number of sub-intervals m".to_string(),
            value: 0.0,
            reason: "must be >= 1".to_string(),
        });
    }
    let nt = process.teeth as f64;
    let dphi = 2.0 * PI / (nt * steps as f64);
    let (kt, kn) = (process.kt, process.kn);
    let mut out = Vec::with_capacity(steps);
    for i in 0..steps {
        let mut sum = Matrix2::zeros();
        for j in 0..process.teeth {
            let a = (i as f64 * dphi + 2.0 * PI * j as f64 / nt).rem_euclid(2.0 * PI);
            let b = a + dphi;
            for shift in [0.0, 2.0 * PI] {
                let lo = a.max(process.entry_angle + shift);
                let hi = b.min(process.exit_angle + shift);
                if hi > lo {
                    let sc = sc_int(hi) - sc_int(lo);
                    let ss = ss_int(hi) - ss_int(lo);
                    let cc = cc_int(hi) - cc_int(lo);
                    sum += Matrix2::new(
                        kt * sc + kn * ss,
                        kt * cc + kn * sc,
                        -kt * ss + kn * sc,
                        -kt * sc + kn * cc,
                    );
                }
            }
        }
        out.push(sum / dphi);
    }
    Ok(out)
}

fn sc_int(phi: f64) -> f64 {
    0.5 * phi.sin().powi(2)
}

fn ss_int(phi: f64) -> f64 {
    0.5 * phi - 0.25 * (2.0 * phi).sin()
}

fn cc_int(phi: f64) -> f64 {
    0.5 * phi + 0.25 * (2.0 * phi).sin()
}

/// The constant-delay milling DDE per unit axial depth: gains `H̄_i` [N/m²]
/// (present and delayed, delay T), i.e. [`constant_delay_dde`] with
/// a_p = 1 m. Scale it with [`scale_dde`] to get any depth without
/// recomputing the averages.
///
/// # Errors
/// [`ChatterError::InvalidParameter`] for an invalid process, speed or m.
pub fn constant_delay_dde_unit_depth(
    process: &MillingProcess,
    rpm: f64,
    steps: usize,
) -> Result<PeriodicDde, ChatterError> {
    let period = process.tooth_period(rpm)?;
    let h = directional_averages(process, steps)?;
    Ok(PeriodicDde {
        period,
        samples: h
            .into_iter()
            .map(|g| DdeSample {
                present: g,
                delayed: vec![DelayTerm {
                    gain: g,
                    delay: period,
                }],
            })
            .collect(),
    })
}

/// The classic constant-delay 2-DOF milling DDE
/// `M p̈ + C ṗ + K p = −a_p H(t)(p(t) − p(t − T))` (Insperger & Stépán
/// 2004 eq. 44) sampled on m sub-intervals: `present = a_p H̄_i`, one
/// delayed term `{gain: a_p H̄_i, delay: T}`.
///
/// # Arguments
/// * `process` — the milling process (axial depth a_p used).
/// * `rpm` — spindle speed [rev/min]; T = 60/(rpm N_t).
/// * `steps` — number of sub-intervals m.
///
/// # Errors
/// [`ChatterError::InvalidParameter`] for an invalid process, speed or m.
pub fn constant_delay_dde(
    process: &MillingProcess,
    rpm: f64,
    steps: usize,
) -> Result<PeriodicDde, ChatterError> {
    let unit = constant_delay_dde_unit_depth(process, rpm, steps)?;
    scale_dde(&unit, process.axial_depth)
}

/// Multiplies every gain (present and delayed) by `factor`, keeping the
/// delays: the depth scaling of a per-unit-depth equation.
///
/// # Errors
/// [`ChatterError::InvalidParameter`] for a non-finite or negative factor.
pub fn scale_dde(dde: &PeriodicDde, factor: f64) -> Result<PeriodicDde, ChatterError> {
    if !(factor.is_finite() && factor >= 0.0) {
        return Err(ChatterError::InvalidParameter {
            name: "gain scale factor".to_string(),
            value: factor,
            reason: "must be finite and >= 0".to_string(),
        });
    }
    Ok(PeriodicDde {
        period: dde.period,
        samples: dde
            .samples
            .iter()
            .map(|s| DdeSample {
                present: s.present * factor,
                delayed: s
                    .delayed
                    .iter()
                    .map(|d| DelayTerm {
                        gain: d.gain * factor,
                        delay: d.delay,
                    })
                    .collect(),
            })
            .collect(),
    })
}

/// Mean directional matrix `H̄₀ = (1/T) ∫₀^T H dt` [N/m²], the zeroth-order
/// approximation of Altintas & Budak (1995, CIRP Annals 44:357, eq. 9).
///
/// # Errors
/// [`ChatterError::InvalidParameter`] for an invalid process.
pub fn mean_directional_matrix(process: &MillingProcess) -> Result<Matrix2<f64>, ChatterError> {
    let h = directional_averages(process, 1)?;
    Ok(h.first().copied().unwrap_or_else(Matrix2::zeros))
}
