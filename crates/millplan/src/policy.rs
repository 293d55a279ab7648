//! A trained DDPG actor as a file, and its fast deterministic forward pass.
//!
//! # Files
//! A policy is two files side by side:
//! * `NAME.safetensors` (any path not ending in `.json`): the actor's
//!   tensors in the safetensors format (candle's support), f32, named
//!   `l{k}.weight` (shape out × in) and `l{k}.bias` (shape out) for the
//!   layers k = 0, 1, … from the input;
//! * `NAME.json` (the same path with the extension replaced by `json`): the
//!   [`PolicyMetadata`] — observation/action sizes, hidden sizes, seed, the
//!   [`DdpgSettings`] of the run, a caller-supplied description of the
//!   environment (cell file, reward weights, …), episodes, final reward and
//!   the crate version.
//!
//! [`Policy::load`] checks both against each other: every tensor present
//! with its exact shape and dtype, no extra tensor, every value finite.
//! [`Policy::check_sizes`] checks a loaded policy against an environment.
//!
//! # Forward pass
//! [`Policy::act`] is the actor A(s | wᵃ) without exploration noise, as a
//! plain Rust loop over the row-major weights (h = relu(W h + b) for the
//! hidden layers, a = tanh(W h + b) for the output; [`crate::nets`]), f32
//! with 8 partial sums per dot product. No candle, no allocation beyond the
//! two activation vectors, no thread pool: a 100-step rollout of the 2×256
//! actor takes 1–2 ms in a release build (measured in
//! `benches/ddpg_update.rs`).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use candle_core::{DType, Device, Tensor};
use serde::{Deserialize, Serialize};

use crate::ddpg::{DdpgSettings, TrainedAgent};
use crate::error::MillPlanError;
use crate::nets::{backend, Mlp};
use crate::rl::{Environment, Transition};

/// The `format` value of the sidecar JSON this version writes and reads.
pub const POLICY_FORMAT: &str = "kerf_millplan ddpg actor v1";

/// The JSON sidecar of a policy file: how the actor was trained.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PolicyMetadata {
    /// Always [`POLICY_FORMAT`].
    pub format: String,
    /// Version of `kerf_millplan` that wrote the file.
    pub crate_version: String,
    /// Length of an observation.
    pub observation_dim: usize,
    /// Length of an action.
    pub action_dim: usize,
    /// Widths of the hidden ReLU layers.
    pub hidden_sizes: Vec<usize>,
    /// Seed of the training run.
    pub seed: u64,
    /// Every setting of the training run.
    pub settings: DdpgSettings,
    /// Description of the environment, supplied by the caller (e.g. the cell
    /// file, the reward weights, the fixed-g flag).
    pub environment: String,
    /// Episodes actually trained.
    pub episodes: usize,
    /// Total reward of the last training episode (with exploration noise);
    /// `None` when no episode was recorded.
    pub final_reward: Option<f64>,
    /// The name of each observation entry, in order
    /// ([`crate::observation::OBSERVATION_LAYOUT`] for the milling
    /// environment); empty in a sidecar written before issue 13 (the
    /// planner refuses such a policy: [`Policy::check_observation`]).
    #[serde(default)]
    pub observation_layout: Vec<String>,
}

/// One dense layer of the plain forward pass.
#[derive(Debug, Clone, PartialEq)]
struct DenseLayer {
    n_in: usize,
    n_out: usize,
    /// Row-major n_out × n_in.
    weight: Vec<f32>,
    bias: Vec<f32>,
}

/// A trained actor, ready to act.
#[derive(Debug, Clone, PartialEq)]
pub struct Policy {
    layers: Vec<DenseLayer>,
    metadata: PolicyMetadata,
    /// Where it was loaded from or last saved to (for messages); empty for a
    /// policy made in memory.
    path: String,
}

/// The result of a greedy rollout ([`Policy::rollout`]).
#[derive(Debug, Clone, PartialEq)]
pub struct GreedyRollout {
    /// The observation after `reset`.
    pub initial_observation: Vec<f32>,
    /// The actions taken, one per step.
    pub actions: Vec<Vec<f32>>,
    /// The environment's answers, one per step.
    pub transitions: Vec<Transition>,
    /// Sum of the rewards.
    pub total_reward: f64,
}

/// Largest policy weights file read (64 MiB; the committed policies are about 100 KB). A larger
/// file, a FIFO, a device or a directory is refused before it is read
/// ([`kerf_robot::file::read_regular`]).
pub const MAX_POLICY_BYTES: u64 = 64 << 20;

