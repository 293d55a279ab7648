//! The reward of seed 004 section 3: eq. 12 (weighted sum) of the
//! singularity reward (eq. 15), the efficiency reward (eq. 16) and the
//! stability reward (eq. 17).
//!
//! # Default weights (kerf's choice, the paper gives none)
//!
//! `w_o = 0.1`, `w_e = 0.4`, `w_p = 0.5` ([`RewardWeights::default`]).
//! Reasoning, with the ranges of the three terms:
//!
//! * `r_s = −exp(clip(|μ|max − 1, 0, 5))` is −1 whenever the cut is stable
//!   (eq. 17 as written: exp(0) = 1), and falls to −e⁵ ≈ −148 in heavy
//!   chatter. The constant −w_p of a stable cut does not change which plan
//!   is best; the slope w_p·e^(|μ|−1) beyond |μ| = 1 is the chatter penalty.
//! * `r_e ∈ [0, 1.25]` (1.25 at f = f_max), `r_o = 1/(K + ε) ∈ (0, 1]`
//!   (about 0.3–0.6 on the default cell).
//!
//! With (0.1, 0.4, 0.5) a stable step at f = f_max and 1/K = 0.5 earns
//! 0.1·0.5 + 0.4·1.25 − 0.5 = 0.05, the paper's reported step reward
//! 0.05 ± 0.01 (seed 004 section 4, Fig. 6a), so its figures are
//! plausible on our scale. Efficiency dominates the operability term
//! (w_e = 4 w_o: a 1e-3 m/s feed gain above 0.7 f_max is worth
//! 0.4 · 3 · 1e-3/0.06 = 0.02, as much as raising 1/K by 0.2), and chatter
//! is penalized by the largest weight: |μ| = 1.2 costs 0.5·(e^0.2 − 1) =
//! 0.11 per step, the value of 5.5e-3 m/s of feed above 0.042 m/s.
//!
//! Measured consequence (`crate::dp`): eq. 17 has no jump at |μ| = 1
//! (its slope there is w_p = 0.5 per unit of |μ|), so the reward optimum
//! may accept marginal chatter (|μ| ≈ 1.00–1.01) where that buys feed or
//! conditioning; the DP's hard-constraint variant shows the price of
//! avoiding it.
//!
//! The weights are parameters ([`RewardWeights::new`] checks them).

use crate::error::MillPlanError;

/// ε of seed 004 eq. 15 (prevents a division by zero at a singularity).
pub const CONDITION_EPSILON: f64 = 1e-6;

/// Break point of the piecewise efficiency reward, seed 004 eq. 16
/// (f/f_max = 0.7).
pub const EFFICIENCY_BREAK: f64 = 0.7;

/// Upper clip of the chatter excess |μ|max − 1 in seed 004 eq. 17.
pub const STABILITY_CLIP: f64 = 5.0;

/// The weights (w_o, w_e, w_p) of seed 004 eq. 12, w_o + w_e + w_p = 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RewardWeights {
    /// Weight of the operational (singularity) reward r_o.
    pub operational: f64,
    /// Weight of the efficiency reward r_e.
    pub efficiency: f64,
    /// Weight of the stability reward r_s (w_p in eq. 12).
    pub stability: f64,
}

impl Default for RewardWeights {
    /// (0.1, 0.4, 0.5): module documentation.
    fn default() -> Self {
        Self {
            operational: 0.1,
            efficiency: 0.4,
            stability: 0.5,
        }
    }
}

impl RewardWeights {
    /// Validated weights.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidParameter`] when a weight is NaN, negative,
    /// or the three do not sum to 1 within 1e-9 (seed 004 eq. 12).
    pub fn new(operational: f64, efficiency: f64, stability: f64) -> Result<Self, MillPlanError> {
        let w = Self {
            operational,
            efficiency,
            stability,
        };
        w.validate()?;
        Ok(w)
    }

    /// Checks the weights (as [`RewardWeights::new`]).
    ///
    /// # Errors
    /// As [`RewardWeights::new`].
    pub fn validate(&self) -> Result<(), MillPlanError> {
        for (name, v) in [
            ("reward weight w_o [-]", self.operational),
            ("reward weight w_e [-]", self.efficiency),
            ("reward weight w_p [-]", self.stability),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(MillPlanError::InvalidParameter {
                    name: name.to_string(),
                    value: v,
                    reason: "must be finite and >= 0".to_string(),
                });
            }
        }
        let sum = self.operational + self.efficiency + self.stability;
        if (sum - 1.0).abs() > 1e-9 {
            return Err(MillPlanError::InvalidParameter {
                name: "reward weights w_o + w_e + w_p [-]".to_string(),
                value: sum,
                reason: "must sum to 1 (seed 004 eq. 12)".to_string(),
            });
        }
        Ok(())
    }
}

