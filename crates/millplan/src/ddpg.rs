//! Deep deterministic policy gradient (DDPG): seed 004 Algorithm 1 with the
//! hyperparameters of its Table 2, after Lillicrap et al., "Continuous
//! control with deep reinforcement learning", ICLR 2016, Algorithm 1.
//!
//! # Algorithm (one environment step t, after the warm-up)
//! 1. Act: a_t = clip(A(s_t | wᵃ) + σ_e ε, −1, 1), ε ~ N(0, I) (Gaussian
//!    exploration, seed 004 Table 2 "initial noise deviation"); observe
//!    r_{t+1}, s_{t+1}; store (s_t, a_t, r_{t+1}, s_{t+1}, terminal) in B.
//! 2. Sample a minibatch of N transitions from B (uniform, with
//!    replacement).
//! 3. Critic (seed 004 Algorithm 1 "TD error", "critic network update"):
//!    y_i = r_i + γ (1 − terminal_i) Q′(s′_i, A′(s′_i | w^{a′}) | w^{q′}),
//!    L_q = (1/N) Σ (Q(s_i, a_i | w^q) − y_i)²; one AdamW step on w^q.
//!    Minimizing L_q moves w^q along δ_t ∇Q, the paper's update; the paper
//!    writes the bootstrap with A and Q, the targets A′, Q′ are Lillicrap's
//!    (and the paper's "Require: target networks A′, Q′").
//! 4. Actor (seed 004 Algorithm 1 "actor network update", the deterministic
//!    policy gradient ∇_{wᵃ} A · ∇_a Q): L_a = −(1/N) Σ Q(s_i, A(s_i | wᵃ));
//!    one AdamW step on wᵃ (the critic's weights are held fixed in this
//!    step; it uses the critic just updated, as Lillicrap's code does).
//!
//! The gradients of both steps are computed by hand on candle tensors
//! ([`Mlp::backward`], [`Mlp::output_and_input_gradient`]; tested against
//! candle's autograd), which is markedly faster for these small networks.
//! 5. Soft target updates (Algorithm 1): w′ ← τ w + (1 − τ) w′ for both
//!    networks.
//!
//! # Optimizer
//! AdamW with weight decay 0 and candle's default β₁ = 0.9, β₂ = 0.999,
//! ε = 1e-8 ([`ParamsAdamW`]), applied by [`FusedAdamW`]: the update of
//! `candle_nn::AdamW` in one pass per variable (tested equal to candle's),
//! because candle's dozen tensor operations per variable were a large part
//! of an update's time.
//!
//! # Warm-up
//! Learning (steps 2–5) starts once the replay buffer holds at least one
//! batch (`batch_size` transitions); before, the agent only acts (with
//! noise) and stores. With batch 64 and 100-step episodes that is the first
//! 64 steps of the first episode.
//!
//! # Terminal versus time limit
//! A transition whose [`crate::rl::Transition::done`] is true is terminal: no
//! bootstrapping from s_{t+1} (the end of the path, a terminal violation).
//! An episode cut at `steps_per_episode` without `done` is a time limit and
//! its last transition still bootstraps.
//!
//! # Exploration noise schedule (seed 004 Table 2, garbled)
//! Table 2 lists "initial noise deviation 0.1, noise decay rate 0.999, noise
//! decay episode 50". Read here as: the noise standard deviation stays at σ₀
//! for the first 50 episodes and then decays geometrically per episode,
//! σ_k = σ₀ · ρ^max(0, k − E_d) for the 1-based episode k, with σ₀ = 0.1,
//! ρ = 0.999, E_d = 50. After 1000 episodes σ = 0.1 · 0.999⁹⁵⁰ ≈ 0.039:
//! exploration never vanishes, which a per-step decay (0.999¹⁰⁰⁰⁰⁰ ≈ 0)
//! would make it do after a few episodes, and which a decay by 0.999 every
//! 50 episodes (σ ≈ 0.098 at the end) would make pointless.
//!
//! # Determinism
//! For a given seed, training is bit-identical from run to run on one
//! machine: all random numbers (initial weights, exploration noise, replay
//! sampling) come from one [`Rng`] seeded with [`DdpgSettings::seed`], the
//! environment is deterministic by contract, and candle runs on one thread
//! (see [`CpuTuning`]). Results may differ between machines whose CPUs
//! select different `gemm` kernels (AVX2 versus AVX-512).

