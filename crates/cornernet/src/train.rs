//! Training the FDLS network with candle: MSE (seed 003 eq. 9) by AdamW
//! (Loshchilov and Hutter 2019; Adam's moments are seed 003 eqs. 10–14,
//! plus a decoupled weight decay), the learning rate cosine-decayed to a
//! tenth, dropout after each block's first layer (seed 003 Fig. 7,
//! "dropout interspersed").
//!
//! Deterministic: candle's CPU generator cannot be seeded, so the initial
//! weights, the shuffles and the dropout masks all come from
//! `kerf_rng::Rng::new(seed)`; the CPU kernels are deterministic for a
//! given thread count.

use std::time::Instant;

use candle_core::{DType, Device, Tensor, Var};
use candle_nn::{AdamW, Optimizer, ParamsAdamW};
use kerf_rng::Rng;
use serde::{Deserialize, Serialize};

use crate::corner::{INPUTS, OUTPUTS};
use crate::dataset::Sample;
use crate::error::CornerNetError;
use crate::net::{Architecture, Dense, Normalization, ResMlp};

/// The training settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TrainSettings {
    /// Passes over the training set.
    pub epochs: usize,
    /// Batch size (seed 003 uses 16 for FDLS).
    pub batch: usize,
    /// Initial learning rate (seed 003: 0.005 for FDLS).
    pub learning_rate: f64,
    /// AdamW's decoupled weight decay.
    pub weight_decay: f64,
    /// Dropout probability, in [0, 1).
    pub dropout: f64,
    /// The seed of the weights, shuffles and masks.
    pub seed: u64,
}

impl Default for TrainSettings {
    /// 60 epochs of batches of 64 at 3·10⁻³, decay 10⁻⁴, dropout 0.05.
    fn default() -> Self {
        TrainSettings {
            epochs: 60,
            batch: 64,
            learning_rate: 3e-3,
            weight_decay: 1e-4,
            dropout: 0.05,
            seed: 3,
        }
    }
}

/// What training measured.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TrainReport {
    /// MSE on the training set (normalized outputs, no dropout).
    pub train_mse: f64,
    /// MSE on the held-out set (normalized outputs).
    pub held_out_mse: f64,
    /// Optimizer steps.
    pub steps: usize,
    /// Wall time \[s\].
    pub seconds: f64,
}

/// The features and labels of samples.
pub fn rows(samples: &[Sample]) -> (Vec<[f64; INPUTS]>, Vec<[f64; OUTPUTS]>) {
    samples.iter().map(|s| (s.corner().features(), s.x)).unzip()
}

/// Mean squared error (seed 003 eq. 9) of a network on samples, in
/// normalized output units.
pub fn mse(net: &ResMlp, norm: &Normalization, samples: &[Sample]) -> f64 {
    let mut total = 0.0;
    for s in samples {
        let y = net.forward(&norm.input(&s.corner().features()));
        let t = norm.output(&s.x);
        total += y
            .iter()
            .zip(&t)
            .map(|(a, b)| f64::from(a - b).powi(2))
            .sum::<f64>();
    }
    total / (samples.len().max(1) * OUTPUTS) as f64
}