/// The three sub-rewards and their weighted sum for one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RewardParts {
    /// r_o, eq. 15.
    pub operational: f64,
    /// r_e, eq. 16.
    pub efficiency: f64,
    /// r_s, eq. 17.
    pub stability: f64,
    /// r = w_o r_o + w_e r_e + w_p r_s, eq. 12.
    pub total: f64,
}

fn finite(name: &str, v: f64) -> Result<f64, MillPlanError> {
    if v.is_nan() {
        return Err(MillPlanError::InvalidParameter {
            name: name.to_string(),
            value: v,
            reason: "is NaN".to_string(),
        });
    }
    Ok(v)
}

/// A chatter margin: kerf's shaping term added to the TRAINING objective
/// (environment and DP), NOT part of seed 004 eq. 12. The reward of a state
/// is lowered by `slope · max(0, |μ|max − limit)`.
///
/// Why: eq. 17 (`−exp(clip(|μ|max − 1, 0, 5))`) has no jump at |μ| = 1 and
/// a slope of only w_p = 0.5 per unit of |μ| there, so the optimum of
/// eq. 12 rides marginally above 1 wherever that buys feed or conditioning
/// (measured by the DP on the default cell: every eq. 12 optimum chatters,
/// `crate::dp`). The paper calls the stability term a constraint
/// "embedded in the reward shaping process" (seed 004 section 3); this
/// margin makes it one. The default limit lies below 1 by the indicator
/// cache's stated error bound for states on its g nodes (0.050,
/// [`crate::cache`]), so that the DP's plans (g on nodes) that the cache
/// calls safe are safe when evaluated directly.
///
/// Plans are REPORTED with eq. 12 alone ([`step_reward`],
/// [`crate::plan`]); the margin only shapes what the planners optimize.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChatterMargin {
    /// |μ|max above which the penalty starts (0 < limit ≤ 1).
    pub limit: f64,
    /// Penalty per unit of |μ|max above the limit (≥ 0).
    pub slope: f64,
}

impl Default for ChatterMargin {
    /// limit 0.95, slope 20: at |μ| = 1.0 a step loses 1.0, as much as the
    /// whole efficiency reward of f = 0.75 f_max; below 0.95 nothing.
    fn default() -> Self {
        Self {
            limit: 0.95,
            slope: 20.0,
        }
    }
}

impl ChatterMargin {
    /// Checks the margin.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidParameter`] for a limit outside (0, 1] or a
    /// negative or non-finite slope.
    pub fn validate(&self) -> Result<(), MillPlanError> {
        if !(self.limit > 0.0 && self.limit <= 1.0) {
            return Err(MillPlanError::InvalidParameter {
                name: "chatter margin limit [-]".to_string(),
                value: self.limit,
                reason: "must be in (0, 1]".to_string(),
            });
        }
        if !(self.slope.is_finite() && self.slope >= 0.0) {
            return Err(MillPlanError::InvalidParameter {
                name: "chatter margin slope [-]".to_string(),
                value: self.slope,
                reason: "must be finite and >= 0".to_string(),
            });
        }
        Ok(())
    }

    /// The penalty `slope · max(0, |μ|max − limit)` (≥ 0; subtract it).
    ///
    /// # Errors
    /// [`MillPlanError::InvalidParameter`] for a NaN |μ|max.
    pub fn penalty(&self, spectral_radius: f64) -> Result<f64, MillPlanError> {
        let mu = finite("chatter indicator |mu|max [-]", spectral_radius)?;
        Ok(self.slope * (mu - self.limit).max(0.0))
    }
}

/// Singularity-avoidance reward, seed 004 eq. 15: `r_o = 1/(K + ε)`,
/// ε = 1e-6.
///
/// # Arguments
/// * `condition_number` — K of seed 004 eq. 14 (≥ 1; +∞ at a singularity
///   gives 0).
///
/// # Errors
/// [`MillPlanError::InvalidParameter`] for NaN or K < 1 (eq. 14 is ≥ 1).
pub fn operational_reward(condition_number: f64) -> Result<f64, MillPlanError> {
    let k = finite("condition number K [-]", condition_number)?;
    if k < 1.0 - 1e-12 {
        return Err(MillPlanError::InvalidParameter {
            name: "condition number K [-]".to_string(),
            value: k,
            reason: "must be >= 1 (seed 004 eq. 14)".to_string(),
        });
    }
    Ok(1.0 / (k + CONDITION_EPSILON))
}

