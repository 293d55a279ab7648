//! Adam (Kingma & Ba, "Adam: a method for stochastic optimization", ICLR
//! 2015, Algorithm 1) on the plain master copy of the Q-network's weights.
//!
//! m ← β₁ m + (1 − β₁) g, v ← β₂ v + (1 − β₂) g²,
//! m̂ = m / (1 − β₁ᵗ), v̂ = v / (1 − β₂ᵗ), θ ← θ − lr m̂ / (√v̂ + ε),
//!
//! with β₁ = 0.9, β₂ = 0.999, ε = 10⁻⁸: the defaults of MATLAB's
//! `rlOptimizerOptions` ("adam": GradientDecayFactor 0.9,
//! SquaredGradientDecayFactor 0.999, Epsilon 1e-8), which the paper used.
//! MATLAB's default L2 regularization (1e-4) is not applied (the seed does
//! not mention it).
//!
//! Why not `candle_nn::AdamW`: it runs about a dozen tensor operations per
//! variable, each allocating; for six variables of at most 24 × 24 values
//! the operation overhead dominates an update. This one is one loop per
//! variable over the flat weights that also serve the agent's greedy
//! action ([`Weights::q_values`]) during training, as kerf_millplan's fused
//! AdamW (`crates/millplan/src/adamw.rs`) does for DDPG.

use crate::error::StepError;

use super::net::Weights;

/// Adam's state: the moments of every parameter and the step count.
#[derive(Debug, Clone)]
pub struct Adam {
    lr: f32,
    beta1: f32,
    beta2: f32,
    eps: f32,
    t: i32,
    /// Per layer: (m, v) of the weight, then of the bias.
    moments: Vec<[(Vec<f32>, Vec<f32>); 2]>,
}

impl Adam {
    /// Zero moments for `weights`, learning rate `lr`.
    pub fn new(weights: &Weights, lr: f64) -> Self {
        let moments = weights
            .layers()
            .iter()
            .map(|l| {
                [
                    (vec![0.0; l.weight.len()], vec![0.0; l.weight.len()]),
                    (vec![0.0; l.bias.len()], vec![0.0; l.bias.len()]),
                ]
            })
            .collect();
        Self {
            lr: lr as f32,
            beta1: 0.9,
            beta2: 0.999,
            eps: 1e-8,
            t: 0,
            moments,
        }
    }

    /// One step with gradients `grads` (weight, bias per layer, from the
    /// input, each flat in the layout of [`Weights`]).
    ///
    /// # Errors
    /// [`StepError::Network`] for a gradient of the wrong count or length.
    pub fn step(&mut self, weights: &mut Weights, grads: &[Vec<f32>]) -> Result<(), StepError> {
        if grads.len() != 2 * self.moments.len() {
            return Err(StepError::Network {
                reason: format!(
                    "{} gradients for {} variables",
                    grads.len(),
                    2 * self.moments.len()
                ),
            });
        }
        self.t = self.t.saturating_add(1);
        let c1 = 1.0 / (1.0 - self.beta1.powi(self.t));
        let c2 = 1.0 / (1.0 - self.beta2.powi(self.t));
        let (b1, b2, lr, eps) = (self.beta1, self.beta2, self.lr, self.eps);
        for (k, (layer, moments)) in weights
            .layers_mut()
            .iter_mut()
            .zip(self.moments.iter_mut())
            .enumerate()
        {
            let params = [&mut layer.weight, &mut layer.bias];
            for (j, (theta, (m, v))) in params.into_iter().zip(moments.iter_mut()).enumerate() {
                let g = &grads[2 * k + j];
                if g.len() != theta.len() {
                    return Err(StepError::Network {
                        reason: format!(
                            "gradient of {} values for a variable of {}",
                            g.len(),
                            theta.len()
                        ),
                    });
                }
                for (((th, m), v), g) in theta.iter_mut().zip(m.iter_mut()).zip(v.iter_mut()).zip(g)
                {
                    *m = b1 * *m + (1.0 - b1) * g;
                    *v = b2 * *v + (1.0 - b2) * g * g;
                    *th -= lr * (*m * c1) / ((*v * c2).sqrt() + eps);
                }
            }
        }
        Ok(())
    }
}