use std::time::Instant;

use candle_core::Tensor;
use candle_nn::ParamsAdamW;
use serde::{Deserialize, Serialize};

use crate::error::MillPlanError;
use crate::nets::{backend, matrix, scalar, CpuTuning, FusedAdamW, Mlp, OutputActivation};
use crate::replay::{Batch, ReplayBuffer};
use crate::rl::Environment;
use crate::rng::Rng;

/// Every parameter of a DDPG training run (defaults: seed 004 Table 2).
///
/// Build with [`DdpgSettings::default`] and the `with_*` setters; check with
/// [`DdpgSettings::validate`] ([`train`] calls it).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DdpgSettings {
    /// Number of episodes N_ep (Table 2: 1000).
    pub episodes: usize,
    /// Largest number of steps of one episode (issue 5: 100, the number of
    /// path segments); the environment's own [`Environment::max_steps`]
    /// caps it too.
    pub steps_per_episode: usize,
    /// Widths of the hidden ReLU layers of both actor and critic (Table 2:
    /// 2×256).
    pub hidden_sizes: Vec<usize>,
    /// Actor learning rate α_{wᵃ} (Table 2: 1e-4).
    pub actor_learning_rate: f64,
    /// Critic learning rate α_{w^q} (Table 2: 1e-3).
    pub critic_learning_rate: f64,
    /// Discount factor Γ (Table 2: 0.99), in [0, 1].
    pub discount: f64,
    /// Soft update rate τ_u (Table 2: 0.005), in (0, 1].
    pub soft_update_rate: f64,
    /// Replay buffer size B (Table 2: 10 000).
    pub buffer_capacity: usize,
    /// Minibatch size N (Table 2: 64).
    pub batch_size: usize,
    /// Initial standard deviation σ₀ of the Gaussian exploration noise, in
    /// normalized action units (Table 2: 0.1).
    pub noise_std: f64,
    /// Per-episode decay factor ρ of the noise after
    /// [`Self::noise_decay_start_episode`] (Table 2: 0.999), in (0, 1].
    pub noise_decay_rate: f64,
    /// Number of episodes E_d at full noise before the decay (Table 2: 50).
    pub noise_decay_start_episode: usize,
    /// Seed of every random number of the run.
    pub seed: u64,
    /// Run candle on one thread (see [`CpuTuning`]); true by default.
    pub single_thread: bool,
}

impl Default for DdpgSettings {
    fn default() -> Self {
        Self {
            episodes: 1000,
            steps_per_episode: 100,
            hidden_sizes: vec![256, 256],
            actor_learning_rate: 1e-4,
            critic_learning_rate: 1e-3,
            discount: 0.99,
            soft_update_rate: 0.005,
            buffer_capacity: 10_000,
            batch_size: 64,
            noise_std: 0.1,
            noise_decay_rate: 0.999,
            noise_decay_start_episode: 50,
            seed: 0,
            single_thread: true,
        }
    }
}

