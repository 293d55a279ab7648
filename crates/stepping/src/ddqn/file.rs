//! The Q-network file: safetensors with the architecture in its
//! `__metadata__` header.
//!
//! # Layout
//! * tensors, f32: `l{k}.weight` (shape out × in) and `l{k}.bias` (shape
//!   out) for k = 0, 1, 2 from the input (shapes of
//!   [`Architecture::shapes`]);
//! * `__metadata__` (string → string): `format` = [`NETWORK_FORMAT`],
//!   `architecture` (Table 2 number), `hidden` (N), `activation` ("relu" or
//!   "tanh"), `inputs`, `outputs`, and whatever the writer adds (the
//!   training run: density, seed, learning rate, …; [`read`] returns them).
//!
//! The `safetensors` crate takes the metadata as a `HashMap`, so the order
//! of the header's keys (not the tensors or their values) can differ
//! between two writes of the same network.
//!
//! [`read`] refuses, with [`StepError::Network`] and the reason, a file that
//! is missing, not a regular file, larger than [`MAX_NETWORK_BYTES`], not
//! valid safetensors (truncated, bad header), of another format, whose
//! architecture is absent, outside 1..=12 or disagrees with its `hidden` /
//! `activation`, with a tensor missing, extra, not f32 or of the wrong
//! shape, or with a non-finite value. It never panics.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use safetensors::{tensor::TensorView, Dtype, SafeTensors};

use crate::error::StepError;

use super::net::{Architecture, Layer, Weights};

/// The `format` value this version writes and reads.
pub const NETWORK_FORMAT: &str = "kerf_stepping ddqn q-network v1";

/// Largest network file read (1 MiB; architecture 1 is about 3 KB).
pub const MAX_NETWORK_BYTES: u64 = 1 << 20;

/// Metadata keys the file format owns (a writer's `info` cannot override
/// them).
const RESERVED: [&str; 6] = [
    "format",
    "architecture",
    "hidden",
    "activation",
    "inputs",
    "outputs",
];

fn refuse(path: &str, reason: impl std::fmt::Display) -> StepError {
    StepError::Network {
        reason: format!("{path}: {reason}"),
    }
}

/// The file's bytes for `weights` with the extra metadata `info`.
///
/// # Errors
/// [`StepError::Network`] when an `info` key is reserved or safetensors
/// fails.
pub fn to_bytes(weights: &Weights, info: &BTreeMap<String, String>) -> Result<Vec<u8>, StepError> {
    let arch = weights.architecture();
    let mut meta: HashMap<String, String> = HashMap::new();
    for (k, v) in info {
        if RESERVED.contains(&k.as_str()) {
            return Err(StepError::Network {
                reason: format!("metadata key \"{k}\" is reserved by the file format"),
            });
        }
        meta.insert(k.clone(), v.clone());
    }
    meta.insert("format".into(), NETWORK_FORMAT.into());
    meta.insert("architecture".into(), arch.number().to_string());
    meta.insert("hidden".into(), arch.hidden().to_string());
    meta.insert("activation".into(), arch.activation().name().into());
    meta.insert("inputs".into(), "v/V,a/A,d/d_max".into());
    meta.insert("outputs".into(), "accelerate,keep,decelerate".into());
    let bytes: Vec<(String, Vec<usize>, Vec<u8>)> = weights
        .layers()
        .iter()
        .zip(arch.shapes())
        .enumerate()
        .flat_map(|(k, (layer, (out, inp)))| {
            [
                (
                    format!("l{k}.weight"),
                    vec![out, inp],
                    le_bytes(&layer.weight),
                ),
                (format!("l{k}.bias"), vec![out], le_bytes(&layer.bias)),
            ]
        })
        .collect();
    let mut views = Vec::with_capacity(bytes.len());
    for (name, shape, data) in &bytes {
        let view =
            TensorView::new(Dtype::F32, shape.clone(), data).map_err(|e| StepError::Network {
                reason: format!("tensor {name}: {e}"),
            })?;
        views.push((name.clone(), view));
    }
    safetensors::serialize(views, Some(meta)).map_err(|e| StepError::Network {
        reason: format!("safetensors: {e}"),
    })
}

/// Writes `weights` and `info` to `path` ([`to_bytes`]).
///
/// # Errors
/// [`StepError::Network`] naming the path when it cannot be written.
pub fn write(
    path: &Path,
    weights: &Weights,
    info: &BTreeMap<String, String>,
) -> Result<(), StepError> {
    let bytes = to_bytes(weights, info)?;
    std::fs::write(path, bytes).map_err(|e| refuse(&path.display().to_string(), e))
}

