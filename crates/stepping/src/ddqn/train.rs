//! Double DQN training of the Q-network against RPRO (seed 002 section 3).
//!
//! # Algorithm
//! Double DQN (van Hasselt, Guez & Silver, "Deep reinforcement learning
//! with double Q-learning", AAAI 2016), as MATLAB's `rlDQNAgent` with
//! `UseDoubleDQN = true` runs it (the paper used MATLAB 2022a):
//!
//! 1. ε-greedy action on the online network θ: a random action with
//!    probability ε, otherwise argmax_a Q(x, a; θ);
//! 2. the environment ([`super::env`]: a replay of RPRO's stored run of the
//!    process) rewards the action against RPRO's recorded decision (seed 002
//!    eq. 4) and moves to RPRO's next recorded state;
//!    the transition (x, a, r, x′, terminal) enters a FIFO experience buffer
//!    of ExperienceBufferLength (Table 3: 5000);
//! 3. once the buffer holds MiniBatchSize (Table 3: 64) transitions, every
//!    step draws a mini-batch (uniformly, with replacement) and takes one
//!    Adam step ([`super::adam`]) on the loss
//!    L(θ) = (1/B) Σ (Yᵢ − Q(xᵢ, aᵢ; θ))², the squared temporal-difference
//!    error of van Hasselt et al. 2016 eq. 1, with the Double DQN target of
//!    their section "Double DQN" (eq. 4 with the target network θ⁻ as the
//!    second network):
//!    Yᵢ = rᵢ + γ (1 − terminalᵢ) Q(x′ᵢ, argmax_a Q(x′ᵢ, a; θ); θ⁻);
//! 4. every TargetUpdateFrequency (Table 3: 5) learning steps the target
//!    network is smoothed: θ⁻ ← τ θ + (1 − τ) θ⁻, τ = TargetSmoothFactor
//!    (Table 3: 0.05);
//! 5. after every step, ε ← ε (1 − EpsilonDecay) while ε > EpsilonMin
//!    (MATLAB's `rlEpsilonGreedyOptions` defaults: Epsilon 1, EpsilonMin
//!    0.01, EpsilonDecay 0.005; the seed does not give them).
//!
//! Episodes (Table 3: maxEpisodes 500, MaxStepsPerEpisode 300) each draw a
//! process uniformly from the training courses (section 3: the 120
//! processes of one pair of paths, [`crate::database::split`]), then a
//! start step uniformly from 0..steps of RPRO's recorded run of it, and
//! replay at most MaxStepsPerEpisode periods from there (kerf's choice, the
//! paper does not say where an episode starts: module [`super::env`],
//! "Where an episode starts"). Discount
//! factor 0.99 and learning rate 10⁻³ are the defaults: the paper's best
//! (section 3, after Table 6).
//!
//! # Determinism
//! Every random number — initial weights, ε-greedy draws, episode processes
//! and start steps, mini-batches — comes from one [`Rng`] seeded by
//! [`DdqnSettings::seed`]; the targets are computed by the plain forward
//! pass, the loss gradient by candle's autograd on the CPU, so a seed gives
//! the same weights on a machine.

use std::collections::BTreeMap;

use candle_core::{Device, Tensor};
use kerf_rng::Rng;

use crate::{
    course::Course,
    database::{Process, PERIOD, PRECISION},
    error::StepError,
    lattice::{Action, Lattice},
    rpro::RproSettings,
};

use super::{
    adam::Adam,
    agent::{argmax, Agent},
    env::{record, Env, Recording, StepEnd},
    net::{backend, Architecture, QNet, Weights},
};

