//! The stability chart of one milling state (issue 4 section 6, seed 004 Fig. 4 and Fig. 7):
//! over a grid of spindle speeds, the constant-delay stability lobe
//! ([`stability_lobes`], Insperger & Stépán 2004), the state-dependent critical depth at a
//! nominal feed ([`state_dependent_critical_depth`], seed 004 eq. 1-8), and |μ|max at the
//! process's axial depth over feed × speed ([`indicator_map`]). `kerf lobes` prints and draws
//! it.
//!
//! The speeds are spread over up to `available_parallelism` (at most 8) scoped threads; the
//! result does not depend on how many.
//!
//! # Example
//!
//! ```
//! use kerf_chatter::{
//!     lobe_map::{depth_search, LobeGrid, LobeMap},
//!     DelayModel, IndicatorSettings, MillingProcess, Modal2, Mode,
//! };
//!
//! let mode = Mode { natural_frequency_hz: 922.0, damping_ratio: 0.011, modal_mass: 0.03993 };
//! let modal = Modal2::from_modes(mode, mode)?;
//! let (entry_angle, exit_angle) = MillingProcess::down_milling_angles(0.05)?;
//! let process = MillingProcess {
//!     teeth: 2, radius: 0.01, axial_depth: 1.0e-3, kt: 6e8, kn: 2e8, entry_angle, exit_angle,
//! };
//! let settings = IndicatorSettings::default().model(DelayModel::Constant).steps(20);
//! let grid = LobeGrid {
//!     rpms: vec![10_000.0],
//!     feeds: vec![0.02],
//!     nominal_feed: 0.02,
//!     options: depth_search(settings.steps, 0.01),
//! };
//! let chart = LobeMap::compute(&modal, &process, &settings, grid)?;
//! assert_eq!(chart.constant.len(), 1);
//! assert!(chart.state_dependent.is_none()); // constant-delay model
//! assert_eq!(chart.map[0].len(), 1);
//! # Ok::<(), kerf_chatter::ChatterError>(())
//! ```

use crate::error::ChatterError;
use crate::indicator::{indicator_map, DelayModel, IndicatorSettings};
use crate::lobes::{stability_lobes, state_dependent_critical_depth, LobeOptions, LobePoint};
use crate::model::{MillingProcess, Modal2};

/// Scan intervals of the depth search (1 mm steps for a max depth of 20 mm).
pub const SCAN_POINTS: usize = 20;

/// Depth tolerance of the bisection \[m\] (1 µm).
pub const DEPTH_TOLERANCE: f64 = 1e-6;

/// Seed 004's initial feed f_0 = 0.04 m/s (section 4): the default nominal feed when it lies
/// in the cell's feed range ([`default_nominal_feed`]).
pub const PAPER_INITIAL_FEED: f64 = 0.04;

/// Most threads [`LobeMap::compute`] uses.
const MAX_THREADS: usize = 8;

/// The depth search of both lobes: depths 0..`max_depth` \[m\], [`SCAN_POINTS`] scan
/// intervals, [`DEPTH_TOLERANCE`].
///
/// # Arguments
/// * `steps` – sub-intervals m of the discretization.
/// * `max_depth` – largest depth searched \[m\].
///
/// # Returns
/// The [`LobeOptions`] (validated when used).
pub fn depth_search(steps: usize, max_depth: f64) -> LobeOptions {
    LobeOptions {
        steps,
        min_depth: 0.0,
        max_depth,
        scan_points: SCAN_POINTS,
        tolerance: DEPTH_TOLERANCE,
    }
}

/// The default feed of the state-dependent lobe: seed 004's f_0 = 0.04 m/s when it lies in
/// `feed_range`, else the range's midpoint.
///
/// # Arguments
/// * `feed_range` – `[lowest, highest]` feed of the cell \[m/s\].
///
/// # Returns
/// The nominal feed \[m/s\].
pub fn default_nominal_feed(feed_range: [f64; 2]) -> f64 {
    if (feed_range[0]..=feed_range[1]).contains(&PAPER_INITIAL_FEED) {
        PAPER_INITIAL_FEED
    } else {
        0.5 * (feed_range[0] + feed_range[1])
    }
}

/// Where [`LobeMap::compute`] evaluates: the speeds, the feeds, the nominal feed and the
/// depth search.
#[derive(Debug, Clone, PartialEq)]
pub struct LobeGrid {
    /// Spindle speeds \[rpm\].
    pub rpms: Vec<f64>,
    /// Feeds \[m/s\] of the map.
    pub feeds: Vec<f64>,
    /// Feed of the state-dependent lobe \[m/s\].
    pub nominal_feed: f64,
    /// Depth search of both lobes ([`depth_search`]).
    pub options: LobeOptions,
}