/// Trains a network of `architecture` on `train`, measuring `held_out`.
///
/// # Returns
/// The network, the normalization fitted on `train`, and the report.
///
/// # Errors
/// [`CornerNetError::InvalidParameter`] for bad settings or an empty
/// training set; [`CornerNetError::Backend`] when candle fails.
///
/// # Performance
/// epochs × ⌈n / batch⌉ steps of one candle forward and backward pass.
pub fn train(
    architecture: Architecture,
    train: &[Sample],
    held_out: &[Sample],
    settings: &TrainSettings,
) -> Result<(ResMlp, Normalization, TrainReport), CornerNetError> {
    let start = Instant::now();
    if train.is_empty() || settings.batch == 0 || !(0.0..1.0).contains(&settings.dropout) {
        return Err(CornerNetError::InvalidParameter {
            name: "training set / batch / dropout".to_string(),
            value: settings.dropout,
            reason: "need samples, batch ≥ 1 and dropout in [0, 1)".to_string(),
        });
    }
    let mut rng = Rng::new(settings.seed);
    let net = ResMlp::init(architecture, &mut rng)?;
    let (xs, ys) = rows(train);
    let norm = Normalization::fit(&xs, &ys);
    let xn: Vec<Vec<f32>> = xs.iter().map(|x| norm.input(x)).collect();
    let yn: Vec<Vec<f32>> = ys.iter().map(|y| norm.output(y)).collect();
    let dev = Device::Cpu;
    let vars = to_vars(&net, &dev)?;
    let mut opt = AdamW::new(
        vars.clone(),
        ParamsAdamW {
            lr: settings.learning_rate,
            weight_decay: settings.weight_decay,
            ..ParamsAdamW::default()
        },
    )?;
    let n = train.len();
    let per_epoch = n.div_ceil(settings.batch);
    let total = (settings.epochs * per_epoch).max(1);
    let mut order: Vec<usize> = (0..n).collect();
    let mut step = 0;
    for _ in 0..settings.epochs {
        for i in (1..n).rev() {
            let j = rng.below(i + 1).unwrap_or(i);
            order.swap(i, j);
        }
        for chunk in order.chunks(settings.batch) {
            let progress = step as f64 / total as f64;
            let decay = 0.1 + 0.9 * 0.5 * (1.0 + (std::f64::consts::PI * progress).cos());
            opt.set_learning_rate(settings.learning_rate * decay);
            let b = chunk.len();
            let x: Vec<f32> = chunk.iter().flat_map(|&i| xn[i].iter().copied()).collect();
            let y: Vec<f32> = chunk.iter().flat_map(|&i| yn[i].iter().copied()).collect();
            let x = Tensor::from_vec(x, (b, INPUTS), &dev)?;
            let y = Tensor::from_vec(y, (b, OUTPUTS), &dev)?;
            let out = forward(&vars, &architecture, &x, settings.dropout, &mut rng)?;
            let loss = out.sub(&y)?.sqr()?.mean_all()?;
            opt.backward_step(&loss)?;
            step += 1;
        }
    }
    let trained = from_vars(&vars, architecture)?;
    let report = TrainReport {
        train_mse: mse(&trained, &norm, train),
        held_out_mse: mse(&trained, &norm, held_out),
        steps: step,
        seconds: start.elapsed().as_secs_f64(),
    };
    Ok((trained, norm, report))
}

/// The network's layers as candle variables, weight then bias per layer.
fn to_vars(net: &ResMlp, dev: &Device) -> Result<Vec<Var>, CornerNetError> {
    let mut vars = Vec::with_capacity(2 * net.layers.len());
    for l in &net.layers {
        let out = l.bias.len();
        vars.push(Var::from_slice(&l.weight, (out, l.inputs), dev)?);
        vars.push(Var::from_slice(&l.bias, out, dev)?);
    }
    Ok(vars)
}

/// The candle variables back as a plain network.
fn from_vars(vars: &[Var], architecture: Architecture) -> Result<ResMlp, CornerNetError> {
    let mut layers = Vec::with_capacity(vars.len() / 2);
    for pair in vars.chunks(2) {
        let w = pair[0].as_tensor();
        layers.push(Dense {
            weight: w.flatten_all()?.to_vec1::<f32>()?,
            bias: pair[1].as_tensor().to_vec1::<f32>()?,
            inputs: w.dim(1)?,
        });
    }
    Ok(ResMlp {
        architecture,
        layers,
    })
}

/// x Wᵀ + b.
fn linear(x: &Tensor, w: &Var, b: &Var) -> Result<Tensor, CornerNetError> {
    Ok(x.matmul(&w.as_tensor().t()?)?
        .broadcast_add(b.as_tensor())?)
}

/// The training forward pass ([`crate::net`]'s, with dropout masks drawn
/// from `rng` and scaled by 1 / (1 − p)).
fn forward(
    vars: &[Var],
    architecture: &Architecture,
    x: &Tensor,
    dropout: f64,
    rng: &mut Rng,
) -> Result<Tensor, CornerNetError> {
    let n = vars.len();
    let b = x.dim(0)?;
    let w = architecture.width;
    let mut h = linear(x, &vars[0], &vars[1])?.relu()?;
    for k in (2..n - 2).step_by(4) {
        let mut a = linear(&h, &vars[k], &vars[k + 1])?.relu()?;
        if dropout > 0.0 {
            let keep = (1.0 / (1.0 - dropout)) as f32;
            let mask: Vec<f32> = (0..b * w)
                .map(|_| if rng.next_f64() < dropout { 0.0 } else { keep })
                .collect();
            a = a.mul(&Tensor::from_vec(mask, (b, w), x.device())?.to_dtype(DType::F32)?)?;
        }
        h = (h + linear(&a, &vars[k + 2], &vars[k + 3])?)?.relu()?;
    }
    linear(&h, &vars[n - 2], &vars[n - 1])
}
