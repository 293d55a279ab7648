//! Per-path indicator caches (issue 13, item 4: "every planner, dp and
//! greedy included, plans any valid path"): the `dp` and `naive` planners
//! query |μ|max millions of times (the DP: every (segment, Ω, f, g) node of
//! its grid), which only an interpolation table can answer. The committed
//! cache ([`crate::cache`], `data/indicator_cache.bin`) holds the DEFAULT
//! cell; for any other path or process the planner builds a coarser cache
//! of the request's own cell on first use ([`path_grid`],
//! [`IndicatorCache::build_within`]) under the request's time budget, and
//! keeps the last [`PATH_CACHE_MEMO`] of them ([`PathCaches`]).
//!
//! # Grid ([`path_grid`])
//!
//! * segments: every k-th and the last, k the largest stride that keeps
//!   the nodes at most [`SEGMENT_SPACING_M`] apart along the path (k = 10
//!   on the default path; a path of many short segments gets as few nodes
//!   as one of a few long ones: the geometry, not the segment count, sets
//!   how fast the dynamics change);
//! * Ω: equally spaced over the cell's spindle range, at most
//!   [`RPM_SPACING`] apart (11 nodes on 2000–4000 rpm);
//! * f: [`FEED_FRACTIONS`] of [f_lo, f_max], f_lo = max(the range's
//!   minimum, f_max / 6) (0.01, 0.03, 0.045, 0.06 m/s on the default
//!   range): lower feeds are not in the cache, so the DP does not plan them
//!   (as with the default cache, whose lowest feed node is also 0.01 m/s;
//!   a lower feed is slower and, on this model, less stable);
//! * g: g0 + k · [`G_SPACING`] within the cell's g range, and its ends (so
//!   the DP's g nodes g0 + k · 0.2 rad of the default step bound are cache
//!   nodes).
//!
//! On the default cell this is 11 × 11 × 4 × 33 = 15 972 nodes, about
//! 9 400 of them feasible (one indicator evaluation each; the others are
//! outside the reachable g band and cost one IK each).
//!
//! # Accuracy (measured)
//!
//! The grid was chosen by subsampling the committed default cache
//! (`cargo run --release -p kerf_millplan --example path_cache_grid`: each
//! candidate grid is a subset of the default cache's nodes, and its
//! interpolation error is measured at every other feasible node of the
//! default cache). Against the default cache's nodes, this grid's error is
//! max 0.125, p99 0.0285, mean 0.0019 (the largest errors come from the
//! 200 rpm spacing; g every 0.4 rad instead would give max 0.233). Against
//! direct evaluation (`cargo bench -p kerf_millplan --bench path_cache`,
//! 1000 uniform random (segment, Ω, f, g) per row, the infeasible ones
//! skipped, seeds 2025 / 2026 as the default cache's):
//!
//! | path | compared | max | p99 | mean | g on a node: max | p99 | mean |
//! |---|---:|---:|---:|---:|---:|---:|---:|
//! | default | 595 / 632 | 0.0717 | 0.0575 | 0.0062 | 0.1099 | 0.0439 | 0.0031 |
//! | default, turned 0.3 rad, moved (−0.1, 0.05, −0.1) m | 589 / 633 | 0.0689 | 0.0440 | 0.0062 | 0.1069 | 0.0342 | 0.0028 |
//! | *the committed default cache (for comparison)* | 630 / 651 | 0.1086 | 0.0414 | 0.0049 | 0.0328 | 0.0184 | 0.0010 |
//!
//! About the committed cache's general error, 2–3× its error for the
//! DP's queries (g on a node), where the coarser segment, Ω and f axes
//! dominate. The cache carries no stated error bound, so the planner never
//! publishes its values: every plan's |μ|max is evaluated directly (step 5
//! of [`crate::planner`]); a DP plan that rides the chatter margin (0.95)
//! can therefore be found chattering by the direct evaluation.
//!
//! # Time
//!
//! One indicator evaluation per feasible node (9 372 of the 15 972 on the
//! default cell and on the moved path) on the planner's evaluation threads:
//! 16.1–16.6 s on 2 threads on the shared 2-core machine at load average
//! about 5 (4 engineers; ≈ 1 ms per evaluation on an idle core would give
//! about 5 s); the DP after it takes 4–10 s, so a new path's `dp` fits the
//! node's default 60 s budget. The build checks the request's budget before
//! every node and ends with [`MillPlanError::Interrupted`] (status TIMEOUT)
//! when it runs out; nothing is kept then, so the next request for the path
//! starts again.