/// The stability chart of one milling state (module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct LobeMap {
    /// The milling process (its axial depth is the map's depth).
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
    /// |μ|max at the process's depth, `map[speed][feed]`; `None` where the model is
    /// undefined ([`LobeMap::undefined_at`]).
    pub map: Vec<Vec<Option<f64>>>,
}

impl LobeMap {
    /// Whether |μ| is undefined at `feed` under `settings`: f = 0 with the state-dependent
    /// model and a force exponent x_F < 1, whose cutting stiffness `x_F F(h)/h ∝ h^(x_F − 1)`
    /// is infinite at a zero chip.
    ///
    /// # Arguments
    /// * `settings` – the indicator settings; `feed` – the feed \[m/s\].
    ///
    /// # Returns
    /// `true` where the map holds `None`.
    pub fn undefined_at(settings: &IndicatorSettings, feed: f64) -> bool {
        feed == 0.0
            && settings.model == DelayModel::StateDependent
            && settings.equilibrium.force_law.exponent < 1.0
    }

    /// Computes the chart of the state `modal` cutting with `process`.
    ///
    /// # Arguments
    /// * `modal` – the tool-tip dynamics; `process` – the process (its depth is the map's).
    /// * `settings` – the indicator settings (model, m, …; the chatter functions validate
    ///   them).
    /// * `grid` – speeds, feeds, nominal feed and depth search.
    ///
    /// # Returns
    /// The lobes and the map, one entry per speed in `grid.rpms` order.
    ///
    /// # Errors
    /// [`ChatterError::Grid`] naming the computation (`constant-delay lobes`,
    /// `state-dependent lobe at F m/s`, `feed map at depth A m`), the speed that failed and
    /// the chatter error there (the first failing speed in grid order).
    pub fn compute(
        modal: &Modal2,
        process: &MillingProcess,
        settings: &IndicatorSettings,
        grid: LobeGrid,
    ) -> Result<Self, ChatterError> {
        let LobeGrid {
            rpms,
            feeds,
            nominal_feed,
            options,
        } = grid;
        let constant = over_speeds("constant-delay lobes", &rpms, |rpm| {
            stability_lobes(modal, process, &[rpm], &options)
                .map_err(|e| e.to_string())?
                .pop()
                .ok_or_else(|| "no lobe point".to_string())
        })?;
        let state_dependent = match settings.model {
            DelayModel::Constant => None,
            DelayModel::StateDependent => Some(over_speeds(
                &format!("state-dependent lobe at {nominal_feed} m/s"),
                &rpms,
                |rpm| {
                    state_dependent_critical_depth(
                        modal,
                        process,
                        rpm,
                        nominal_feed,
                        settings,
                        &options,
                    )
                    .map_err(|e| e.to_string())
                },
            )?),
        };
        let defined: Vec<f64> = feeds
            .iter()
            .copied()
            .filter(|f| !Self::undefined_at(settings, *f))
            .collect();
        let map = over_speeds(
            &format!("feed map at depth {} m", process.axial_depth),
            &rpms,
            |rpm| {
                let mut values = if defined.is_empty() {
                    Vec::new()
                } else {
                    indicator_map(modal, process, &[rpm], &defined, settings)
                        .map_err(|e| e.to_string())?
                        .pop()
                        .ok_or_else(|| "empty map row".to_string())?
                }
                .into_iter();
                Ok(feeds
                    .iter()
                    .map(|f| {
                        if Self::undefined_at(settings, *f) {
                            None
                        } else {
                            values.next()
                        }
                    })
                    .collect())
            },
        )?;
        Ok(Self {
            process: *process,
            settings: *settings,
            rpms,
            feeds,
            nominal_feed,
            options,
            constant,
            state_dependent,
            map,
        })
    }
}

