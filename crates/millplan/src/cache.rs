//! A grid cache of the chatter indicator |μ|max over (segment, Ω, f, g)
//! with multilinear interpolation — the chatter indicator (seed 004
//! section 2, `kerf_chatter::indicator::chatter_indicator`) costs about
//! 0.5 ms per evaluation in release and dominates every planner.
//!
//! # Grid
//!
//! [`GridSpec`]: explicit, strictly increasing node lists per axis — path
//! segment indices (usually every k-th segment and the last, [`GridSpec::uniform`]),
//! spindle speed \[rpm\], feed [m/s] and redundancy angle g \[rad\]. At each
//! (segment, g) node the cell state (IK with the cell's reference joints,
//! `MillCell::evaluate(segment, g, None)`) is computed once; when it is
//! infeasible (IK unreachable, joint limit, singular) — or the indicator
//! itself fails — every node of that (segment, g) column is marked
//! infeasible (stored as NaN, never returned as a number).
//!
//! # Interpolation and infeasible nodes
//!
//! Multilinear in the four coordinates (the segment index as a real
//! number). Corners whose weight is exactly 0 are skipped, so a query ON a
//! node returns the stored value exactly, whatever its neighbours. A query
//! whose interpolation cell has an infeasible corner with a non-zero weight
//! is REPORTED (`Ok(None)` from [`IndicatorCache::try_query`], an error from
//! [`IndicatorCache::query`]); it is never mixed in. The environment
//! ([`crate::env`]) then evaluates directly; the DP treats the state as
//! infeasible (documented in [`crate::dp`]). A query outside the node range
//! of an axis is also reported (`None`).
//!
//! # Error bound
//!
//! Two numbers: the a-priori estimate [`IndicatorCache::curvature_bound`]
//! (the multilinear error `Σ_i h_i²/8 · max|∂²μ/∂x_i²|` with the second
//! derivatives taken from second divided differences of the nodes, times a
//! safety factor 2), and the measured error against direct evaluation at
//! random points ([`IndicatorCache::measure_error`]). The default cache
//! (`examples/build_cache.rs`, `data/indicator_cache.bin`) stores the
//! measured statistics and its stated bound in the file header
//! ([`CacheHeader`]); `tests/cache.rs` re-checks it at new random points.
//!
//! # The default cache (measured)
//!
//! `cargo run --release -p kerf_millplan --example build_cache` builds
//! `data/indicator_cache.bin` (0.99 MB) for the default cell: segments
//! 0, 5, …, 95, 99 (21) × Ω 2000–4000 rpm every 100 rpm (21) × f at 0.01,
//! 0.02, 0.03, 0.035 … 0.06 m/s (9) × g −3.0…3.0 rad every 0.2 rad (31) =
//! 123 039 nodes, of which 46 116 are infeasible (g outside the reachable
//! band). Build: 64 s with 2 threads on the shared 2-core machine (125–189 s
//! in earlier runs under more load; the indicator measured 1.34 ms per
//! evaluation under load, `--probe`). Error against direct evaluation
//! (seed 2025, 1000 random points, the infeasible ones skipped):
//!
//! | queries | compared | max | p99 | mean | stated bound (1.5 × max) |
//! |---|---:|---:|---:|---:|---:|
//! | any (segment, Ω, f, g) | 630 | 0.1086 | 0.0414 | 0.0049 | 0.163 |
//! | g on a g node (the DP's) | 651 | 0.0328 | 0.0184 | 0.0010 | 0.050 |
//!
//! The largest errors are at g ≈ −1.1 rad, near the lower edge of the
//! reachable band, where the tool-tip dynamics change fast with g (0.2 rad
//! spacing); elsewhere the error is about 0.005. The numbers are in the
//! file header and re-checked by `tests/cache.rs`. A planner that needs
//! |μ| closer to 1 than the bound should evaluate directly (the
//! environment does when no cache is given; [`crate::plan`] always does).
//!
//! # File format
//!
//! `kerf-indicator-cache 1\n`, one line of JSON ([`CacheHeader`]: grid,
//! cell fingerprint, error statistics, build command, data checksum), then
//! the values as little-endian f64 (NaN = infeasible). A wrong magic line,
//! truncated data, a checksum mismatch, or a fingerprint that differs from
//! the cell's (a stale cache: the cell file was edited) is an error.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

