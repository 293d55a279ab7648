//! The interface between a learning agent and an environment: what DDPG
//! (seed 004 Algorithm 1) needs and nothing more.

use crate::error::MillPlanError;

/// One environment step's outcome (seed 004 Algorithm 1: r_{t+1}, s_{t+1}).
#[derive(Debug, Clone, PartialEq)]
pub struct Transition {
    /// Normalized observation of the next state, every entry in [−1, 1].
    pub observation: Vec<f32>,
    /// Reward r_{t+1} (seed 004 eq. 12).
    pub reward: f64,
    /// The episode ended with this step (last segment reached, or a
    /// terminal constraint violation).
    pub done: bool,
}

/// A deterministic episodic environment with a continuous action space.
///
/// Observations and actions are normalized: observations to [−1, 1] per
/// entry, actions to [−1, 1] per entry (the actor's tanh output); the
/// environment scales actions to its physical step bounds.
pub trait Environment {
    /// Length of an observation vector.
    fn observation_dim(&self) -> usize;
    /// Length of an action vector.
    fn action_dim(&self) -> usize;
    /// Largest number of steps of one episode.
    fn max_steps(&self) -> usize;
    /// The names of the observation entries, in order (recorded in a trained
    /// policy's sidecar, [`crate::PolicyMetadata::observation_layout`]);
    /// empty by default.
    fn observation_layout(&self) -> Vec<String> {
        Vec::new()
    }
    /// Starts a new episode at the initial state (seed 004: the initial value
    /// problem) and returns its observation.
    ///
    /// # Errors
    /// When the initial state itself cannot be evaluated.
    fn reset(&mut self) -> Result<Vec<f32>, MillPlanError>;
    /// Applies a normalized action (entries in [−1, 1]; anything else,
    /// including NaN, is an error, never clamped silently).
    ///
    /// # Errors
    /// [`MillPlanError`] for a bad action or a failed evaluation.
    fn step(&mut self, action: &[f32]) -> Result<Transition, MillPlanError>;
}
