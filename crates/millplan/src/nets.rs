//! The actor and critic networks of DDPG (seed 004 Algorithm 1, Table 2:
//! "2×256 ReLU") on candle, initialized from the crate's seeded generator.
//! Their optimizer is in [`crate::adamw`], the CPU settings that make
//! small-batch training fast in [`crate::cpu_tuning`] (both reached here too).
//!
//! # Networks
//! * Actor A(s | wᵃ): observation → hidden ReLU layers → action dimension,
//!   tanh output, so every action entry is in [−1, 1] (the normalized action
//!   of [`crate::rl::Environment`]).
//! * Critic Q(s, a | w^q): the concatenation [s, a] → hidden ReLU layers → 1,
//!   linear output (the action enters at the input, as in Fujimoto et al.'s
//!   TD3 reference code; seed 004 does not say where it enters).
//!
//! # Initialization (deterministic)
//! candle's CPU random generator cannot be seeded, so the weights are drawn
//! from [`Rng`]:
//! * hidden layers: PyTorch's `nn.Linear` default — `kaiming_uniform_` with
//!   a = √5 gives the bound gain·√(3/fan_in) with gain = √(2/(1 + a²)) =
//!   √(1/3), i.e. W, b ~ U(−1/√fan_in, 1/√fan_in);
//! * output layers of both networks: U(−3·10⁻³, 3·10⁻³) for W and b
//!   (Lillicrap et al., "Continuous control with deep reinforcement
//!   learning", ICLR 2016, section 7), so initial actions and Q-values are
//!   near 0 and the tanh starts in its linear range.
//!
//! Draw order: layer by layer from the input, the weight matrix row-major
//! (shape out × in, candle's `Linear` layout), then the bias.

use std::collections::HashMap;

use candle_core::{DType, Device, Tensor, Var};
use candle_nn::{Linear, Module};

use crate::error::MillPlanError;
use crate::rng::Rng;

pub use crate::adamw::FusedAdamW;
pub use crate::cpu_tuning::{CpuTuning, CpuTuningReport, MMAP_THRESHOLD_BYTES};

/// Bound of the uniform initialization of the output layers (Lillicrap et
/// al. 2016, section 7).
pub const OUTPUT_INIT_BOUND: f64 = 3e-3;

/// The parameters of one layer as flat vectors: (weight row-major
/// out × in, bias of length out).
pub type LayerParameters = (Vec<f32>, Vec<f32>);

/// Converts a candle error into the crate's error.
pub(crate) fn backend(e: candle_core::Error) -> MillPlanError {
    MillPlanError::Backend(e.to_string())
}

/// The activation of a network's last layer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputActivation {
    /// tanh, output in [−1, 1] (the actor).
    Tanh,
    /// Identity (the critic).
    Linear,
}

/// One fully connected layer: weight `out × in` and bias `out`, both
/// trainable candle variables.
#[derive(Debug, Clone)]
struct Layer {
    weight: Var,
    bias: Var,
    linear: Linear,
}

impl Layer {
    fn new(weight: Var, bias: Var) -> Self {
        let linear = Linear::new(weight.as_tensor().clone(), Some(bias.as_tensor().clone()));
        Self {
            weight,
            bias,
            linear,
        }
    }

    /// The layer with weights detached from the autograd graph (gradients
    /// flow to the input only).
    fn detached(&self) -> Linear {
        Linear::new(
            self.weight.as_tensor().detach(),
            Some(self.bias.as_tensor().detach()),
        )
    }
}

/// A multilayer perceptron with ReLU hidden layers (the actor or the
/// critic).
#[derive(Debug, Clone)]
pub struct Mlp {
    sizes: Vec<usize>,
    layers: Vec<Layer>,
    output: OutputActivation,
}

/// What [`Mlp::forward_trace`] keeps for [`Mlp::backward`].
#[derive(Debug, Clone)]
pub struct ForwardTrace {
    /// The input of every layer (the network input first).
    inputs: Vec<Tensor>,
    /// 1[z_k ≥ 0] of every hidden layer, as f32.
    masks: Vec<Tensor>,
    /// The network output.
    output: Tensor,
}

