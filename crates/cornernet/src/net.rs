//! The FDLS network (seed 003 Figs. 5–7): a residual multilayer perceptron,
//! with a plain-Rust forward pass for prediction (candle's per-operation
//! overhead would exceed the whole corner's budget; [`crate::train`] holds
//! the candle side).
//!
//! # Reading (seed 003 "Deep learning optimization", Figs. 5–7)
//! A ResNet of fully connected layers (Fig. 5: the block fits
//! f(x) = H(x) − x and adds the shortcut, H(x) = f(x) + x), 64 layers with
//! a shortcut every 8 and dropout between them, trained on MSE (eq. 9) by
//! Adam (eqs. 10–14). Here the shortcut spans 2 layers (the brief's
//! reading) and the depth is chosen on a held-out split (the example's
//! table): `layers` counts every fully connected layer, the stem and the
//! head included, so a net of L layers has (L − 2) / 2 blocks.
//!
//! Forward: h = relu(W₀ x + b₀); per block h ← relu(h + W₂ relu(W₁ h + b₁)
//! + b₂) (He et al. 2016's block, seed 003 Fig. 7); y = W_L h + b_L.

use kerf_rng::Rng;
use serde::{Deserialize, Serialize};

use crate::corner::{INPUTS, LOWER, OUTPUTS, UPPER};
use crate::error::CornerNetError;

/// A network's sizes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Architecture {
    /// Inputs.
    pub inputs: usize,
    /// Outputs.
    pub outputs: usize,
    /// Hidden width.
    pub width: usize,
    /// Fully connected layers, even, ≥ 4.
    pub layers: usize,
}

impl Architecture {
    /// FDLS's sizes for this crate's features with the given width and depth.
    pub fn fdls(width: usize, layers: usize) -> Self {
        Architecture {
            inputs: INPUTS,
            outputs: OUTPUTS,
            width,
            layers,
        }
    }

    /// Checks the sizes.
    ///
    /// # Errors
    /// [`CornerNetError::InvalidParameter`] for an odd or too small depth or
    /// a zero size.
    pub fn check(&self) -> Result<(), CornerNetError> {
        if self.layers < 4 || !self.layers.is_multiple_of(2) {
            return Err(CornerNetError::InvalidParameter {
                name: "layers".to_string(),
                value: self.layers as f64,
                reason: "must be even and ≥ 4 (stem, blocks of two, head)".to_string(),
            });
        }
        if self.inputs == 0 || self.outputs == 0 || self.width == 0 {
            return Err(CornerNetError::InvalidParameter {
                name: "network size".to_string(),
                value: 0.0,
                reason: "inputs, outputs and width must be ≥ 1".to_string(),
            });
        }
        Ok(())
    }

    /// Residual blocks.
    pub fn blocks(&self) -> usize {
        (self.layers - 2) / 2
    }

    /// Every layer's (name, out, in), in forward order.
    pub fn shapes(&self) -> Vec<(String, usize, usize)> {
        let mut v = vec![("stem".to_string(), self.width, self.inputs)];
        for b in 0..self.blocks() {
            v.push((format!("block{b}.a"), self.width, self.width));
            v.push((format!("block{b}.b"), self.width, self.width));
        }
        v.push(("head".to_string(), self.outputs, self.width));
        v
    }
}

/// One fully connected layer, its weight row-major (out × in, candle's
/// `Linear` layout).
#[derive(Debug, Clone, PartialEq)]
pub struct Dense {
    /// out × in weights.
    pub weight: Vec<f32>,
    /// out biases.
    pub bias: Vec<f32>,
    /// Inputs.
    pub inputs: usize,
}

impl Dense {
    /// y = W x + b.
    fn apply(&self, x: &[f32], y: &mut [f32]) {
        for (o, out) in y.iter_mut().enumerate() {
            let row = &self.weight[o * self.inputs..(o + 1) * self.inputs];
            *out = self.bias[o] + row.iter().zip(x).map(|(w, v)| w * v).sum::<f32>();
        }
    }
}

/// The residual MLP.
#[derive(Debug, Clone, PartialEq)]
pub struct ResMlp {
    /// Its sizes.
    pub architecture: Architecture,
    /// The layers in [`Architecture::shapes`] order.
    pub layers: Vec<Dense>,
}

