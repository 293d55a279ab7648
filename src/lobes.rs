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
//! and prints a table, one row per speed: a_lim (constant and state-dependent), |μ| at the
//! cell's depth for the lowest, middle and highest grid feed, and the feed lower bound
//! ([`feed_lower_bound`]). Units: SI, except rpm (named so) and the depths of the table and
//! plots, in mm (named so). Every failure — bad segment, g outside the range or unreachable,
//! bad ranges, a chatter computation that fails — exits with code 2 and a message.
//!
//! `G` in the file names is g formatted with Rust's shortest round-trip `f64` display
//! (`0`, `-0.5`, `1.25`). PNG needs plotters' bitmap backend, which would pull crates outside
//! the workspace's dependency set: `--format png` is refused with a clear message.

mod plots;

use std::{fmt::Write as _, path::PathBuf, time::Instant};

use clap::{Args, ValueEnum};
use kerf_chatter::{
    indicator_map, lobes::state_dependent_critical_depth, stability_lobes, ChatterError,
    DelayModel, IndicatorSettings, LobeOptions, LobePoint, MillingProcess, Modal2,
};
use kerf_mill::{CellState, MillCell};

/// Exit code of every `kerf lobes` failure (as `kerf plan cut`).
pub const EXIT_FAILURE: u8 = 2;

/// Scan intervals of the depth search (1 mm steps for the default max depth of 20 mm).
const SCAN_POINTS: usize = 20;

/// Depth tolerance of the bisection \[m\] (1 µm).
const DEPTH_TOLERANCE: f64 = 1e-6;

/// Default number of spindle speeds.
const DEFAULT_SPEEDS: usize = 100;

/// Default number of feeds.
const DEFAULT_FEEDS: usize = 25;

/// Seed 004's initial feed f_0 = 0.04 m/s (section 4): the default nominal feed when it lies
/// in the cell's feed range (the cell file has no nominal feed of its own; its force law's
/// reference chip is the mean chip at this feed and 2000 rpm).
const PAPER_INITIAL_FEED: f64 = 0.04;

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

/// An evenly spaced grid `MIN:MAX:COUNT` (COUNT = 1 needs MIN = MAX).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// First value.
    pub min: f64,
    /// Last value.
    pub max: f64,
    /// Number of values (≥ 1).
    pub count: usize,
}

impl Grid {
    /// Parses `MIN:MAX:COUNT` for the option `name`, requiring `MIN >= lower` (and
    /// `MIN > lower` when `strict`).
    ///
    /// # Errors
    /// A message naming the option: wrong syntax, NaN or infinite bounds, MIN > MAX, COUNT 0,
    /// COUNT 1 with MIN ≠ MAX, a bound under `lower`.
    pub fn parse(name: &str, text: &str, lower: f64, strict: bool) -> Result<Self, String> {
        let parts: Vec<&str> = text.split(':').collect();
        let [min, max, count] = parts[..] else {
            return Err(format!("--{name} {text}: expected MIN:MAX:COUNT"));
        };
        let num = |what: &str, s: &str| -> Result<f64, String> {
            let v: f64 = s
                .trim()
                .parse()
                .map_err(|_| format!("--{name} {text}: {what} `{s}` is not a number"))?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(format!("--{name} {text}: {what} is {v}, must be finite"))
            }
        };
        let min = num("MIN", min)?;
        let max = num("MAX", max)?;
        let count: usize = count
            .trim()
            .parse()
            .map_err(|_| format!("--{name} {text}: COUNT `{count}` is not a whole number"))?;
        Self::new(name, min, max, count, lower, strict)
    }

    /// Validates a grid (the checks of [`Grid::parse`]).
    ///
    /// # Errors
    /// As [`Grid::parse`].
    pub fn new(
        name: &str,
        min: f64,
        max: f64,
        count: usize,
        lower: f64,
        strict: bool,
    ) -> Result<Self, String> {
        let text = format!("{min}:{max}:{count}");
        if !(min.is_finite() && max.is_finite()) {
            return Err(format!("--{name} {text}: bounds must be finite"));
        }
        if min > max {
            return Err(format!("--{name} {text}: MIN {min} > MAX {max}"));
        }
        if count == 0 {
            return Err(format!("--{name} {text}: COUNT must be >= 1"));
        }
        if count == 1 && min != max {
            return Err(format!("--{name} {text}: COUNT 1 needs MIN = MAX"));
        }
        if min < lower || (strict && min == lower) {
            let rel = if strict { ">" } else { ">=" };
            return Err(format!("--{name} {text}: MIN must be {rel} {lower}"));
        }
        Ok(Self { min, max, count })
    }

    /// The values, evenly spaced from `min` to `max` inclusive.
    pub fn values(&self) -> Vec<f64> {
        if self.count == 1 {
            return vec![self.min];
        }
        let n = (self.count - 1) as f64;
        (0..self.count)
            .map(|i| self.min + (self.max - self.min) * i as f64 / n)
            .collect()
    }
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
    /// The milling process of the cell (its axial depth is the map's depth).
    pub process: MillingProcess,
    /// The indicator settings used (model, m, force law, wall term).
    pub settings: IndicatorSettings,
    /// Spindle speeds \[rpm\].
    pub rpms: Vec<f64>,
    /// Feeds \[m/s\].
    pub feeds: Vec<f64>,
    /// Feed of the state-dependent lobe \[m/s\].
    pub nominal_feed: f64,
    /// Depth search settings (max depth, scan, tolerance, m).
    pub options: LobeOptions,
    /// Constant-delay lobe, one point per speed.
    pub constant: Vec<LobePoint>,
    /// State-dependent critical depth \[m\] at the nominal feed, one per speed (`None` for
    /// the constant model; `Some(None)` = stable up to the max depth).
    pub state_dependent: Option<Vec<Option<f64>>>,
    /// |μ|max at the cell's depth, `map[speed][feed]`; `None` where the model is undefined:
    /// f = 0 with the state-dependent model and a force exponent x_F < 1, whose cutting
    /// stiffness `x_F F(h)/h ∝ h^(x_F − 1)` is infinite at a zero chip (printed `undef`,
    /// drawn grey, counted as not stable).
    pub map: Vec<Vec<Option<f64>>>,
    /// Wall-clock time of the computation \[s\].
    pub seconds: f64,
}