impl ForwardTrace {
    /// The network output y.
    pub fn output(&self) -> &Tensor {
        &self.output
    }
}

impl Mlp {
    /// A network with layer sizes `sizes` = [input, hidden…, output],
    /// initialized as in the module documentation from `rng`.
    ///
    /// # Arguments
    /// * `sizes` — at least 2 entries, every entry ≥ 1.
    /// * `output` — activation of the last layer.
    /// * `rng` — the seeded generator; the draws advance it.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] for bad sizes,
    /// [`MillPlanError::Backend`] when candle fails.
    pub fn new(
        sizes: &[usize],
        output: OutputActivation,
        rng: &mut Rng,
    ) -> Result<Self, MillPlanError> {
        if sizes.len() < 2 || sizes.contains(&0) {
            return Err(MillPlanError::InvalidConfig {
                name: "network layer sizes".to_string(),
                reason: format!(
                    "need at least an input and an output size, all ≥ 1; got {sizes:?}"
                ),
            });
        }
        let n_layers = sizes.len() - 1;
        let mut params = Vec::with_capacity(n_layers);
        for (k, pair) in sizes.windows(2).enumerate() {
            let (fan_in, fan_out) = (pair[0], pair[1]);
            let bound = if k + 1 == n_layers {
                OUTPUT_INIT_BOUND
            } else {
                1.0 / (fan_in as f64).sqrt()
            };
            let weight: Vec<f32> = (0..fan_in * fan_out)
                .map(|_| rng.uniform(-bound, bound) as f32)
                .collect();
            let bias: Vec<f32> = (0..fan_out)
                .map(|_| rng.uniform(-bound, bound) as f32)
                .collect();
            params.push((weight, bias));
        }
        Self::from_parameters(sizes, output, params)
    }

    /// A network with the given parameters: for each layer k, the weight
    /// `sizes[k+1] × sizes[k]` row-major and the bias `sizes[k+1]`.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] when the sizes or the parameter
    /// lengths are inconsistent or a parameter is not finite;
    /// [`MillPlanError::Backend`] when candle fails.
    pub fn from_parameters(
        sizes: &[usize],
        output: OutputActivation,
        params: Vec<LayerParameters>,
    ) -> Result<Self, MillPlanError> {
        if sizes.len() < 2 || sizes.contains(&0) || params.len() + 1 != sizes.len() {
            return Err(MillPlanError::InvalidConfig {
                name: "network layer sizes".to_string(),
                reason: format!("{} parameter pairs for layer sizes {sizes:?}", params.len()),
            });
        }
        let device = Device::Cpu;
        let mut layers = Vec::with_capacity(params.len());
        for (k, ((weight, bias), pair)) in params.into_iter().zip(sizes.windows(2)).enumerate() {
            let (fan_in, fan_out) = (pair[0], pair[1]);
            if weight.len() != fan_in * fan_out || bias.len() != fan_out {
                return Err(MillPlanError::InvalidConfig {
                    name: format!("layer {k} parameters"),
                    reason: format!(
                        "weight has {} entries and bias {}, expected {} ({fan_out}×{fan_in}) and {fan_out}",
                        weight.len(),
                        bias.len(),
                        fan_in * fan_out
                    ),
                });
            }
            if weight.iter().chain(bias.iter()).any(|v| !v.is_finite()) {
                return Err(MillPlanError::InvalidConfig {
                    name: format!("layer {k} parameters"),
                    reason: "contain NaN or infinite values".to_string(),
                });
            }
            let w = Var::from_vec(weight, (fan_out, fan_in), &device).map_err(backend)?;
            let b = Var::from_vec(bias, fan_out, &device).map_err(backend)?;
            layers.push(Layer::new(w, b));
        }
        Ok(Self {
            sizes: sizes.to_vec(),
            layers,
            output,
        })
    }

    /// A copy with its own variables (the target networks of Algorithm 1:
    /// w′ ← w at initialization).
    ///
    /// # Errors
    /// [`MillPlanError::Backend`] when candle fails.
    pub fn deep_copy(&self) -> Result<Self, MillPlanError> {
        Self::from_parameters(&self.sizes, self.output, self.parameters()?)
    }