/// Settings of a training run (builder style); the defaults are seed 002
/// Table 3, γ = 0.99 and lr = 10⁻³ (section 3), MATLAB's ε-greedy
/// defaults, architecture 2 (24 tanh) and seed 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DdqnSettings {
    /// Table 2 architecture.
    pub architecture: Architecture,
    /// Table 3 maxEpisodes (500).
    pub max_episodes: usize,
    /// Table 3 TargetSmoothFactor τ (0.05).
    pub target_smooth_factor: f64,
    /// Table 3 TargetUpdateFrequency, in learning steps (5).
    pub target_update_frequency: usize,
    /// Table 3 MiniBatchSize (64).
    pub mini_batch_size: usize,
    /// Table 3 ExperienceBufferLength (5000).
    pub experience_buffer_length: usize,
    /// Table 3 MaxStepsPerEpisode (300).
    pub max_steps_per_episode: usize,
    /// Discount factor γ (0.99).
    pub discount: f64,
    /// Adam learning rate (10⁻³).
    pub learning_rate: f64,
    /// Initial ε (MATLAB default 1).
    pub epsilon: f64,
    /// Smallest ε (MATLAB default 0.01).
    pub epsilon_min: f64,
    /// ε decay per step (MATLAB default 0.005).
    pub epsilon_decay: f64,
    /// Seed of every random draw.
    pub seed: u64,
    /// The RPRO that labels the states.
    pub rpro: RproSettings,
}

impl Default for DdqnSettings {
    fn default() -> Self {
        Self {
            architecture: Architecture::default(),
            max_episodes: 500,
            target_smooth_factor: 0.05,
            target_update_frequency: 5,
            mini_batch_size: 64,
            experience_buffer_length: 5000,
            max_steps_per_episode: 300,
            discount: 0.99,
            learning_rate: 1e-3,
            epsilon: 1.0,
            epsilon_min: 0.01,
            epsilon_decay: 0.005,
            seed: 0,
            rpro: RproSettings::default(),
        }
    }
}