/// `f` at every speed of `rpms`, on up to [`MAX_THREADS`] scoped threads, in order.
///
/// # Errors
/// The first failure in speed order as [`ChatterError::Grid`] named `what` (with the speed;
/// a panicking worker without one).
fn over_speeds<R: Send>(
    what: &str,
    rpms: &[f64],
    f: impl Fn(f64) -> Result<R, String> + Sync,
) -> Result<Vec<R>, ChatterError> {
    let fail = |rpm: Option<f64>, reason: String| ChatterError::Grid {
        what: what.to_string(),
        rpm,
        reason,
    };
    let one = |rpm: &f64| f(*rpm).map_err(|reason| fail(Some(*rpm), reason));
    let threads = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
        .clamp(1, MAX_THREADS)
        .min(rpms.len().max(1));
    if threads <= 1 {
        return rpms.iter().map(one).collect();
    }
    let chunk = rpms.len().div_ceil(threads);
    let one = &one;
    let parts: Vec<Result<Vec<R>, ChatterError>> = std::thread::scope(|s| {
        let handles: Vec<_> = rpms
            .chunks(chunk)
            .map(|c| s.spawn(move || c.iter().map(one).collect::<Result<Vec<R>, _>>()))
            .collect();
        handles
            .into_iter()
            .map(|h| {
                h.join()
                    .unwrap_or_else(|_| Err(fail(None, "a worker thread panicked".to_string())))
            })
            .collect()
    });
    let mut out = Vec::with_capacity(rpms.len());
    for p in parts {
        out.extend(p?);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{chatter_indicator, Mode};

    /// The classic 2-DOF example (Insperger & Stépán) at 1 mm depth, down milling a/D = 0.05.
    fn classic() -> (Modal2, MillingProcess) {
        let mode = Mode {
            natural_frequency_hz: 922.0,
            damping_ratio: 0.011,
            modal_mass: 0.03993,
        };
        let modal = Modal2::from_modes(mode, mode).unwrap();
        let (entry_angle, exit_angle) = MillingProcess::down_milling_angles(0.05).unwrap();
        let process = MillingProcess {
            teeth: 2,
            radius: 0.01,
            axial_depth: 1.0e-3,
            kt: 6e8,
            kn: 2e8,
            entry_angle,
            exit_angle,
        };
        (modal, process)
    }

    fn grid(rpms: Vec<f64>, feeds: Vec<f64>, steps: usize) -> LobeGrid {
        LobeGrid {
            rpms,
            feeds,
            nominal_feed: 0.03,
            options: depth_search(steps, 0.01),
        }
    }

    #[test]
    fn defaults_follow_seed_004() {
        assert_eq!(default_nominal_feed([0.01, 0.06]), PAPER_INITIAL_FEED);
        assert_eq!(default_nominal_feed([0.05, 0.09]), 0.07);
        let o = depth_search(30, 0.02);
        assert_eq!((o.steps, o.min_depth, o.max_depth), (30, 0.0, 0.02));
        assert_eq!((o.scan_points, o.tolerance), (SCAN_POINTS, DEPTH_TOLERANCE));
    }

    #[test]
    fn chart_agrees_with_the_chatter_functions_at_every_speed() {
        let (modal, process) = classic();
        let settings = IndicatorSettings::default().steps(20);
        let rpms = vec![9_000.0, 10_000.0, 11_000.0];
        let feeds = vec![0.02, 0.04];
        let chart =
            LobeMap::compute(&modal, &process, &settings, grid(rpms.clone(), feeds, 20)).unwrap();
        assert_eq!(chart.rpms, rpms);
        let sd = chart.state_dependent.as_ref().unwrap();
        for (i, &rpm) in rpms.iter().enumerate() {
            let lobe = stability_lobes(&modal, &process, &[rpm], &chart.options).unwrap();
            assert_eq!(chart.constant[i], lobe[0]);
            let d = state_dependent_critical_depth(
                &modal,
                &process,
                rpm,
                0.03,
                &settings,
                &chart.options,
            )
            .unwrap();
            assert_eq!(sd[i], d);
            for (k, &f) in chart.feeds.iter().enumerate() {
                let mu = chatter_indicator(&modal, &process, rpm, f, &settings)
                    .unwrap()
                    .spectral_radius;
                let got = chart.map[i][k].unwrap();
                assert!(
                    (got - mu).abs() <= 1e-9 * mu,
                    "{rpm} rpm, {f} m/s: {got} vs {mu}"
                );
            }
        }
    }

    #[test]
    fn zero_feed_is_undefined_only_for_a_sublinear_state_dependent_law() {
        let (modal, process) = classic();
        let sublinear = IndicatorSettings::default().steps(20).force_law(0.75, 1e-4);
        assert!(LobeMap::undefined_at(&sublinear, 0.0));
        assert!(!LobeMap::undefined_at(&sublinear, 0.01));
        let constant = sublinear.model(DelayModel::Constant);
        assert!(!LobeMap::undefined_at(&constant, 0.0));
        let chart = LobeMap::compute(
            &modal,
            &process,
            &constant,
            grid(vec![10_000.0], vec![0.0, 0.02], 20),
        )
        .unwrap();
        assert!(chart.state_dependent.is_none());
        assert!(chart.map[0].iter().all(Option::is_some));
        let chart = LobeMap::compute(
            &modal,
            &process,
            &sublinear,
            grid(vec![10_000.0], vec![0.0], 20),
        )
        .unwrap();
        assert_eq!(chart.map, vec![vec![None]]);
    }

    #[test]
    fn a_failing_speed_is_named_with_its_computation() {
        let (modal, process) = classic();
        let settings = IndicatorSettings::default().model(DelayModel::Constant);
        let e = LobeMap::compute(
            &modal,
            &process,
            &settings,
            grid(vec![10_000.0, -5.0], vec![0.02], 20),
        )
        .unwrap_err();
        assert!(
            matches!(e, ChatterError::Grid { rpm: Some(r), .. } if r == -5.0),
            "{e:?}"
        );
        assert!(
            e.to_string()
                .starts_with("constant-delay lobes: -5 rpm: invalid"),
            "{e}"
        );
    }
}
