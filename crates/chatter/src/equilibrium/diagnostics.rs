//! The summary of an equilibrium over the nominal engagement.

use super::{engaged, Equilibrium};
use crate::error::ChatterError;

/// Summary of an [`Equilibrium`] over the nominal engagement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EquilibriumDiagnostics {
    /// Smallest equilibrium chip h̃ over the engagement [m] (≤ 0: loss of
    /// contact somewhere).
    pub min_chip: f64,
    /// Fraction of the nominal engagement time with h̃ > 0 [-] (sampled at
    /// the grid-step midpoints, so resolved to about 1/(engaged steps)).
    pub contact_fraction: f64,
    /// max |τ_j(t) − m T| / T over the engagement (order m of the cut) [-].
    pub max_delay_deviation: f64,
    /// Forced-vibration amplitude max |õ − mean õ| [m].
    pub forced_amplitude: f64,
    /// Highest regeneration order that gives the chip somewhere.
    pub max_order: usize,
}

impl Equilibrium {
    /// Evaluates [`EquilibriumDiagnostics`] at the midpoints of the grid
    /// steps (weighted by step length).
    ///
    /// # Errors
    /// As [`Equilibrium::chip_state`].
    pub fn diagnostics(&self) -> Result<EquilibriumDiagnostics, ChatterError> {
        let mut min_chip = f64::INFINITY;
        let mut engaged_time = 0.0;
        let mut contact_time = 0.0;
        let mut dev: f64 = 0.0;
        let mut max_order = 0;
        for w in self.times.windows(2) {
            let tm = 0.5 * (w[0] + w[1]);
            let h = w[1] - w[0];
            for j in 0..self.process.teeth {
                if !engaged(&self.process, self.angle(j, tm)) {
                    continue;
                }
                let cs = self.chip_state(j, tm)?;
                engaged_time += h;
                min_chip = min_chip.min(cs.chip);
                dev = dev.max((cs.delay - cs.order as f64 * self.period).abs() / self.period);
                if cs.in_contact {
                    contact_time += h;
                    max_order = max_order.max(cs.order);
                }
            }
        }
        Ok(EquilibriumDiagnostics {
            min_chip: if min_chip.is_finite() { min_chip } else { 0.0 },
            contact_fraction: if engaged_time > 0.0 {
                contact_time / engaged_time
            } else {
                0.0
            },
            max_delay_deviation: dev,
            forced_amplitude: self.forced_amplitude(),
            max_order,
        })
    }
}
