//! The Q-network of seed 002 (section 3, Fig. 2, Table 2) as plain weights
//! ([`Weights`], the agent's fast forward pass) and as candle variables
//! ([`QNet`], the batched forward pass that training differentiates).
//!
//! # kerf's reading of Fig. 2 and Table 2
//! Fig. 2 ("diagram of the used neural network") is not in the seed's text;
//! Table 2 gives, per architecture, one "layerwise neuron count" N and one
//! "layerwise activation function". kerf reads this as
//!
//! ```text
//! x (3: v/V, a/A, d/d_max) → N → N → 3 Q-values (accelerate, keep, decelerate)
//! ```
//!
//! two fully connected hidden layers of N neurons with the table's
//! activation, and a linear output layer (Q-values are unbounded returns), in
//! [`crate::lattice::Action::ALL`] order. Architectures 1..12 are
//! N ∈ {24, 20, 16, 12, 8, 6}, each with ReLU (odd numbers) and tanh (even
//! numbers).
//!
//! # Initialization (deterministic)
//! candle's CPU generator cannot be seeded, so the weights are drawn from
//! [`kerf_rng::Rng`]. The paper used MATLAB 2022a, whose
//! `fullyConnectedLayer` defaults to Glorot (Xavier) uniform weights and zero
//! biases: W ~ U(−√(6/(fan_in + fan_out)), +√(6/(fan_in + fan_out)))
//! (Glorot & Bengio, AISTATS 2010, eq. 16), b = 0. Draw order: layer by layer
//! from the input, each weight matrix row-major (out × in, candle's `Linear`
//! layout).

use std::fmt;

use candle_core::{Device, Tensor, Var};
use candle_nn::{Linear, Module};
use kerf_rng::Rng;

use crate::error::StepError;

/// Inputs of the network (seed 002 section 3: v/V, a/A, d/d_max).
pub const INPUTS: usize = 3;
/// Outputs: one Q-value per action of [`crate::lattice::Action::ALL`].
pub const OUTPUTS: usize = 3;

/// Converts a candle error into [`StepError::Network`].
pub(crate) fn backend(e: candle_core::Error) -> StepError {
    StepError::Network {
        reason: format!("candle: {e}"),
    }
}

/// Activation of the hidden layers (seed 002 Table 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Activation {
    /// max(0, x).
    Relu,
    /// tanh(x) (the paper's "sigmoidal" activation).
    Tanh,
}

impl Activation {
    /// "relu" or "tanh" (as stored in a network file).
    pub fn name(self) -> &'static str {
        match self {
            Activation::Relu => "relu",
            Activation::Tanh => "tanh",
        }
    }

    #[inline]
    fn apply(self, x: f32) -> f32 {
        match self {
            Activation::Relu => x.max(0.0),
            Activation::Tanh => x.tanh(),
        }
    }
}

/// Hidden widths of Table 2, for architectures (1, 2), (3, 4), …, (11, 12).
const WIDTHS: [usize; 6] = [24, 20, 16, 12, 8, 6];

/// One of the 12 evaluated architectures of seed 002 Table 2.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Architecture {
    number: usize,
}

impl Architecture {
    /// Architecture `number` (1..=12) of Table 2.
    ///
    /// # Errors
    /// [`StepError::Network`] for a number outside 1..=12.
    pub fn new(number: usize) -> Result<Self, StepError> {
        if (1..=12).contains(&number) {
            Ok(Self { number })
        } else {
            Err(StepError::Network {
                reason: format!("architecture {number}: Table 2 numbers them 1 to 12"),
            })
        }
    }

    /// All 12, in table order.
    pub fn all() -> Vec<Architecture> {
        (1..=12).map(|number| Self { number }).collect()
    }

    /// Its number in Table 2.
    pub fn number(self) -> usize {
        self.number
    }

    /// Neurons per hidden layer (N).
    pub fn hidden(self) -> usize {
        WIDTHS[(self.number - 1) / 2]
    }

    /// Hidden-layer activation.
    pub fn activation(self) -> Activation {
        if self.number % 2 == 1 {
            Activation::Relu
        } else {
            Activation::Tanh
        }
    }

