//! The DRLS model file: the FDLS weights as SafeTensors
//! (`name.safetensors`, one F32 tensor `<layer>.weight` (out × in) and
//! `<layer>.bias` per layer) and a JSON sidecar (`name.json`) with the
//! settings: architecture, normalization, the dataset's distribution, seed
//! and swarm, the training settings and what they measured.
//!
//! Loading refuses, naming the reason: another format tag, sizes other
//! than this crate's inputs and outputs, a tensor whose shape differs from
//! the sidecar's architecture (or missing), normalization vectors of the
//! wrong length, and a distribution other than the one the caller expects.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use candle_core::{DType, Device, Tensor};
use serde::{Deserialize, Serialize};

use crate::corner::{INPUTS, OUTPUTS};
use crate::dataset::Distribution;
use crate::error::CornerNetError;
use crate::net::{Architecture, Dense, Normalization, ResMlp};
use crate::train::{TrainReport, TrainSettings};
use kerf_toolpath::NurbsSettings;

/// The sidecar's format tag.
pub const FORMAT: &str = "kerf_cornernet DRLS v1";

/// The sidecar.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Sidecar {
    /// [`FORMAT`].
    pub format: String,
    /// FDLS's sizes.
    pub architecture: Architecture,
    /// Its input and output z-scores.
    pub normalization: Normalization,
    /// The corners it was trained for.
    pub distribution: Distribution,
    /// The swarm that labelled them (and the fallback's).
    pub swarm: NurbsSettings,
    /// The dataset's seed.
    pub dataset_seed: u64,
    /// Its size (training and held-out).
    pub dataset_size: usize,
    /// The training settings.
    pub train: TrainSettings,
    /// What training measured.
    pub report: TrainReport,
}

/// A trained FDLS network and its sidecar.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    /// The network.
    pub net: ResMlp,
    /// Its settings.
    pub sidecar: Sidecar,
}

/// The sidecar's path next to a weights file.
pub fn sidecar_path(weights: &Path) -> PathBuf {
    weights.with_extension("json")
}

impl Model {
    /// Writes the weights to `weights` and the sidecar next to it.
    ///
    /// # Errors
    /// [`CornerNetError::Io`] or [`CornerNetError::Backend`] when a file
    /// cannot be written.
    pub fn save(&self, weights: &Path) -> Result<(), CornerNetError> {
        let dev = Device::Cpu;
        let mut map = HashMap::new();
        for ((name, out, inp), l) in self
            .net
            .architecture
            .shapes()
            .into_iter()
            .zip(&self.net.layers)
        {
            map.insert(
                format!("{name}.weight"),
                Tensor::from_slice(&l.weight, (out, inp), &dev)?,
            );
            map.insert(
                format!("{name}.bias"),
                Tensor::from_slice(&l.bias, out, &dev)?,
            );
        }
        candle_core::safetensors::save(&map, weights)?;
        let side = sidecar_path(weights);
        let text = serde_json::to_string_pretty(&self.sidecar).map_err(|e| CornerNetError::Io {
            path: side.display().to_string(),
            reason: e.to_string(),
        })?;
        std::fs::write(&side, text).map_err(|e| CornerNetError::Io {
            path: side.display().to_string(),
            reason: e.to_string(),
        })
    }

    /// Reads a model written by [`Self::save`].
    ///
    /// # Arguments
    /// * `expected` — the distribution the caller will predict for; a file
    ///   trained for another is refused.
    ///
    /// # Errors
    /// [`CornerNetError::Io`] when a file cannot be read;
    /// [`CornerNetError::Mismatch`] for every refusal of the module
    /// documentation.
    pub fn load(weights: &Path, expected: &Distribution) -> Result<Self, CornerNetError> {
        let side = sidecar_path(weights);
        let refuse = |reason: String| CornerNetError::Mismatch {
            path: weights.display().to_string(),
            reason,
        };
        let text = std::fs::read_to_string(&side).map_err(|e| CornerNetError::Io {
            path: side.display().to_string(),
            reason: e.to_string(),
        })?;
        let sidecar: Sidecar = serde_json::from_str(&text)
            .map_err(|e| refuse(format!("sidecar {}: {e}", side.display())))?;
        if sidecar.format != FORMAT {
            return Err(refuse(format!(
                "format {:?}, expected {FORMAT:?}",
                sidecar.format
            )));
        }
        let a = sidecar.architecture;
        a.check().map_err(|e| refuse(e.to_string()))?;
        if a.inputs != INPUTS || a.outputs != OUTPUTS {
            return Err(refuse(format!(
                "{} inputs and {} outputs, this crate's FDLS has {INPUTS} and {OUTPUTS}",
                a.inputs, a.outputs
            )));
        }
        let n = &sidecar.normalization;
        if n.input_mean.len() != INPUTS
            || n.input_std.len() != INPUTS
            || n.output_mean.len() != OUTPUTS
            || n.output_std.len() != OUTPUTS
        {
            return Err(refuse(
                "normalization vectors of the wrong length".to_string(),
            ));
        }
        if sidecar.distribution != *expected {
            return Err(refuse(format!(
                "trained for {:?}, expected {:?}",
                sidecar.distribution, expected
            )));
        }
        let map = candle_core::safetensors::load(weights, &Device::Cpu)
            .map_err(|e| refuse(format!("not a readable safetensors file: {e}")))?;
        let mut layers = Vec::new();
        for (name, out, inp) in a.shapes() {
            let weight = tensor(&map, &format!("{name}.weight"), &[out, inp]).map_err(&refuse)?;
            let bias = tensor(&map, &format!("{name}.bias"), &[out]).map_err(&refuse)?;
            layers.push(Dense {
                weight,
                bias,
                inputs: inp,
            });
        }
        if map.len() != 2 * layers.len() {
            return Err(refuse(format!(
                "{} tensors, the sidecar's architecture has {}",
                map.len(),
                2 * layers.len()
            )));
        }
        Ok(Model {
            net: ResMlp {
                architecture: a,
                layers,
            },
            sidecar,
        })
    }
}

/// One F32 tensor of the expected shape, flattened.
fn tensor(map: &HashMap<String, Tensor>, name: &str, shape: &[usize]) -> Result<Vec<f32>, String> {
    let t = map
        .get(name)
        .ok_or_else(|| format!("tensor {name} missing"))?;
    if t.dims() != shape {
        return Err(format!(
            "tensor {name} has shape {:?}, the sidecar's architecture needs {shape:?}",
            t.dims()
        ));
    }
    if t.dtype() != DType::F32 {
        return Err(format!("tensor {name} is {:?}, not F32", t.dtype()));
    }
    t.flatten_all()
        .and_then(|f| f.to_vec1::<f32>())
        .map_err(|e| format!("tensor {name}: {e}"))
}
