//! Writes the figures of `kerf_toolpath::pipeline_plots` (seed 000 Fig. 5, seed 003 Figs. 12–14)
//! for the W-shape, dress, torch and dense rosette programs of `crates/gcode/data/programs/`: each
//! G01 program smoothed within δ = 0.1 mm, sampled every 10 µm, its feed planned under seed 003's Table 1
//! (A_t 800 mm/s², J_t 20 000 mm/s³) and sampled at T = 2 ms. Prints each path's per-corner
//! figures (seed 003 Table 2's kind; their extremes for more than 60 corners), the largest value
//! of each plotted quantity, and where the SVG files went.
//!
//! ```sh
//! cargo run --release -p kerf_toolpath --example plots [-- OUTPUT_DIR]   # default target/plots
//! ```
#![allow(clippy::unwrap_used, clippy::expect_used)] // an example reports failures by panicking

use std::path::PathBuf;

#[allow(dead_code)] // the tests' shared data; this example uses some of it
#[path = "../tests/support/mod.rs"]
mod support;

use kerf_toolpath::plot::pipeline_charts;
use kerf_toolpath::{
    corner_metrics, plan_feed, sample_path, smooth_polyline, CurvatureLimits, FeedLimits,
};

fn main() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let out_dir = std::env::args()
        .nth(1)
        .map_or_else(|| root.join("target/plots"), PathBuf::from);
    let limits = FeedLimits {
        curvature: CurvatureLimits::seed_003_table_1(),
        tangential_acceleration: 0.8,
        tangential_jerk: 20.0,
    };
    let period = limits.curvature.interpolation_period;
    for name in ["w_shape", "dress", "torch", "rosette_dense_g64"] {
        let polyline = support::program_polyline(name);
        let path = smooth_polyline(&polyline, 1e-4).unwrap();
        let samples = sample_path(&path, 1e-5);
        let plan = plan_feed(&samples, &limits).unwrap();
        let feed = plan.sample(period);
        let start = std::time::Instant::now();
        let charts = pipeline_charts(&path, &samples, &feed, &limits, period).unwrap();
        let plots: Vec<(String, String)> = charts
            .iter()
            .map(|(file, chart)| (file.clone(), chart.render().unwrap()))
            .collect();
        let took = start.elapsed().as_secs_f64();
        let dir = out_dir.join(name);
        std::fs::create_dir_all(&dir).unwrap();
        let mut bytes = 0;
        for (file, svg) in &plots {
            bytes += svg.len();
            std::fs::write(dir.join(file), svg).unwrap();
        }
        println!(
            "{name}: {} corners, T = {:.3} s, {} plots ({:.0} kB) in {} ({:.0} ms)",
            path.corners().count(),
            plan.time,
            plots.len(),
            bytes as f64 / 1e3,
            dir.display(),
            took * 1e3
        );
        // The largest |y| of every plotted series against its chart's limits.
        for (file, chart) in charts.iter().skip(1) {
            let series: Vec<String> = chart
                .series
                .iter()
                .map(|x| {
                    let max = x.points.iter().map(|p| p[1].abs()).fold(0.0, f64::max);
                    format!("{} {max:.3}", x.name)
                })
                .collect();
            let limits: Vec<String> = chart
                .limits
                .iter()
                .map(|l| format!("{} {}", l.name, l.y))
                .collect();
            println!(
                "  {file}: max |y|: {}; limits: {} ({})",
                series.join(", "),
                limits.join(", "),
                chart.y_label
            );
        }
        let corners = corner_metrics(&path);
        if corners.len() > 60 {
            let error = corners
                .iter()
                .map(|c| c.approximation_error)
                .fold(0.0, f64::max);
            let kappa = corners.iter().map(|c| c.max_curvature).fold(0.0, f64::max);
            println!(
                "  corners: largest approximation error {:.4} mm, largest curvature {:.3} 1/mm",
                error * 1e3,
                kappa * 1e-3
            );
            continue;
        }
        println!(
            "| corner | vertex (mm) | θ (°) | approximation error (mm) | κ_max (1/mm) | bound by |"
        );
        println!("|---:|---|---:|---:|---:|---|");
        for (k, c) in corners.iter().enumerate() {
            println!(
                "| {k} | ({:.3}, {:.3}) | {:.2} | {:.4} | {:.3} | {:?} |",
                c.vertex[0] * 1e3,
                c.vertex[1] * 1e3,
                c.turn.to_degrees(),
                c.approximation_error * 1e3,
                c.max_curvature * 1e-3,
                c.binding
            );
        }
    }
}