macro_rules! setter {
    ($(#[$doc:meta] $name:ident: $ty:ty),* $(,)?) => {
        $(
            #[$doc]
            pub fn $name(mut self, value: $ty) -> Self {
                self.$name = value;
                self
            }
        )*
    };
}

impl DdqnSettings {
    setter!(
        /// Sets [`DdqnSettings::architecture`].
        architecture: Architecture,
        /// Sets [`DdqnSettings::max_episodes`].
        max_episodes: usize,
        /// Sets [`DdqnSettings::target_smooth_factor`].
        target_smooth_factor: f64,
        /// Sets [`DdqnSettings::target_update_frequency`].
        target_update_frequency: usize,
        /// Sets [`DdqnSettings::mini_batch_size`].
        mini_batch_size: usize,
        /// Sets [`DdqnSettings::experience_buffer_length`].
        experience_buffer_length: usize,
        /// Sets [`DdqnSettings::max_steps_per_episode`].
        max_steps_per_episode: usize,
        /// Sets [`DdqnSettings::discount`].
        discount: f64,
        /// Sets [`DdqnSettings::learning_rate`].
        learning_rate: f64,
        /// Sets [`DdqnSettings::epsilon`].
        epsilon: f64,
        /// Sets [`DdqnSettings::epsilon_min`].
        epsilon_min: f64,
        /// Sets [`DdqnSettings::epsilon_decay`].
        epsilon_decay: f64,
        /// Sets [`DdqnSettings::seed`].
        seed: u64,
        /// Sets [`DdqnSettings::rpro`].
        rpro: RproSettings,
    );

    /// # Errors
    /// [`StepError::InvalidParameter`] naming the first setting out of
    /// range: counts of 0 (or a buffer smaller than a batch), τ, γ, ε
    /// bounds or decay outside [0, 1] (τ, lr > 0), a learning rate not
    /// finite and > 0, or bad RPRO settings.
    pub fn validate(&self) -> Result<(), StepError> {
        let bad = |name: &str, value: f64, reason: &str| {
            Err(StepError::InvalidParameter {
                name: name.to_string(),
                value,
                reason: reason.to_string(),
            })
        };
        for (name, n) in [
            ("maxEpisodes", self.max_episodes),
            ("TargetUpdateFrequency", self.target_update_frequency),
            ("MiniBatchSize", self.mini_batch_size),
            ("MaxStepsPerEpisode", self.max_steps_per_episode),
        ] {
            if n == 0 {
                return bad(name, 0.0, "must be at least 1");
            }
        }
        if self.experience_buffer_length < self.mini_batch_size {
            return bad(
                "ExperienceBufferLength",
                self.experience_buffer_length as f64,
                "must hold at least one mini-batch",
            );
        }
        let unit = |x: f64| x.is_finite() && (0.0..=1.0).contains(&x);
        if !(unit(self.target_smooth_factor) && self.target_smooth_factor > 0.0) {
            return bad(
                "TargetSmoothFactor",
                self.target_smooth_factor,
                "must be in (0, 1]",
            );
        }
        if !unit(self.discount) {
            return bad("discount factor", self.discount, "must be in [0, 1]");
        }
        if !(self.learning_rate.is_finite() && self.learning_rate > 0.0) {
            return bad(
                "learning rate",
                self.learning_rate,
                "must be finite and > 0",
            );
        }
        for (name, x) in [
            ("Epsilon", self.epsilon),
            ("EpsilonMin", self.epsilon_min),
            ("EpsilonDecay", self.epsilon_decay),
        ] {
            if !unit(x) {
                return bad(name, x, "must be in [0, 1]");
            }
        }
        self.rpro.validate()
    }

    /// The settings as strings, for a network file's metadata.
    pub fn describe(&self) -> BTreeMap<String, String> {
        [
            ("max_episodes", self.max_episodes.to_string()),
            (
                "target_smooth_factor",
                self.target_smooth_factor.to_string(),
            ),
            (
                "target_update_frequency",
                self.target_update_frequency.to_string(),
            ),
            ("mini_batch_size", self.mini_batch_size.to_string()),
            (
                "experience_buffer_length",
                self.experience_buffer_length.to_string(),
            ),
            (
                "max_steps_per_episode",
                self.max_steps_per_episode.to_string(),
            ),
            ("discount", self.discount.to_string()),
            ("learning_rate", self.learning_rate.to_string()),
            ("epsilon", self.epsilon.to_string()),
            ("epsilon_min", self.epsilon_min.to_string()),
            ("epsilon_decay", self.epsilon_decay.to_string()),
            ("seed", self.seed.to_string()),
            (
                "rpro",
                format!(
                    "lookahead_points {} levels {}",
                    self.rpro.lookahead_points, self.rpro.levels
                ),
            ),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect()
    }
}

/// How an episode ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EpisodeEnd {
    /// The recorded RPRO run was replayed to its end (RPRO at rest on the
    /// last point).
    Completed,
    /// MaxStepsPerEpisode reached first.
    Truncated,
}

/// Step cap of the RPRO runs that are recorded for training (RPRO finishes
/// every Table 1 process in a few thousand periods at most).
pub const RECORD_MAX_STEPS: usize = 1_000_000;

/// The record of one training episode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpisodeRecord {
    /// Episode index (0-based).
    pub episode: usize,
    /// Index of the course in the training set.
    pub course: usize,
    /// The recorded step of RPRO's run the episode started at.
    pub start: usize,
    /// Steps taken.
    pub steps: usize,
    /// Steps whose action equalled RPRO's.
    pub matches: usize,
    /// Sum of rewards (seed 002 eq. 4).
    pub reward: f64,
    /// ε at the end of the episode.
    pub epsilon: f64,
    /// How it ended.
    pub end: EpisodeEnd,
}

/// The result of [`train`].
#[derive(Debug, Clone)]
pub struct Trained {
    /// The online network as a greedy agent, its metadata the settings.
    pub agent: Agent,
    /// One record per episode.
    pub history: Vec<EpisodeRecord>,
    /// Gradient steps taken.
    pub learning_steps: usize,
}

