//! The chatter indicator |μ|max of seed 004 section 2 — the public entry
//! point of the planner and of the `kerf lobes` tool.
//!
//! Two models ([`DelayModel`]):
//!
//! * `Constant` — the classic constant-delay model (Insperger & Stépán
//!   2004, [`crate::directional`]): feed-independent.
//! * `StateDependent` — seed 004 eq. 1-8 after Bachrathy, Insperger &
//!   Stépán 2011: the periodic equilibrium with feed-dependent delays
//!   ([`crate::equilibrium`]), linearized about it ([`crate::linearize`]).
//!
//! Both are discretized by the same [`Discretization`] (full
//! discretization, Ding et al. 2010) and the indicator is the spectral
//! radius of its monodromy matrix (Floquet theory: stable iff |μ|max < 1).
//!
//! # What makes |μ| depend on feed (mechanism)
//!
//! With the paper's *linear* force law `F = a_p h b(φ)`, the equilibrium
//! is a T-periodic forced vibration and its regenerative terms cancel
//! (`õ(t − τ) − õ(t) ≈ −õ̇ (τ − T)`), so h̃ ≈ f_z sin φ and loss of contact
//! in the equilibrium happens only near the exit (φ → π, where f_z sin φ
//! → 0) and near resonance of the tooth frequency with the tool mode. The
//! feed then enters the variational system ([`crate::linearize`]) through
//! (i) the delay shift `τ − T = O(f T/(R Ω))`, (ii) the delay-variation
//! term `κ w` of the chip (`κ = O(f/(R Ω), õ̇/(R Ω))`, ≈ 0.02 at 2000 rpm,
//! 0.06 m/s), (iii) the workpiece-wall term at a wall entry/exit with a
//! finite chip (`O(f_z/R)` per pass; a restoring, stabilizing impulse for
//! down milling at φ_en = 0.75π), and (iv) the loss-of-contact windows.
//! Each is a few percent of the cutting stiffness at the speeds and feeds
//! of seed 004, and their net sign depends on the tool-tip mode and the
//! speed: measured (`tests/feed_effect.rs`) from +1.3 % to −2.4 % in |μ|
//! between f = 0 and 0.06 m/s — a decrease, and a feed lower bound (seed
//! 004 Fig. 4, 7), for a robot mode of 80 Hz above its resonance speed; an
//! increase for a 25 Hz mode. These values agree with the independent
//! nonlinear time-domain simulation of [`crate::timedomain`].
//!
//! A nonlinear force law `F ∝ h^x_F` (x_F < 1, [`crate::equilibrium::ForceLaw`],
//! Stépán 2001) — an option, not the paper's law — has the cutting
//! stiffness `x_F F(h̃)/h̃ ∝ f_z^(x_F − 1)`, which falls with the feed: a
//! strong decrease of |μ| with feed at every speed (e.g. 1.15 → 0.95
//! between 0.005 and 0.06 m/s at 3000 rpm, x_F = 0.75).

use crate::directional::constant_delay_dde;
use crate::equilibrium::{Equilibrium, EquilibriumDiagnostics, EquilibriumSettings, ForceLaw};
use crate::error::{check_non_negative, ChatterError};
use crate::fdm::Discretization;
use crate::linearize::{linearize, LinearizeSettings};
use crate::model::{MillingProcess, Modal2, PeriodicDde};

/// Which delay model the indicator uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DelayModel {
    /// Constant delay τ = T, feed-independent (Insperger & Stépán 2004).
    Constant,
    /// State-dependent delays about the periodic equilibrium (seed 004
    /// eq. 1-8, Bachrathy et al. 2011).
    #[default]
    StateDependent,
}

/// Settings of [`chatter_indicator`] / [`indicator_map`] (builder style).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IndicatorSettings {
    /// Number of sub-intervals m of the discretization (≥ 2; default 40).
    pub steps: usize,
    /// Delay model (default state-dependent).
    pub model: DelayModel,
    /// Equilibrium settings (grid ≥ 200 nodes, regeneration orders,
    /// tolerance, force law).
    pub equilibrium: EquilibriumSettings,
    /// Include the workpiece-wall entry/exit term of [`crate::linearize`]
    /// (default true).
    pub wall_term: bool,
}