/// Largest settings sidecar read (1 MiB; the committed ones are a few KB).
pub const MAX_SIDECAR_BYTES: u64 = 1 << 20;

/// The sidecar path of a policy file: the same path with the extension
/// `json`.
pub fn metadata_path(path: &Path) -> PathBuf {
    path.with_extension("json")
}

/// The policy file a request names (`policy_file`), resolved as every file a request names
/// ([`kerf_robot::file::resolve_uri`]).
///
/// # Arguments
/// * `reference` - a path (relative paths: to the working directory), a local `file://` URI
///   (`file:///abs/x.safetensors`, `file://localhost/abs/x.safetensors`) or
///   `package://kerf/<path>`.
///
/// # Returns
/// The weights file's path (whether it exists is not checked: [`Policy::load`] does).
///
/// # Errors
/// [`MillPlanError::Policy`] naming `reference`: it is empty, a URI of another scheme or
/// host, a malformed `file://` URI, a `package://` URI of another package or leaving the
/// data root, or no data root is found for `package://kerf/`.
pub fn resolve_policy_file(reference: &str) -> Result<PathBuf, MillPlanError> {
    kerf_robot::file::resolve_uri(reference).map_err(|e| MillPlanError::Policy {
        path: reference.to_owned(),
        reason: e.uri_reason(),
    })
}

fn policy_error(path: &Path, reason: impl Into<String>) -> MillPlanError {
    MillPlanError::Policy {
        path: path.display().to_string(),
        reason: reason.into(),
    }
}

impl Policy {
    /// The policy of a training run's actor.
    ///
    /// # Arguments
    /// * `agent` — the result of [`crate::ddpg::train`].
    /// * `environment` — a description of the environment, stored in the
    ///   sidecar (cell file, reward weights, α, …).
    ///
    /// # Errors
    /// [`MillPlanError::Backend`] when the weights cannot be read from
    /// candle.
    pub fn from_agent(agent: &TrainedAgent, environment: &str) -> Result<Self, MillPlanError> {
        let settings = agent.settings().clone();
        let metadata = PolicyMetadata {
            format: POLICY_FORMAT.to_string(),
            crate_version: env!("CARGO_PKG_VERSION").to_string(),
            observation_dim: agent.observation_dim(),
            action_dim: agent.action_dim(),
            hidden_sizes: settings.hidden_sizes.clone(),
            seed: settings.seed,
            episodes: agent.history().len(),
            final_reward: agent.history().last().map(|r| r.total_reward),
            settings,
            environment: environment.to_string(),
            observation_layout: agent.observation_layout().to_vec(),
        };
        Self::from_actor(agent.actor(), metadata)
    }

    /// The policy of an actor network with the given metadata.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] when the network's sizes disagree
    /// with the metadata; [`MillPlanError::Backend`] when the weights cannot
    /// be read from candle.
    pub fn from_actor(actor: &Mlp, metadata: PolicyMetadata) -> Result<Self, MillPlanError> {
        let sizes = layer_sizes(&metadata);
        if actor.sizes() != sizes.as_slice() {
            return Err(MillPlanError::InvalidConfig {
                name: "policy metadata".to_string(),
                reason: format!(
                    "actor layer sizes {:?} differ from the metadata's {sizes:?}",
                    actor.sizes()
                ),
            });
        }
        let layers = actor
            .parameters()?
            .into_iter()
            .zip(sizes.windows(2))
            .map(|((weight, bias), pair)| DenseLayer {
                n_in: pair[0],
                n_out: pair[1],
                weight,
                bias,
            })
            .collect();
        Ok(Self {
            layers,
            metadata,
            path: String::new(),
        })
    }

    /// How the policy was trained.
    pub fn metadata(&self) -> &PolicyMetadata {
        &self.metadata
    }

    /// Observation length the policy expects.
    pub fn observation_dim(&self) -> usize {
        self.metadata.observation_dim
    }

    /// Action length the policy returns.
    pub fn action_dim(&self) -> usize {
        self.metadata.action_dim
    }

