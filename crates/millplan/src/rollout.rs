//! The states of the milling environment and what it reports about them:
//! [`PhysicalState`], the model's [`Evaluation`], per-state [`StepInfo`]
//! and a whole episode ([`Rollout`]).

use crate::reward::RewardParts;

/// The physical state (segment, Ω, f, g).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhysicalState {
    /// Segment index (0-based).
    pub segment: usize,
    /// Spindle speed \[rpm\].
    pub rpm: f64,
    /// Feed [m/s].
    pub feed: f64,
    /// Redundancy angle \[rad\].
    pub g: f64,
}

/// What the model gives for a feasible state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Evaluation {
    /// Joint vector \[rad\].
    pub joints: [f64; 6],
    /// Condition number K (seed 004 eq. 14).
    pub condition_number: f64,
    /// Condition indicator 1/K.
    pub condition_indicator: f64,
    /// |μ|max.
    pub spectral_radius: f64,
    /// Whether |μ|max came from the cache (else direct evaluation).
    pub from_cache: bool,
    /// Segment length / feed \[s\].
    pub segment_time: f64,
    /// Reward parts (eq. 12, 15-17).
    pub reward: RewardParts,
    /// The chatter-margin penalty ([`EnvConfig::chatter_margin`], ≥ 0; 0
    /// without a margin). The step reward is `reward.total − chatter_penalty`.
    pub chatter_penalty: f64,
}

/// Diagnostics of one state (the initial state or the result of a step).
#[derive(Debug, Clone, PartialEq)]
pub struct StepInfo {
    /// The state.
    pub state: PhysicalState,
    /// The filtered move â that led to it (ΔΩ \[rpm\], Δf [m/s], Δg \[rad\];
    /// zero for the initial state).
    pub filtered_action: [f64; 3],
    /// The reward (eq. 12, or the violation penalty).
    pub reward: f64,
    /// The model's values; `None` for a constraint violation.
    pub evaluation: Option<Evaluation>,
    /// Why the state violates a constraint (terminal), if it does.
    pub violation: Option<String>,
}

/// One episode: the initial state and every step.
#[derive(Debug, Clone, PartialEq)]
pub struct Rollout {
    /// s_0 (the IVP on segment 0).
    pub initial: StepInfo,
    /// s_1 … (one per step).
    pub steps: Vec<StepInfo>,
    /// r(s_0) + Σ step rewards (all machined segments).
    pub total_reward: f64,
    /// All N segments were machined without a violation.
    pub completed: bool,
}

impl Rollout {
    /// Why an incomplete rollout stopped: "segment i: <violation>" of the
    /// first violating step, or "the rollout ended early".
    pub fn stop_reason(&self) -> String {
        self.steps
            .iter()
            .find_map(|s| {
                s.violation
                    .as_ref()
                    .map(|v| format!("segment {}: {v}", s.state.segment))
            })
            .unwrap_or_else(|| "the rollout ended early".to_string())
    }

    /// The state sequence s_0, s_1, ….
    pub fn states(&self) -> Vec<PhysicalState> {
        std::iter::once(self.initial.state)
            .chain(self.steps.iter().map(|s| s.state))
            .collect()
    }
}