    /// Layer shapes (out, in) from the input: (N, 3), (N, N), (3, N).
    pub fn shapes(self) -> [(usize, usize); 3] {
        let n = self.hidden();
        [(n, INPUTS), (n, n), (OUTPUTS, n)]
    }
}

impl Default for Architecture {
    /// Architecture 2 (24 tanh): one of the three best of Table 5
    /// (section 3: "the three best performing architectures are those
    /// numbered 2, 8 and 10").
    fn default() -> Self {
        Self { number: 2 }
    }
}

impl fmt::Display for Architecture {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} (3-{}-{}-3 {})",
            self.number,
            self.hidden(),
            self.hidden(),
            self.activation().name()
        )
    }
}

/// The parameters of one layer: weight row-major (out × in) and bias (out).
#[derive(Debug, Clone, PartialEq)]
pub struct Layer {
    /// Row-major out × in.
    pub weight: Vec<f32>,
    /// Length out.
    pub bias: Vec<f32>,
}

/// The parameters of a Q-network as plain vectors, with a forward pass in
/// plain Rust (no candle, no allocation).
#[derive(Debug, Clone, PartialEq)]
pub struct Weights {
    architecture: Architecture,
    layers: Vec<Layer>,
}

impl Weights {
    /// Glorot-uniform weights and zero biases drawn from `rng` (module
    /// documentation).
    pub fn init(architecture: Architecture, rng: &mut Rng) -> Self {
        let layers = architecture
            .shapes()
            .iter()
            .map(|&(out, inp)| {
                let bound = (6.0 / (inp + out) as f64).sqrt();
                Layer {
                    weight: (0..out * inp)
                        .map(|_| rng.uniform(-bound, bound) as f32)
                        .collect(),
                    bias: vec![0.0; out],
                }
            })
            .collect();
        Self {
            architecture,
            layers,
        }
    }

    /// Weights from given layers, checked.
    ///
    /// # Errors
    /// [`StepError::Network`] for a wrong number of layers, a wrong length,
    /// or a non-finite value.
    pub fn from_layers(architecture: Architecture, layers: Vec<Layer>) -> Result<Self, StepError> {
        let w = Self {
            architecture,
            layers,
        };
        w.validate()?;
        Ok(w)
    }

    /// Checks the layer count, every length against the architecture, and
    /// that every value is finite.
    ///
    /// # Errors
    /// [`StepError::Network`] naming the first offending layer.
    pub fn validate(&self) -> Result<(), StepError> {
        let shapes = self.architecture.shapes();
        if self.layers.len() != shapes.len() {
            return Err(StepError::Network {
                reason: format!(
                    "{} layers for architecture {}, which has {}",
                    self.layers.len(),
                    self.architecture,
                    shapes.len()
                ),
            });
        }
        for (k, (layer, &(out, inp))) in self.layers.iter().zip(shapes.iter()).enumerate() {
            if layer.weight.len() != out * inp || layer.bias.len() != out {
                return Err(StepError::Network {
                    reason: format!(
                        "layer {k}: weight of {} and bias of {} values, architecture {} needs \
                         {out}×{inp} and {out}",
                        layer.weight.len(),
                        layer.bias.len(),
                        self.architecture
                    ),
                });
            }
            if layer
                .weight
                .iter()
                .chain(layer.bias.iter())
                .any(|v| !v.is_finite())
            {
                return Err(StepError::Network {
                    reason: format!("layer {k} holds a NaN or infinite value"),
                });
            }
        }
        Ok(())
    }

    /// The architecture.
    pub fn architecture(&self) -> Architecture {
        self.architecture
    }

    /// The layers, from the input.
    pub fn layers(&self) -> &[Layer] {
        &self.layers
    }

    /// Mutable layers (the optimizer's master copy).
    pub(crate) fn layers_mut(&mut self) -> &mut [Layer] {
        &mut self.layers
    }