    /// Writes the safetensors file at `path` and the JSON sidecar at
    /// [`metadata_path`]`(path)`.
    ///
    /// # Errors
    /// [`MillPlanError::Policy`] when `path` ends in `.json` (it would be
    /// its own sidecar); [`MillPlanError::Io`] when a file cannot be
    /// written; [`MillPlanError::Backend`] when candle fails.
    pub fn save(&mut self, path: &Path) -> Result<(), MillPlanError> {
        let sidecar = metadata_path(path);
        if sidecar == path {
            return Err(policy_error(
                path,
                "the policy file must not end in .json (that is the settings sidecar)",
            ));
        }
        let device = Device::Cpu;
        let mut tensors = HashMap::new();
        for (k, layer) in self.layers.iter().enumerate() {
            let w = Tensor::from_slice(&layer.weight, (layer.n_out, layer.n_in), &device)
                .map_err(backend)?;
            let b = Tensor::from_slice(&layer.bias, layer.n_out, &device).map_err(backend)?;
            tensors.insert(format!("l{k}.weight"), w);
            tensors.insert(format!("l{k}.bias"), b);
        }
        candle_core::safetensors::save(&tensors, path).map_err(|e| MillPlanError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        let json = serde_json::to_string_pretty(&self.metadata).map_err(|e| MillPlanError::Io {
            path: sidecar.display().to_string(),
            message: e.to_string(),
        })?;
        std::fs::write(&sidecar, json + "\n").map_err(|e| MillPlanError::Io {
            path: sidecar.display().to_string(),
            message: e.to_string(),
        })?;
        self.path = path.display().to_string();
        Ok(())
    }

    /// Reads a policy written by [`Policy::save`] and validates it.
    ///
    /// # Errors
    /// [`MillPlanError::Policy`] with the reason when: either file is
    /// missing or unreadable; the sidecar is not valid JSON of
    /// [`PolicyMetadata`] or has another [`POLICY_FORMAT`]; its sizes are
    /// zero or its hidden sizes disagree with its settings; the weights file
    /// is not valid safetensors; a tensor is missing, extra, not f32, of
    /// the wrong shape, or holds a non-finite value.
    pub fn load(path: &Path) -> Result<Self, MillPlanError> {
        let sidecar = metadata_path(path);
        if sidecar == path {
            return Err(policy_error(
                path,
                "give the .safetensors weights file, not the .json sidecar",
            ));
        }
        let bytes = if path.exists() {
            kerf_robot::file::read_regular(path, MAX_POLICY_BYTES)
                .map_err(|reason| policy_error(path, format!("the weights file: {reason}")))?
        } else {
            return Err(policy_error(path, "weights file not found"));
        };
        let json = if sidecar.exists() {
            let raw = kerf_robot::file::read_regular(&sidecar, MAX_SIDECAR_BYTES)
                .map_err(|reason| policy_error(path, format!("the settings sidecar: {reason}")))?;
            String::from_utf8(raw).map_err(|_| {
                policy_error(
                    path,
                    format!("settings sidecar {} is not UTF-8 text", sidecar.display()),
                )
            })?
        } else {
            return Err(policy_error(
                path,
                format!("settings sidecar {} not found", sidecar.display()),
            ));
        };
        let metadata: PolicyMetadata = serde_json::from_str(&json).map_err(|e| {
            policy_error(
                path,
                format!("settings sidecar {} is not valid: {e}", sidecar.display()),
            )
        })?;
        if metadata.format != POLICY_FORMAT {
            return Err(policy_error(
                path,
                format!(
                    "format \"{}\", this version reads \"{POLICY_FORMAT}\"",
                    metadata.format
                ),
            ));
        }
        if metadata.observation_dim == 0
            || metadata.action_dim == 0
            || metadata.hidden_sizes.is_empty()
            || metadata.hidden_sizes.contains(&0)
        {
            return Err(policy_error(
                path,
                format!(
                    "sidecar sizes must be positive: observation {}, action {}, hidden {:?}",
                    metadata.observation_dim, metadata.action_dim, metadata.hidden_sizes
                ),
            ));
        }
        if metadata.hidden_sizes != metadata.settings.hidden_sizes {
            return Err(policy_error(
                path,
                format!(
                    "sidecar hidden sizes {:?} differ from its settings' {:?}",
                    metadata.hidden_sizes, metadata.settings.hidden_sizes
                ),
            ));
        }
        let tensors = candle_core::safetensors::load_buffer(&bytes, &Device::Cpu)
            .map_err(|e| policy_error(path, format!("not a valid safetensors file: {e}")))?;
        let sizes = layer_sizes(&metadata);
        let n_layers = sizes.len() - 1;
        let expected: Vec<String> = (0..n_layers)
            .flat_map(|k| [format!("l{k}.weight"), format!("l{k}.bias")])
            .collect();
        let mut extra: Vec<&String> = tensors.keys().filter(|k| !expected.contains(k)).collect();
        if !extra.is_empty() {
            extra.sort();
            return Err(policy_error(
                path,
                format!("unexpected tensors {extra:?}; expected {expected:?}"),
            ));
        }
        let mut layers = Vec::with_capacity(n_layers);
        for (k, pair) in sizes.windows(2).enumerate() {
            let (n_in, n_out) = (pair[0], pair[1]);
            let weight = read_tensor(path, &tensors, &format!("l{k}.weight"), &[n_out, n_in])?;
            let bias = read_tensor(path, &tensors, &format!("l{k}.bias"), &[n_out])?;
            layers.push(DenseLayer {
                n_in,
                n_out,
                weight,
                bias,
            });
        }
        Ok(Self {
            layers,
            metadata,
            path: path.display().to_string(),
        })
    }

    /// Checks that the policy fits an environment's sizes.
    ///
    /// # Errors
    /// [`MillPlanError::Policy`] naming both sizes when they differ.
    pub fn check_sizes(
        &self,
        observation_dim: usize,
        action_dim: usize,
    ) -> Result<(), MillPlanError> {
        if self.metadata.observation_dim != observation_dim
            || self.metadata.action_dim != action_dim
        {
            return Err(MillPlanError::Policy {
                path: self.path.clone(),
                reason: format!(
                    "trained for observations of {} and actions of {} entries, \
                     the environment has {observation_dim} and {action_dim} \
                     (trained on: {})",
                    self.metadata.observation_dim,
                    self.metadata.action_dim,
                    self.metadata.environment
                ),
            });
        }
        Ok(())
    }

    /// Records the observation layout in the metadata (saved with the
    /// sidecar by [`Policy::save`]).
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] when the layout's length is not the
    /// policy's observation size.
    pub fn set_observation_layout(&mut self, layout: Vec<String>) -> Result<(), MillPlanError> {
        if layout.len() != self.metadata.observation_dim {
            return Err(MillPlanError::InvalidConfig {
                name: "observation layout".to_string(),
                reason: format!(
                    "{} names for a policy of {} observation entries",
                    layout.len(),
                    self.metadata.observation_dim
                ),
            });
        }
        self.metadata.observation_layout = layout;
        Ok(())
    }

