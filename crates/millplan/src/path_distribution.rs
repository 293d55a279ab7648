//! A distribution of planar milling paths inside the reachable workspace of
//! the cell (issue 13, item 4): what the shipped policy is trained on, and
//! the held-out paths it is evaluated on.
//!
//! # A path
//! Four coplanar points, as seed 004 section 4 builds its path ("a cubic
//! B-spline curve interpolating four coplanar control points";
//! [`kerf_mill::MillingPath`] fits it), 100 equal-arc segments, tool from
//! above. Drawn from [`PathDistribution`] with [`SplitMix64`] seeded by the
//! path's seed, so a seed names one path on every machine:
//! * the plane: its normal tilted from +z by θ ∈ [0, `max_tilt`] towards
//!   the azimuth φ ∈ [0, 2π);
//! * the heading ψ ∈ [−π, π) of the chord, projected into the plane;
//! * the chord length L ∈ `length`, the centre in the box `center_min`…
//!   `center_max`;
//! * the bend: the points sit at 0, L/3, 2L/3, L along the chord and are
//!   offset across it by w_k = b_k · `max_bend` · L, b_k ∈ [−1, 1] (b_0, b_3
//!   halved), which gives curvatures up to about 10 /m.
//!
//! # Accepted paths
//! A draw is kept only when the environment can machine it from the
//! paper's initial state under kerf's constraints ([`check_path`]):
//! 1. the cell builds it ([`MillCell::with_path`]);
//! 2. segment 0 is feasible at g0 with 1/K ≥ the minimum (the IVP);
//! 3. a g corridor exists: on a grid of g with spacing ≤ 0.05 rad, a
//!    sequence g_0 = g0, g_1, …, g_{N−1} with |g_{t+1} − g_t| ≤ the step
//!    bound and every (segment t, g_t) feasible with 1/K ≥ the minimum
//!    (forward reachability over the grid, IK from the cell's reference
//!    joints). This is `check_reachable` of the planner (some g per
//!    segment) made stronger by the step bound and the condition minimum.
//!
//! Otherwise the next draw of the same generator is tried (rejection
//! sampling, at most [`MAX_ATTEMPTS`] draws); [`SampledPath::attempts`]
//! says how many it took.
//!
//! # Training and held-out paths
//! [`training_paths`] are the seeds `TRAINING_SEED + i`,
//! [`held_out_paths`] the ten seeds of [`HELD_OUT_SEEDS`], disjoint from
//! them. The default path of seed 004 Table 1 is trained on as well
//! (it is the shipped planner's default request).

use std::sync::Arc;

use kerf_mill::{MillCell, PathSpec};
use nalgebra::Vector3;

use crate::cache::is_infeasible;
use crate::env::{EnvConfig, MillEnv};
use crate::error::MillPlanError;
use crate::rl::{Environment, Transition};
use crate::rng::SplitMix64;

/// Draws per path before [`sample_path`] gives up.
pub const MAX_ATTEMPTS: usize = 400;

/// First seed of the training paths.
pub const TRAINING_SEED: u64 = 1_000;

/// The seeds of the ten held-out paths (never trained on).
pub const HELD_OUT_SEEDS: [u64; 10] = [
    900_001, 900_002, 900_003, 900_004, 900_005, 900_006, 900_007, 900_008, 900_009, 900_010,
];

/// Largest spacing of the g grid of the corridor check \[rad\].
pub const CORRIDOR_SPACING: f64 = 0.05;

/// The ranges paths are drawn from (module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathDistribution {
    /// Lowest chord centre \[m\] (base frame).
    pub center_min: [f64; 3],
    /// Highest chord centre \[m\].
    pub center_max: [f64; 3],
    /// Chord length range \[m\].
    pub length: [f64; 2],
    /// Largest tilt of the plane normal from +z \[rad\].
    pub max_tilt: f64,
    /// Largest offset across the chord, as a fraction of its length.
    pub max_bend: f64,
    /// Segments per path.
    pub segments: usize,
    /// Redundancy angle of the initial state \[rad\] (seed 004: 0).
    pub initial_g: f64,
    /// Minimum 1/K of the corridor (the environment's
    /// [`crate::EnvConfig::min_condition_indicator`]).
    pub min_condition_indicator: f64,
}

impl Default for PathDistribution {
    /// Around the default path of seed 004 Table 1 (x 1.4–2.1 m, y ±0.3 m,
    /// z 1.7 m, 0.93 m long): centres x 1.5–2.0, y ±0.4, z 1.3–1.8 m,
    /// chords 0.4–1.0 m, planes tilted up to 20°, bends up to 0.2 L,
    /// 100 segments, g0 = 0, 1/K ≥ 0.35.
    fn default() -> Self {
        Self {
            center_min: [1.5, -0.4, 1.3],
            center_max: [2.0, 0.4, 1.8],
            length: [0.4, 1.0],
            max_tilt: 20f64.to_radians(),
            max_bend: 0.2,
            segments: 100,
            initial_g: 0.0,
            min_condition_indicator: crate::env_config::DEFAULT_MIN_CONDITION_INDICATOR,
        }
    }
}