/// One experience.
#[derive(Debug, Clone, Copy)]
struct Transition {
    x: [f32; 3],
    action: usize,
    reward: f32,
    next: [f32; 3],
    terminal: bool,
}

/// The courses of database processes (period and precision of Table 1).
///
/// # Errors
/// A process whose limits or points are refused ([`Lattice::new`],
/// [`Course::new`]).
pub fn courses(processes: &[&Process]) -> Result<Vec<Course>, StepError> {
    processes
        .iter()
        .map(|p| {
            let lat = Lattice::new(p.limits, PERIOD)?;
            Course::new(lat, p.points.clone(), PRECISION)
        })
        .collect()
}

/// Trains a Q-network on `courses` (module documentation).
///
/// # Errors
/// [`StepError::InvalidParameter`] for bad settings or no course;
/// [`StepError::Network`] when candle fails; RPRO's errors.
///
/// # Performance
/// One RPRO run per distinct training process drawn (recorded once), then
/// at most maxEpisodes × MaxStepsPerEpisode steps, each one mini-batch
/// update.
pub fn train(settings: &DdqnSettings, courses: &[Course]) -> Result<Trained, StepError> {
    train_observed(settings, courses, &mut |_| {})
}

/// [`train`], calling `observe` after every episode.
///
/// # Errors
/// As [`train`].
pub fn train_observed(
    settings: &DdqnSettings,
    courses: &[Course],
    observe: &mut dyn FnMut(&EpisodeRecord),
) -> Result<Trained, StepError> {
    settings.validate()?;
    if courses.is_empty() {
        return Err(StepError::InvalidParameter {
            name: "training courses".to_string(),
            value: 0.0,
            reason: "at least one course is needed".to_string(),
        });
    }
    // RPRO's runs are deterministic: each process is recorded once, the
    // first time an episode draws it (module `env`).
    let mut recordings: Vec<Option<Recording>> = vec![None; courses.len()];
    let mut rng = Rng::new(settings.seed);
    let mut online = Weights::init(settings.architecture, &mut rng);
    let mut target = online.clone();
    let net = QNet::new(&online)?;
    let mut adam = Adam::new(&online, settings.learning_rate);
    let mut buffer: Vec<Transition> = Vec::with_capacity(settings.experience_buffer_length);
    let mut next_slot = 0usize;
    let mut epsilon = settings.epsilon;
    let mut learning_steps = 0usize;
    let mut history = Vec::with_capacity(settings.max_episodes);
    let gamma = settings.discount as f32;
    for episode in 0..settings.max_episodes {
        let index = rng.below(courses.len()).unwrap_or(0);
        let recording = match &mut recordings[index] {
            Some(r) => &*r,
            slot => &*slot.insert(record(&courses[index], settings.rpro, RECORD_MAX_STEPS)?),
        };
        // Uniform over the run's periods (module `env`, "Where an episode
        // starts").
        let start = rng.below(recording.steps()).unwrap_or(0);
        let mut env = Env::starting_at(recording, start);
        let mut x = env.features();
        let (mut reward, mut matches) = (0.0f64, 0usize);
        let mut end = EpisodeEnd::Truncated;
        for _ in 0..settings.max_steps_per_episode {
            let action = if rng.next_f64() < epsilon {
                Action::ALL[rng.below(3).unwrap_or(0)]
            } else {
                argmax(&online.q_values(&x)).ok_or_else(|| StepError::Network {
                    reason: format!("non-finite Q-value in training episode {episode}"),
                })?
            };
            let Some(outcome) = env.step(action) else {
                end = EpisodeEnd::Completed;
                break;
            };
            reward += f64::from(outcome.reward);
            matches += usize::from(outcome.rpro == action);
            let t = Transition {
                x,
                action: action.index(),
                reward: outcome.reward,
                next: outcome.next,
                terminal: outcome.end == StepEnd::Done,
            };
            if buffer.len() < settings.experience_buffer_length {
                buffer.push(t);
            } else {
                buffer[next_slot] = t;
            }
            next_slot = (next_slot + 1) % settings.experience_buffer_length;
            if buffer.len() >= settings.mini_batch_size {
                let grads = gradients(&net, &online, &target, &buffer, settings, gamma, &mut rng)?;
                adam.step(&mut online, &grads)?;
                net.set(&online)?;
                learning_steps += 1;
                if learning_steps.is_multiple_of(settings.target_update_frequency) {
                    soft_update(&mut target, &online, settings.target_smooth_factor as f32);
                }
            }
            if epsilon > settings.epsilon_min {
                epsilon *= 1.0 - settings.epsilon_decay;
            }
            x = outcome.next;
            if outcome.end == StepEnd::Done {
                end = EpisodeEnd::Completed;
                break;
            }
        }
        let record = EpisodeRecord {
            episode,
            course: index,
            start,
            steps: env.steps(),
            matches,
            reward,
            epsilon,
            end,
        };
        observe(&record);
        history.push(record);
    }
    let mut info = settings.describe();
    info.insert("episodes".to_string(), history.len().to_string());
    info.insert("learning_steps".to_string(), learning_steps.to_string());
    Ok(Trained {
        agent: Agent::new(online, info)?,
        history,
        learning_steps,
    })
}

