//! kerf's chatter shield ([`EnvConfig::chatter_shield`]): a post-posed
//! shield in the sense of Alshiekh et al., "Safe Reinforcement Learning via
//! Shielding" (AAAI 2018, section "Post-posed shielding"): the policy's
//! move is applied when it is safe, otherwise the safe move nearest to it.
//! Here "safe" is seed 004's stability condition |μ|max < 1 (eq. 9, the
//! spectral radius of the monodromy operator) with kerf's margin, checked on
//! the state the move leads to.

use super::{EnvConfig, Evaluation, MillEnv, PhysicalState};
use crate::env_config::{SHIELD_FRACTIONS, SHIELD_G_FRACTIONS, SHIELD_MAX_EVALUATIONS};
use crate::error::MillPlanError;

impl MillEnv {
    /// The shield's replacement of a step to `proposed`, whose |μ|max
    /// (`proposed_mu`) is at least `limit`.
    ///
    /// # Arguments
    /// * `current` — the state the step starts from (its joints are the
    ///   environment's).
    /// * `proposed` — the state of the filtered (and projected) move.
    /// * `proposed_mu` — its |μ|max.
    /// * `limit` — [`EnvConfig::chatter_shield`].
    ///
    /// # Returns
    /// The feasible state nearest to `proposed` whose |μ|max is below
    /// `limit`, among the moves (ΔΩ, Δf, Δg) = the step bounds times
    /// [`SHIELD_FRACTIONS`] per dimension (Δg = 0 with
    /// [`EnvConfig::fixed_g`] and on a held move, [`MillEnv::with_held_g`]), clipped to the state ranges like eq. 11;
    /// "nearest" in the move normalized by the step bounds (Euclidean), ties
    /// in the candidates' order, among the [`SHIELD_MAX_EVALUATIONS`]
    /// nearest feasible ones. When none is below `limit`, the evaluated
    /// candidate of least |μ|max if it is below `proposed_mu`; `None` when
    /// no candidate improves on the proposal (the step stays as proposed).
    ///
    /// # Performance
    /// Candidates are tried nearest first and the search stops at the first
    /// safe one; each costs an IK (feasibility, without the chatter model)
    /// and, when feasible, one |μ|max (the cache's, else a direct
    /// evaluation, about 0.4 ms): at most [`SHIELD_MAX_EVALUATIONS`] of the
    /// 225 candidates (25 with g fixed) are evaluated, the nearest feasible
    /// ones.
    ///
    /// # Errors
    /// Cell-model errors other than infeasibility; chatter-model errors.
    pub(super) fn shield(
        &self,
        current: &PhysicalState,
        proposed: &PhysicalState,
        proposed_mu: f64,
        limit: f64,
    ) -> Result<Option<(PhysicalState, Evaluation)>, MillPlanError> {
        let lim = *self.cell.state_limits();
        let bounds = [
            lim.max_spindle_step_rpm,
            lim.max_feed_step,
            lim.max_redundancy_step,
        ];
        let wanted = [
            proposed.rpm - current.rpm,
            proposed.feed - current.feed,
            proposed.g - current.g,
        ];
        let g_fractions: &[f64] = if self.config.fixed_g || self.holds_g(current.segment) {
            &[0.0]
        } else {
            &SHIELD_G_FRACTIONS
        };
        let mut candidates = Vec::with_capacity(SHIELD_FRACTIONS.len().pow(2) * g_fractions.len());
        for a in SHIELD_FRACTIONS {
            for b in SHIELD_FRACTIONS {
                for c in g_fractions {
                    let state = PhysicalState {
                        segment: proposed.segment,
                        rpm: (current.rpm + a * bounds[0])
                            .clamp(lim.spindle_rpm[0], lim.spindle_rpm[1]),
                        feed: (current.feed + b * bounds[1])
                            .clamp(lim.feed[0].max(self.config.min_feed), lim.feed[1]),
                        g: (current.g + c * bounds[2])
                            .clamp(lim.redundancy_angle[0], lim.redundancy_angle[1]),
                    };
                    let moved = [
                        state.rpm - current.rpm,
                        state.feed - current.feed,
                        state.g - current.g,
                    ];
                    let distance: f64 = (0..3)
                        .map(|k| ((moved[k] - wanted[k]) / bounds[k]).powi(2))
                        .sum();
                    candidates.push((distance, state));
                }
            }
        }
        // A stable sort: equal distances keep the candidates' order.
        candidates.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut tried: Vec<PhysicalState> = Vec::with_capacity(candidates.len());
        let mut best: Option<(f64, (PhysicalState, Evaluation))> = None;
        let mut evaluated = 0;
        for (_, state) in candidates {
            if evaluated == SHIELD_MAX_EVALUATIONS {
                break;
            }
            // The clip can map several moves to one state.
            if state == *proposed || tried.contains(&state) {
                continue;
            }
            tried.push(state);
            if !self.feasible(current, &state)? {
                continue;
            }
            evaluated += 1;
            let Ok(e) = self.checked_evaluation(current, &state)? else {
                continue;
            };
            let mu = self.shielded_radius(&state, &e)?;
            if mu < limit {
                return Ok(Some((state, e)));
            }
            if mu < best.as_ref().map_or(proposed_mu, |b| b.0) {
                best = Some((mu, (state, e)));
            }
        }
        Ok(best.map(|(_, b)| b))
    }

    /// The |μ|max the shield judges a state by: the larger of its |μ|max
    /// (`evaluation`) and, when [`MillEnv::with_shield_slowdown`] slows its
    /// segment by c > 1, its |μ|max at the feed f / c (same Ω, g and IK
    /// branch); the executed segment runs between the two feeds.
    ///
    /// # Errors
    /// Cell-model errors other than infeasibility; chatter-model errors.
    pub(super) fn shielded_radius(
        &self,
        state: &PhysicalState,
        evaluation: &Evaluation,
    ) -> Result<f64, MillPlanError> {
        let c = self
            .shield_slowdown
            .as_ref()
            .and_then(|s| s.get(state.segment))
            .copied()
            .unwrap_or(1.0);
        if c <= 1.0 {
            return Ok(evaluation.spectral_radius);
        }
        let slowed = PhysicalState {
            feed: state.feed / c,
            ..*state
        };
        Ok(match self.evaluate_state(&slowed, Some(&self.joints))? {
            Ok(e) => e.spectral_radius.max(evaluation.spectral_radius),
            Err(_) => evaluation.spectral_radius,
        })
    }
}

/// Checks [`EnvConfig::chatter_shield`]: `Some(limit)` needs a finite
/// limit > 0.
///
/// # Errors
/// [`MillPlanError::InvalidParameter`] naming the setting.
pub(super) fn check_shield(config: &EnvConfig) -> Result<(), MillPlanError> {
    match config.chatter_shield {
        Some(limit) if !(limit.is_finite() && limit > 0.0) => {
            Err(MillPlanError::InvalidParameter {
                name: "chatter shield |mu|max limit [-]".to_string(),
                value: limit,
                reason: "must be finite and > 0 (seed 004 eq. 9: stable below 1)".to_string(),
            })
        }
        _ => Ok(()),
    }
}