use kerf_budget::Budget;
use kerf_chatter::indicator::chatter_indicator;
use kerf_mill::MillCell;
use serde::{Deserialize, Serialize};

use crate::error::MillPlanError;
use crate::fingerprint::fnv1a;

pub use crate::direct::{direct_indicator, is_infeasible};
pub use crate::fingerprint::cell_fingerprint;
pub use crate::grid_spec::GridSpec;
pub use crate::rng::SplitMix64;

/// First line of a cache file.
pub const CACHE_MAGIC: &str = "kerf-indicator-cache 1";

/// Error of the cache against direct evaluation at random points.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ErrorStats {
    /// Points compared (both the cache and the direct evaluation feasible).
    pub points: usize,
    /// Random points skipped (infeasible state, or reported by the cache).
    pub skipped: usize,
    /// Largest absolute error of |μ|max.
    pub max_abs: f64,
    /// 99th percentile of the absolute error.
    pub p99_abs: f64,
    /// Mean absolute error.
    pub mean_abs: f64,
    /// Seed of the random points.
    pub seed: u64,
    /// The random g were snapped to the nearest g node (the queries of the
    /// DP, whose g grid is the cache's), so only segment, Ω and f were
    /// interpolated.
    #[serde(default)]
    pub g_on_nodes: bool,
}

/// The JSON header line of a cache file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CacheHeader {
    /// The grid.
    pub grid: GridSpec,
    /// FNV-1a hash (hex) of the cell's parameters ([`cell_fingerprint`]).
    pub cell_fingerprint: String,
    /// Infeasible nodes (NaN).
    pub infeasible_nodes: usize,
    /// Build time \[s\] (wall clock).
    pub build_seconds: f64,
    /// Threads used for the build.
    pub threads: usize,
    /// Measured interpolation error, when measured.
    pub error: Option<ErrorStats>,
    /// The stated bound on |cache − direct| for feasible queries, when set.
    pub error_bound: Option<f64>,
    /// Measured error with g on the g nodes (the DP's queries).
    #[serde(default)]
    pub error_g_nodes: Option<ErrorStats>,
    /// The stated bound for queries with g on a g node.
    #[serde(default)]
    pub error_bound_g_nodes: Option<f64>,
    /// The command that produced the file.
    pub command: String,
    /// FNV-1a hash (hex) of the value bytes.
    pub data_checksum: String,
}

/// The cached indicator (module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct IndicatorCache {
    pub(crate) header: CacheHeader,
    pub(crate) values: Vec<f64>,
}

/// Bracketing interval of `x` in `nodes`: (lower index, weight of the
/// upper node); `None` outside [first, last].
fn bracket(nodes: &[f64], x: f64) -> Option<(usize, f64)> {
    let (first, last) = (*nodes.first()?, *nodes.last()?);
    if !(x >= first && x <= last) {
        return None;
    }
    let n = nodes.len();
    if n == 1 {
        return Some((0, 0.0));
    }
    // First node > x, minus one, kept in 0..n-1.
    let upper = nodes.partition_point(|v| *v <= x);
    let lo = upper.saturating_sub(1).min(n - 2);
    let (a, b) = (nodes[lo], nodes[lo + 1]);
    let w = ((x - a) / (b - a)).clamp(0.0, 1.0);
    Some((lo, w))
}

/// The outcome of one column: its values, `None` when infeasible.
type ColumnResult = Result<Option<Vec<f64>>, MillPlanError>;