    /// Checks that the policy was trained for an environment's observation
    /// layout (names and order) and action size: what the planner calls
    /// before a rollout.
    ///
    /// # Errors
    /// [`MillPlanError::Policy`] (status POLICY_ERROR) naming the sizes,
    /// when the policy records no layout (written before issue 13's
    /// path-independent observation), or at the first entry that differs.
    pub fn check_observation(
        &self,
        layout: &[&str],
        action_dim: usize,
    ) -> Result<(), MillPlanError> {
        self.check_sizes(layout.len(), action_dim)?;
        let recorded = &self.metadata.observation_layout;
        if recorded.is_empty() {
            return Err(policy_error(
                Path::new(&self.path),
                format!(
                    "records no observation layout (a policy written before the \
                     path-independent observation); the planner observes {:?} (trained on: {})",
                    layout, self.metadata.environment
                ),
            ));
        }
        if let Some(k) =
            (0..layout.len()).find(|&k| recorded.get(k).map(String::as_str) != Some(layout[k]))
        {
            return Err(policy_error(
                Path::new(&self.path),
                format!(
                    "observation entry {k} is \"{}\" in the policy, \"{}\" in the planner \
                     (trained for another observation layout)",
                    recorded.get(k).map(String::as_str).unwrap_or("<missing>"),
                    layout[k]
                ),
            ));
        }
        Ok(())
    }

    /// [`Policy::load`] followed by [`Policy::check_sizes`].
    ///
    /// # Errors
    /// As those two.
    pub fn load_for(
        path: &Path,
        observation_dim: usize,
        action_dim: usize,
    ) -> Result<Self, MillPlanError> {
        let policy = Self::load(path)?;
        policy.check_sizes(observation_dim, action_dim)?;
        Ok(policy)
    }

