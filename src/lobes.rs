//! `kerf lobes`: the stability-lobe diagram and the feed × speed chatter map of one milling
//! state (issue 4 section 6, seed 004 Fig. 4 and Fig. 7).
//!
//! ```sh
//! kerf lobes --segment 50 --g 0 [--cell FILE] [--rpm MIN:MAX:COUNT] [--max-depth M]
//!            [--feed MIN:MAX:COUNT] [--nominal-feed F] [--model state-dependent|constant]
//!            [--steps m] [--out DIR] [--format svg|png]
//! ```
//!
//! For path segment N and redundancy angle g of the cell (default `urdf/irb6660_milling.yaml`,
//! [`kerf_mill::MillCell::evaluate`]: IK, condition number, pose-dependent 2-DOF tool-tip
//! dynamics), it writes into `--out`:
//!
//! * `lobes_seg{N}_g{G}.svg` — critical axial depth a_lim \[mm\] against spindle speed
//!   \[rpm\]: the constant-delay lobes ([`kerf_chatter::stability_lobes`], Insperger & Stépán
//!   2004), the cell's axial depth as a horizontal line, and (state-dependent model) the
//!   state-dependent critical depth at the nominal feed
//!   ([`kerf_chatter::lobes::state_dependent_critical_depth`], seed 004 eq. 1-8);
//! * `feed_map_seg{N}_g{G}.svg` — |μ|max at the cell's depth over feed \[m/s\] × spindle
//!   speed \[rpm\] ([`kerf_chatter::indicator_map`]) as a heatmap with the |μ| = 1 boundary
//!   (marching squares) and a colour bar, like seed 004 Fig. 7;
//!
//! and prints a table ([`table`]), one row per speed: a_lim (constant and state-dependent),
//! |μ| at the cell's depth for the lowest, middle and highest grid feed, and the feed lower
//! bound ([`kerf_chatter::feed_lower_bound`]). The chart is
//! [`kerf_chatter::lobe_map::LobeMap`]; this module parses, calls, prints and draws
//! ([`crate::plots::lobes`], [`crate::plots::feed_map`]). Units: SI, except rpm (named so) and the depths of the table and
//! plots, in mm (named so). Every failure — bad segment, g outside the range or unreachable,
//! bad ranges, a chatter computation that fails — exits with code 2 and a message.
//!
//! `G` in the file names is g formatted with Rust's shortest round-trip `f64` display
//! (`0`, `-0.5`, `1.25`). PNG needs plotters' bitmap backend, which would pull crates outside
//! the workspace's dependency set: `--format png` is refused with a clear message.

mod grid;
pub mod table;

use std::{path::PathBuf, time::Instant};

use clap::{Args, ValueEnum};
use kerf_chatter::{
    lobe_map::{default_nominal_feed, depth_search},
    DelayModel, LobeGrid, LobeMap,
};
use kerf_mill::{CellState, MillCell};

pub use grid::Grid;
pub use table::table;

use crate::plots;

/// Default number of spindle speeds.
const DEFAULT_SPEEDS: usize = 100;

/// Default number of feeds.
const DEFAULT_FEEDS: usize = 25;

/// Delay model of the chatter indicator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ModelArg {
    /// Seed 004's state-dependent delays (equilibrium + linearization).
    StateDependent,
    /// The classic constant-delay model (feed-independent).
    Constant,
}

/// Output format of the plots.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// Scalable vector graphics (built in).
    Svg,
    /// Portable network graphics (not built in: refused).
    Png,
}

/// Arguments of `kerf lobes`.
#[derive(Args, Debug)]
pub struct LobesArgs {
    /// Milling cell YAML (default: the shipped urdf/irb6660_milling.yaml).
    #[arg(long)]
    cell: Option<PathBuf>,
    /// Path segment index (0-based).
    #[arg(long)]
    segment: usize,
    /// Redundancy angle g [rad].
    #[arg(long, allow_hyphen_values = true)]
    g: f64,
    /// Spindle speeds MIN:MAX:COUNT [rpm] (default: the cell's range, 100 speeds).
    #[arg(long)]
    rpm: Option<String>,
    /// Largest axial depth searched [m] (default 0.02 = 20 mm).
    #[arg(long, default_value_t = 0.02, allow_hyphen_values = true)]
    max_depth: f64,
    /// Feeds MIN:MAX:COUNT [m/s] of the map (default: the cell's range, 25 feeds; 0 allowed).
    #[arg(long)]
    feed: Option<String>,
    /// Feed of the state-dependent lobe [m/s] (default: seed 004's f0 = 0.04 m/s if in the
    /// cell's feed range, else the range's midpoint).
    #[arg(long, allow_hyphen_values = true)]
    nominal_feed: Option<f64>,
    /// Delay model (default: the cell's `chatter.model`).
    #[arg(long, value_enum)]
    model: Option<ModelArg>,
    /// Sub-intervals m of the discretization (default: the cell's `chatter.steps`).
    #[arg(long)]
    steps: Option<usize>,
    /// Output directory (created if missing).
    #[arg(long, default_value = ".")]
    out: PathBuf,
    /// Plot format.
    #[arg(long, value_enum, default_value_t = Format::Svg)]
    format: Format,
}