/// Efficiency reward, seed 004 eq. 16 (piecewise linear in ρ = f/f_max):
/// `0.5 ρ` for ρ ≤ 0.7, `3 (ρ − 0.7) + 0.35` above (continuous at 0.7,
/// where both give 0.35; 1.25 at ρ = 1).
///
/// The extracted formula lost its case conditions; the break at 0.7 is the
/// only point where the two lines meet (0.5·0.7 = 0.35 = 3·0 + 0.35), so
/// it is the reading that keeps r_e continuous.
///
/// # Arguments
/// * `feed` — f [m/s] (≥ 0); `max_feed` — f_max [m/s] (> 0).
///
/// # Errors
/// [`MillPlanError::InvalidParameter`] for NaN, f < 0, or f_max ≤ 0.
pub fn efficiency_reward(feed: f64, max_feed: f64) -> Result<f64, MillPlanError> {
    let f = finite("feed f [m/s]", feed)?;
    let fm = finite("maximum feed f_max [m/s]", max_feed)?;
    if !(fm > 0.0 && fm.is_finite()) {
        return Err(MillPlanError::InvalidParameter {
            name: "maximum feed f_max [m/s]".to_string(),
            value: fm,
            reason: "must be finite and > 0".to_string(),
        });
    }
    if !(f >= 0.0 && f.is_finite()) {
        return Err(MillPlanError::InvalidParameter {
            name: "feed f [m/s]".to_string(),
            value: f,
            reason: "must be finite and >= 0".to_string(),
        });
    }
    let rho = f / fm;
    Ok(if rho <= EFFICIENCY_BREAK {
        0.5 * rho
    } else {
        3.0 * (rho - EFFICIENCY_BREAK) + 0.5 * EFFICIENCY_BREAK
    })
}

/// Stability reward, seed 004 eq. 17: `r_s = −exp(clip(|μ|max − 1, 0, 5))`
/// (−1 for every stable cut, −e⁵ at |μ|max ≥ 6).
///
/// # Errors
/// [`MillPlanError::InvalidParameter`] for NaN or a negative |μ|max.
pub fn stability_reward(spectral_radius: f64) -> Result<f64, MillPlanError> {
    let mu = finite("chatter indicator |mu|max [-]", spectral_radius)?;
    if mu < 0.0 {
        return Err(MillPlanError::InvalidParameter {
            name: "chatter indicator |mu|max [-]".to_string(),
            value: mu,
            reason: "a spectral radius is >= 0".to_string(),
        });
    }
    Ok(-((mu - 1.0).clamp(0.0, STABILITY_CLIP)).exp())
}