    /// Layer sizes [input, hidden…, output].
    pub fn sizes(&self) -> &[usize] {
        &self.sizes
    }

    /// Activation of the last layer.
    pub fn output_activation(&self) -> OutputActivation {
        self.output
    }

    /// The trainable variables (weight, bias per layer, from the input).
    pub fn vars(&self) -> Vec<Var> {
        self.layers
            .iter()
            .flat_map(|l| [l.weight.clone(), l.bias.clone()])
            .collect()
    }

    /// Forward pass of a batch `x` (rows × input size); gradients flow to
    /// the network's variables.
    ///
    /// # Errors
    /// [`MillPlanError::Backend`] for a shape mismatch or a candle failure.
    pub fn forward(&self, x: &Tensor) -> Result<Tensor, MillPlanError> {
        self.forward_with(x, |l| l.linear.clone())
    }

    /// Forward pass with the weights detached from the autograd graph:
    /// gradients flow to `x` only (the critic inside the actor loss, whose
    /// own weight gradients would be computed and thrown away).
    ///
    /// # Errors
    /// [`MillPlanError::Backend`] for a shape mismatch or a candle failure.
    pub fn forward_detached(&self, x: &Tensor) -> Result<Tensor, MillPlanError> {
        self.forward_with(x, Layer::detached)
    }

    fn forward_with(
        &self,
        x: &Tensor,
        linear: impl Fn(&Layer) -> Linear,
    ) -> Result<Tensor, MillPlanError> {
        let mut h = x.clone();
        let last = self.layers.len().saturating_sub(1);
        for (k, layer) in self.layers.iter().enumerate() {
            h = linear(layer).forward(&h).map_err(backend)?;
            h = if k < last {
                h.relu()
            } else {
                match self.output {
                    OutputActivation::Tanh => h.tanh(),
                    OutputActivation::Linear => Ok(h),
                }
            }
            .map_err(backend)?;
        }
        Ok(h)
    }

    /// Forward pass without autograd that keeps what [`Mlp::backward`]
    /// needs: each layer's input and each hidden layer's ReLU mask.
    ///
    /// # Errors
    /// [`MillPlanError::Backend`] for a shape mismatch or a candle failure.
    pub fn forward_trace(&self, x: &Tensor) -> Result<ForwardTrace, MillPlanError> {
        let last = self.layers.len().saturating_sub(1);
        let mut inputs = Vec::with_capacity(self.layers.len());
        let mut masks = Vec::with_capacity(last);
        let mut h = x.detach();
        for (k, layer) in self.layers.iter().enumerate() {
            let z = layer.detached().forward(&h).map_err(backend)?;
            inputs.push(h);
            h = if k < last {
                let mask = z
                    .ge(0f32)
                    .and_then(|m| m.to_dtype(DType::F32))
                    .map_err(backend)?;
                let out = (&z * &mask).map_err(backend)?;
                masks.push(mask);
                out
            } else {
                match self.output {
                    OutputActivation::Tanh => z.tanh().map_err(backend)?,
                    OutputActivation::Linear => z,
                }
            };
        }
        Ok(ForwardTrace {
            inputs,
            masks,
            output: h,
        })
    }