use std::sync::{Arc, Mutex};

use kerf_budget::Budget;
use kerf_mill::{MillCell, PathSpec};

use crate::cache::{GridSpec, IndicatorCache};
use crate::error::MillPlanError;
use crate::request::RequestProcess;

/// Per-path caches a planner keeps (most recently used last).
pub const PATH_CACHE_MEMO: usize = 8;
/// Largest spacing of the segment nodes along the path \[m\] (the default
/// path: 0.93 m in 100 segments of 9.3 mm, so every 10th segment).
pub const SEGMENT_SPACING_M: f64 = 0.1;
/// Largest spacing of the spindle-speed nodes \[rpm\].
pub const RPM_SPACING: f64 = 200.0;
/// Most spindle-speed intervals of a per-path cache (500 cover 100 000 rpm, the fastest spindle
/// a request may ask for).
pub const MAX_RPM_INTERVALS: usize = 1000;
/// The feed nodes as fractions of [f_lo, f_max] (module documentation).
pub const FEED_FRACTIONS: [f64; 4] = [0.0, 0.4, 0.7, 1.0];
/// Spacing of the g nodes \[rad\] (the default g step bound).
pub const G_SPACING: f64 = 0.2;

/// What a per-path cache depends on: the request's path and process (the
/// cell's model) and the grid (which follows from the request's ranges and
/// g0).
#[derive(Debug, Clone, PartialEq)]
pub struct PathCacheKey {
    /// The request's path.
    pub path: PathSpec,
    /// The request's process (`None`: the cell's).
    pub process: Option<RequestProcess>,
    /// The grid ([`path_grid`]).
    pub grid: GridSpec,
}

/// The grid of a per-path cache for `cell` (its path and its state ranges)
/// with the initial redundancy angle `g0` (module documentation).
///
/// # Errors
/// [`MillPlanError::InvalidConfig`] for a path without segments, a feed
/// range whose maximum is not positive, or a g0 outside the g range.
pub fn path_grid(cell: &MillCell, g0: f64) -> Result<GridSpec, MillPlanError> {
    let bad = |name: &str, reason: String| MillPlanError::InvalidConfig {
        name: format!("per-path cache {name}"),
        reason,
    };
    let lim = cell.state_limits();
    let segments = cell.path().segments();
    let n = segments.len();
    if n == 0 {
        return Err(bad("segments", "the path has no segments".to_string()));
    }
    let longest = segments.iter().map(|s| s.length).fold(0.0, f64::max);
    let stride = if longest > 0.0 {
        ((SEGMENT_SPACING_M / longest).floor() as usize).clamp(1, n)
    } else {
        n
    };
    let mut seg: Vec<usize> = (0..n).step_by(stride).collect();
    if seg.last() != Some(&(n - 1)) {
        seg.push(n - 1);
    }
    let [r0, r1] = lim.spindle_rpm;
    // Counted in f64 before allocating: a spindle range of 1e308 rpm saturated the cast and
    // panicked collecting the nodes ("capacity overflow", issue 33).
    let intervals = ((r1 - r0) / RPM_SPACING).ceil().max(1.0);
    if intervals.is_nan() || intervals > MAX_RPM_INTERVALS as f64 {
        return Err(bad(
            "spindle speed",
            format!(
                "the range [{r0}, {r1}] rpm at {RPM_SPACING} rpm spacing needs {intervals} \
                 intervals, more than {MAX_RPM_INTERVALS}"
            ),
        ));
    }
    let intervals = intervals as usize;
    let rpm: Vec<f64> = (0..=intervals)
        .map(|k| r0 + (r1 - r0) * k as f64 / intervals as f64)
        .collect();
    let [f_min, f_max] = lim.feed;
    if f_max.is_nan() || f_max <= 0.0 {
        return Err(bad(
            "feed",
            format!("the feed range's maximum {f_max} must be > 0"),
        ));
    }
    let f_lo = f_min.max(f_max / 6.0);
    let mut feed: Vec<f64> = FEED_FRACTIONS
        .iter()
        .map(|a| f_lo + a * (f_max - f_lo))
        .collect();
    feed.dedup_by(|a, b| *a <= *b);
    if feed.len() < 2 {
        feed = vec![f_lo, f_max];
    }
    let [g_lo, g_hi] = lim.redundancy_angle;
    if !(g0 >= g_lo && g0 <= g_hi) {
        return Err(bad("g", format!("g0 = {g0} is outside [{g_lo}, {g_hi}]")));
    }
    let below = ((g0 - g_lo) / G_SPACING + 1e-9).floor() as i64;
    let above = ((g_hi - g0) / G_SPACING + 1e-9).floor() as i64;
    let mut g: Vec<f64> = (-below..=above)
        .map(|k| g0 + k as f64 * G_SPACING)
        .collect();
    let tol = 1e-9;
    if g.first().is_none_or(|v| *v > g_lo + tol) {
        g.insert(0, g_lo);
    }
    if g.last().is_none_or(|v| *v < g_hi - tol) {
        g.push(g_hi);
    }
    let spec = GridSpec {
        segments: seg,
        rpm,
        feed,
        g,
    };
    spec.validate()?;
    Ok(spec)
}