/// One (segment, g) column of the grid: the indicator at every (Ω, f), or
/// None (infeasible).
fn build_column(
    cell: &MillCell,
    spec: &GridSpec,
    segment: usize,
    g: f64,
    budget: &Budget,
) -> Result<Option<Vec<f64>>, MillPlanError> {
    budget.check("the indicator cache")?;
    let state = match cell.evaluate(segment, g, None) {
        Ok(s) => s,
        Err(e) if is_infeasible(&e) => return Ok(None),
        Err(e) => return Err(e.into()),
    };
    let process = cell.milling_process();
    let mut out = Vec::with_capacity(spec.rpm.len() * spec.feed.len());
    for &rpm in &spec.rpm {
        for &feed in &spec.feed {
            budget.check("the indicator cache")?;
            let v = chatter_indicator(&state.modal, &process, rpm, feed, cell.indicator_settings())
                .map(|i| i.spectral_radius)
                // A failed indicator marks the node infeasible (NaN), never
                // a number; it is counted in the header.
                .unwrap_or(f64::NAN);
            out.push(v);
        }
    }
    Ok(Some(out))
}

impl IndicatorCache {
    /// Evaluates the indicator at every node.
    ///
    /// # Arguments
    /// * `cell` — the milling cell; `spec` — the grid;
    /// * `threads` — worker threads (1 or 2; more is refused: the build
    ///   machine has 2 cores). The result does not depend on it: every
    ///   (segment, g) column is computed independently and stored at its
    ///   index.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] for a bad grid, a segment node
    /// beyond the path, or a thread count outside 1..=2; cell-model errors
    /// other than infeasibility.
    ///
    /// # Performance
    /// One indicator evaluation per feasible node (≈ 0.5 ms release).
    pub fn build(cell: &MillCell, spec: &GridSpec, threads: usize) -> Result<Self, MillPlanError> {
        if !(1..=2).contains(&threads) {
            return Err(MillPlanError::InvalidConfig {
                name: "cache build threads".to_string(),
                reason: format!("{threads}: must be 1 or 2"),
            });
        }
        Self::build_within(cell, spec, threads, &Budget::unlimited())
    }

