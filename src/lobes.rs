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

use std::{
    path::{Path, PathBuf},
    time::Instant,
};

use clap::{Args, ValueEnum};
use kerf_chatter::{
    lobe_map::{default_nominal_feed, depth_search},
    DelayModel, LobeGrid, LobeMap,
};
use kerf_mill::{CellState, MillCell};

pub use grid::{Grid, GridParser};
pub use table::table;

use crate::{
    bounds::{Count, Real},
    input::{self, InputFile},
    plots,
};

/// `--rpm`: speeds in (0, 1e6] rpm, at most 10 000 of them (the plots stay readable; a long
/// run prints progress and stops on Ctrl-C).
const RPM_GRID: GridParser = GridParser {
    name: "rpm",
    values: Real::above(0.0, 1e6, "rpm"),
    count: Count::new(1, 10_000, "speeds"),
};

/// `--feed`: feeds in [0, 10] m/s, at most 1 000 of them.
const FEED_GRID: GridParser = GridParser {
    name: "feed",
    values: Real::closed(0.0, 10.0, "m/s"),
    count: Count::new(1, 1_000, "feeds"),
};

/// Most map cells (speeds × feeds): 10⁶ (16 MB of map, an SVG of about 100 MB).
const MAX_MAP_CELLS: usize = 1_000_000;