/// θ⁻ ← τ θ + (1 − τ) θ⁻ (module documentation, step 4).
fn soft_update(target: &mut Weights, online: &Weights, tau: f32) {
    for (t, o) in target.layers_mut().iter_mut().zip(online.layers()) {
        for (a, b) in t
            .weight
            .iter_mut()
            .zip(&o.weight)
            .chain(t.bias.iter_mut().zip(&o.bias))
        {
            *a = tau * b + (1.0 - tau) * *a;
        }
    }
}

/// The gradient of the mini-batch loss (module documentation, step 3) with
/// respect to the online variables, flat, in [`QNet::vars`] order.
fn gradients(
    net: &QNet,
    online: &Weights,
    target: &Weights,
    buffer: &[Transition],
    settings: &DdqnSettings,
    gamma: f32,
    rng: &mut Rng,
) -> Result<Vec<Vec<f32>>, StepError> {
    let b = settings.mini_batch_size;
    let mut xs = Vec::with_capacity(3 * b);
    let mut onehot = vec![0f32; 3 * b];
    let mut ys = Vec::with_capacity(b);
    for row in 0..b {
        let t = &buffer[rng.below(buffer.len()).unwrap_or(0)];
        xs.extend_from_slice(&t.x);
        onehot[3 * row + t.action] = 1.0;
        let mut y = t.reward;
        if !t.terminal {
            // Double DQN: the online network picks, the target evaluates.
            let best = argmax(&online.q_values(&t.next)).map_or(0, Action::index);
            y += gamma * target.q_values(&t.next)[best];
        }
        ys.push(y);
    }
    let dev = Device::Cpu;
    let x = Tensor::from_vec(xs, (b, 3), &dev).map_err(backend)?;
    let mask = Tensor::from_vec(onehot, (b, 3), &dev).map_err(backend)?;
    let y = Tensor::from_vec(ys, b, &dev).map_err(backend)?;
    let q = net.forward(&x)?;
    let loss = (q * mask)
        .and_then(|qm| qm.sum(1))
        .and_then(|qa| qa - y)
        .and_then(|d| d.sqr())
        .and_then(|d2| d2.mean_all())
        .map_err(backend)?;
    let grads = loss.backward().map_err(backend)?;
    net.vars()
        .iter()
        .map(|v| match grads.get(v.as_tensor()) {
            Some(g) => g
                .flatten_all()
                .and_then(|g| g.to_vec1::<f32>())
                .map_err(backend),
            None => Ok(vec![0.0; v.elem_count()]),
        })
        .collect()
}