impl DdpgSettings {
    /// Sets [`Self::episodes`].
    pub fn with_episodes(mut self, episodes: usize) -> Self {
        self.episodes = episodes;
        self
    }
    /// Sets [`Self::steps_per_episode`].
    pub fn with_steps_per_episode(mut self, steps: usize) -> Self {
        self.steps_per_episode = steps;
        self
    }
    /// Sets [`Self::hidden_sizes`].
    pub fn with_hidden_sizes(mut self, sizes: Vec<usize>) -> Self {
        self.hidden_sizes = sizes;
        self
    }
    /// Sets [`Self::actor_learning_rate`].
    pub fn with_actor_learning_rate(mut self, lr: f64) -> Self {
        self.actor_learning_rate = lr;
        self
    }
    /// Sets [`Self::critic_learning_rate`].
    pub fn with_critic_learning_rate(mut self, lr: f64) -> Self {
        self.critic_learning_rate = lr;
        self
    }
    /// Sets [`Self::discount`].
    pub fn with_discount(mut self, gamma: f64) -> Self {
        self.discount = gamma;
        self
    }
    /// Sets [`Self::soft_update_rate`].
    pub fn with_soft_update_rate(mut self, tau: f64) -> Self {
        self.soft_update_rate = tau;
        self
    }
    /// Sets [`Self::buffer_capacity`].
    pub fn with_buffer_capacity(mut self, capacity: usize) -> Self {
        self.buffer_capacity = capacity;
        self
    }
    /// Sets [`Self::batch_size`].
    pub fn with_batch_size(mut self, batch: usize) -> Self {
        self.batch_size = batch;
        self
    }
    /// Sets [`Self::noise_std`].
    pub fn with_noise_std(mut self, sigma: f64) -> Self {
        self.noise_std = sigma;
        self
    }
    /// Sets [`Self::noise_decay_rate`].
    pub fn with_noise_decay_rate(mut self, rate: f64) -> Self {
        self.noise_decay_rate = rate;
        self
    }
    /// Sets [`Self::noise_decay_start_episode`].
    pub fn with_noise_decay_start_episode(mut self, episode: usize) -> Self {
        self.noise_decay_start_episode = episode;
        self
    }
    /// Sets [`Self::seed`].
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }
    /// Sets [`Self::single_thread`].
    pub fn with_single_thread(mut self, single_thread: bool) -> Self {
        self.single_thread = single_thread;
        self
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidParameter`] naming the first bad field: zero
    /// episodes, steps, batch, capacity or hidden width; batch larger than
    /// the buffer; a learning rate that is not finite and positive; γ outside
    /// [0, 1]; τ outside (0, 1]; σ₀ negative or not finite; ρ outside
    /// (0, 1]. [`MillPlanError::InvalidConfig`] for no or more than 8 hidden
    /// layers.
    pub fn validate(&self) -> Result<(), MillPlanError> {
        let bad = |name: &str, value: f64, reason: &str| {
            Err(MillPlanError::InvalidParameter {
                name: name.to_string(),
                value,
                reason: reason.to_string(),
            })
        };
        for (name, value) in [
            ("episodes", self.episodes),
            ("steps per episode", self.steps_per_episode),
            ("batch size", self.batch_size),
            ("replay buffer capacity", self.buffer_capacity),
        ] {
            if value == 0 {
                return bad(name, 0.0, "must be at least 1");
            }
        }
        if self.batch_size > self.buffer_capacity {
            return bad(
                "batch size",
                self.batch_size as f64,
                &format!(
                    "exceeds the replay buffer capacity {}",
                    self.buffer_capacity
                ),
            );
        }
        if self.hidden_sizes.is_empty() || self.hidden_sizes.len() > 8 {
            return Err(MillPlanError::InvalidConfig {
                name: "hidden sizes".to_string(),
                reason: format!("need 1 to 8 hidden layers, got {}", self.hidden_sizes.len()),
            });
        }
        if let Some(&w) = self.hidden_sizes.iter().find(|&&w| w == 0 || w > 65_536) {
            return bad("hidden layer width", w as f64, "must be in 1..=65536");
        }
        for (name, lr) in [
            ("actor learning rate", self.actor_learning_rate),
            ("critic learning rate", self.critic_learning_rate),
        ] {
            if !(lr.is_finite() && lr > 0.0) {
                return bad(name, lr, "must be finite and positive");
            }
        }
        if !(0.0..=1.0).contains(&self.discount) {
            return bad("discount factor γ", self.discount, "must be in [0, 1]");
        }
        if !(self.soft_update_rate > 0.0 && self.soft_update_rate <= 1.0) {
            return bad(
                "soft update rate τ",
                self.soft_update_rate,
                "must be in (0, 1]",
            );
        }
        if !(self.noise_std.is_finite() && self.noise_std >= 0.0) {
            return bad(
                "noise standard deviation",
                self.noise_std,
                "must be finite and ≥ 0",
            );
        }
        if !(self.noise_decay_rate > 0.0 && self.noise_decay_rate <= 1.0) {
            return bad(
                "noise decay rate",
                self.noise_decay_rate,
                "must be in (0, 1]",
            );
        }
        Ok(())
    }

    /// The exploration noise standard deviation of the 0-based episode
    /// `episode`: σ₀ · ρ^max(0, episode + 1 − E_d) (module documentation).
    pub fn noise_std_at(&self, episode: usize) -> f64 {
        let decayed = (episode + 1).saturating_sub(self.noise_decay_start_episode);
        let exponent = i32::try_from(decayed).unwrap_or(i32::MAX);
        self.noise_std * self.noise_decay_rate.powi(exponent)
    }
}

/// What one training episode did, for a progress bar and the training
/// curve (seed 004 Fig. 5).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EpisodeReport {
    /// 1-based episode number.
    pub episode: usize,
    /// Total number of episodes of the run.
    pub episodes: usize,
    /// Steps taken in this episode.
    pub steps: usize,
    /// Sum of the rewards of the episode (with exploration noise).
    pub total_reward: f64,
    /// Mean critic loss L_q over the updates of the episode; `None` during
    /// the warm-up (no update yet).
    pub mean_critic_loss: Option<f64>,
    /// Mean actor loss L_a = −mean Q over the updates of the episode;
    /// `None` during the warm-up.
    pub mean_actor_loss: Option<f64>,
    /// Exploration noise standard deviation used in the episode.
    pub noise_std: f64,
    /// Wall time since the start of training, s.
    pub elapsed_s: f64,
    /// Estimated wall time to the end of training (mean episode time so far
    /// × remaining episodes), s.
    pub remaining_s: f64,
}

/// The result of [`train`]: the actor and the training history.
#[derive(Debug, Clone)]
pub struct TrainedAgent {
    actor: Mlp,
    settings: DdpgSettings,
    history: Vec<EpisodeReport>,
    observation_dim: usize,
    action_dim: usize,
    observation_layout: Vec<String>,
}

impl TrainedAgent {
    /// The names of the observation entries of the environment trained on
    /// ([`Environment::observation_layout`]; empty when it names none).
    pub fn observation_layout(&self) -> &[String] {
        &self.observation_layout
    }
    /// The trained actor network A(s | wᵃ).
    pub fn actor(&self) -> &Mlp {
        &self.actor
    }
    /// The settings of the run.
    pub fn settings(&self) -> &DdpgSettings {
        &self.settings
    }
    /// One report per episode, in order.
    pub fn history(&self) -> &[EpisodeReport] {
        &self.history
    }
    /// Observation size of the environment trained on.
    pub fn observation_dim(&self) -> usize {
        self.observation_dim
    }
    /// Action size of the environment trained on.
    pub fn action_dim(&self) -> usize {
        self.action_dim
    }
    /// The greedy (noise-free) action A(s) for one observation.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] for a wrong length,
    /// [`MillPlanError::InvalidParameter`] for a non-finite entry,
    /// [`MillPlanError::Backend`] when candle fails.
    pub fn act(&self, observation: &[f32]) -> Result<Vec<f32>, MillPlanError> {
        check_observation(observation, self.observation_dim)?;
        actor_action(&self.actor, observation)
    }
}

/// The networks and optimizers of a run.
struct Learner {
    actor: Mlp,
    critic: Mlp,
    actor_target: Mlp,
    critic_target: Mlp,
    actor_opt: FusedAdamW,
    critic_opt: FusedAdamW,
    discount: f64,
    tau: f64,
    observation_dim: usize,
    action_dim: usize,
}

/// Losses of one update.
#[derive(Debug, Clone, Copy)]
struct UpdateLosses {
    critic: f64,
    actor: f64,
}

impl Learner {
    fn new(
        observation_dim: usize,
        action_dim: usize,
        settings: &DdpgSettings,
        rng: &mut Rng,
    ) -> Result<Self, MillPlanError> {
        let mut actor_sizes = vec![observation_dim];
        actor_sizes.extend_from_slice(&settings.hidden_sizes);
        actor_sizes.push(action_dim);
        let mut critic_sizes = vec![observation_dim + action_dim];
        critic_sizes.extend_from_slice(&settings.hidden_sizes);
        critic_sizes.push(1);
        let actor = Mlp::new(&actor_sizes, OutputActivation::Tanh, rng)?;
        let critic = Mlp::new(&critic_sizes, OutputActivation::Linear, rng)?;
        let actor_target = actor.deep_copy()?;
        let critic_target = critic.deep_copy()?;
        let adam = |lr: f64| ParamsAdamW {
            lr,
            weight_decay: 0.0,
            ..ParamsAdamW::default()
        };
        let actor_opt = FusedAdamW::new(actor.vars(), adam(settings.actor_learning_rate))?;
        let critic_opt = FusedAdamW::new(critic.vars(), adam(settings.critic_learning_rate))?;
        Ok(Self {
            actor,
            critic,
            actor_target,
            critic_target,
            actor_opt,
            critic_opt,
            discount: settings.discount,
            tau: settings.soft_update_rate,
            observation_dim,
            action_dim,
        })
    }

    /// One DDPG update (steps 3–5 of the module documentation) on `batch`.
    fn update(&mut self, batch: Batch) -> Result<UpdateLosses, MillPlanError> {
        let n = batch.size;
        let (o, a) = (self.observation_dim, self.action_dim);
        let s = matrix(batch.observations, n, o)?;
        let act = matrix(batch.actions, n, a)?;
        let r = matrix(batch.rewards, n, 1)?;
        let s2 = matrix(batch.next_observations, n, o)?;
        let not_done = matrix(batch.not_done, n, 1)?;

        // Critic: y = r + γ (1 − terminal) Q′(s′, A′(s′)), constants.
        let a2 = self.actor_target.forward_detached(&s2)?;
        let q2 = self
            .critic_target
            .forward_detached(&Tensor::cat(&[&s2, &a2], 1).map_err(backend)?)?;
        let y = (q2 * not_done)
            .and_then(|t| t.affine(self.discount, 0.0))
            .and_then(|t| t + r)
            .map_err(backend)?;
        let trace = self
            .critic
            .forward_trace(&Tensor::cat(&[&s, &act], 1).map_err(backend)?)?;
        let diff = (trace.output() - y).map_err(backend)?;
        let critic_loss = diff.sqr().and_then(|d| d.mean_all()).map_err(backend)?;
        let critic_value = scalar(&critic_loss)?;
        if !critic_value.is_finite() {
            return Err(MillPlanError::Backend(format!(
                "training diverged: critic loss {critic_value}"
            )));
        }
        // ∂L_q/∂Q = 2 (Q − y) / N.
        let dq = diff.affine(2.0 / n as f64, 0.0).map_err(backend)?;
        let critic_grads = self.critic.backward(&trace, &dq)?;
        self.critic_opt.step_gradients(&critic_grads)?;

        // Actor: L_a = −mean Q(s, A(s)), critic weights held fixed. With
        // G_i = ∇_a Q(s_i, a)|_{a = A(s_i)} from the critic
        // (`Mlp::output_and_input_gradient`), ∂L_a/∂A(s_i) = −G_i / N, and
        // the actor's backward pass gives −(1/N) Σ_i ∇_{wᵃ}A(s_i) G_i, the
        // deterministic policy gradient.
        let actor_trace = self.actor.forward_trace(&s)?;
        let (q_pi, dq_dx) = self.critic.output_and_input_gradient(
            &Tensor::cat(&[&s, actor_trace.output()], 1).map_err(backend)?,
        )?;
        let actor_value = -scalar(&q_pi.mean_all().map_err(backend)?)?;
        if !actor_value.is_finite() {
            return Err(MillPlanError::Backend(format!(
                "training diverged: actor loss {actor_value}"
            )));
        }
        let dpi = dq_dx
            .narrow(1, o, a)
            .and_then(|g| g.affine(-1.0 / n as f64, 0.0))
            .map_err(backend)?;
        let actor_grads = self.actor.backward(&actor_trace, &dpi)?;
        self.actor_opt.step_gradients(&actor_grads)?;

        self.actor_target.soft_update_from(&self.actor, self.tau)?;
        self.critic_target
            .soft_update_from(&self.critic, self.tau)?;
        Ok(UpdateLosses {
            critic: critic_value,
            actor: actor_value,
        })
    }
}

/// The actor's action for one observation (no noise).
fn actor_action(actor: &Mlp, observation: &[f32]) -> Result<Vec<f32>, MillPlanError> {
    let x = matrix(observation.to_vec(), 1, observation.len())?;
    let y = actor.forward(&x)?;
    let v = y
        .flatten_all()
        .and_then(|t| t.to_vec1::<f32>())
        .map_err(backend)?;
    if v.iter().any(|x| !x.is_finite()) {
        return Err(MillPlanError::Backend(format!(
            "actor output is not finite: {v:?}"
        )));
    }
    Ok(v)
}

/// Length and finiteness check of an observation.
fn check_observation(observation: &[f32], dim: usize) -> Result<(), MillPlanError> {
    if observation.len() != dim {
        return Err(MillPlanError::InvalidConfig {
            name: "observation".to_string(),
            reason: format!("has {} entries, expected {dim}", observation.len()),
        });
    }
    if let Some(v) = observation.iter().find(|v| !v.is_finite()) {
        return Err(MillPlanError::InvalidParameter {
            name: "observation entry".to_string(),
            value: f64::from(*v),
            reason: "must be finite".to_string(),
        });
    }
    Ok(())
}

/// Trains a DDPG agent on `env` (seed 004 Algorithm 1; module
/// documentation).
///
/// # Arguments
/// * `env` — the environment; reset at the start of every episode.
/// * `settings` — validated first.
/// * `progress` — called after every episode.
///
/// # Returns
/// The trained actor and the per-episode history.
///
/// # Errors
/// * invalid `settings` or environment sizes (zero observation/action
///   dimension or zero `max_steps`) → [`MillPlanError::InvalidParameter`] /
///   [`MillPlanError::InvalidConfig`];
/// * any error of [`Environment::reset`] or [`Environment::step`],
///   propagated unchanged;
/// * an observation of the wrong length or with a non-finite entry, or a
///   non-finite reward → [`MillPlanError::InvalidConfig`] /
///   [`MillPlanError::InvalidParameter`];
/// * a non-finite loss or action (divergence) or a candle failure →
///   [`MillPlanError::Backend`].
///
/// # Performance
/// The run applies [`CpuTuning`] for its duration. One update (batch 64,
/// 2×256, release build, `benches/ddpg_update.rs`) costs 2.6 ms of CPU
/// time on the 2-core development machine (2.2–3.0 ms wall time while other
/// jobs run), against 8–10 ms with candle's default CPU settings. A
/// training step on the milling environment with its indicator cache
/// (`examples/ddpg_mill_smoke.rs`) costs 2.6 ms of CPU time in all (the
/// environment ≈ 10–20 µs of it), so 1000 × 99 steps take about 4.4 min
/// on an idle core (≈ 5 min wall time on the loaded machine).
pub fn train<E: Environment>(
    env: &mut E,
    settings: &DdpgSettings,
    progress: &mut dyn FnMut(&EpisodeReport),
) -> Result<TrainedAgent, MillPlanError> {
    settings.validate()?;
    let observation_dim = env.observation_dim();
    let action_dim = env.action_dim();
    let max_steps = env.max_steps();
    for (name, value) in [
        ("environment observation dimension", observation_dim),
        ("environment action dimension", action_dim),
        ("environment max steps", max_steps),
    ] {
        if value == 0 {
            return Err(MillPlanError::InvalidParameter {
                name: name.to_string(),
                value: 0.0,
                reason: "must be at least 1".to_string(),
            });
        }
    }
    let steps = settings.steps_per_episode.min(max_steps);

    let _tuning = CpuTuning::apply(settings.single_thread);
    let mut rng = Rng::new(settings.seed);
    let mut learner = Learner::new(observation_dim, action_dim, settings, &mut rng)?;
    let mut buffer = ReplayBuffer::new(settings.buffer_capacity, observation_dim, action_dim)?;
    let mut history = Vec::with_capacity(settings.episodes);
    let start = Instant::now();

    for episode in 0..settings.episodes {
        let sigma = settings.noise_std_at(episode);
        let mut observation = env.reset()?;
        check_observation(&observation, observation_dim)?;
        let mut total_reward = 0.0;
        let mut critic_sum = 0.0;
        let mut actor_sum = 0.0;
        let mut updates = 0usize;
        let mut taken = 0usize;
        for _ in 0..steps {
            let mut action = actor_action(&learner.actor, &observation)?;
            for a in action.iter_mut() {
                *a = (f64::from(*a) + sigma * rng.normal()).clamp(-1.0, 1.0) as f32;
            }
            let transition = env.step(&action)?;
            check_observation(&transition.observation, observation_dim)?;
            if !transition.reward.is_finite() {
                return Err(MillPlanError::InvalidParameter {
                    name: "environment reward".to_string(),
                    value: transition.reward,
                    reason: "must be finite".to_string(),
                });
            }
            buffer.push(
                &observation,
                &action,
                transition.reward,
                &transition.observation,
                transition.done,
            )?;
            total_reward += transition.reward;
            taken += 1;
            if buffer.len() >= settings.batch_size {
                let batch = buffer.sample(settings.batch_size, &mut rng)?;
                let losses = learner.update(batch)?;
                critic_sum += losses.critic;
                actor_sum += losses.actor;
                updates += 1;
            }
            observation = transition.observation;
            if transition.done {
                break;
            }
        }
        let elapsed = start.elapsed();
        let done_episodes = episode + 1;
        let remaining = settings.episodes - done_episodes;
        let per_episode = elapsed.as_secs_f64() / done_episodes as f64;
        let mean = |sum: f64| (updates > 0).then(|| sum / updates as f64);
        let report = EpisodeReport {
            episode: done_episodes,
            episodes: settings.episodes,
            steps: taken,
            total_reward,
            mean_critic_loss: mean(critic_sum),
            mean_actor_loss: mean(actor_sum),
            noise_std: sigma,
            elapsed_s: elapsed.as_secs_f64(),
            remaining_s: per_episode * remaining as f64,
        };
        progress(&report);
        history.push(report);
    }
    Ok(TrainedAgent {
        actor: learner.actor,
        settings: settings.clone(),
        history,
        observation_dim,
        action_dim,
        observation_layout: env.observation_layout(),
    })
}

/// One DDPG update on a synthetic batch, for benchmarks: builds the
/// networks for the given sizes once and returns a closure that performs
/// one full update (critic step, actor step, soft updates) on a fresh
/// random batch from a filled replay buffer.
///
/// # Errors
/// As [`DdpgSettings::validate`]; [`MillPlanError::Backend`] when candle
/// fails.
pub fn update_benchmark(
    observation_dim: usize,
    action_dim: usize,
    settings: &DdpgSettings,
) -> Result<impl FnMut() -> Result<(), MillPlanError>, MillPlanError> {
    settings.validate()?;
    let mut rng = Rng::new(settings.seed);
    let mut learner = Learner::new(observation_dim, action_dim, settings, &mut rng)?;
    let mut buffer = ReplayBuffer::new(settings.buffer_capacity, observation_dim, action_dim)?;
    for _ in 0..settings.buffer_capacity {
        let s: Vec<f32> = (0..observation_dim)
            .map(|_| rng.uniform(-1.0, 1.0) as f32)
            .collect();
        let a: Vec<f32> = (0..action_dim)
            .map(|_| rng.uniform(-1.0, 1.0) as f32)
            .collect();
        let s2: Vec<f32> = (0..observation_dim)
            .map(|_| rng.uniform(-1.0, 1.0) as f32)
            .collect();
        buffer.push(&s, &a, rng.uniform(-1.0, 1.0), &s2, false)?;
    }
    let batch_size = settings.batch_size;
    Ok(move || {
        let batch = buffer.sample(batch_size, &mut rng)?;
        learner.update(batch).map(|_| ())
    })
}