/// The per-path caches of a planner: the last [`PATH_CACHE_MEMO`] built,
/// each for its [`PathCacheKey`] (the same key gives the same cache, so
/// the memo never changes a plan). Two requests for a new path at the same
/// time may both build it (the lock is not held while building).
#[derive(Debug, Default)]
pub struct PathCaches {
    memo: Mutex<Vec<(PathCacheKey, Arc<IndicatorCache>)>>,
}

impl PathCaches {
    /// No caches yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// How many caches are kept.
    pub fn len(&self) -> usize {
        self.memo.lock().map(|m| m.len()).unwrap_or(0)
    }

    /// Whether no cache is kept.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The cache of `key` for `cell` (the request's cell: its path,
    /// process and limits, of which `key` is the description): from the
    /// memo, else built with [`IndicatorCache::build_within`] on `threads`
    /// threads under `budget` and kept.
    ///
    /// # Returns
    /// The cache and whether it was built by this call.
    ///
    /// # Errors
    /// [`IndicatorCache::build_within`] errors, among them
    /// [`MillPlanError::Interrupted`] (nothing is kept).
    pub fn get_or_build(
        &self,
        key: PathCacheKey,
        cell: &MillCell,
        threads: usize,
        budget: &Budget,
    ) -> Result<(Arc<IndicatorCache>, bool), MillPlanError> {
        {
            let mut memo = self.memo.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(k) = memo.iter().position(|(m, _)| *m == key) {
                let entry = memo.remove(k);
                let hit = entry.1.clone();
                memo.push(entry);
                return Ok((hit, false));
            }
        }
        let cache = Arc::new(IndicatorCache::build_within(
            cell,
            &key.grid,
            threads.clamp(1, crate::plan::MAX_EVAL_THREADS),
            budget,
        )?);
        log::info!(
            "milling planner: built the per-path indicator cache ({} nodes, {} infeasible) in \
             {:.2} s",
            key.grid.node_count(),
            cache.header().infeasible_nodes,
            cache.header().build_seconds
        );
        let mut memo = self.memo.lock().unwrap_or_else(|e| e.into_inner());
        if !memo.iter().any(|(m, _)| *m == key) {
            memo.push((key, cache.clone()));
            if memo.len() > PATH_CACHE_MEMO {
                memo.remove(0);
            }
        }
        Ok((cache, true))
    }
}