    /// The deterministic action A(s) (no exploration noise), every entry in
    /// [−1, 1].
    ///
    /// # Errors
    /// [`MillPlanError::Policy`] for an observation of the wrong length;
    /// [`MillPlanError::InvalidParameter`] for a non-finite entry.
    ///
    /// # Performance
    /// One plain forward pass (module documentation); no allocation beyond
    /// the activations.
    pub fn act(&self, observation: &[f32]) -> Result<Vec<f32>, MillPlanError> {
        if observation.len() != self.metadata.observation_dim {
            return Err(MillPlanError::Policy {
                path: self.path.clone(),
                reason: format!(
                    "observation has {} entries, the policy expects {}",
                    observation.len(),
                    self.metadata.observation_dim
                ),
            });
        }
        if let Some(v) = observation.iter().find(|v| !v.is_finite()) {
            return Err(MillPlanError::InvalidParameter {
                name: "observation entry".to_string(),
                value: f64::from(*v),
                reason: "must be finite".to_string(),
            });
        }
        let mut h = observation.to_vec();
        let last = self.layers.len().saturating_sub(1);
        for (k, layer) in self.layers.iter().enumerate() {
            let mut y = Vec::with_capacity(layer.n_out);
            for (row, b) in layer.weight.chunks_exact(layer.n_in).zip(&layer.bias) {
                let z = dot(row, &h) + b;
                y.push(if k < last { z.max(0.0) } else { z.tanh() });
            }
            h = y;
        }
        Ok(h)
    }

    /// A greedy episode on `env`: reset, then [`Policy::act`] and
    /// [`Environment::step`] until `done` or `env.max_steps()` steps.
    ///
    /// # Errors
    /// [`Policy::check_sizes`] against the environment; every error of the
    /// environment, propagated.
    pub fn rollout<E: Environment + ?Sized>(
        &self,
        env: &mut E,
    ) -> Result<GreedyRollout, MillPlanError> {
        self.check_sizes(env.observation_dim(), env.action_dim())?;
        let initial_observation = env.reset()?;
        let mut observation = initial_observation.clone();
        let mut rollout = GreedyRollout {
            initial_observation,
            actions: Vec::new(),
            transitions: Vec::new(),
            total_reward: 0.0,
        };
        for _ in 0..env.max_steps() {
            let action = self.act(&observation)?;
            let transition = env.step(&action)?;
            rollout.total_reward += transition.reward;
            observation.clone_from(&transition.observation);
            let done = transition.done;
            rollout.actions.push(action);
            rollout.transitions.push(transition);
            if done {
                break;
            }
        }
        Ok(rollout)
    }
}

/// [observation, hidden…, action].
fn layer_sizes(metadata: &PolicyMetadata) -> Vec<usize> {
    let mut sizes = vec![metadata.observation_dim];
    sizes.extend_from_slice(&metadata.hidden_sizes);
    sizes.push(metadata.action_dim);
    sizes
}

/// One named f32 tensor of exactly `shape`, all finite, as a flat vector.
fn read_tensor(
    path: &Path,
    tensors: &HashMap<String, Tensor>,
    name: &str,
    shape: &[usize],
) -> Result<Vec<f32>, MillPlanError> {
    let t = tensors
        .get(name)
        .ok_or_else(|| policy_error(path, format!("tensor {name} is missing")))?;
    if t.dtype() != DType::F32 {
        return Err(policy_error(
            path,
            format!("tensor {name} is {:?}, expected F32", t.dtype()),
        ));
    }
    if t.dims() != shape {
        return Err(policy_error(
            path,
            format!(
                "tensor {name} has shape {:?}, expected {shape:?} from the sidecar sizes",
                t.dims()
            ),
        ));
    }
    let v = t
        .flatten_all()
        .and_then(|t| t.to_vec1::<f32>())
        .map_err(|e| policy_error(path, format!("tensor {name}: {e}")))?;
    if v.iter().any(|x| !x.is_finite()) {
        return Err(policy_error(
            path,
            format!("tensor {name} contains NaN or infinite values"),
        ));
    }
    Ok(v)
}

/// Dot product with 8 partial sums (vectorizable).
fn dot(a: &[f32], b: &[f32]) -> f32 {
    let mut acc = [0f32; 8];
    let chunks_a = a.chunks_exact(8);
    let chunks_b = b.chunks_exact(8);
    let tail: f32 = chunks_a
        .remainder()
        .iter()
        .zip(chunks_b.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (ca, cb) in chunks_a.zip(chunks_b) {
        for i in 0..8 {
            acc[i] += ca[i] * cb[i];
        }
    }
    acc.iter().sum::<f32>() + tail
}