/// Everything `kerf lobes` computes (the plots and the table are drawn from it).
#[derive(Debug, Clone)]
pub struct LobesReport {
    /// Path segment.
    pub segment: usize,
    /// Redundancy angle g \[rad\].
    pub g: f64,
    /// The cell's state at (segment, g).
    pub state: CellState,
    /// The lobes and the feed map of the state ([`LobeMap::compute`]).
    pub chart: LobeMap,
    /// Wall-clock time of the computation \[s\].
    pub seconds: f64,
}

/// Runs the computation of `kerf lobes` (no files, no printing): loads the cell, checks the
/// arguments, evaluates the state and calls [`LobeMap::compute`].
///
/// # Errors
/// A message: the cell's error (file, segment index, g range, joint limit with the joint and
/// its excess), a bad grid or option, or a chatter error with the speed it occurred at.
pub fn compute(a: &LobesArgs) -> Result<LobesReport, String> {
    let start = Instant::now();
    let cell = match &a.cell {
        Some(p) => MillCell::load(p),
        None => MillCell::default_cell(),
    }
    .map_err(|e| e.to_string())?;
    let n_segments = cell.path().segments().len();
    if a.segment >= n_segments {
        return Err(format!(
            "--segment {}: the path has {n_segments} segments (0..={})",
            a.segment,
            n_segments.saturating_sub(1)
        ));
    }
    if !a.g.is_finite() {
        return Err(format!("--g {}: must be finite", a.g));
    }
    let state = cell
        .evaluate(a.segment, a.g, None)
        .map_err(|e| format!("segment {}, g = {} rad: {e}", a.segment, a.g))?;
    let limits = *cell.state_limits();
    let rpm_grid = match &a.rpm {
        Some(t) => Grid::parse("rpm", t, 0.0, true)?,
        None => Grid::new(
            "rpm",
            limits.spindle_rpm[0],
            limits.spindle_rpm[1],
            DEFAULT_SPEEDS,
            0.0,
            true,
        )?,
    };
    let feed_grid = match &a.feed {
        Some(t) => Grid::parse("feed", t, 0.0, false)?,
        None => Grid::new(
            "feed",
            limits.feed[0],
            limits.feed[1],
            DEFAULT_FEEDS,
            0.0,
            false,
        )?,
    };
    if !(a.max_depth.is_finite() && a.max_depth > 0.0) {
        return Err(format!(
            "--max-depth {}: must be finite and > 0 [m]",
            a.max_depth
        ));
    }
    let nominal_feed = match a.nominal_feed {
        Some(f) if f.is_finite() && f >= 0.0 => f,
        Some(f) => return Err(format!("--nominal-feed {f}: must be finite and >= 0 [m/s]")),
        // Seed 004's f_0 when in the cell's range (the cell file has no nominal feed of its
        // own; its force law's reference chip is the mean chip at f_0 and 2000 rpm).
        None => default_nominal_feed(limits.feed),
    };
    let mut settings = *cell.indicator_settings();
    if let Some(m) = a.model {
        settings.model = match m {
            ModelArg::StateDependent => DelayModel::StateDependent,
            ModelArg::Constant => DelayModel::Constant,
        };
    }
    if let Some(m) = a.steps {
        settings.steps = m;
    }
    settings
        .validate()
        .map_err(|e| format!("--steps {}: {e}", settings.steps))?;
    let chart = LobeMap::compute(
        &state.modal,
        &cell.milling_process(),
        &settings,
        LobeGrid {
            rpms: rpm_grid.values(),
            feeds: feed_grid.values(),
            nominal_feed,
            options: depth_search(settings.steps, a.max_depth),
        },
    )
    .map_err(|e| e.to_string())?;
    Ok(LobesReport {
        segment: a.segment,
        g: a.g,
        state,
        chart,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Runs `kerf lobes`: computes, writes the two plots, prints the table.
///
/// # Errors
/// The message to print; the caller exits with [`crate::EXIT_FAILURE`].
pub fn run(a: LobesArgs) -> Result<(), String> {
    if a.format == Format::Png {
        return Err("--format png: png not built in; use svg".to_string());
    }
    let report = compute(&a)?;
    std::fs::create_dir_all(&a.out)
        .map_err(|e| format!("cannot create {}: {e}", a.out.display()))?;
    let g = format!("{}", a.g);
    let lobes_path = a.out.join(format!("lobes_seg{}_g{g}.svg", a.segment));
    let map_path = a.out.join(format!("feed_map_seg{}_g{g}.svg", a.segment));
    plots::lobes::lobe_diagram(
        &lobes_path,
        &report.chart,
        report.segment,
        report.g,
        report.state.condition_number,
    )?;
    plots::feed_map::feed_map(&map_path, &report.chart, report.segment, report.g)?;
    print!("{}", table(&report));
    println!(
        "# wrote {} and {} ({:.2} s of computation)",
        lobes_path.display(),
        map_path.display(),
        report.seconds
    );
    Ok(())
}