impl Default for IndicatorSettings {
    fn default() -> Self {
        Self {
            steps: 40,
            model: DelayModel::StateDependent,
            equilibrium: EquilibriumSettings::default(),
            wall_term: true,
        }
    }
}

impl IndicatorSettings {
    /// Sets m.
    pub fn steps(mut self, steps: usize) -> Self {
        self.steps = steps;
        self
    }

    /// Sets the delay model.
    pub fn model(mut self, model: DelayModel) -> Self {
        self.model = model;
        self
    }

    /// Sets the equilibrium grid nodes per period (≥ 200).
    pub fn points_per_period(mut self, n: usize) -> Self {
        self.equilibrium.points_per_period = n;
        self
    }

    /// Sets the highest regeneration order searched (1..=8).
    pub fn max_regeneration(mut self, order: usize) -> Self {
        self.equilibrium.max_regeneration = order;
        self
    }

    /// Sets the cutting-force law (exponent x_F and reference chip h_ref).
    pub fn force_law(mut self, exponent: f64, reference_chip: f64) -> Self {
        self.equilibrium.force_law = ForceLaw {
            exponent,
            reference_chip,
        };
        self
    }

    /// Sets the wall term on or off.
    pub fn wall_term(mut self, on: bool) -> Self {
        self.wall_term = on;
        self
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`ChatterError::InvalidParameter`].
    pub fn validate(&self) -> Result<(), ChatterError> {
        if !(2..=100_000).contains(&self.steps) {
            return Err(ChatterError::InvalidParameter {
                name: "number of sub-intervals m".to_string(),
                value: self.steps as f64,
                reason: "must be in 2..=100000 (use >= 40)".to_string(),
            });
        }
        self.equilibrium.validate()
    }
}

/// The indicator and its diagnostics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Indicator {
    /// |μ|max, the spectral radius of the monodromy matrix [-].
    pub spectral_radius: f64,
    /// Equilibrium diagnostics (min chip, contact fraction, max |τ − T|/T,
    /// forced amplitude); `None` for the constant-delay model.
    pub equilibrium: Option<EquilibriumDiagnostics>,
    /// Fixed-point iterations of the equilibrium (0 for constant delay).
    pub equilibrium_iterations: usize,
}

fn check_inputs(
    modal: &Modal2,
    process: &MillingProcess,
    rpm: f64,
    feed: f64,
    settings: &IndicatorSettings,
) -> Result<f64, ChatterError> {
    modal.validate()?;
    process.validate()?;
    settings.validate()?;
    check_non_negative("feed [m/s]", feed)?;
    process.tooth_period(rpm)
}

/// The linear periodic DDE of the chosen model at one (speed, feed), with
/// the equilibrium for the state-dependent model.
///
/// # Errors
/// As [`chatter_indicator`].
pub fn indicator_dde(
    modal: &Modal2,
    process: &MillingProcess,
    rpm: f64,
    feed: f64,
    settings: &IndicatorSettings,
) -> Result<(PeriodicDde, Option<Equilibrium>), ChatterError> {
    check_inputs(modal, process, rpm, feed, settings)?;
    match settings.model {
        DelayModel::Constant => Ok((constant_delay_dde(process, rpm, settings.steps)?, None)),
        DelayModel::StateDependent => {
            let eq = Equilibrium::compute(modal, process, rpm, feed, &settings.equilibrium)?;
            let dde = linearize(
                &eq,
                &LinearizeSettings {
                    steps: settings.steps,
                    wall_term: settings.wall_term,
                },
            )?;
            Ok((dde, Some(eq)))
        }
    }
}

fn finite(rho: f64) -> Result<f64, ChatterError> {
    if rho.is_finite() {
        Ok(rho)
    } else {
        Err(ChatterError::NonFinite {
            what: "chatter indicator |mu|max".to_string(),
        })
    }
}

