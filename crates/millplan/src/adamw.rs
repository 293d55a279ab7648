//! The fused AdamW optimizer of the DDPG networks ([`FusedAdamW`]).

use candle_core::backprop::GradStore;
use candle_core::{Device, Tensor, Var};
use candle_nn::ParamsAdamW;

use crate::error::MillPlanError;
use crate::nets::{backend, flat};

/// AdamW (Loshchilov & Hutter, "Decoupled weight decay regularization",
/// ICLR 2019, Algorithm 2; Kingma & Ba, ICLR 2015, Algorithm 1 for the
/// moments and bias correction) with exactly the update of
/// `candle_nn::AdamW` and its [`ParamsAdamW`], fused into one pass per
/// variable over plain vectors:
///
/// m ← β₁ m + (1 − β₁) g, v ← β₂ v + (1 − β₂) g²,
/// m̂ = m / (1 − β₁ᵗ), v̂ = v / (1 − β₂ᵗ),
/// θ ← θ (1 − lr λ) − lr m̂ / (√v̂ + ε).
///
/// Same arithmetic as candle's (f32, the scalars rounded to f32, the same
/// operation order; the test compares both), but candle's version runs a
/// dozen tensor operations per variable, each allocating and traversing a
/// 256×256 buffer; this one reads the gradient and the weights once and
/// writes the weights once, which makes a DDPG update markedly faster
/// (`benches/ddpg_update.rs`).
#[derive(Debug)]
pub struct FusedAdamW {
    vars: Vec<Var>,
    first_moment: Vec<Vec<f32>>,
    second_moment: Vec<Vec<f32>>,
    step_t: i32,
    params: ParamsAdamW,
}

impl FusedAdamW {
    /// An optimizer over `vars` with zero moments.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidParameter`] for a learning rate that is not
    /// finite and positive, β outside [0, 1), ε or λ negative or not finite.
    pub fn new(vars: Vec<Var>, params: ParamsAdamW) -> Result<Self, MillPlanError> {
        let bad = |name: &str, value: f64, reason: &str| {
            Err(MillPlanError::InvalidParameter {
                name: name.to_string(),
                value,
                reason: reason.to_string(),
            })
        };
        if !(params.lr.is_finite() && params.lr > 0.0) {
            return bad(
                "AdamW learning rate",
                params.lr,
                "must be finite and positive",
            );
        }
        for (name, b) in [("AdamW beta1", params.beta1), ("AdamW beta2", params.beta2)] {
            if !(0.0..1.0).contains(&b) {
                return bad(name, b, "must be in [0, 1)");
            }
        }
        for (name, x) in [
            ("AdamW eps", params.eps),
            ("AdamW weight decay", params.weight_decay),
        ] {
            if !(x.is_finite() && x >= 0.0) {
                return bad(name, x, "must be finite and ≥ 0");
            }
        }
        let first_moment = vars.iter().map(|v| vec![0f32; v.elem_count()]).collect();
        let second_moment = vars.iter().map(|v| vec![0f32; v.elem_count()]).collect();
        Ok(Self {
            vars,
            first_moment,
            second_moment,
            step_t: 0,
            params,
        })
    }

    /// One AdamW step with the gradients in `grads` (variables without a
    /// gradient are left unchanged, as in candle).
    ///
    /// # Errors
    /// [`MillPlanError::Backend`] when candle fails or the step count
    /// overflows.
    pub fn step(&mut self, grads: &GradStore) -> Result<(), MillPlanError> {
        let list: Vec<Option<Tensor>> = self
            .vars
            .iter()
            .map(|v| grads.get(v.as_tensor()).cloned())
            .collect();
        self.apply(&list)
    }

    /// One AdamW step with one gradient per variable, in the order of the
    /// variables given to [`FusedAdamW::new`] (e.g. from
    /// [`Mlp::backward`]).
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] for a wrong number of gradients or
    /// a gradient whose size differs from its variable's;
    /// [`MillPlanError::Backend`] when candle fails.
    pub fn step_gradients(&mut self, grads: &[Tensor]) -> Result<(), MillPlanError> {
        if grads.len() != self.vars.len() {
            return Err(MillPlanError::InvalidConfig {
                name: "AdamW gradients".to_string(),
                reason: format!(
                    "{} gradients for {} variables",
                    grads.len(),
                    self.vars.len()
                ),
            });
        }
        let list: Vec<Option<Tensor>> = grads.iter().cloned().map(Some).collect();
        self.apply(&list)
    }

    fn apply(&mut self, grads: &[Option<Tensor>]) -> Result<(), MillPlanError> {
        self.step_t = self
            .step_t
            .checked_add(1)
            .ok_or_else(|| MillPlanError::Backend("AdamW step count overflow".to_string()))?;
        let p = &self.params;
        let lr = p.lr as f32;
        let decay = (1.0 - p.lr * p.weight_decay) as f32;
        let (beta1, beta2) = (p.beta1 as f32, p.beta2 as f32);
        let (one_m_beta1, one_m_beta2) = ((1.0 - p.beta1) as f32, (1.0 - p.beta2) as f32);
        let scale_m = (1.0 / (1.0 - p.beta1.powi(self.step_t))) as f32;
        let scale_v = (1.0 / (1.0 - p.beta2.powi(self.step_t))) as f32;
        let eps = p.eps as f32;
        for (((var, m), v), g) in self
            .vars
            .iter()
            .zip(self.first_moment.iter_mut())
            .zip(self.second_moment.iter_mut())
            .zip(grads)
        {
            let Some(g) = g else {
                continue;
            };
            let g = flat(g)?;
            if g.len() != m.len() {
                return Err(MillPlanError::InvalidConfig {
                    name: "AdamW gradient".to_string(),
                    reason: format!("{} entries for a variable of {}", g.len(), m.len()),
                });
            }
            let mut theta = flat(var.as_tensor())?;
            for (((theta, m), v), g) in theta.iter_mut().zip(m.iter_mut()).zip(v.iter_mut()).zip(&g)
            {
                *m = *m * beta1 + g * one_m_beta1;
                *v = *v * beta2 + (g * g) * one_m_beta2;
                let m_hat = *m * scale_m;
                let v_hat = *v * scale_v;
                *theta = *theta * decay - (m_hat / (v_hat.sqrt() + eps)) * lr;
            }
            let next = Tensor::from_vec(theta, var.shape(), &Device::Cpu).map_err(backend)?;
            var.set(&next).map_err(backend)?;
        }
        Ok(())
    }

    /// Backpropagates `loss` and takes one step.
    ///
    /// # Errors
    /// As [`FusedAdamW::step`].
    pub fn backward_step(&mut self, loss: &Tensor) -> Result<(), MillPlanError> {
        let grads = loss.backward().map_err(backend)?;
        self.step(&grads)
    }
}