/// Reads a network file ([`from_bytes`]).
///
/// # Errors
/// [`StepError::Network`] naming the path (module documentation).
pub fn read(path: &Path) -> Result<(Weights, BTreeMap<String, String>), StepError> {
    let name = path.display().to_string();
    let meta = std::fs::metadata(path).map_err(|e| refuse(&name, e))?;
    if !meta.is_file() {
        return Err(refuse(&name, "not a regular file"));
    }
    if meta.len() > MAX_NETWORK_BYTES {
        return Err(refuse(
            &name,
            format!(
                "{} bytes, more than the {MAX_NETWORK_BYTES} a network file may have",
                meta.len()
            ),
        ));
    }
    let bytes = std::fs::read(path).map_err(|e| refuse(&name, e))?;
    from_bytes(&bytes).map_err(|e| match e {
        StepError::Network { reason } => refuse(&name, reason),
        other => other,
    })
}

/// Parses and validates a network file's bytes.
///
/// # Returns
/// The weights and the writer's extra metadata (reserved keys removed).
///
/// # Errors
/// [`StepError::Network`] (module documentation).
pub fn from_bytes(bytes: &[u8]) -> Result<(Weights, BTreeMap<String, String>), StepError> {
    let net_err = |reason: String| StepError::Network { reason };
    let (_, header) = SafeTensors::read_metadata(bytes)
        .map_err(|e| net_err(format!("not a valid safetensors file: {e}")))?;
    let meta: BTreeMap<String, String> = header
        .metadata()
        .as_ref()
        .map(|m| m.iter().map(|(k, v)| (k.clone(), v.clone())).collect())
        .unwrap_or_default();
    match meta.get("format") {
        Some(f) if f == NETWORK_FORMAT => {}
        Some(f) => {
            return Err(net_err(format!(
                "format \"{f}\", this version reads \"{NETWORK_FORMAT}\""
            )))
        }
        None => {
            return Err(net_err(format!(
                "no \"format\" in the metadata (not a {NETWORK_FORMAT} file)"
            )))
        }
    }
    let number = meta
        .get("architecture")
        .ok_or_else(|| net_err("no \"architecture\" in the metadata".to_string()))?;
    let arch = number
        .parse::<usize>()
        .map_err(|_| net_err(format!("architecture \"{number}\" is not a number")))
        .and_then(Architecture::new)?;
    if let Some(h) = meta.get("hidden") {
        if h != &arch.hidden().to_string() {
            return Err(net_err(format!(
                "hidden = {h} disagrees with architecture {arch}"
            )));
        }
    }
    if let Some(a) = meta.get("activation") {
        if a != arch.activation().name() {
            return Err(net_err(format!(
                "activation = {a} disagrees with architecture {arch}"
            )));
        }
    }
    let st = SafeTensors::deserialize(bytes)
        .map_err(|e| net_err(format!("not a valid safetensors file: {e}")))?;
    let shapes = arch.shapes();
    let expected: Vec<String> = (0..shapes.len())
        .flat_map(|k| [format!("l{k}.weight"), format!("l{k}.bias")])
        .collect();
    for name in st.names() {
        if !expected.iter().any(|e| e == name) {
            return Err(net_err(format!(
                "unexpected tensor \"{name}\" for architecture {arch}"
            )));
        }
    }
    let mut layers = Vec::with_capacity(shapes.len());
    for (k, &(out, inp)) in shapes.iter().enumerate() {
        let weight = tensor(&st, &format!("l{k}.weight"), &[out, inp], arch)?;
        let bias = tensor(&st, &format!("l{k}.bias"), &[out], arch)?;
        layers.push(Layer { weight, bias });
    }
    let weights = Weights::from_layers(arch, layers)?;
    let info = meta
        .into_iter()
        .filter(|(k, _)| !RESERVED.contains(&k.as_str()))
        .collect();
    Ok((weights, info))
}

/// Tensor `name` as f32 values, checked for presence, dtype and shape.
fn tensor(
    st: &SafeTensors<'_>,
    name: &str,
    shape: &[usize],
    arch: Architecture,
) -> Result<Vec<f32>, StepError> {
    let view = st.tensor(name).map_err(|_| StepError::Network {
        reason: format!("tensor \"{name}\" missing (architecture {arch})"),
    })?;
    if view.dtype() != Dtype::F32 {
        return Err(StepError::Network {
            reason: format!("tensor \"{name}\" is {:?}, expected F32", view.dtype()),
        });
    }
    if view.shape() != shape {
        return Err(StepError::Network {
            reason: format!(
                "tensor \"{name}\" has shape {:?}, architecture {arch} needs {shape:?}",
                view.shape()
            ),
        });
    }
    Ok(view
        .data()
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect())
}

fn le_bytes(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}