/// One accepted path.
#[derive(Debug, Clone)]
pub struct SampledPath {
    /// The seed that names it.
    pub seed: u64,
    /// Draws it took (1 = the first was accepted).
    pub attempts: usize,
    /// The path.
    pub spec: PathSpec,
    /// The base cell with this path.
    pub cell: Arc<MillCell>,
}

/// `points` turned by `angle` \[rad\] about the vertical (base z) axis through their
/// centroid, then moved by `shift` \[m\]: a copy of a path elsewhere in the cell (the
/// baselines' "shifted, turned" path, which no shipped indicator cache covers).
pub fn moved_points(points: &[[f64; 3]], angle: f64, shift: [f64; 3]) -> Vec<[f64; 3]> {
    let n = points.len().max(1) as f64;
    let c = [0, 1, 2].map(|k| points.iter().map(|p| p[k]).sum::<f64>() / n);
    let (s, co) = angle.sin_cos();
    points
        .iter()
        .map(|p| {
            let (x, y) = (p[0] - c[0], p[1] - c[1]);
            [
                c[0] + co * x - s * y + shift[0],
                c[1] + s * x + co * y + shift[1],
                p[2] + shift[2],
            ]
        })
        .collect()
}

/// One draw (not checked).
pub fn draw(dist: &PathDistribution, rng: &mut SplitMix64) -> PathSpec {
    let tilt = rng.uniform(0.0, dist.max_tilt);
    let azimuth = rng.uniform(0.0, std::f64::consts::TAU);
    let heading = rng.uniform(-std::f64::consts::PI, std::f64::consts::PI);
    let length = rng.uniform(dist.length[0], dist.length[1]);
    let center: Vector3<f64> =
        Vector3::from_fn(|k, _| rng.uniform(dist.center_min[k], dist.center_max[k]));
    let bends: [f64; 4] = std::array::from_fn(|k| {
        let b = rng.uniform(-1.0, 1.0);
        if k == 0 || k == 3 {
            0.5 * b
        } else {
            b
        }
    });
    let normal = Vector3::new(
        tilt.sin() * azimuth.cos(),
        tilt.sin() * azimuth.sin(),
        tilt.cos(),
    );
    let h = Vector3::new(heading.cos(), heading.sin(), 0.0);
    // The heading projected into the plane (never zero: tilt ≤ 90°).
    let e1 = (h - h.dot(&normal) * normal).normalize();
    let e2 = normal.cross(&e1);
    let points = (0..4)
        .map(|k| {
            let along = (k as f64 / 3.0 - 0.5) * length;
            let across = bends[k] * dist.max_bend * length;
            let p = center + along * e1 + across * e2;
            [p.x, p.y, p.z]
        })
        .collect();
    PathSpec {
        points,
        segments: dist.segments,
        approach_from_above: true,
        up: [0.0, 0.0, 1.0],
    }
}

/// Whether `cell`'s path can be machined from g0 (module documentation,
/// "Accepted paths", items 2 and 3): `Ok(None)` when it can, `Ok(Some(why))`
/// when not.
///
/// # Errors
/// Cell-model errors other than infeasibility.
pub fn check_path(
    cell: &MillCell,
    initial_g: f64,
    min_condition_indicator: f64,
) -> Result<Option<String>, MillPlanError> {
    let lim = cell.state_limits();
    let [lo, hi] = lim.redundancy_angle;
    let feasible = |segment: usize, g: f64| -> Result<bool, MillPlanError> {
        match cell.evaluate(segment, g, None) {
            Ok(cs) => Ok(cs.condition_indicator >= min_condition_indicator),
            Err(e) if is_infeasible(&e) => Ok(false),
            Err(e) => Err(e.into()),
        }
    };
    if !feasible(0, initial_g)? {
        return Ok(Some(format!(
            "segment 0 is infeasible at g0 = {initial_g} (or 1/K < {min_condition_indicator})"
        )));
    }
    let intervals = ((hi - lo) / CORRIDOR_SPACING).ceil().max(1.0) as usize;
    let spacing = (hi - lo) / intervals as f64;
    let grid: Vec<f64> = (0..=intervals)
        .map(|k| lo + spacing * k as f64)
        .chain(std::iter::once(initial_g))
        .collect();
    // Segment 0 is machined at g0 (the last grid entry).
    let mut current: Vec<bool> = grid.iter().map(|g| *g == initial_g).collect();
    for segment in 1..cell.path().segments().len() {
        let mut next = vec![false; grid.len()];
        let mut any = false;
        for (k, &g) in grid.iter().enumerate() {
            let from = grid
                .iter()
                .zip(&current)
                .any(|(h, on)| *on && (g - h).abs() <= lim.max_redundancy_step + 1e-12);
            if from && feasible(segment, g)? {
                next[k] = true;
                any = true;
            }
        }
        if !any {
            return Ok(Some(format!(
                "no g corridor with 1/K >= {min_condition_indicator} reaches segment {segment}"
            )));
        }
        current = next;
    }
    Ok(None)
}