/// The feed lower bound of one row of the map: the lowest grid feed from which every higher
/// grid feed is stable (|μ| < 1) too — seed 004's observation (Fig. 4, 7) that chatter can be
/// left by feeding faster.
///
/// # Returns
/// `Bound::All` if every feed is stable, `Bound::None` if the highest feed is unstable (or the
/// row is empty), else `Bound::Feed(f)`. An undefined entry (`None`) counts as not stable.
pub fn feed_lower_bound(feeds: &[f64], row: &[Option<f64>]) -> Bound {
    let stable = |mu: &Option<f64>| matches!(mu, Some(m) if *m < 1.0);
    let mut lowest = None;
    for (f, mu) in feeds.iter().zip(row).rev() {
        if stable(mu) {
            lowest = Some(*f);
        } else {
            break;
        }
    }
    match lowest {
        None => Bound::None,
        Some(_) if row.len() == feeds.len() && row.iter().all(stable) => Bound::All,
        Some(f) => Bound::Feed(f),
    }
}

/// A feed lower bound ([`feed_lower_bound`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Bound {
    /// Stable at every grid feed.
    All,
    /// Unstable at the highest grid feed.
    None,
    /// Stable from this feed \[m/s\] upward.
    Feed(f64),
}

impl std::fmt::Display for Bound {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Bound::All => write!(f, "all"),
            Bound::None => write!(f, "none"),
            Bound::Feed(v) => write!(f, "{v:.4}"),
        }
    }
}

/// The depth search of both lobes: depths 0..`max_depth`, 20 scan intervals, 1 µm.
fn lobe_options(steps: usize, max_depth: f64) -> LobeOptions {
    LobeOptions {
        steps,
        min_depth: 0.0,
        max_depth,
        scan_points: SCAN_POINTS,
        tolerance: DEPTH_TOLERANCE,
    }
}