impl ResMlp {
    /// Initial weights: He-uniform U(±√(6 / in)) (He et al. 2015), the
    /// second layer of each block scaled by 0.1 so that every block starts
    /// near the identity; biases zero. Drawn from `rng` in layer order.
    ///
    /// # Errors
    /// As [`Architecture::check`].
    pub fn init(architecture: Architecture, rng: &mut Rng) -> Result<Self, CornerNetError> {
        architecture.check()?;
        let layers = architecture
            .shapes()
            .into_iter()
            .map(|(name, out, inp)| {
                let bound =
                    (6.0 / inp as f64).sqrt() * if name.ends_with(".b") { 0.1 } else { 1.0 };
                Dense {
                    weight: (0..out * inp)
                        .map(|_| rng.uniform(-bound, bound) as f32)
                        .collect(),
                    bias: vec![0.0; out],
                    inputs: inp,
                }
            })
            .collect();
        Ok(ResMlp {
            architecture,
            layers,
        })
    }

    /// The forward pass (module documentation) of one normalized input.
    ///
    /// # Returns
    /// The normalized outputs.
    ///
    /// # Performance
    /// About width² × layers multiply-adds (40 k for 64 × 8), no candle.
    pub fn forward(&self, x: &[f32]) -> Vec<f32> {
        let w = self.architecture.width;
        let (mut h, mut a, mut b) = (vec![0.0f32; w], vec![0.0f32; w], vec![0.0f32; w]);
        let n = self.layers.len();
        self.layers[0].apply(x, &mut h);
        relu(&mut h);
        for pair in self.layers[1..n - 1].chunks(2) {
            pair[0].apply(&h, &mut a);
            relu(&mut a);
            pair[1].apply(&a, &mut b);
            for (hv, bv) in h.iter_mut().zip(&b) {
                *hv = (*hv + bv).max(0.0);
            }
        }
        let mut y = vec![0.0f32; self.architecture.outputs];
        self.layers[n - 1].apply(&h, &mut y);
        y
    }
}

/// max(0, x) in place.
fn relu(v: &mut [f32]) {
    for x in v {
        *x = x.max(0.0);
    }
}

/// The z-scores of inputs and outputs (training set's mean and standard
/// deviation; a constant feature keeps σ = 1 and becomes 0).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Normalization {
    /// Input means.
    pub input_mean: Vec<f64>,
    /// Input standard deviations.
    pub input_std: Vec<f64>,
    /// Output means.
    pub output_mean: Vec<f64>,
    /// Output standard deviations.
    pub output_std: Vec<f64>,
}

impl Normalization {
    /// From training inputs and outputs.
    pub fn fit(inputs: &[[f64; INPUTS]], outputs: &[[f64; OUTPUTS]]) -> Self {
        let (input_mean, input_std) = moments(inputs);
        let (output_mean, output_std) = moments(outputs);
        Normalization {
            input_mean,
            input_std,
            output_mean,
            output_std,
        }
    }

    /// A normalized input.
    pub fn input(&self, x: &[f64; INPUTS]) -> Vec<f32> {
        x.iter()
            .zip(self.input_mean.iter().zip(&self.input_std))
            .map(|(v, (m, s))| ((v - m) / s) as f32)
            .collect()
    }

    /// A normalized output.
    pub fn output(&self, y: &[f64; OUTPUTS]) -> Vec<f32> {
        y.iter()
            .zip(self.output_mean.iter().zip(&self.output_std))
            .map(|(v, (m, s))| ((v - m) / s) as f32)
            .collect()
    }

    /// A network output back in (ℓ / A, α, β), clamped to the swarm's box.
    pub fn variables(&self, y: &[f32]) -> [f64; OUTPUTS] {
        std::array::from_fn(|k| {
            let v = f64::from(y.get(k).copied().unwrap_or(0.0)) * self.output_std[k]
                + self.output_mean[k];
            v.clamp(LOWER[k], UPPER[k])
        })
    }
}

/// Per-column mean and standard deviation.
fn moments<const D: usize>(rows: &[[f64; D]]) -> (Vec<f64>, Vec<f64>) {
    let n = rows.len().max(1) as f64;
    let mean: Vec<f64> = (0..D)
        .map(|k| rows.iter().map(|r| r[k]).sum::<f64>() / n)
        .collect();
    let std = (0..D)
        .map(|k| {
            let var = rows.iter().map(|r| (r[k] - mean[k]).powi(2)).sum::<f64>() / n;
            if var.sqrt() > 1e-9 {
                var.sqrt()
            } else {
                1.0
            }
        })
        .collect();
    (mean, std)
}