    /// Q-values of one input, in [`crate::lattice::Action::ALL`] order:
    /// h₁ = σ(W₁x + b₁), h₂ = σ(W₂h₁ + b₂), q = W₃h₂ + b₃.
    ///
    /// # Performance
    /// O(N²), no allocation beyond two stack-sized buffers (N ≤ 24).
    pub fn q_values(&self, x: &[f32; INPUTS]) -> [f32; OUTPUTS] {
        let act = self.architecture.activation();
        let mut h = [0f32; 32];
        let mut g = [0f32; 32];
        let n = self.architecture.hidden().min(32);
        dense(&self.layers[0], x, &mut h[..n], Some(act));
        dense(&self.layers[1], &h[..n], &mut g[..n], Some(act));
        let mut q = [0f32; OUTPUTS];
        dense(&self.layers[2], &g[..n], &mut q, None);
        q
    }
}

/// y = σ(W x + b) for a row-major W of shape (y.len(), x.len()).
#[inline]
fn dense(layer: &Layer, x: &[f32], y: &mut [f32], act: Option<Activation>) {
    let n_in = x.len();
    for (i, yi) in y.iter_mut().enumerate() {
        let row = &layer.weight[i * n_in..(i + 1) * n_in];
        let z = row.iter().zip(x).map(|(w, v)| w * v).sum::<f32>() + layer.bias[i];
        *yi = act.map_or(z, |a| a.apply(z));
    }
}

/// The Q-network as candle variables, for batched forward passes and
/// autograd.
#[derive(Debug, Clone)]
pub struct QNet {
    architecture: Architecture,
    /// weight, bias per layer, from the input.
    vars: Vec<Var>,
}

impl QNet {
    /// Candle variables holding `weights`.
    ///
    /// # Errors
    /// [`StepError::Network`] when candle fails.
    pub fn new(weights: &Weights) -> Result<Self, StepError> {
        let mut vars = Vec::with_capacity(6);
        for (layer, &(out, inp)) in weights
            .layers
            .iter()
            .zip(weights.architecture.shapes().iter())
        {
            vars.push(Var::from_slice(&layer.weight, (out, inp), &Device::Cpu).map_err(backend)?);
            vars.push(Var::from_slice(&layer.bias, out, &Device::Cpu).map_err(backend)?);
        }
        Ok(Self {
            architecture: weights.architecture,
            vars,
        })
    }

    /// Overwrites the variables with `weights` (same architecture).
    ///
    /// # Errors
    /// [`StepError::Network`] for another architecture or a candle failure.
    pub fn set(&self, weights: &Weights) -> Result<(), StepError> {
        if weights.architecture != self.architecture {
            return Err(StepError::Network {
                reason: format!(
                    "architecture {} given to a network of architecture {}",
                    weights.architecture, self.architecture
                ),
            });
        }
        for (k, layer) in weights.layers.iter().enumerate() {
            let w = &self.vars[2 * k];
            let b = &self.vars[2 * k + 1];
            w.set(&Tensor::from_slice(&layer.weight, w.shape(), &Device::Cpu).map_err(backend)?)
                .map_err(backend)?;
            b.set(&Tensor::from_slice(&layer.bias, b.shape(), &Device::Cpu).map_err(backend)?)
                .map_err(backend)?;
        }
        Ok(())
    }

    /// The trainable variables: weight, bias per layer, from the input.
    pub fn vars(&self) -> &[Var] {
        &self.vars
    }

    /// Q-values of a batch `x` (rows × 3) → rows × 3; gradients flow to the
    /// variables.
    ///
    /// # Errors
    /// [`StepError::Network`] for a shape mismatch or a candle failure.
    pub fn forward(&self, x: &Tensor) -> Result<Tensor, StepError> {
        let act = self.architecture.activation();
        let mut h = x.clone();
        for k in 0..3 {
            let lin = Linear::new(
                self.vars[2 * k].as_tensor().clone(),
                Some(self.vars[2 * k + 1].as_tensor().clone()),
            );
            h = lin.forward(&h).map_err(backend)?;
            if k < 2 {
                h = match act {
                    Activation::Relu => h.relu(),
                    Activation::Tanh => h.tanh(),
                }
                .map_err(backend)?;
            }
        }
        Ok(h)
    }
}