    /// [`IndicatorCache::build`] under a time budget, checked before every
    /// node (one indicator evaluation, about 1 ms) on every worker thread,
    /// with up to [`crate::plan::MAX_EVAL_THREADS`] threads (the per-path
    /// caches of [`crate::path_cache`] use the planner's evaluation
    /// threads). The result does not depend on the thread count.
    ///
    /// # Errors
    /// As [`IndicatorCache::build`] (threads in 1..=`MAX_EVAL_THREADS`),
    /// and [`MillPlanError::Interrupted`] when the budget runs out or is
    /// cancelled (every worker stops at its next node).
    pub fn build_within(
        cell: &MillCell,
        spec: &GridSpec,
        threads: usize,
        budget: &Budget,
    ) -> Result<Self, MillPlanError> {
        spec.validate()?;
        if !(1..=crate::plan::MAX_EVAL_THREADS).contains(&threads) {
            return Err(MillPlanError::InvalidConfig {
                name: "cache build threads".to_string(),
                reason: format!(
                    "{threads}: must be in 1..={}",
                    crate::plan::MAX_EVAL_THREADS
                ),
            });
        }
        let n_seg = cell.path().segments().len();
        if spec.segments.last().is_some_and(|s| *s >= n_seg) {
            return Err(MillPlanError::InvalidConfig {
                name: "cache grid segments".to_string(),
                reason: format!("the path has {n_seg} segments"),
            });
        }
        let start = std::time::Instant::now();
        let columns: Vec<(usize, usize)> = (0..spec.segments.len())
            .flat_map(|s| (0..spec.g.len()).map(move |g| (s, g)))
            .collect();
        let results: Mutex<Vec<Option<ColumnResult>>> =
            Mutex::new((0..columns.len()).map(|_| None).collect());
        // Set by the first worker that meets an error (the budget, or the
        // model): the others stop before their next column.
        let failed = AtomicBool::new(false);
        let work = |t: usize| {
            for (k, (s, g)) in columns.iter().enumerate() {
                if k % threads != t {
                    continue;
                }
                if failed.load(Ordering::Relaxed) {
                    break;
                }
                let (Some(seg), Some(gv)) = (spec.segments.get(*s), spec.g.get(*g)) else {
                    continue;
                };
                let col = build_column(cell, spec, *seg, *gv, budget);
                if col.is_err() {
                    failed.store(true, Ordering::Relaxed);
                }
                if let Ok(mut r) = results.lock() {
                    if let Some(slot) = r.get_mut(k) {
                        *slot = Some(col);
                    }
                }
            }
        };
        std::thread::scope(|scope| {
            // Workers 1.. on helper threads (one the OS refuses to start is
            // not an error: its columns are built below), worker 0 here.
            for t in 1..threads {
                let work = &work;
                let _ = std::thread::Builder::new().spawn_scoped(scope, move || work(t));
            }
            work(0);
        });
        let results = results
            .into_inner()
            .map_err(|_| MillPlanError::InvalidConfig {
                name: "cache build".to_string(),
                reason: "a worker thread panicked".to_string(),
            })?;
        // The first error in column order wins, before any "not computed"
        // column (the workers stopped after an error).
        let mut results = results;
        if let Some(k) = results.iter().position(|r| matches!(r, Some(Err(_)))) {
            if let Some(Some(Err(e))) = results.get_mut(k).map(Option::take) {
                return Err(e);
            }
        }
        let mut values = vec![f64::NAN; spec.node_count()];
        for ((s, g), res) in columns.iter().zip(results) {
            let col = match res {
                Some(col) => col?,
                // A worker that did not start: its columns, here.
                None => match (spec.segments.get(*s), spec.g.get(*g)) {
                    (Some(seg), Some(gv)) => build_column(cell, spec, *seg, *gv, budget)?,
                    _ => None,
                },
            };
            if let Some(col) = col {
                for r in 0..spec.rpm.len() {
                    for f in 0..spec.feed.len() {
                        let v = col
                            .get(r * spec.feed.len() + f)
                            .copied()
                            .unwrap_or(f64::NAN);
                        if let Some(slot) = values.get_mut(spec.index(*s, r, f, *g)) {
                            *slot = v;
                        }
                    }
                }
            }
        }
        let infeasible_nodes = values.iter().filter(|v| v.is_nan()).count();
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let header = CacheHeader {
            grid: spec.clone(),
            cell_fingerprint: cell_fingerprint(cell),
            infeasible_nodes,
            build_seconds: start.elapsed().as_secs_f64(),
            threads,
            error: None,
            error_bound: None,
            error_g_nodes: None,
            error_bound_g_nodes: None,
            command: String::new(),
            data_checksum: format!("{:016x}", fnv1a(&bytes)),
        };
        Ok(Self { header, values })
    }