/// Seconds between two progress lines of a long computation, about.
const PROGRESS_EVERY: f64 = 1.0;

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
    /// Milling cell YAML (default: the shipped urdf/irb6660_milling.yaml; at most 1 MiB).
    #[arg(long)]
    cell: Option<InputFile>,
    /// Path segment index (0-based); [0, 1000000].
    #[arg(long, value_parser = Count::<usize>::new(0, 1_000_000, ""))]
    segment: usize,
    /// Redundancy angle g; [-4, 4] rad.
    #[arg(long, allow_hyphen_values = true, value_parser = Real::closed(-4.0, 4.0, "rad"))]
    g: f64,
    /// Spindle speeds (default: the cell's range, 100 speeds); MIN:MAX:COUNT, MIN and MAX in
    /// (0, 1000000] rpm, COUNT in [1, 10000] speeds. At most 10⁶ speeds × feeds.
    #[arg(long, value_parser = RPM_GRID)]
    rpm: Option<Grid>,
    /// Largest axial depth searched (default 0.02 = 20 mm); (0, 1] m.
    #[arg(long, default_value_t = 0.02, allow_hyphen_values = true,
          value_parser = Real::above(0.0, 1.0, "m"))]
    max_depth: f64,
    /// Feeds of the map (default: the cell's range, 25 feeds); MIN:MAX:COUNT, MIN and MAX in
    /// [0, 10] m/s, COUNT in [1, 1000] feeds.
    #[arg(long, value_parser = FEED_GRID)]
    feed: Option<Grid>,
    /// Feed of the state-dependent lobe (default: seed 004's f0 = 0.04 m/s if in the cell's
    /// feed range, else the range's midpoint); [0, 10] m/s.
    #[arg(long, allow_hyphen_values = true, value_parser = Real::closed(0.0, 10.0, "m/s"))]
    nominal_feed: Option<f64>,
    /// Delay model (default: the cell's `chatter.model`).
    #[arg(long, value_enum)]
    model: Option<ModelArg>,
    /// Sub-intervals m of the discretization (default: the cell's `chatter.steps`, seed 004:
    /// 40); [2, 200] sub-intervals.
    #[arg(long, value_parser = Count::<usize>::new(2, 200, "sub-intervals"))]
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
        Some(f) => load_cell("--cell", f),
        None => MillCell::default_cell().map_err(|e| e.to_string()),
    }?;
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
    let rpm_grid = match a.rpm {
        Some(g) => g,
        None => Grid::new(
            "rpm",
            limits.spindle_rpm[0],
            limits.spindle_rpm[1],
            DEFAULT_SPEEDS,
            0.0,
            true,
        )?,
    };
    let feed_grid = match a.feed {
        Some(g) => g,
        None => Grid::new(
            "feed",
            limits.feed[0],
            limits.feed[1],
            DEFAULT_FEEDS,
            0.0,
            false,
        )?,
    };
    if rpm_grid.count.saturating_mul(feed_grid.count) > MAX_MAP_CELLS {
        return Err(format!(
            "--rpm and --feed: {} speeds × {} feeds is over {MAX_MAP_CELLS} map cells",
            rpm_grid.count, feed_grid.count
        ));
    }
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
    let grid = LobeGrid {
        rpms: rpm_grid.values(),
        feeds: feed_grid.values(),
        nominal_feed,
        options: depth_search(settings.steps, a.max_depth),
    };
    let chart = compute_with_progress(&state, &cell, &settings, grid)?;
    Ok(LobesReport {
        segment: a.segment,
        g: a.g,
        state,
        chart,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// A milling cell file read through the capped reader ([`input::CELL_CAP`]); its robot files
/// are relative to its directory (the working directory for standard input).
///
/// # Errors
/// The reader's or the cell's message, naming the argument and the file.
pub fn load_cell(arg: &str, file: &InputFile) -> Result<MillCell, String> {
    let text = input::read_text(arg, file, input::CELL_CAP)?;
    let dir = if file.is_stdin() {
        Path::new(".")
    } else {
        file.path().parent().unwrap_or(Path::new("."))
    };
    MillCell::from_yaml_str(&text, dir, file.path()).map_err(|e| format!("{arg} {file}: {e}"))
}

/// [`LobeMap::compute`] over the speeds in chunks, with a progress line on stderr about every
/// [`PROGRESS_EVERY`] s once the run has taken that long (Ctrl-C ends it: `crate::interrupt`).
/// The chart is the one computation over all speeds gives: every speed is computed alone.
///
/// # Errors
/// The chatter error with the speed it occurred at.
fn compute_with_progress(
    state: &CellState,
    cell: &MillCell,
    settings: &kerf_chatter::IndicatorSettings,
    grid: LobeGrid,
) -> Result<LobeMap, String> {
    let start = Instant::now();
    let total = grid.rpms.len();
    let mut chart: Option<LobeMap> = None;
    let mut done = 0;
    let mut chunk = 1;
    let mut last_line = 0.0;
    while done < total {
        let end = (done + chunk).min(total);
        let part_started = Instant::now();
        let part = LobeMap::compute(
            &state.modal,
            &cell.milling_process(),
            settings,
            LobeGrid {
                rpms: grid.rpms[done..end].to_vec(),
                ..grid.clone()
            },
        )
        .map_err(|e| e.to_string())?;
        let took = part_started.elapsed().as_secs_f64();
        // The next chunk takes about PROGRESS_EVERY seconds.
        let per_speed = took / (end - done) as f64;
        chunk = if per_speed > 0.0 {
            ((PROGRESS_EVERY / per_speed) as usize).clamp(1, 256)
        } else {
            256
        };
        done = end;
        chart = Some(match chart {
            None => part,
            Some(mut c) => {
                c.rpms.extend(part.rpms);
                c.constant.extend(part.constant);
                if let (Some(a), Some(b)) = (&mut c.state_dependent, part.state_dependent) {
                    a.extend(b);
                }
                c.map.extend(part.map);
                c
            }
        });
        let elapsed = start.elapsed().as_secs_f64();
        if elapsed - last_line >= PROGRESS_EVERY && done < total {
            last_line = elapsed;
            let left = elapsed / done as f64 * (total - done) as f64;
            eprintln!(
                "kerf lobes: {done}/{total} speeds, {elapsed:.0} s, about {left:.0} s left (Ctrl-C stops)"
            );
        }
    }
    chart.ok_or_else(|| "no speeds".to_string())
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