/// `f` over `items` on up to `available_parallelism` scoped threads, in order. The first
/// error (in item order) is returned.
fn par_map<T: Sync, R: Send>(
    items: &[T],
    f: impl Fn(&T) -> Result<R, String> + Sync,
) -> Result<Vec<R>, String> {
    let threads = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
        .clamp(1, 8)
        .min(items.len().max(1));
    if threads <= 1 {
        return items.iter().map(&f).collect();
    }
    let chunk = items.len().div_ceil(threads);
    let f = &f;
    let parts: Vec<Result<Vec<R>, String>> = std::thread::scope(|s| {
        let handles: Vec<_> = items
            .chunks(chunk)
            .map(|c| s.spawn(move || c.iter().map(f).collect::<Result<Vec<R>, _>>()))
            .collect();
        handles
            .into_iter()
            .map(|h| {
                h.join()
                    .unwrap_or_else(|_| Err("a worker thread panicked".to_string()))
            })
            .collect()
    });
    let mut out = Vec::with_capacity(items.len());
    for p in parts {
        out.extend(p?);
    }
    Ok(out)
}

/// Runs the computation of `kerf lobes` (no files, no printing).
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
        None if (limits.feed[0]..=limits.feed[1]).contains(&PAPER_INITIAL_FEED) => {
            PAPER_INITIAL_FEED
        }
        None => 0.5 * (limits.feed[0] + limits.feed[1]),
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
    let process = cell.milling_process();
    let modal = state.modal;
    let rpms = rpm_grid.values();
    let feeds = feed_grid.values();
    let options = lobe_options(settings.steps, a.max_depth);
    let at = |rpm: f64| move |e: ChatterError| format!("{rpm} rpm: {e}");

    let constant = par_map(&rpms, |&rpm| {
        stability_lobes(&modal, &process, &[rpm], &options)
            .map_err(at(rpm))?
            .pop()
            .ok_or_else(|| format!("{rpm} rpm: no lobe point"))
    })
    .map_err(|e| format!("constant-delay lobes: {e}"))?;
    let state_dependent = match settings.model {
        DelayModel::Constant => None,
        DelayModel::StateDependent => Some(
            par_map(&rpms, |&rpm| {
                state_dependent_critical_depth(
                    &modal,
                    &process,
                    rpm,
                    nominal_feed,
                    &settings,
                    &options,
                )
                .map_err(at(rpm))
            })
            .map_err(|e| format!("state-dependent lobe at {nominal_feed} m/s: {e}"))?,
        ),
    };
    let undefined = |f: f64| {
        f == 0.0
            && settings.model == DelayModel::StateDependent
            && settings.equilibrium.force_law.exponent < 1.0
    };
    let defined: Vec<f64> = feeds.iter().copied().filter(|f| !undefined(*f)).collect();
    let map = par_map(&rpms, |&rpm| {
        let mut values = if defined.is_empty() {
            Vec::new()
        } else {
            indicator_map(&modal, &process, &[rpm], &defined, &settings)
                .map_err(at(rpm))?
                .pop()
                .ok_or_else(|| format!("{rpm} rpm: empty map row"))?
        }
        .into_iter();
        let row: Vec<Option<f64>> = feeds
            .iter()
            .map(|f| if undefined(*f) { None } else { values.next() })
            .collect();
        Ok(row)
    })
    .map_err(|e| format!("feed map at depth {} m: {e}", process.axial_depth))?;
    Ok(LobesReport {
        segment: a.segment,
        g: a.g,
        state,
        process,
        settings,
        rpms,
        feeds,
        nominal_feed,
        options,
        constant,
        state_dependent,
        map,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Eigenvalues (ascending) of a symmetric 2×2 matrix `[[a, b], [b, d]]`, closed form.
fn sym_eigen(a: f64, b: f64, d: f64) -> [f64; 2] {
    let mean = 0.5 * (a + d);
    let r = (0.25 * (a - d) * (a - d) + b * b).sqrt();
    [mean - r, mean + r]
}

/// Undamped natural frequencies \[Hz\] (ascending) of `M p̈ + K p = 0`: the roots λ = ω² of
/// `det(K − λ M) = 0`, a quadratic `A λ² + B λ + C` with `A = det M`,
/// `B = −(k00 m11 + k11 m00 − 2 k01 m01)`, `C = det K` (M, K symmetric).
fn natural_frequencies(modal: &Modal2) -> Option<[f64; 2]> {
    let (m, k) = (&modal.mass, &modal.stiffness);
    let a = m[(0, 0)] * m[(1, 1)] - m[(0, 1)] * m[(1, 0)];
    let b = -(k[(0, 0)] * m[(1, 1)] + k[(1, 1)] * m[(0, 0)] - 2.0 * k[(0, 1)] * m[(0, 1)]);
    let c = k[(0, 0)] * k[(1, 1)] - k[(0, 1)] * k[(1, 0)];
    let disc = b * b - 4.0 * a * c;
    if !(a > 0.0 && disc >= 0.0) {
        return None;
    }
    let l1 = (-b - disc.sqrt()) / (2.0 * a);
    let l2 = (-b + disc.sqrt()) / (2.0 * a);
    if !(l1 > 0.0 && l2.is_finite()) {
        return None;
    }
    let hz = |l: f64| l.sqrt() / (2.0 * std::f64::consts::PI);
    Some([hz(l1), hz(l2)])
}

/// A critical depth in mm for the table: `>MAX` when stable up to the max depth.
fn depth_mm(d: Option<f64>, max_depth: f64) -> String {
    match d {
        Some(v) => format!("{:.4}", v * 1e3),
        None => format!(">{:.4}", max_depth * 1e3),
    }
}

/// Indices of the lowest, middle and highest feed of the grid.
pub fn feed_columns(n: usize) -> [usize; 3] {
    let last = n.saturating_sub(1);
    [0, last / 2, last]
}

/// The printed report: a `#` header (cell state, settings) and one row per speed.
///
/// Columns: `rpm`, `a_lim_const_mm`, `a_lim_sd_mm` (`-` for the constant model; `>MAX` =
/// stable up to the max depth), `mu@f=…` for the lowest, middle and highest grid feed at the
/// cell's depth, `feed_lb_m/s` ([`feed_lower_bound`]).
pub fn table(r: &LobesReport) -> String {
    let mut s = String::new();
    let st = &r.state;
    let k = &st.modal.stiffness;
    let eig = sym_eigen(k[(0, 0)], k[(0, 1)], k[(1, 1)]);
    let _ = writeln!(s, "# kerf lobes: segment {}, g = {} rad", r.segment, r.g);
    let _ = writeln!(
        s,
        "# joints [rad]: [{}]",
        st.joints
            .iter()
            .map(|q| format!("{q:.6}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let _ = writeln!(
        s,
        "# condition number K = {:.4}, condition indicator 1/K = {:.4}",
        st.condition_number, st.condition_indicator
    );
    let _ = writeln!(
        s,
        "# tool-tip stiffness [N/m] (cutting frame): [[{:.6e}, {:.6e}], [{:.6e}, {:.6e}]], eigenvalues {:.6e}, {:.6e}",
        k[(0, 0)],
        k[(0, 1)],
        k[(1, 0)],
        k[(1, 1)],
        eig[0],
        eig[1]
    );
    if let Some([f1, f2]) = natural_frequencies(&st.modal) {
        let _ = writeln!(s, "# undamped tool-tip modes: {f1:.3} Hz, {f2:.3} Hz");
    }
    let p = &r.process;
    let model = match r.settings.model {
        DelayModel::Constant => "constant delay".to_string(),
        DelayModel::StateDependent => format!(
            "state-dependent (force exponent {}, reference chip {} m, wall term {})",
            r.settings.equilibrium.force_law.exponent,
            r.settings.equilibrium.force_law.reference_chip,
            if r.settings.wall_term { "on" } else { "off" }
        ),
    };
    let _ = writeln!(
        s,
        "# process: {} teeth, R = {} m, cell depth a_p = {} mm, engagement [{:.4}, {:.4}] rad; model {model}, m = {}",
        p.teeth,
        p.radius,
        p.axial_depth * 1e3,
        p.entry_angle,
        p.exit_angle,
        r.settings.steps
    );
    let _ = writeln!(
        s,
        "# depth search 0..{} mm, {} scan intervals, tolerance {} um; state-dependent lobe at the nominal feed {} m/s",
        r.options.max_depth * 1e3,
        r.options.scan_points,
        r.options.tolerance * 1e6,
        r.nominal_feed
    );
    let cols = feed_columns(r.feeds.len());
    let feed_at = |i: usize| r.feeds.get(i).copied().unwrap_or(f64::NAN);
    let _ = writeln!(
        s,
        "# {:>9} {:>15} {:>12} {:>14} {:>14} {:>14} {:>12}",
        "rpm",
        "a_lim_const_mm",
        "a_lim_sd_mm",
        format!("mu@f={:.4}", feed_at(cols[0])),
        format!("mu@f={:.4}", feed_at(cols[1])),
        format!("mu@f={:.4}", feed_at(cols[2])),
        "feed_lb_m/s"
    );
    for (i, rpm) in r.rpms.iter().enumerate() {
        let constant = r.constant.get(i).map_or("error".to_string(), |p| {
            depth_mm(p.critical_depth, r.options.max_depth)
        });
        let sd = match &r.state_dependent {
            None => "-".to_string(),
            Some(v) => v
                .get(i)
                .map_or("error".to_string(), |d| depth_mm(*d, r.options.max_depth)),
        };
        let row = r.map.get(i).map_or(&[][..], |v| &v[..]);
        let mu = |j: usize| match row.get(j) {
            Some(Some(m)) => format!("{m:.6}"),
            Some(None) => "undef".to_string(),
            None => "-".to_string(),
        };
        let _ = writeln!(
            s,
            "{:>11.3} {:>15} {:>12} {:>14} {:>14} {:>14} {:>12}",
            rpm,
            constant,
            sd,
            mu(cols[0]),
            mu(cols[1]),
            mu(cols[2]),
            feed_lower_bound(&r.feeds, row).to_string()
        );
    }
    s
}

/// Runs `kerf lobes`: computes, writes the two plots, prints the table.
///
/// # Errors
/// The message to print; the caller exits with [`EXIT_FAILURE`].
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
    plots::lobe_diagram(&lobes_path, &report)?;
    plots::feed_map(&map_path, &report)?;
    print!("{}", table(&report));
    println!(
        "# wrote {} and {} ({:.2} s of computation)",
        lobes_path.display(),
        map_path.display(),
        report.seconds
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_parses_and_refuses_bad_ranges() {
        let g = Grid::parse("rpm", "2000:4000:5", 0.0, true).expect("grid");
        assert_eq!(g.values(), vec![2000.0, 2500.0, 3000.0, 3500.0, 4000.0]);
        assert_eq!(
            Grid::parse("feed", "0:0:1", 0.0, false)
                .expect("single")
                .values(),
            vec![0.0]
        );
        for bad in [
            "4000:2000:5",
            "NaN:4000:5",
            "2000:inf:5",
            "2000:4000:0",
            "2000:4000",
        ] {
            assert!(Grid::parse("rpm", bad, 0.0, true).is_err(), "{bad}");
        }
        assert!(Grid::parse("rpm", "0:4000:5", 0.0, true).is_err());
        assert!(Grid::parse("feed", "-0.01:0.06:5", 0.0, false).is_err());
        assert!(Grid::parse("feed", "0.01:0.06:1", 0.0, false).is_err());
    }

    #[test]
    fn feed_lower_bound_cases() {
        let f = [0.0, 0.02, 0.04, 0.06];
        let b = |row: [Option<f64>; 4]| feed_lower_bound(&f, &row);
        assert_eq!(b([Some(0.9), Some(0.9), Some(0.9), Some(0.9)]), Bound::All);
        assert_eq!(
            b([Some(1.2), Some(1.1), Some(0.99), Some(0.9)]),
            Bound::Feed(0.04)
        );
        // Stable, unstable, stable: the bound is the start of the stable tail.
        assert_eq!(
            b([Some(0.9), Some(1.1), Some(0.9), Some(0.9)]),
            Bound::Feed(0.04)
        );
        assert_eq!(b([Some(0.9), Some(0.9), Some(0.9), Some(1.0)]), Bound::None);
        // Undefined (f = 0, sublinear law) counts as not stable.
        assert_eq!(
            b([None, Some(0.9), Some(0.9), Some(0.9)]),
            Bound::Feed(0.02)
        );
    }

    #[test]
    fn closed_forms_match_uncoupled_modes() {
        use kerf_chatter::Mode;
        let x = Mode {
            natural_frequency_hz: 15.0,
            damping_ratio: 0.05,
            modal_mass: 60.0,
        };
        let y = Mode {
            natural_frequency_hz: 28.0,
            ..x
        };
        let modal = Modal2::from_modes(y, x).expect("modes");
        let f = natural_frequencies(&modal).expect("frequencies");
        assert!(
            (f[0] - 15.0).abs() < 1e-9 && (f[1] - 28.0).abs() < 1e-9,
            "{f:?}"
        );
        // [[2, 1], [1, 2]] has eigenvalues 1 and 3.
        assert_eq!(sym_eigen(2.0, 1.0, 2.0), [1.0, 3.0]);
    }
}