    /// The cache restricted to the nodes of `spec`, every one of which must
    /// be a node of this cache (exact match of the node values): the values
    /// are copied, nothing is evaluated. Used to choose the grid of a
    /// per-path cache ([`crate::path_cache`]) by the error a coarser grid
    /// would make at this cache's other nodes (`examples/path_cache_grid.rs`).
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] for a bad grid or a node of `spec`
    /// that this cache does not have.
    pub fn subgrid(&self, spec: &GridSpec) -> Result<Self, MillPlanError> {
        spec.validate()?;
        let grid = &self.header.grid;
        let find = |name: &str, nodes: &[f64], v: f64| {
            nodes
                .iter()
                .position(|n| *n == v)
                .ok_or_else(|| MillPlanError::InvalidConfig {
                    name: format!("cache subgrid {name}"),
                    reason: format!("{v} is not a node of the cache"),
                })
        };
        let seg_nodes: Vec<f64> = grid.segments.iter().map(|s| *s as f64).collect();
        let map = |name: &str, nodes: &[f64], want: &[f64]| -> Result<Vec<usize>, MillPlanError> {
            want.iter().map(|v| find(name, nodes, *v)).collect()
        };
        let want_seg: Vec<f64> = spec.segments.iter().map(|s| *s as f64).collect();
        let (si, ri, fi, gi) = (
            map("segments", &seg_nodes, &want_seg)?,
            map("rpm", &grid.rpm, &spec.rpm)?,
            map("feed", &grid.feed, &spec.feed)?,
            map("g", &grid.g, &spec.g)?,
        );
        let mut values = vec![f64::NAN; spec.node_count()];
        for (s, &os) in si.iter().enumerate() {
            for (r, &or) in ri.iter().enumerate() {
                for (f, &of) in fi.iter().enumerate() {
                    for (g, &og) in gi.iter().enumerate() {
                        let v = self
                            .values
                            .get(grid.index(os, or, of, og))
                            .copied()
                            .unwrap_or(f64::NAN);
                        if let Some(slot) = values.get_mut(spec.index(s, r, f, g)) {
                            *slot = v;
                        }
                    }
                }
            }
        }
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let header = CacheHeader {
            grid: spec.clone(),
            infeasible_nodes: values.iter().filter(|v| v.is_nan()).count(),
            error: None,
            error_bound: None,
            error_g_nodes: None,
            error_bound_g_nodes: None,
            command: String::new(),
            data_checksum: format!("{:016x}", fnv1a(&bytes)),
            ..self.header.clone()
        };
        Ok(Self { header, values })
    }

    /// The header (grid, fingerprint, error statistics, bound).
    pub fn header(&self) -> &CacheHeader {
        &self.header
    }

    /// The grid.
    pub fn grid(&self) -> &GridSpec {
        &self.header.grid
    }

    /// The stored value at a node (`None` for an infeasible node or an
    /// index out of range).
    pub fn node_value(&self, s: usize, r: usize, f: usize, g: usize) -> Option<f64> {
        let grid = &self.header.grid;
        if s >= grid.segments.len()
            || r >= grid.rpm.len()
            || f >= grid.feed.len()
            || g >= grid.g.len()
        {
            return None;
        }
        self.values
            .get(grid.index(s, r, f, g))
            .copied()
            .filter(|v| !v.is_nan())
    }

    /// Sets the measured error statistics and stated bounds (general
    /// queries, and queries with g on a node) and the build command
    /// (written to the header by [`IndicatorCache::save`]).
    ///
    /// # Errors
    /// [`MillPlanError::InvalidParameter`] for a NaN or negative bound.
    pub fn set_error(
        &mut self,
        general: (Option<ErrorStats>, Option<f64>),
        g_nodes: (Option<ErrorStats>, Option<f64>),
        command: &str,
    ) -> Result<(), MillPlanError> {
        for b in [general.1, g_nodes.1].into_iter().flatten() {
            if !(b.is_finite() && b >= 0.0) {
                return Err(MillPlanError::InvalidParameter {
                    name: "cache error bound [-]".to_string(),
                    value: b,
                    reason: "must be finite and >= 0".to_string(),
                });
            }
        }
        self.header.error = general.0;
        self.header.error_bound = general.1;
        self.header.error_g_nodes = g_nodes.0;
        self.header.error_bound_g_nodes = g_nodes.1;
        self.header.command = command.to_string();
        Ok(())
    }

    /// Interpolated |μ|max, or `None` when the query is outside the grid or
    /// its interpolation cell has an infeasible corner with non-zero weight
    /// (module documentation).
    ///
    /// # Errors
    /// [`MillPlanError::InvalidParameter`] for NaN inputs.
    pub fn try_query(
        &self,
        segment: usize,
        rpm: f64,
        feed: f64,
        g: f64,
    ) -> Result<Option<f64>, MillPlanError> {
        for (name, v) in [
            ("spindle speed [rpm]", rpm),
            ("feed [m/s]", feed),
            ("g [rad]", g),
        ] {
            if v.is_nan() {
                return Err(MillPlanError::InvalidParameter {
                    name: name.to_string(),
                    value: v,
                    reason: "is NaN".to_string(),
                });
            }
        }
        let grid = &self.header.grid;
        let seg_nodes: Vec<f64> = grid.segments.iter().map(|s| *s as f64).collect();
        let Some(bs) = bracket(&seg_nodes, segment as f64) else {
            return Ok(None);
        };
        let (Some(br), Some(bf), Some(bg)) = (
            bracket(&grid.rpm, rpm),
            bracket(&grid.feed, feed),
            bracket(&grid.g, g),
        ) else {
            return Ok(None);
        };
        let mut acc = 0.0;
        for cs in 0..2usize {
            let ws = if cs == 0 { 1.0 - bs.1 } else { bs.1 };
            if ws == 0.0 {
                continue;
            }
            for cr in 0..2usize {
                let wr = if cr == 0 { 1.0 - br.1 } else { br.1 };
                if wr == 0.0 {
                    continue;
                }
                for cf in 0..2usize {
                    let wf = if cf == 0 { 1.0 - bf.1 } else { bf.1 };
                    if wf == 0.0 {
                        continue;
                    }
                    for cg in 0..2usize {
                        let wg = if cg == 0 { 1.0 - bg.1 } else { bg.1 };
                        if wg == 0.0 {
                            continue;
                        }
                        let idx = grid.index(bs.0 + cs, br.0 + cr, bf.0 + cf, bg.0 + cg);
                        match self.values.get(idx) {
                            Some(v) if !v.is_nan() => acc += ws * wr * wf * wg * v,
                            _ => return Ok(None),
                        }
                    }
                }
            }
        }
        Ok(Some(acc))
    }

    /// Interpolated |μ|max ([`IndicatorCache::try_query`]).
    ///
    /// # Errors
    /// [`MillPlanError::InvalidParameter`] for NaN inputs, or when the query
    /// is outside the grid or next to an infeasible node (the message says
    /// which; evaluate directly with [`direct_indicator`] instead).
    pub fn query(&self, segment: usize, rpm: f64, feed: f64, g: f64) -> Result<f64, MillPlanError> {
        self.try_query(segment, rpm, feed, g)?
            .ok_or_else(|| MillPlanError::InvalidConfig {
                name: "indicator cache query".to_string(),
                reason: format!(
                    "(segment {segment}, {rpm} rpm, {feed} m/s, g = {g} rad) is outside the grid \
                     or next to an infeasible node: evaluate it directly"
                ),
            })
    }

    /// A-priori interpolation error estimate: for multilinear interpolation
    /// `|e| ≤ Σ_i h_i²/8 · max|∂²μ/∂x_i²|` (tensor-product linear
    /// interpolation, e.g. Davis, "Interpolation and Approximation", §3.1);
    /// each second derivative is estimated by the second divided difference
    /// `2[(u₂−u₁)/h₂ − (u₁−u₀)/h₁]/(h₁+h₂)` over all feasible node triples,
    /// and the sum is multiplied by a safety factor 2 (the largest
    /// curvature between nodes can exceed the sampled one). An axis with 2
    /// nodes has no triple and contributes nothing: use ≥ 3 nodes per axis
    /// for a meaningful bound.
    pub fn curvature_bound(&self) -> f64 {
        let grid = &self.header.grid;
        let seg: Vec<f64> = grid.segments.iter().map(|s| *s as f64).collect();
        let axes: [&[f64]; 4] = [&seg, &grid.rpm, &grid.feed, &grid.g];
        let dims = [seg.len(), grid.rpm.len(), grid.feed.len(), grid.g.len()];
        let mut total = 0.0;
        for (axis, nodes) in axes.iter().enumerate() {
            let hmax = nodes.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
            let mut dmax: f64 = 0.0;
            for s in 0..dims[0] {
                for r in 0..dims[1] {
                    for f in 0..dims[2] {
                        for g in 0..dims[3] {
                            let mut idx = [s, r, f, g];
                            let i = idx[axis];
                            if i + 2 >= dims[axis] {
                                continue;
                            }
                            let mut u = [0.0; 3];
                            let mut ok = true;
                            for (k, uk) in u.iter_mut().enumerate() {
                                idx[axis] = i + k;
                                match self.node_value(idx[0], idx[1], idx[2], idx[3]) {
                                    Some(v) => *uk = v,
                                    None => ok = false,
                                }
                            }
                            if !ok {
                                continue;
                            }
                            let (x0, x1, x2) = (nodes[i], nodes[i + 1], nodes[i + 2]);
                            let (h1, h2) = (x1 - x0, x2 - x1);
                            let d2 = 2.0 * ((u[2] - u[1]) / h2 - (u[1] - u[0]) / h1) / (h1 + h2);
                            dmax = dmax.max(d2.abs());
                        }
                    }
                }
            }
            total += hmax * hmax / 8.0 * dmax;
        }
        2.0 * total
    }

    /// Measures |cache − direct| at `count` random points (uniform segment
    /// index, Ω, f, g over the grid's range; direct evaluation with the
    /// cell's reference joints, as the nodes), skipping points where either
    /// is infeasible. With `g_on_nodes` each g is snapped to its nearest g
    /// node (the DP's queries).
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] when no point could be compared;
    /// model errors of [`direct_indicator`].
    pub fn measure_error(
        &self,
        cell: &MillCell,
        count: usize,
        seed: u64,
        g_on_nodes: bool,
    ) -> Result<ErrorStats, MillPlanError> {
        let grid = &self.header.grid;
        let mut rng = SplitMix64::new(seed);
        let mut errors = Vec::with_capacity(count);
        let mut skipped = 0;
        let (s0, s1) = (
            grid.segments.first().copied().unwrap_or(0),
            grid.segments.last().copied().unwrap_or(0),
        );
        let span = |a: &[f64]| {
            (
                a.first().copied().unwrap_or(0.0),
                a.last().copied().unwrap_or(0.0),
            )
        };
        let (r0, r1) = span(&grid.rpm);
        let (f0, f1) = span(&grid.feed);
        let (g0, g1) = span(&grid.g);
        for _ in 0..count {
            let seg = rng.integer(s0, s1);
            let rpm = rng.uniform(r0, r1);
            let feed = rng.uniform(f0, f1);
            let mut g = rng.uniform(g0, g1);
            if g_on_nodes {
                g = grid
                    .g
                    .iter()
                    .copied()
                    .min_by(|a, b| (a - g).abs().total_cmp(&(b - g).abs()))
                    .unwrap_or(g);
            }
            let cached = self.try_query(seg, rpm, feed, g)?;
            let direct = match direct_indicator(cell, seg, rpm, feed, g, None) {
                Ok(d) => d,
                Err(MillPlanError::Chatter(_)) => None,
                Err(e) => return Err(e),
            };
            match (cached, direct) {
                (Some(c), Some(d)) => errors.push((c - d).abs()),
                _ => skipped += 1,
            }
        }
        if errors.is_empty() {
            return Err(MillPlanError::InvalidConfig {
                name: "cache error measurement".to_string(),
                reason: format!("none of the {count} random points was feasible"),
            });
        }
        errors.sort_by(f64::total_cmp);
        let n = errors.len();
        let p99_index = ((0.99 * n as f64).ceil() as usize).clamp(1, n) - 1;
        Ok(ErrorStats {
            points: n,
            skipped,
            max_abs: errors.last().copied().unwrap_or(0.0),
            p99_abs: errors.get(p99_index).copied().unwrap_or(0.0),
            mean_abs: errors.iter().sum::<f64>() / n as f64,
            seed,
            g_on_nodes,
        })
    }

    /// The default cache file of the default cell,
    /// `crates/millplan/data/indicator_cache.bin` below the kerf data root
    /// ([`kerf_robot::data`]: `KERF_DATA_DIR`, the share directory beside the binary, the
    /// source tree).
    ///
    /// # Returns
    /// The path; when the data search fails, below the place it failed at
    /// ([`kerf_robot::data::default_path`]).
    pub fn default_path() -> std::path::PathBuf {
        kerf_robot::data::default_path("crates/millplan/data/indicator_cache.bin")
    }
}