    /// Backpropagation by hand (no autograd): the gradients of a loss L
    /// with respect to every variable, in the order of [`Mlp::vars`], given
    /// the forward trace and ∂L/∂y (rows × output size).
    ///
    /// With z_k = h_{k−1} W_kᵀ + b_k, h_k = relu(z_k) for the hidden layers
    /// and y = φ(z_out) (φ = tanh or identity): δ_out = ∂L/∂y ⊙ φ′ (φ′ =
    /// 1 − y² for tanh), and for each layer from the output,
    /// ∂L/∂W_k = δ_kᵀ h_{k−1}, ∂L/∂b_k = Σ_rows δ_k,
    /// δ_{k−1} = (δ_k W_k) ⊙ 1[z_{k−1} ≥ 0] (the ReLU derivative taken as 1
    /// at 0, as candle's autograd does; the test compares both). candle's
    /// autograd computes the same products but also zero-fills and adds an
    /// accumulator per node, which made it a large share of an update.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] when the trace does not belong to
    /// this network's layout; [`MillPlanError::Backend`] when candle fails.
    pub fn backward(
        &self,
        trace: &ForwardTrace,
        output_gradient: &Tensor,
    ) -> Result<Vec<Tensor>, MillPlanError> {
        let n = self.layers.len();
        if trace.inputs.len() != n || trace.masks.len() + 1 != n {
            return Err(MillPlanError::InvalidConfig {
                name: "backward".to_string(),
                reason: format!(
                    "trace of {} layers and {} masks for a network of {n} layers",
                    trace.inputs.len(),
                    trace.masks.len()
                ),
            });
        }
        let mut delta = match self.output {
            OutputActivation::Tanh => trace
                .output
                .sqr()
                .and_then(|y2| y2.affine(-1.0, 1.0))
                .and_then(|d| output_gradient * d)
                .map_err(backend)?,
            OutputActivation::Linear => output_gradient.detach(),
        };
        let mut grads = vec![None; 2 * n];
        for k in (0..n).rev() {
            let (layer, input) = (&self.layers[k], &trace.inputs[k]);
            let dw = delta.t().and_then(|d| d.matmul(input)).map_err(backend)?;
            let db = delta.sum(0).map_err(backend)?;
            grads[2 * k] = Some(dw);
            grads[2 * k + 1] = Some(db);
            if k > 0 {
                delta = delta
                    .matmul(&layer.weight.as_tensor().detach())
                    .and_then(|d| d * &trace.masks[k - 1])
                    .map_err(backend)?;
            }
        }
        grads
            .into_iter()
            .map(|g| g.ok_or_else(|| MillPlanError::Backend("backward: missing gradient".into())))
            .collect()
    }

    /// The outputs y (rows × 1) of a single-output network and, without
    /// autograd, the gradient of each row's output with respect to that
    /// row's input, ∂y_i/∂x_i (rows × input size): the critic's action
    /// gradient ∇_a Q(s, a) of the deterministic policy gradient (seed 004
    /// Algorithm 1, "actor network update"; Silver et al., "Deterministic
    /// policy gradient algorithms", ICML 2014, eq. 9).
    ///
    /// Backpropagation by hand through the ReLU layers, with
    /// z_k = h_{k−1} W_kᵀ + b_k, h_k = relu(z_k), y = h_L W_outᵀ + b_out:
    /// δ_L = W_out ⊙ 1[z_L ≥ 0], δ_{k−1} = (δ_k W_k) ⊙ 1[z_{k−1} ≥ 0] and
    /// ∂y/∂x = δ_1 W_1 (the ReLU derivative taken as 1 at 0, as candle's).
    /// candle's autograd would also compute every weight gradient, which the
    /// actor update throws away; this costs one forward and one backward
    /// matrix product per layer.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] unless the network has a linear
    /// output of size 1; [`MillPlanError::Backend`] when candle fails.
    pub fn output_and_input_gradient(&self, x: &Tensor) -> Result<(Tensor, Tensor), MillPlanError> {
        if self.output != OutputActivation::Linear || self.sizes.last() != Some(&1) {
            return Err(MillPlanError::InvalidConfig {
                name: "input gradient".to_string(),
                reason: format!(
                    "needs a linear single-output network, got sizes {:?} with {:?} output",
                    self.sizes, self.output
                ),
            });
        }
        let Some((last, hidden)) = self.layers.split_last() else {
            return Err(MillPlanError::InvalidConfig {
                name: "input gradient".to_string(),
                reason: "network without layers".to_string(),
            });
        };
        let mut h = x.detach();
        let mut masks = Vec::with_capacity(hidden.len());
        for layer in hidden {
            let z = layer.detached().forward(&h).map_err(backend)?;
            let mask = z
                .ge(0f32)
                .and_then(|m| m.to_dtype(DType::F32))
                .map_err(backend)?;
            h = (&z * &mask).map_err(backend)?;
            masks.push(mask);
        }
        let y = last.detached().forward(&h).map_err(backend)?;
        // δ_L = W_out (1 × H_L) broadcast over rows, masked.
        let mut delta = last
            .weight
            .as_tensor()
            .detach()
            .broadcast_mul(&masks.pop().ok_or_else(|| MillPlanError::InvalidConfig {
                name: "input gradient".to_string(),
                reason: "network without hidden layers".to_string(),
            })?)
            .map_err(backend)?;
        for (k, layer) in hidden.iter().enumerate().rev() {
            delta = delta
                .matmul(&layer.weight.as_tensor().detach())
                .map_err(backend)?;
            if k > 0 {
                let mask = masks.pop().ok_or_else(|| {
                    MillPlanError::Backend("input gradient: mask stack empty".to_string())
                })?;
                delta = (&delta * &mask).map_err(backend)?;
            }
        }
        Ok((y, delta))
    }