/// The path named by `seed` (module documentation).
///
/// # Errors
/// [`MillPlanError::InvalidConfig`] when no draw of [`MAX_ATTEMPTS`] is
/// accepted; cell-model errors other than infeasibility.
pub fn sample_path(
    base: &MillCell,
    dist: &PathDistribution,
    seed: u64,
) -> Result<SampledPath, MillPlanError> {
    let mut rng = SplitMix64::new(seed);
    let mut last = String::new();
    for attempt in 1..=MAX_ATTEMPTS {
        let spec = draw(dist, &mut rng);
        let cell = match base.with_path(&spec) {
            Ok(c) => c,
            Err(e) => {
                last = e.to_string();
                continue;
            }
        };
        match check_path(&cell, dist.initial_g, dist.min_condition_indicator)? {
            None => {
                return Ok(SampledPath {
                    seed,
                    attempts: attempt,
                    spec,
                    cell: Arc::new(cell),
                })
            }
            Some(why) => last = why,
        }
    }
    Err(MillPlanError::InvalidConfig {
        name: format!("path distribution (seed {seed})"),
        reason: format!("no accepted path in {MAX_ATTEMPTS} draws; the last: {last}"),
    })
}

/// The training paths: seeds `TRAINING_SEED .. TRAINING_SEED + count`.
///
/// # Errors
/// As [`sample_path`].
pub fn training_paths(
    base: &MillCell,
    dist: &PathDistribution,
    count: usize,
) -> Result<Vec<SampledPath>, MillPlanError> {
    (0..count as u64)
        .map(|i| sample_path(base, dist, TRAINING_SEED + i))
        .collect()
}

/// The ten held-out paths ([`HELD_OUT_SEEDS`]).
///
/// # Errors
/// As [`sample_path`].
pub fn held_out_paths(
    base: &MillCell,
    dist: &PathDistribution,
) -> Result<Vec<SampledPath>, MillPlanError> {
    HELD_OUT_SEEDS
        .iter()
        .map(|&seed| sample_path(base, dist, seed))
        .collect()
}

/// The milling environment over a set of paths: episode k runs on path
/// k mod n (round robin, so training is deterministic for a seed), every
/// path with the same [`EnvConfig`] (what [`crate::ddpg::train`] trains the
/// shipped policy on).
#[derive(Debug, Clone)]
pub struct PathSetEnv {
    envs: Vec<MillEnv>,
    episode: usize,
    active: usize,
}

impl PathSetEnv {
    /// One environment per cell, direct |μ|max (no cache: the cache holds
    /// the default cell only).
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] for no cell or cells of different
    /// segment counts; [`MillEnv::new`]'s errors.
    pub fn new(cells: &[Arc<MillCell>], config: EnvConfig) -> Result<Self, MillPlanError> {
        let envs = cells
            .iter()
            .map(|c| MillEnv::new(c.clone(), None, config))
            .collect::<Result<Vec<_>, _>>()?;
        let Some(first) = envs.first() else {
            return Err(MillPlanError::InvalidConfig {
                name: "path set".to_string(),
                reason: "needs at least one path".to_string(),
            });
        };
        let n = first.segment_count();
        if let Some(bad) = envs.iter().find(|e| e.segment_count() != n) {
            return Err(MillPlanError::InvalidConfig {
                name: "path set".to_string(),
                reason: format!(
                    "paths of {n} and {} segments (an episode has one length)",
                    bad.segment_count()
                ),
            });
        }
        Ok(Self {
            envs,
            episode: 0,
            active: 0,
        })
    }

    /// The environment of the current episode.
    pub fn active(&self) -> &MillEnv {
        &self.envs[self.active]
    }

    /// Number of paths.
    pub fn len(&self) -> usize {
        self.envs.len()
    }

    /// Whether there is no path (never: [`PathSetEnv::new`] refuses that).
    pub fn is_empty(&self) -> bool {
        self.envs.is_empty()
    }
}

impl Environment for PathSetEnv {
    fn observation_dim(&self) -> usize {
        self.envs[self.active].observation_dim()
    }

    fn action_dim(&self) -> usize {
        self.envs[self.active].action_dim()
    }

    fn observation_layout(&self) -> Vec<String> {
        self.envs[self.active].observation_layout()
    }

    fn max_steps(&self) -> usize {
        self.envs[self.active].max_steps()
    }

    fn reset(&mut self) -> Result<Vec<f32>, MillPlanError> {
        self.active = self.episode % self.envs.len();
        self.episode += 1;
        self.envs[self.active].reset()
    }

    fn step(&mut self, action: &[f32]) -> Result<Transition, MillPlanError> {
        self.envs[self.active].step(action)
    }
}