/// The chatter indicator |μ|max at one spindle speed and feed (seed 004
/// section 2).
///
/// # Arguments
/// * `modal` — tool-tip dynamics
/// * `process` — milling process (teeth, R, a_p, K_t, K_n, engagement)
/// * `rpm` — spindle speed [rpm] (> 0)
/// * `feed` — feed speed [m/s] (≥ 0)
/// * `settings` — model, m, equilibrium settings
///
/// # Returns
/// [`Indicator`]: |μ|max and, for the state-dependent model, the
/// equilibrium diagnostics.
///
/// # Errors
/// [`ChatterError::InvalidParameter`] for NaN/out-of-range inputs (negative
/// feed, rpm ≤ 0, m < 2, …); [`ChatterError::NotConverged`] when the
/// equilibrium, a delay, or the eigen-solve hits its cap;
/// [`ChatterError::NonFinite`]; [`ChatterError::Unsupported`].
///
/// # Performance
/// State-dependent, m = 40, 200 equilibrium nodes, release build on the
/// 2-core build machine (the default cell's case of BENCHMARKS.md, "Chatter
/// indicator per evaluation"): about 0.37 ms (equilibrium 0.22 ms,
/// linearization 0.03 ms, diagnostics 0.01 ms, `Discretization::new` 0.02 ms,
/// compile and Arnoldi 0.09 ms); constant delay about 0.13 ms. A dev build
/// (opt-level 1) takes about three times as long.
pub fn chatter_indicator(
    modal: &Modal2,
    process: &MillingProcess,
    rpm: f64,
    feed: f64,
    settings: &IndicatorSettings,
) -> Result<Indicator, ChatterError> {
    let (dde, eq) = indicator_dde(modal, process, rpm, feed, settings)?;
    let disc = Discretization::new(
        modal,
        dde.period,
        settings.steps,
        dde.max_delay().max(dde.period),
    )?;
    let rho = finite(disc.spectral_radius(&dde)?)?;
    let (diag, iterations) = match eq {
        Some(eq) => (Some(eq.diagnostics()?), eq.iterations()),
        None => (None, 0),
    };
    Ok(Indicator {
        spectral_radius: rho,
        equilibrium: diag,
        equilibrium_iterations: iterations,
    })
}

/// |μ|max over a spindle-speed × feed grid (seed 004 Fig. 7), one
/// [`Discretization`] per speed (what depends on the speed only is
/// precomputed once).
///
/// # Arguments
/// * `rpms` — spindle speeds [rpm]; `feeds` — feed speeds [m/s]
///
/// # Returns
/// `map[i][k]` = |μ|max at `rpms[i]`, `feeds[k]`.
///
/// # Errors
/// As [`chatter_indicator`], for the first failing point; empty inputs
/// give an empty map.
pub fn indicator_map(
    modal: &Modal2,
    process: &MillingProcess,
    rpms: &[f64],
    feeds: &[f64],
    settings: &IndicatorSettings,
) -> Result<Vec<Vec<f64>>, ChatterError> {
    settings.validate()?;
    for &f in feeds {
        check_non_negative("feed [m/s]", f)?;
    }
    let mut map = Vec::with_capacity(rpms.len());
    for &rpm in rpms {
        let period = process.tooth_period(rpm)?;
        let ddes = match settings.model {
            DelayModel::Constant => {
                let dde = constant_delay_dde(process, rpm, settings.steps)?;
                vec![dde; feeds.len()]
            }
            DelayModel::StateDependent => feeds
                .iter()
                .map(|&f| indicator_dde(modal, process, rpm, f, settings).map(|(d, _)| d))
                .collect::<Result<Vec<_>, _>>()?,
        };
        let max_delay = ddes.iter().map(|d| d.max_delay()).fold(period, f64::max);
        let disc = Discretization::new(modal, period, settings.steps, max_delay)?;
        let row = match settings.model {
            DelayModel::Constant => match ddes.first() {
                Some(d) => vec![finite(disc.spectral_radius(d)?)?; feeds.len()],
                None => Vec::new(),
            },
            DelayModel::StateDependent => ddes
                .iter()
                .map(|d| disc.spectral_radius(d).and_then(finite))
                .collect::<Result<Vec<_>, _>>()?,
        };
        map.push(row);
    }
    Ok(map)
}