    /// Soft target update (seed 004 Algorithm 1, "soft target network
    /// update"; Lillicrap et al. 2016 Algorithm 1): w′ ← τ w + (1 − τ) w′
    /// for every variable, `self` being the target w′.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] when the architectures differ,
    /// [`MillPlanError::Backend`] when candle fails.
    pub fn soft_update_from(&self, source: &Mlp, tau: f64) -> Result<(), MillPlanError> {
        if self.sizes != source.sizes {
            return Err(MillPlanError::InvalidConfig {
                name: "soft update".to_string(),
                reason: format!(
                    "target sizes {:?} differ from source sizes {:?}",
                    self.sizes, source.sizes
                ),
            });
        }
        // Fused: one pass over plain vectors instead of three candle ops
        // (same f32 arithmetic: τ·s + (1 − τ)·t with τ rounded to f32).
        let tau32 = tau as f32;
        let keep32 = (1.0 - tau) as f32;
        for (target, src) in self.vars().iter().zip(source.vars().iter()) {
            let s = flat(src.as_tensor())?;
            let mut t = flat(target.as_tensor())?;
            for (t, s) in t.iter_mut().zip(&s) {
                *t = s * tau32 + *t * keep32;
            }
            let mixed = Tensor::from_vec(t, target.shape(), &Device::Cpu).map_err(backend)?;
            target.set(&mixed).map_err(backend)?;
        }
        Ok(())
    }

    /// The parameters as flat `f32` vectors: (weight row-major out × in,
    /// bias) per layer.
    ///
    /// # Errors
    /// [`MillPlanError::Backend`] when candle fails.
    pub fn parameters(&self) -> Result<Vec<LayerParameters>, MillPlanError> {
        self.layers
            .iter()
            .map(|l| {
                let w = l
                    .weight
                    .as_tensor()
                    .flatten_all()
                    .and_then(|t| t.to_vec1::<f32>())
                    .map_err(backend)?;
                let b = l.bias.as_tensor().to_vec1::<f32>().map_err(backend)?;
                Ok((w, b))
            })
            .collect()
    }

    /// The variables as named tensors `l{k}.weight`, `l{k}.bias` (k from 0
    /// at the input), the layout of the policy file.
    pub fn named_tensors(&self) -> HashMap<String, Tensor> {
        let mut map = HashMap::new();
        for (k, l) in self.layers.iter().enumerate() {
            map.insert(format!("l{k}.weight"), l.weight.as_tensor().detach());
            map.insert(format!("l{k}.bias"), l.bias.as_tensor().detach());
        }
        map
    }
}

/// Builds a `rows × cols` f32 tensor from row-major data.
///
/// # Errors
/// [`MillPlanError::Backend`] when the length is not `rows · cols`.
pub fn matrix(data: Vec<f32>, rows: usize, cols: usize) -> Result<Tensor, MillPlanError> {
    Tensor::from_vec(data, (rows, cols), &Device::Cpu).map_err(backend)
}

/// Reads a scalar (0-d or one-element) f32 tensor as f64.
pub(crate) fn scalar(t: &Tensor) -> Result<f64, MillPlanError> {
    let v = t
        .to_dtype(DType::F64)
        .and_then(|t| t.flatten_all())
        .and_then(|t| t.to_vec1::<f64>())
        .map_err(backend)?;
    match v.as_slice() {
        [x] => Ok(*x),
        _ => Err(MillPlanError::Backend(format!(
            "expected a scalar, got {} values",
            v.len()
        ))),
    }
}

