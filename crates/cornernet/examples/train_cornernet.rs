//! Makes the DRLS dataset with the NURBS corner's swarm, chooses FDLS's
//! depth on a held-out split, trains, and writes
//! `crates/cornernet/weights/drls.safetensors` and `drls.json`.
//!
//! ```text
//! cargo run --release -p kerf_cornernet --example train_cornernet [-- SAMPLES EPOCHS]
//! ```
//!
//! Defaults: 8000 corners (15 % held out) from [`Distribution::default`],
//! seed 30_003, swarm [`NurbsSettings::default`], width 64, depths 4, 8
//! and 16 tried for EPOCHS (default 200) epochs each. The dataset is also
//! written as JSON to the system's temporary directory.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;
use std::time::Instant;

use kerf_cornernet::file::FORMAT;
use kerf_cornernet::train::train;
use kerf_cornernet::{Architecture, Dataset, Distribution, Model, Sidecar, TrainSettings};
use kerf_toolpath::NurbsSettings;

/// The dataset's seed.
const SEED: u64 = 30_003;
/// The held-out share.
const HELD_OUT: f64 = 0.15;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let samples: usize = args.get(1).map(|s| s.parse()).transpose()?.unwrap_or(8000);
    let epochs: usize = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(200);
    let start = Instant::now();
    let swarm = NurbsSettings::default();
    let distribution = Distribution::default();

    let t = Instant::now();
    let data = Dataset::generate(distribution, &swarm, SEED, samples, 2)?;
    let gen = t.elapsed().as_secs_f64();
    println!(
        "dataset: {samples} corners in {gen:.1} s on 2 threads = {:.2} ms of CPU per swarm corner",
        1e3 * 2.0 * gen / samples as f64
    );
    let data_path = std::env::temp_dir().join("kerf_cornernet_dataset.json");
    data.save(&data_path)?;
    println!("dataset written to {}", data_path.display());
    let (tr, ho) = data.split(HELD_OUT);
    println!("split: {} training, {} held out", tr.len(), ho.len());

    let settings = TrainSettings {
        epochs,
        ..TrainSettings::default()
    };
    println!("| layers | width | train MSE | held-out MSE | steps | time [s] |");
    println!("|---|---|---|---|---|---|");
    let mut best: Option<(f64, Model)> = None;
    for layers in [4, 8, 16] {
        let arch = Architecture::fdls(64, layers);
        let (net, normalization, report) = train(arch, tr, ho, &settings)?;
        println!(
            "| {layers} | 64 | {:.5} | {:.5} | {} | {:.1} |",
            report.train_mse, report.held_out_mse, report.steps, report.seconds
        );
        // A deeper net must beat the shallower by 5 % to be kept.
        let better = best
            .as_ref()
            .is_none_or(|(b, _)| report.held_out_mse < 0.95 * b);
        if better {
            let sidecar = Sidecar {
                format: FORMAT.to_string(),
                architecture: arch,
                normalization,
                distribution,
                swarm,
                dataset_seed: SEED,
                dataset_size: samples,
                train: settings,
                report,
            };
            best = Some((report.held_out_mse, Model { net, sidecar }));
        }
    }
    let (mse, model) = best.ok_or("no network trained")?;
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("weights");
    std::fs::create_dir_all(&dir)?;
    let path = dir.join("drls.safetensors");
    model.save(&path)?;
    println!(
        "kept {} layers (held-out MSE {mse:.5}); wrote {} and its .json; total {:.1} s",
        model.net.architecture.layers,
        path.display(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