/// The step reward of seed 004 eq. 12 and its parts.
///
/// # Arguments
/// * `weights` — (w_o, w_e, w_p);
/// * `condition_number` — K (eq. 14); `feed`, `max_feed` [m/s];
///   `spectral_radius` — |μ|max.
///
/// # Errors
/// As [`operational_reward`], [`efficiency_reward`], [`stability_reward`]
/// and [`RewardWeights::validate`].
pub fn step_reward(
    weights: &RewardWeights,
    condition_number: f64,
    feed: f64,
    max_feed: f64,
    spectral_radius: f64,
) -> Result<RewardParts, MillPlanError> {
    weights.validate()?;
    let operational = operational_reward(condition_number)?;
    let efficiency = efficiency_reward(feed, max_feed)?;
    let stability = stability_reward(spectral_radius)?;
    Ok(RewardParts {
        operational,
        efficiency,
        stability,
        total: weights.operational * operational
            + weights.efficiency * efficiency
            + weights.stability * stability,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn chatter_margin_is_zero_below_the_limit_and_linear_above() {
        let m = ChatterMargin::default();
        assert_eq!(m.penalty(0.5).unwrap(), 0.0);
        assert_eq!(m.penalty(0.95).unwrap(), 0.0);
        assert_relative_eq!(m.penalty(1.0).unwrap(), 1.0, epsilon = 1e-12);
        assert_relative_eq!(m.penalty(1.2).unwrap(), 5.0, epsilon = 1e-12);
        assert!(m.penalty(f64::NAN).is_err());
        for bad in [
            ChatterMargin {
                limit: 0.0,
                slope: 1.0,
            },
            ChatterMargin {
                limit: 1.1,
                slope: 1.0,
            },
            ChatterMargin {
                limit: f64::NAN,
                slope: 1.0,
            },
            ChatterMargin {
                limit: 0.9,
                slope: -1.0,
            },
            ChatterMargin {
                limit: 0.9,
                slope: f64::INFINITY,
            },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
        assert!(m.validate().is_ok());
    }

    #[test]
    fn operational_hand_values() {
        assert_relative_eq!(
            operational_reward(1.0).unwrap(),
            1.0 / 1.000001,
            epsilon = 1e-15
        );
        assert_relative_eq!(
            operational_reward(2.5).unwrap(),
            1.0 / 2.500001,
            epsilon = 1e-15
        );
        assert_eq!(operational_reward(f64::INFINITY).unwrap(), 0.0);
        assert!(operational_reward(0.5).is_err());
        assert!(operational_reward(f64::NAN).is_err());
    }

    #[test]
    fn efficiency_hand_values_and_continuity() {
        let fm = 0.06;
        assert_relative_eq!(efficiency_reward(0.0, fm).unwrap(), 0.0);
        // f0 = 0.04: ρ = 2/3 < 0.7 → 1/3.
        assert_relative_eq!(
            efficiency_reward(0.04, fm).unwrap(),
            1.0 / 3.0,
            epsilon = 1e-12
        );
        // Break point ρ = 0.7 (f = 0.042): 0.35 from both sides.
        assert_relative_eq!(efficiency_reward(0.042, fm).unwrap(), 0.35, epsilon = 1e-12);
        let below = efficiency_reward(0.042 - 1e-9, fm).unwrap();
        let above = efficiency_reward(0.042 + 1e-9, fm).unwrap();
        assert!((above - below).abs() < 1e-6);
        // ρ = 0.9: 3·0.2 + 0.35 = 0.95; ρ = 1: 1.25.
        assert_relative_eq!(efficiency_reward(0.054, fm).unwrap(), 0.95, epsilon = 1e-12);
        assert_relative_eq!(efficiency_reward(0.06, fm).unwrap(), 1.25, epsilon = 1e-12);
        assert!(efficiency_reward(-1e-3, fm).is_err());
        assert!(efficiency_reward(0.01, 0.0).is_err());
        assert!(efficiency_reward(f64::NAN, fm).is_err());
    }

    #[test]
    fn stability_hand_values() {
        assert_eq!(stability_reward(0.3).unwrap(), -1.0);
        assert_eq!(stability_reward(1.0).unwrap(), -1.0);
        assert_relative_eq!(
            stability_reward(1.2).unwrap(),
            -(0.2f64).exp(),
            epsilon = 1e-12
        );
        // Clipped at 5.
        assert_relative_eq!(
            stability_reward(9.0).unwrap(),
            -(5.0f64).exp(),
            epsilon = 1e-9
        );
        assert!(stability_reward(f64::NAN).is_err());
        assert!(stability_reward(-0.1).is_err());
    }

    #[test]
    fn weighted_sum_and_weight_validation() {
        let w = RewardWeights::default();
        // The paper's step: f = f_max, 1/K = 0.5 (K = 2), stable → 0.05.
        let p = step_reward(&w, 2.0, 0.06, 0.06, 0.998).unwrap();
        assert_relative_eq!(p.total, 0.1 / 2.000001 + 0.4 * 1.25 - 0.5, epsilon = 1e-12);
        assert!((p.total - 0.05).abs() < 1e-6);
        let w2 = RewardWeights::new(0.2, 0.3, 0.5).unwrap();
        let q = step_reward(&w2, 4.0, 0.03, 0.06, 1.5).unwrap();
        let expect = 0.2 / 4.000001 + 0.3 * 0.25 - 0.5 * (0.5f64).exp();
        assert_relative_eq!(q.total, expect, epsilon = 1e-12);
        assert!(RewardWeights::new(0.2, 0.3, 0.4).is_err());
        assert!(RewardWeights::new(-0.1, 0.6, 0.5).is_err());
        assert!(RewardWeights::new(f64::NAN, 0.5, 0.5).is_err());
    }
}