/// The values of a tensor as a flat `f32` vector (a copy).
pub(crate) fn flat(t: &Tensor) -> Result<Vec<f32>, MillPlanError> {
    t.flatten_all()
        .and_then(|t| t.to_vec1::<f32>())
        .map_err(backend)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The candle forward pass equals a hand-written one
    /// (h = relu(W x + b), y = tanh(W x + b)) on the same parameters.
    #[test]
    fn forward_matches_plain_computation() {
        let mut rng = Rng::new(3);
        let net = Mlp::new(&[3, 5, 4, 2], OutputActivation::Tanh, &mut rng).expect("valid");
        let params = net.parameters().expect("params");
        let x = [0.3f32, -0.7, 0.9];
        let mut h: Vec<f32> = x.to_vec();
        for (k, (w, b)) in params.iter().enumerate() {
            let n_out = b.len();
            let n_in = h.len();
            let mut y = vec![0f32; n_out];
            for i in 0..n_out {
                let mut s = f64::from(b[i]);
                for j in 0..n_in {
                    s += f64::from(w[i * n_in + j]) * f64::from(h[j]);
                }
                y[i] = if k + 1 < params.len() {
                    s.max(0.0) as f32
                } else {
                    s.tanh() as f32
                };
            }
            h = y;
        }
        let out = net
            .forward(&matrix(x.to_vec(), 1, 3).expect("matrix"))
            .and_then(|t| t.flatten_all().map_err(backend))
            .and_then(|t| t.to_vec1::<f32>().map_err(backend))
            .expect("forward");
        for (a, b) in out.iter().zip(h.iter()) {
            assert!((a - b).abs() < 1e-6, "{a} vs {b}");
        }
    }

    /// Initialization bounds: hidden layers within 1/√fan_in and using it
    /// (max close to the bound), output layer within 3e-3.
    #[test]
    fn initialization_bounds() {
        let mut rng = Rng::new(11);
        let net = Mlp::new(&[4, 256, 256, 3], OutputActivation::Tanh, &mut rng).expect("valid");
        let params = net.parameters().expect("params");
        let bounds = [0.5, 1.0 / 16.0, 3e-3];
        for ((w, _b), bound) in params.iter().zip(bounds) {
            let max = w.iter().fold(0f32, |m, v| m.max(v.abs()));
            assert!(f64::from(max) <= bound);
            assert!(f64::from(max) > 0.9 * bound);
        }
    }

    /// The fused AdamW gives the same weights as candle_nn::AdamW over 20
    /// steps on the same losses (MSE of a 3→16→16→2 network on fixed
    /// data), with nonzero weight decay to cover that term too.
    #[test]
    fn fused_adamw_matches_candle() {
        use candle_nn::{AdamW, Optimizer, ParamsAdamW};
        let mut rng = Rng::new(21);
        let a = Mlp::new(&[3, 16, 16, 2], OutputActivation::Tanh, &mut rng).expect("valid");
        let b = a.deep_copy().expect("copy");
        let x: Vec<f32> = (0..24).map(|_| rng.uniform(-1.0, 1.0) as f32).collect();
        let y: Vec<f32> = (0..16).map(|_| rng.uniform(-0.5, 0.5) as f32).collect();
        let x = matrix(x, 8, 3).expect("x");
        let y = matrix(y, 8, 2).expect("y");
        let params = ParamsAdamW {
            lr: 1e-2,
            weight_decay: 0.1,
            ..ParamsAdamW::default()
        };
        let mut reference = AdamW::new(a.vars(), params.clone()).expect("adamw");
        let mut fused = FusedAdamW::new(b.vars(), params).expect("fused");
        let loss = |net: &Mlp| {
            net.forward(&x)
                .and_then(|p| (p - &y).map_err(backend))
                .and_then(|d| d.sqr().and_then(|d| d.mean_all()).map_err(backend))
                .expect("loss")
        };
        let first = scalar(&loss(&a)).expect("loss");
        for _ in 0..20 {
            reference.backward_step(&loss(&a)).expect("step");
            fused.backward_step(&loss(&b)).expect("step");
        }
        let last = scalar(&loss(&a)).expect("loss");
        assert!(
            last < 0.8 * first,
            "AdamW did not descend: {first} → {last}"
        );
        let pa = a.parameters().expect("p");
        let pb = b.parameters().expect("p");
        let mut max_diff = 0f32;
        for ((wa, ba), (wb, bb)) in pa.iter().zip(&pb) {
            for (u, v) in wa.iter().chain(ba).zip(wb.iter().chain(bb)) {
                max_diff = max_diff.max((u - v).abs());
            }
        }
        assert!(
            max_diff < 1e-6,
            "fused and candle AdamW differ by {max_diff}"
        );
        let bad = ParamsAdamW {
            lr: f64::NAN,
            ..ParamsAdamW::default()
        };
        assert!(FusedAdamW::new(a.vars(), bad).is_err());
    }

    /// The hand-written input gradient equals candle's autograd gradient of
    /// Σ_i y_i with respect to x (each row's output depends on its row
    /// only), and the outputs equal the forward pass.
    #[test]
    fn input_gradient_matches_autograd() {
        let mut rng = Rng::new(8);
        let net = Mlp::new(&[5, 32, 24, 1], OutputActivation::Linear, &mut rng).expect("valid");
        // Larger output weights than the ±3e-3 init, for a sensitive check.
        let mut params = net.parameters().expect("p");
        if let Some((w, _)) = params.last_mut() {
            w.iter_mut().for_each(|v| *v *= 100.0);
        }
        let net =
            Mlp::from_parameters(&[5, 32, 24, 1], OutputActivation::Linear, params).expect("valid");
        let data: Vec<f32> = (0..40).map(|_| rng.uniform(-1.0, 1.0) as f32).collect();
        let x = Var::from_vec(data.clone(), (8, 5), &Device::Cpu).expect("var");
        let y_auto = net.forward_detached(x.as_tensor()).expect("forward");
        let grads = y_auto
            .sum_all()
            .and_then(|s| s.backward())
            .expect("backward");
        let g_auto = flat(grads.get(x.as_tensor()).expect("grad")).expect("flat");
        let (y, g) = net
            .output_and_input_gradient(&matrix(data, 8, 5).expect("x"))
            .expect("gradient");
        assert_eq!(g.dims(), &[8, 5]);
        let y_auto = flat(&y_auto).expect("flat");
        for (a, b) in flat(&y).expect("flat").iter().zip(&y_auto) {
            assert!((a - b).abs() < 1e-6, "{a} vs {b}");
        }
        let g = flat(&g).expect("flat");
        let scale = g_auto.iter().fold(0f32, |m, v| m.max(v.abs()));
        assert!(scale > 1e-2, "gradient too small to test: {scale}");
        for (a, b) in g.iter().zip(&g_auto) {
            assert!((a - b).abs() < 1e-5 * scale, "{a} vs {b}");
        }
        let actor = Mlp::new(&[5, 8, 2], OutputActivation::Tanh, &mut rng).expect("valid");
        assert!(actor
            .output_and_input_gradient(&matrix(vec![0.0; 5], 1, 5).expect("x"))
            .is_err());
    }

    /// Flush-to-zero is on while the guard lives and off after: a product
    /// with a denormal result (1e-20 × 1e-20 = 1e-40 < f32::MIN_POSITIVE
    /// ≈ 1.18e-38) is 0 under FTZ and the denormal 1e-40 without it.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn flush_to_zero_guard() {
        let tiny = std::hint::black_box(1e-20f32);
        let before = std::hint::black_box(tiny) * std::hint::black_box(tiny);
        assert!(before > 0.0 && before < f32::MIN_POSITIVE);
        {
            let guard = CpuTuning::apply(false);
            assert!(guard.report().flush_to_zero);
            assert!(!guard.report().single_thread);
            let flushed = std::hint::black_box(tiny) * std::hint::black_box(tiny);
            assert_eq!(flushed, 0.0);
        }
        let after = std::hint::black_box(tiny) * std::hint::black_box(tiny);
        assert_eq!(after, before);
    }

    /// The hand-written backward pass equals candle's autograd for both
    /// output activations: gradients of L = Σ y ⊙ D (D a fixed random
    /// matrix, so ∂L/∂y = D) with respect to every variable.
    #[test]
    fn backward_matches_autograd() {
        let mut rng = Rng::new(31);
        for output in [OutputActivation::Tanh, OutputActivation::Linear] {
            let sizes = [6, 20, 12, 3];
            let net = Mlp::new(&sizes, output, &mut rng).expect("valid");
            let mut params = net.parameters().expect("p");
            if let Some((w, b)) = params.last_mut() {
                w.iter_mut().for_each(|v| *v *= 300.0);
                b.iter_mut().for_each(|v| *v *= 300.0);
            }
            let net = Mlp::from_parameters(&sizes, output, params).expect("valid");
            let x: Vec<f32> = (0..60).map(|_| rng.uniform(-1.0, 1.0) as f32).collect();
            let d: Vec<f32> = (0..30).map(|_| rng.uniform(-1.0, 1.0) as f32).collect();
            let x = matrix(x, 10, 6).expect("x");
            let d = matrix(d, 10, 3).expect("d");
            let grads = net
                .forward(&x)
                .and_then(|y| (y * &d).and_then(|t| t.sum_all()).map_err(backend))
                .and_then(|l| l.backward().map_err(backend))
                .expect("autograd");
            let trace = net.forward_trace(&x).expect("trace");
            let y_auto = flat(&net.forward(&x).expect("forward")).expect("flat");
            for (a, b) in flat(trace.output()).expect("flat").iter().zip(&y_auto) {
                assert!((a - b).abs() < 1e-6, "{output:?}: y {a} vs {b}");
            }
            let manual = net.backward(&trace, &d).expect("backward");
            let vars = net.vars();
            assert_eq!(manual.len(), vars.len());
            for (k, (var, g)) in vars.iter().zip(&manual).enumerate() {
                let auto = flat(grads.get(var.as_tensor()).expect("grad")).expect("flat");
                let mine = flat(g).expect("flat");
                assert_eq!(g.dims(), var.dims());
                let scale = auto.iter().fold(0f32, |m, v| m.max(v.abs()));
                assert!(
                    scale > 1e-3,
                    "{output:?} var {k}: gradient too small to test"
                );
                for (a, b) in mine.iter().zip(&auto) {
                    assert!(
                        (a - b).abs() <= 1e-5 * scale,
                        "{output:?} var {k}: {a} vs {b} (scale {scale})"
                    );
                }
            }
        }
    }

    /// Soft update: w′ ← τ w + (1 − τ) w′ exactly (to f32 rounding).
    #[test]
    fn soft_update_mixes() {
        let mut rng = Rng::new(4);
        let a = Mlp::new(&[2, 3, 1], OutputActivation::Linear, &mut rng).expect("valid");
        let b = Mlp::new(&[2, 3, 1], OutputActivation::Linear, &mut rng).expect("valid");
        let pa = a.parameters().expect("p");
        let pb = b.parameters().expect("p");
        b.soft_update_from(&a, 0.25).expect("same sizes");
        let pc = b.parameters().expect("p");
        for ((wa, wb), wc) in pa.iter().zip(pb.iter()).zip(pc.iter()) {
            for ((x, y), z) in wa.0.iter().zip(wb.0.iter()).zip(wc.0.iter()) {
                assert!((0.25 * x + 0.75 * y - z).abs() < 1e-7);
            }
        }
        let c = Mlp::new(&[2, 4, 1], OutputActivation::Linear, &mut rng).expect("valid");
        assert!(c.soft_update_from(&a, 0.5).is_err());
        assert!(Mlp::new(&[2], OutputActivation::Linear, &mut rng).is_err());
        assert!(Mlp::new(&[2, 0, 1], OutputActivation::Linear, &mut rng).is_err());
    }
}
