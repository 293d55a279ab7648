//! The ROS-free front half of the milling planner node (issue 5 section 4):
//! a [`MillRequest`] in, a [`MillPlanOutput`] (per-segment plan, totals and
//! the IRB-6660 joint trajectory) or an error with a status category
//! ([`status_of`]) out.
//!
//! # Steps of [`MillPlanner::plan`]
//! 1. [`MillRequest::validate_with`] against the default cell's limits.
//! 2. The request's cell: the default cell with the request's path
//!    ([`kerf_mill::MillCell::with_path`]), process and limits. The cell
//!    with the path and process (and its fingerprint) is kept for the
//!    last 8 distinct (path, process) pairs: the path's spline fit and
//!    arc-length table cost 10–30 ms, paid by the first request with a
//!    path only (the memo is exact: the same inputs give the same cell).
//! 3. Reachability: every segment must have a feasible redundancy angle
//!    (the initial g0 first, then 65 equally spaced values of the g
//!    range); otherwise the cell's error of the least-violating g is
//!    returned (segment, joint and excess, or the distance beyond reach).
//!    The initial state itself must be feasible at segment 0.
//! 4. The planner: `ddpg`/`fixed_g` — greedy rollout of the policy in
//!    [`MillEnv`] (α and weights of [`MillPlanner::env_config`]); `dp` —
//!    the DP over the full state ranges from the request's initial state with
//!    the executed timing in its loop ([`crate::dp_executed::solve_executed`]:
//!    its answer holds as executed; issue 28, item 5); `naive` — [`crate::naive::solve`] at g = g0;
//!    `greedy` — [`crate::greedy::solve_within`] from the initial state at
//!    g = g0; `greedy_best_g` — [`crate::greedy::best_fixed_g_within`]
//!    (direct |μ|max, no cache: any path).
//!    A policy is applied to a request when it records the environment's
//!    observation layout ([`crate::observation`]: path-independent
//!    features, normalized by the REQUEST's limits) and action size, else
//!    [`MillPlanError::Policy`]. The environment keeps 1/K above
//!    [`EnvConfig::min_condition_indicator`] (0.35), raised to a request's
//!    `tolerances.min_condition_indicator` + 0.05 when that is higher, and
//!    for `ddpg` the joints 0.01 rad inside their limits
//!    ([`crate::env::PLANNER_JOINT_LIMIT_MARGIN`]). The
//!    shipped policies are trained on a
//!    distribution of planar paths ([`crate::path_distribution`]) and
//!    evaluated on held-out ones (`BENCHMARKS.md`, "Milling: a policy that
//!    generalizes"). A rollout that leaves the feasible set is a
//!    [`MillPlanError::Infeasible`] error (status INFEASIBLE: the path is valid, this planner
//!    cannot finish it); so is a path on which `fixed_g`, `greedy` or `naive`, which hold g
//!    at g0, find a segment infeasible at g0 (checked before planning, IK chained). The policy's moves pass the chatter
//!    shield ([`EnvConfig::chatter_shield`], [`crate::env::PLANNER_CHATTER_SHIELD`]).
//! 5. [`Plan::evaluate_with_threads`]: every segment evaluated directly
//!    (|μ|max never from the cache) on [`MillPlanner::eval_threads`]
//!    threads (the same plan, bit for bit, for every thread count), the
//!    totals.
//! 6. The joint trajectory ([`crate::trajectory::JointTrajectory`],
//!    [`crate::planned`]).
//! 7. What the robot runs ([`MillPlanOutput::executed`]): the dense
//!    trajectory from rest to rest with smooth Ω, f and g along the path,
//!    within the joints' velocity, acceleration and jerk limits and the
//!    path tolerance (the request's `tolerances.path_tolerance`, else
//!    [`MillPlanner::trajectory_settings`]; [`crate::timing::time_scale`]:
//!    slowed where the planned feeds ask too much of a joint, never sped
//!    up; the tool path measured with the executor's own interpolation at
//!    its control period), and the plan at the feeds that result, |μ|max
//!    re-evaluated directly where a feed changed ([`Plan::as_executed`]).
//! 8. A request's `tolerances.min_condition_indicator`: the smallest 1/K
//!    over the trajectory's points must reach it, else
//!    [`MillPlanError::IllConditioned`] (status ILL_CONDITIONED) with the
//!    value, the arc length and the segment.
//! 9. The shield's rounds (`ddpg`, `fixed_g`): a plan that chatters as
//!    executed (step 7) is planned again from step 4, the shield judging
//!    each segment also at its executed feed and g held around the
//!    segments slowed into chatter, then with a lower limit, at
//!    most [`SHIELD_ROUNDS`] plans in all; the best is answered
//!    ([`MillPlanOutput::phases`] are the answered plan's,
//!    [`MillPlanOutput::planning_seconds`] all rounds'). A round that
//!    runs out of the time budget ends the rounds with the plan in hand
//!    (the first plan's timeout is TIMEOUT as always); a cancellation is
//!    an error.
//!
//! # When the indicator cache applies
//! The cache ([`IndicatorCache`]) holds |μ|max of the DEFAULT cell. It
//! applies to a request's cell when that cell, with the default cell's
//! state limits, has the default cell's [`cell_fingerprint`]: the cached
//! values do not depend on the limits (they depend on the path geometry,
//! the process, the dynamics and the reference joints), so a request that
//! only narrows or widens the limits or changes the initial state still
//! uses it (queries outside its grid fall back to direct evaluation in the
//! environment, and are infeasible states for the DP and the naive
//! screening: conservative, never wrong). A request with another path or
//! process cannot use it: `dp` and `naive` then use a per-path cache of
//! the request's own cell, built on first use under the request's budget
//! and kept for the last 8 (path, process, grid) ([`crate::path_cache`];
//! also when the default cache did not load, and when the request's
//! spindle-speed range or largest feed reaches beyond its grid); `ddpg` and `fixed_g`
//! evaluate directly (slower, same result); `greedy` and `greedy_best_g`
//! always evaluate directly.
//!
//! # Trajectory
//! Step 6 builds the planned joint trajectory ([`crate::planned`]: path
//! start, segment midpoints, path end, in the executor's trajectory type
//! [`crate::trajectory::JointTrajectory`]); step 7 time-scales it
//! ([`crate::executed`]).
//!
//! # Overlap
//! With direct |μ|max (the default source, or the cache source when the
//! cache does not apply) the steps share the [`MillPlanner::eval_threads`]
//! threads instead of running one after the other; the answer is the
//! sequential one bit for bit (every value is the same function of the same
//! inputs; only when it is computed changes), and errors are reported in the
//! order of the steps:
//! * During a `ddpg`/`fixed_g` rollout (≥ 2 threads), a helper thread
//!   evaluates |μ|max of each state as the policy reaches it
//!   (`evaluation::Prefetch`); step 5 keeps its values for the
//!   longest prefix of the final states it saw unchanged.
//! * Step 7 up to the executed plan's assembly (the time scaling and the
//!   direct |μ|max of the segments it slows, `plan::Reevaluation`)
//!   reads the segments' Ω, f, g and cell states, never their |μ|max: it runs
//!   on its own thread as soon as step 5's cell states are known, and that
//!   thread then joins step 5's remaining evaluations
//!   (`evaluation::evaluate_direct_alongside`). With 1 thread the
//!   steps run in order.
//!
//! [`MillPlanOutput::phases`] then has: `evaluation`, the wall time from the
//! start of step 5 until every |μ|max of the plan is known (step 7 ran
//! inside it); `trajectory`, the rest until the executed plan is assembled.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Instant, SystemTime};

use kerf_budget::Budget;
use kerf_mill::{MillCell, MillError, PathSpec, StateLimits};

use crate::cache::{cell_fingerprint, is_infeasible, IndicatorCache};
use crate::dp::{self, DpSpec};
use crate::env::{EnvConfig, MillEnv, PhysicalState};
use crate::error::MillPlanError;
use crate::evaluation::{evaluate_direct_alongside, Prefetch};
use crate::executed::executed;
use crate::greedy;
use crate::naive;
use crate::observation::OBSERVATION_LAYOUT;
use crate::path_cache::{path_grid, PathCacheKey, PathCaches};
use crate::plan::{
    default_eval_threads, IndicatorProvenance, IndicatorSource, Plan, Reevaluation, SegmentInput,
};
use crate::planned::planned_trajectory;
use crate::policy::{resolve_policy_file, Policy};
use crate::request::{MillRequest, PlannerKind, RequestProcess};
use crate::rl::Environment;
use crate::timing::{joint_limits, time_scale_inputs, TrajectorySettings};

pub use crate::executed::{execute, Executed};
pub use crate::output::{Candidate, MillPlanOutput, PlanningPhases};
pub use crate::status::{self, status_name, status_of};

/// The shipped policy of a planner: `crates/millplan/policies/ddpg.safetensors`
/// and `…/fixed_g.safetensors` below the kerf data root ([`kerf_robot::data`]:
/// `KERF_DATA_DIR`, the share directory beside the binary, the source tree); `None` for `dp`
/// and `naive`. When the data search fails the path is below the place it failed at
/// ([`kerf_robot::data::default_path`]) and reading it fails naming that path.
pub fn default_policy_path(planner: PlannerKind) -> Option<PathBuf> {
    let dir = kerf_robot::data::default_path("crates/millplan/policies");
    match planner {
        PlannerKind::Ddpg => Some(dir.join("ddpg.safetensors")),
        PlannerKind::FixedG => Some(dir.join("fixed_g.safetensors")),
        PlannerKind::Dp
        | PlannerKind::Naive
        | PlannerKind::Greedy
        | PlannerKind::GreedyBestG
        | PlannerKind::Best => None,
    }
}

/// Distinct (path, process) pairs of requests whose cells
/// [`MillPlanner`] keeps (most recently used last).
const MODEL_MEMO: usize = 8;

/// Plans of a policy (`ddpg`, `fixed_g`) per request at most, with the
/// chatter shield ([`EnvConfig::chatter_shield`]). When a plan chatters as
/// executed, the next round plans again ([`ShieldRound::next`]): first with
/// the shield judging each segment also at the feed the executed trajectory
/// ran it at ([`MillEnv::with_shield_slowdown`]) and g held around the
/// segments it slowed into chatter ([`MillEnv::with_held_g`]), then with
/// the limit lowered by [`SHIELD_LIMIT_STEP`]. The best plan is answered
/// ([`shield_prefers`]).
/// Why: the executed trajectory slows the segments where the joints are
/// the limit, and on the default cell |μ|max rises as the feed falls, so a
/// plan chatter-free as planned can chatter as executed; a lower limit from
/// the start makes the shield intervene more often, and its g moves are
/// what slows the trajectory (measured in `BENCHMARKS.md`, "Milling: a
/// policy that generalizes").
pub const SHIELD_ROUNDS: usize = 6;

/// How much each lowering round of [`SHIELD_ROUNDS`] lowers the shield's
/// limit.
pub const SHIELD_LIMIT_STEP: f64 = 0.02;

/// One round of [`SHIELD_ROUNDS`]: the shield's limit, the slowdown it
/// assumes and the moves whose g it holds.
#[derive(Debug, Clone, PartialEq)]
struct ShieldRound {
    /// [`EnvConfig::chatter_shield`] of the round.
    limit: Option<f64>,
    /// [`MillEnv::with_shield_slowdown`] of the round (`None`: the planned
    /// feeds).
    slowdown: Option<Arc<[f64]>>,
    /// [`MillEnv::with_held_g`] of the round (`None`: no move held).
    held: Option<Arc<[bool]>>,
}

impl ShieldRound {
    /// The first round: the planner's limit, the planned feeds, no move held.
    fn first(limit: Option<f64>) -> Self {
        Self {
            limit,
            slowdown: None,
            held: None,
        }
    }

    /// The round after this one, whose plan ran as `executed`:
    /// * after a round at the planned feeds, the same limit with the
    ///   executed slowdown and g held on the moves from [`HOLD_REACH`]
    ///   segments before to one after every segment that the executed
    ///   trajectory slowed (by more than
    ///   [`crate::dp_executed::SLOWDOWN_TOLERANCE`]) and that chatters as
    ///   executed, when there is either;
    /// * else the limit lowered by [`SHIELD_LIMIT_STEP`], at the planned
    ///   feeds with no move held;
    ///
    /// `None` without a shield or when the limit would reach 0.
    fn next(&self, executed: &crate::executed::Executed) -> Option<Self> {
        let limit = self.limit?;
        let measured = &executed.scaling.segment_slowdown;
        let slowdown: Arc<[f64]> = match &self.slowdown {
            Some(s) => s.iter().zip(measured).map(|(a, b)| a.max(*b)).collect(),
            None => measured.iter().copied().collect(),
        };
        let mut held: Vec<bool> = match &self.held {
            Some(h) => h.to_vec(),
            None => vec![false; measured.len()],
        };
        for (i, (segment, c)) in executed.plan.segments.iter().zip(measured).enumerate() {
            if segment.spectral_radius >= 1.0 && *c > crate::dp_executed::SLOWDOWN_TOLERANCE {
                let end = (i + 1).min(held.len().saturating_sub(1));
                for slot in held
                    .iter_mut()
                    .take(end + 1)
                    .skip(i.saturating_sub(HOLD_REACH))
                {
                    *slot = true;
                }
            }
        }
        let slowed = slowdown.iter().any(|c| *c > 1.0);
        let holds = held.iter().any(|h| *h);
        if self.slowdown.is_none() && self.held.is_none() && (slowed || holds) {
            return Some(Self {
                limit: Some(limit),
                slowdown: slowed.then_some(slowdown),
                held: holds.then(|| held.into()),
            });
        }
        let lowered = limit - SHIELD_LIMIT_STEP;
        (lowered > 0.0).then_some(Self::first(Some(lowered)))
    }
}

/// One candidate planner and its plan or error ([`MillPlanner::plan_each`]).
type CandidatePlan = (PlannerKind, Result<MillPlanOutput, MillPlanError>);

/// The smallest condition indicator 1/K along the trajectory [`PlannerKind::Best`] accepts
/// when the request asks for none (issue 28, item 3).
pub const BEST_MIN_CONDITION_INDICATOR: f64 = 0.3;

/// [`MillPlanError::Chattering`] of the plan `out` (its worst executed sample).
fn chattering(out: &MillPlanOutput, planner: &str, reason: String) -> MillPlanError {
    let worst = out
        .executed
        .chatter
        .worst
        .unwrap_or(crate::chatter_judge::JudgedSample {
            time: 0.0,
            arc_length: 0.0,
            segment: 0,
            rpm: 0.0,
            feed: 0.0,
            g: 0.0,
            spectral_radius: out.executed.plan.max_spectral_radius,
        });
    MillPlanError::Chattering {
        planner: planner.to_string(),
        worst: Box::new(worst),
        lowest: Some((
            out.planner.name().to_string(),
            out.executed.plan.max_spectral_radius,
        )),
        reason,
    }
}

/// The plan segment at the trajectory point of arc length `arc_length` (0 if none).
fn segment_at(executed: &Executed, arc_length: f64) -> usize {
    let points = &executed.scaling.trajectory;
    points
        .arc_length
        .iter()
        .position(|s| *s == arc_length)
        .and_then(|k| points.segment.get(k).copied())
        .unwrap_or(0)
}

/// Moves held before a segment slowed into chatter ([`ShieldRound::next`]):
/// the executed g(s) is a cubic spline through the midpoints, so a move
/// shapes the neighbouring intervals too.
const HOLD_REACH: usize = 2;

/// Whether the shield's new plan `a` is better than `b`: chatter-free as
/// executed before chattering; among chatter-free plans the shorter
/// executed time; among chattering ones the lower executed |μ|max.
fn shield_prefers(a: &MillPlanOutput, b: &MillPlanOutput) -> bool {
    let (a, b) = (&a.executed.plan, &b.executed.plan);
    match (a.chatter_free, b.chatter_free) {
        (true, false) => true,
        (false, true) => false,
        (true, true) => a.total_time < b.total_time,
        (false, false) => a.max_spectral_radius < b.max_spectral_radius,
    }
}

/// What a request's cell depends on besides the limits (the memo key of
/// `MillPlanner::model_cell`).
#[derive(Debug, Clone, PartialEq)]
struct RequestModel {
    path: PathSpec,
    process: Option<RequestProcess>,
}

#[derive(Debug)]
struct CachedPolicy {
    policy: Arc<Policy>,
    stamp: Option<(SystemTime, u64)>,
}

/// The planner (module documentation). `plan` takes `&self`: one planner
/// can serve requests from several threads.
#[derive(Debug)]
pub struct MillPlanner {
    cell: Arc<MillCell>,
    fingerprint: String,
    cache: Option<Arc<IndicatorCache>>,
    cache_note: String,
    env_config: EnvConfig,
    eval_threads: usize,
    indicator_source: IndicatorSource,
    trajectory_settings: TrajectorySettings,
    models: Mutex<Vec<(RequestModel, Arc<MillCell>, bool)>>,
    policies: Mutex<HashMap<PathBuf, CachedPolicy>>,
    path_caches: PathCaches,
    default_policies: HashMap<PlannerKind, PathBuf>,
}

fn file_stamp(path: &Path) -> Option<(SystemTime, u64)> {
    let m = std::fs::metadata(path).ok()?;
    Some((m.modified().ok()?, m.len()))
}

impl MillPlanner {
    /// A planner for `cell` with an optional indicator cache.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] when the cache was built for
    /// another cell (fingerprint mismatch).
    pub fn new(
        cell: Arc<MillCell>,
        cache: Option<Arc<IndicatorCache>>,
    ) -> Result<Self, MillPlanError> {
        let fingerprint = cell_fingerprint(&cell);
        if let Some(c) = &cache {
            if c.header().cell_fingerprint != fingerprint {
                return Err(MillPlanError::InvalidConfig {
                    name: "indicator cache".to_string(),
                    reason: format!(
                        "built for cell fingerprint {}, the planner's cell is {fingerprint}",
                        c.header().cell_fingerprint
                    ),
                });
            }
        }
        let cache_note = if cache.is_some() {
            "loaded".to_string()
        } else {
            "no indicator cache was given".to_string()
        };
        Ok(Self {
            cell,
            fingerprint,
            cache,
            cache_note,
            env_config: EnvConfig {
                chatter_shield: Some(crate::env::PLANNER_CHATTER_SHIELD),
                ..EnvConfig::default()
            },
            eval_threads: default_eval_threads(),
            indicator_source: IndicatorSource::Direct,
            trajectory_settings: TrajectorySettings::default(),
            models: Mutex::new(Vec::new()),
            policies: Mutex::new(HashMap::new()),
            path_caches: PathCaches::new(),
            default_policies: HashMap::new(),
        })
    }

    /// The default cell with the default cache
    /// ([`IndicatorCache::default_path`]) when it loads fresh; a missing or
    /// stale cache is logged (warning) and the planner runs without it.
    ///
    /// # Errors
    /// The cell's load errors.
    pub fn with_default_cell() -> Result<Self, MillPlanError> {
        let cell = Arc::new(MillCell::default_cell()?);
        let path = IndicatorCache::default_path();
        match IndicatorCache::load(&path, &cell) {
            Ok(cache) => Self::new(cell, Some(Arc::new(cache))),
            Err(e) => {
                log::warn!("milling planner: indicator cache not used: {e}");
                let mut planner = Self::new(cell, None)?;
                planner.cache_note = format!("the indicator cache did not load: {e}");
                Ok(planner)
            }
        }
    }

    /// Replaces the environment settings of `ddpg`/`fixed_g` (reward
    /// weights, α, penalty; the initial state and `fixed_g` are set per
    /// request) and the reward weights of every plan. The planner's own
    /// default is [`EnvConfig::default`] with the chatter shield
    /// [`crate::env::PLANNER_CHATTER_SHIELD`]; a config given here is taken
    /// as it is (`chatter_shield: None` switches the shield off).
    pub fn with_env_config(mut self, config: EnvConfig) -> Self {
        self.env_config = config;
        self
    }

    /// Sets the number of threads of the plan evaluation (step 5,
    /// [`Plan::evaluate_with_threads`]; default [`default_eval_threads`]).
    /// The plan does not depend on it (bit for bit); only the latency does.
    ///
    /// # Arguments
    /// * `threads` — 1 = sequential; at most [`crate::plan::MAX_EVAL_THREADS`]
    ///   are used.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidParameter`] for 0.
    pub fn with_eval_threads(mut self, threads: usize) -> Result<Self, MillPlanError> {
        if threads == 0 {
            return Err(MillPlanError::InvalidParameter {
                name: "evaluation threads".to_string(),
                value: 0.0,
                reason: "must be >= 1".to_string(),
            });
        }
        self.eval_threads = threads;
        Ok(self)
    }

    /// The policy a `ddpg` or `fixed_g` plan uses when its request names none, instead of
    /// [`default_policy_path`] (a node's configured policies; also the candidates of
    /// [`PlannerKind::Best`]).
    pub fn with_default_policy(mut self, kind: PlannerKind, path: PathBuf) -> Self {
        self.default_policies.insert(kind, path);
        self
    }

    /// The number of threads of the plan evaluation.
    pub fn eval_threads(&self) -> usize {
        self.eval_threads
    }

    /// Sets where the plan's |μ|max comes from (step 5).
    /// [`IndicatorSource::Direct`] (the default): every segment evaluated
    /// directly. [`IndicatorSource::Cache`]: when the default cell's cache
    /// applies to the request (module documentation) and states an error
    /// bound, each segment that the cache answers on the state's IK branch
    /// takes the cache's interpolated |μ|max (microseconds instead of
    /// about 1.25 ms), the others are evaluated directly; the answer's
    /// [`MillPlanOutput::indicator`] lists the cached segments and the
    /// bound, and `chatter_free` is claimed only where |μ|max + bound < 1.
    /// Otherwise the evaluation is direct and the note says why.
    ///
    /// # Arguments
    /// * `source` — the source.
    ///
    /// # Returns
    /// The planner with the source set.
    pub fn with_indicator_source(mut self, source: IndicatorSource) -> Self {
        self.indicator_source = source;
        self
    }

    /// Where the plan's |μ|max comes from ([`MillPlanner::with_indicator_source`]).
    pub fn indicator_source(&self) -> IndicatorSource {
        self.indicator_source
    }

    /// With the settings of the executed trajectory (path tolerance,
    /// control period, ramp time, point limit; [`TrajectorySettings`]).
    ///
    /// # Errors
    /// [`MillPlanError::InvalidParameter`] for a bad setting.
    pub fn with_trajectory_settings(
        mut self,
        settings: TrajectorySettings,
    ) -> Result<Self, MillPlanError> {
        settings.validate()?;
        self.trajectory_settings = settings;
        Ok(self)
    }

    /// The settings of the executed trajectory.
    pub fn trajectory_settings(&self) -> &TrajectorySettings {
        &self.trajectory_settings
    }

    /// The environment settings.
    pub fn env_config(&self) -> &EnvConfig {
        &self.env_config
    }

    /// The default cell.
    pub fn cell(&self) -> &Arc<MillCell> {
        &self.cell
    }

    /// The default cell's indicator cache, if loaded.
    pub fn cache(&self) -> Option<&Arc<IndicatorCache>> {
        self.cache.as_ref()
    }

    /// The policy at `path` (relative paths: to the working directory),
    /// loaded on first use and kept; reloaded when the weights file's
    /// modification time or size changes.
    ///
    /// # Errors
    /// [`Policy::load`]'s [`MillPlanError::Policy`] errors.
    pub fn policy(&self, path: &Path) -> Result<Arc<Policy>, MillPlanError> {
        let stamp = file_stamp(path);
        let mut map = self.policies.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(c) = map.get(path) {
            if c.stamp.is_some() && c.stamp == stamp {
                return Ok(c.policy.clone());
            }
        }
        let policy = Arc::new(Policy::load(path)?);
        map.insert(
            path.to_path_buf(),
            CachedPolicy {
                policy: policy.clone(),
                stamp,
            },
        );
        Ok(policy)
    }

    /// The request's cell and whether the default cache applies to it
    /// (module documentation).
    fn request_cell(
        &self,
        request: &MillRequest,
        limits: StateLimits,
    ) -> Result<(Arc<MillCell>, bool), MillPlanError> {
        let segments = self.cell.path().segments().len();
        let key = RequestModel {
            path: request.path_spec(segments),
            process: request.process,
        };
        let (model_cell, same_model) = self.model_cell(key)?;
        let cell = model_cell.with_state_limits(limits)?;
        Ok((Arc::new(cell), same_model && self.cache.is_some()))
    }

    /// The default cell with a request's path and process, and whether it
    /// has the default cell's fingerprint: from the memo of the last
    /// [`MODEL_MEMO`] distinct (path, process) pairs when there, else
    /// built (the path's spline fit and arc-length table, about 10–30 ms
    /// in release on the shared 2-core machine, and the fingerprint,
    /// about 1 ms) and kept. A pure function of the key and the planner's
    /// default cell, so the memo never changes a plan.
    ///
    /// # Errors
    /// [`MillCell::with_path`] / [`MillCell::with_process`] errors (not
    /// kept).
    fn model_cell(&self, key: RequestModel) -> Result<(Arc<MillCell>, bool), MillPlanError> {
        {
            let mut memo = self.models.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(k) = memo.iter().position(|(m, _, _)| *m == key) {
                let entry = memo.remove(k);
                let hit = (entry.1.clone(), entry.2);
                memo.push(entry);
                return Ok(hit);
            }
        }
        let mut cell = self.cell.with_path(&key.path)?;
        if let Some(p) = &key.process {
            cell = cell.with_process(p.to_process())?;
        }
        let same_model = cell_fingerprint(&cell) == self.fingerprint;
        let cell = Arc::new(cell);
        let mut memo = self.models.lock().unwrap_or_else(|e| e.into_inner());
        if !memo.iter().any(|(m, _, _)| *m == key) {
            memo.push((key, cell.clone(), same_model));
            if memo.len() > MODEL_MEMO {
                memo.remove(0);
            }
        }
        Ok((cell, same_model))
    }

    /// The per-path indicator cache of a request whose cell the default
    /// cache does not apply to ([`crate::path_cache`]): kept from an earlier
    /// request with the same path, process and grid, else built on the
    /// planner's evaluation threads under `budget`.
    ///
    /// # Errors
    /// [`path_grid`] and [`PathCaches::get_or_build`] errors, among them
    /// [`MillPlanError::Interrupted`].
    fn path_cache(
        &self,
        request: &MillRequest,
        cell: &MillCell,
        g0: f64,
        budget: &Budget,
    ) -> Result<Arc<IndicatorCache>, MillPlanError> {
        let key = PathCacheKey {
            path: request.path_spec(self.cell.path().segments().len()),
            process: request.process,
            grid: path_grid(cell, g0)?,
        };
        let (cache, _) = self
            .path_caches
            .get_or_build(key, cell, self.eval_threads, budget)?;
        Ok(cache)
    }

    /// The per-path indicator caches kept ([`crate::path_cache`]).
    pub fn path_caches(&self) -> &PathCaches {
        &self.path_caches
    }

    /// Plans a request (module documentation).
    ///
    /// # Errors
    /// Validation errors (INVALID_REQUEST); the cell's
    /// [`MillError::Unreachable`] / [`MillError::JointLimit`] with the
    /// segment (UNREACHABLE); [`MillPlanError::Policy`] for a missing or
    /// incompatible policy file; [`MillPlanError::Infeasible`] for a rollout that leaves the
    /// feasible set or a held g infeasible on some segment; [`MillPlanError::Chattering`] for a
    /// plan that chatters as executed (unless the request allows chatter);
    /// [`MillPlanError::InvalidConfig`] when `greedy_best_g` finds no
    /// fixed g feasible on every segment, or `dp`/`naive` find no plan on
    /// their grid; chatter-model errors; see [`status_of`].
    ///
    /// # Performance
    /// Dominated by the N direct indicator evaluations of step 5 (about
    /// 0.5–0.65 ms of CPU each on the 2-core build machine) and, for `dp`,
    /// the DP (seconds on the full grid); [`MillPlanOutput::phases`] has the
    /// wall time of each step (with direct |μ|max and ≥ 2 threads the steps
    /// overlap: module documentation, "Overlap"). Measured in release
    /// (`cargo bench -p kerf_millplan --bench plan_latency -- --warm-up-time 1
    /// --measurement-time 5`, default 100-segment request, the shipped ddpg
    /// policy, request cell kept from an earlier plan) on the shared 2-core
    /// machine; the figures, the load they were measured under and where the
    /// CPU time goes are in `BENCHMARKS.md`, "Planning one 100-segment path
    /// (goal ≤ 50 ms)". For the default ddpg request with direct |μ|max on 2
    /// threads the plan costs about 90–97 ms of CPU (setup 1.5, rollout 9,
    /// 100 indicators about 60, step 7 about 20 of which the time scaling
    /// 11 and the re-evaluation of the slowed segments 3–4), and takes about
    /// half of it in wall time when both cores are free (49.5 ms criterion
    /// median at load average 1.9, after the overlap of this item 5);
    /// on 1 thread the steps run in order (85–95 ms). With
    /// [`IndicatorSource::Cache`] the evaluation takes 3 ms (about 27–30 ms
    /// in all, the cache's stated bound in the answer). The first plan of a
    /// new path pays 15–30 ms more for the path's spline fit (then kept,
    /// step 2).
    pub fn plan(&self, request: &MillRequest) -> Result<MillPlanOutput, MillPlanError> {
        self.plan_within(request, &Budget::unlimited())
    }

    /// [`Self::plan`] under a time budget and a cancellation token (issue 11, item 3).
    ///
    /// # Arguments
    /// * `request` — the request; its own `time_budget` (if any) tightens `budget`.
    /// * `budget` — checked between units of work: each segment of the reachability check,
    ///   each step of the policy rollout, each indicator evaluation, each segment of the
    ///   naive planner's verifications, every row of the DP grid, each stage after.
    ///
    /// # Errors
    /// As [`Self::plan`], and [`MillPlanError::Interrupted`] when the budget runs out
    /// (status TIMEOUT) or is cancelled.
    pub fn plan_within(
        &self,
        request: &MillRequest,
        budget: &Budget,
    ) -> Result<MillPlanOutput, MillPlanError> {
        let start = Instant::now();
        request.validate_with(self.cell.state_limits())?;
        let budget = &budget.tightened(request.time_limit()?);
        let mut out = match request.planner_kind()? {
            PlannerKind::Best => self.plan_best(request, budget)?,
            _ => {
                let out = self.plan_shielded(request, budget)?;
                self.refuse_chatter(request, out, budget)?
            }
        };
        out.planning_seconds = start.elapsed().as_secs_f64();
        Ok(out)
    }

    /// [`PlannerKind::Best`] (issue 28, item 3): every planner of
    /// [`PlannerKind::BEST_CANDIDATES`] plans the request in turn (each with its shield
    /// rounds, under the request's one budget); the answer is the fastest as executed (the
    /// trajectory's duration from rest to rest) among those chatter-free at every executed
    /// sample whose trajectory keeps 1/K at or above the request's minimum, else
    /// [`BEST_MIN_CONDITION_INDICATOR`]. Its [`MillPlanOutput::candidates`] say how every
    /// planner did.
    ///
    /// # Errors
    /// Without such a plan: [`MillPlanError::Chattering`] when every plan chatters (the one
    /// with the lowest |μ|max is answered instead when the request allows chatter);
    /// [`MillPlanError::Infeasible`] when the chatter-free ones fall below the 1/K minimum
    /// (naming the best of them and the best-conditioned plan's |μ|max); when no candidate planned, the error of the first whose status is a path
    /// property (INVALID_REQUEST, UNREACHABLE, INFEASIBLE), else the first error. A
    /// cancellation ends the search with its error; a timeout ends it with the plans in hand.
    fn plan_best(
        &self,
        request: &MillRequest,
        budget: &Budget,
    ) -> Result<MillPlanOutput, MillPlanError> {
        if let Some(p) = &request.policy_file {
            return Err(MillPlanError::InvalidConfig {
                name: "policy_file".to_string(),
                reason: format!(
                    "{p:?} was given for planner best, which runs both policy planners (ddpg and \
                     fixed_g) with their default policies; leave policy_file empty or name \
                     the planner"
                ),
            });
        }
        let minimum = request
            .min_condition_indicator()
            .unwrap_or(BEST_MIN_CONDITION_INDICATOR);
        let mut candidates = Vec::new();
        let mut planned: Vec<MillPlanOutput> = Vec::new();
        let mut errors = Vec::new();
        for (kind, result) in self.plan_candidates(request, &PlannerKind::BEST_CANDIDATES, budget) {
            match result {
                Ok(out) => {
                    candidates.push(Candidate::planned(&out));
                    planned.push(out);
                }
                Err(e @ MillPlanError::Interrupted(kerf_budget::Interrupt::Cancelled { .. })) => {
                    return Err(e)
                }
                Err(e) => {
                    candidates.push(Candidate::failed(kind, &e));
                    errors.push(e);
                }
            }
        }
        let duration = |o: &MillPlanOutput| o.executed.scaling.duration();
        let conditioned =
            |o: &MillPlanOutput| o.executed.scaling.min_condition_indicator.0 >= minimum;
        let chosen = planned
            .iter()
            .enumerate()
            .filter(|(_, o)| !o.executed.chatters() && conditioned(o))
            .min_by(|a, b| duration(a.1).total_cmp(&duration(b.1)))
            .map(|(k, _)| k);
        if let Some(k) = chosen {
            let mut out = planned.swap_remove(k);
            out.candidates = candidates;
            return Ok(out);
        }
        let free = planned
            .iter()
            .filter(|o| !o.executed.chatters())
            .max_by(|a, b| {
                let (x, y) = (
                    a.executed.scaling.min_condition_indicator.0,
                    b.executed.scaling.min_condition_indicator.0,
                );
                x.total_cmp(&y)
            });
        if let Some(o) = free {
            // Chatter-free plans exist, but none keeps 1/K: say both sides.
            let (value, arc_length) = o.executed.scaling.min_condition_indicator;
            let conditioned_one = planned.iter().filter(|p| conditioned(p)).min_by(|a, b| {
                a.executed
                    .plan
                    .max_spectral_radius
                    .total_cmp(&b.executed.plan.max_spectral_radius)
            });
            let other = match conditioned_one {
                Some(p) => format!(
                    "; {} keeps 1/K at {:.3} but chatters (|μ|max {:.4})",
                    p.planner.name(),
                    p.executed.scaling.min_condition_indicator.0,
                    p.executed.plan.max_spectral_radius
                ),
                None => "; no candidate keeps 1/K that high".to_string(),
            };
            return Err(MillPlanError::Infeasible {
                planner: "best".to_string(),
                reason: format!(
                    "no candidate is both chatter-free as executed and at 1/K >= {minimum}: {} is \
                     chatter-free ({:.2} s) but 1/K falls to {value:.3} at arc length \
                     {arc_length:.4} m (segment {}){other}; ask for {} by name, or for a lower \
                     tolerances.min_condition_indicator",
                    o.planner.name(),
                    o.executed.scaling.duration(),
                    segment_at(&o.executed, arc_length),
                    o.planner.name()
                ),
            });
        }
        let lowest = planned.iter().enumerate().min_by(|a, b| {
            let (x, y) = (
                a.1.executed.plan.max_spectral_radius,
                b.1.executed.plan.max_spectral_radius,
            );
            x.total_cmp(&y)
        });
        let Some((k, _)) = lowest else {
            let path_property = errors.iter().position(|e| {
                matches!(
                    status_of(e),
                    status::INVALID_REQUEST | status::UNREACHABLE | status::INFEASIBLE
                )
            });
            let k = path_property.unwrap_or(0);
            return Err(if k < errors.len() {
                errors.swap_remove(k)
            } else {
                MillPlanError::InvalidConfig {
                    name: "planner best".to_string(),
                    reason: "no candidate planner ran".to_string(),
                }
            });
        };
        let mut out = planned.swap_remove(k);
        if request.allow_chatter {
            out.candidates = candidates;
            return Ok(out);
        }
        let reason = self.why_no_stable_plan(request, &out)?;
        Err(chattering(&out, "best", reason))
    }

    /// `request` planned by each of `kinds` ([`Self::plan_each`]), except that greedy_best_g,
    /// which replans greedy for each fixed g (seconds), runs only where greedy (g held at g0)
    /// has no chatter-free plan among them: where greedy has one, greedy_best_g chose greedy's
    /// g on every path measured (BENCHMARKS.md, "Milling: no chattering plan as SUCCESS").
    /// Results in the order of `kinds`, greedy_best_g last.
    fn plan_candidates(
        &self,
        request: &MillRequest,
        kinds: &[PlannerKind],
        budget: &Budget,
    ) -> Vec<CandidatePlan> {
        let first: Vec<PlannerKind> = kinds
            .iter()
            .copied()
            .filter(|k| *k != PlannerKind::GreedyBestG)
            .collect();
        let mut results = self.plan_each(request, &first, budget);
        let greedy_stable = results.iter().any(|(k, r)| {
            *k == PlannerKind::Greedy && r.as_ref().is_ok_and(|o| !o.executed.chatters())
        });
        if !greedy_stable && kinds.contains(&PlannerKind::GreedyBestG) {
            results.extend(self.plan_each(request, &[PlannerKind::GreedyBestG], budget));
        }
        results
    }

    /// `request` planned by each of `kinds` ([`Self::plan_shielded`]), on up to
    /// [`Self::eval_threads`] threads at once (each plan is the same on any thread: the
    /// results are in the order of `kinds` whatever the scheduling).
    fn plan_each(
        &self,
        request: &MillRequest,
        kinds: &[PlannerKind],
        budget: &Budget,
    ) -> Vec<CandidatePlan> {
        crate::parallel::map_ordered(kinds.len(), self.eval_threads, "plan-candidate", |k| {
            let kind = kinds[k];
            let mut one = request.clone();
            one.planner = kind.name().to_string();
            (kind, self.plan_shielded(&one, budget))
        })
    }

    /// A plan of an explicit planner that chatters as executed becomes
    /// [`MillPlanError::Chattering`] unless the request allows chatter: the other planners of
    /// [`PlannerKind::BEST_CANDIDATES`] plan the path (under the same budget) so that the
    /// message gives the lowest |μ|max any of them reached and, when one is chatter-free,
    /// names it.
    fn refuse_chatter(
        &self,
        request: &MillRequest,
        out: MillPlanOutput,
        budget: &Budget,
    ) -> Result<MillPlanOutput, MillPlanError> {
        if !out.executed.chatters() || request.allow_chatter {
            return Ok(out);
        }
        let mut lowest = (
            out.planner.name().to_string(),
            out.executed.plan.max_spectral_radius,
        );
        let mut stable: Option<(PlannerKind, f64)> = None;
        let others: Vec<PlannerKind> = PlannerKind::BEST_CANDIDATES
            .into_iter()
            .filter(|k| *k != out.planner)
            .collect();
        for (kind, result) in self.plan_candidates(request, &others, budget) {
            match result {
                Ok(other) => {
                    let mu = other.executed.plan.max_spectral_radius;
                    if mu < lowest.1 {
                        lowest = (kind.name().to_string(), mu);
                    }
                    let d = other.executed.scaling.duration();
                    if !other.executed.chatters() && stable.is_none_or(|(_, b)| d < b) {
                        stable = Some((kind, d));
                    }
                }
                Err(e @ MillPlanError::Interrupted(kerf_budget::Interrupt::Cancelled { .. })) => {
                    return Err(e)
                }
                Err(_) => {}
            }
        }
        let reason = match stable {
            Some((kind, d)) => format!(
                "{} plans this path chatter-free ({d:.2} s as executed): ask for planner {} or \
                 best",
                kind.name(),
                kind.name()
            ),
            None => self.why_no_stable_plan(request, &out)?,
        };
        let mut error = chattering(&out, out.planner.name(), reason);
        if let MillPlanError::Chattering { lowest: l, .. } = &mut error {
            *l = Some(lowest);
        }
        Err(error)
    }

    /// Why no planner finds a chatter-free plan for `request`, read from the plan with the
    /// lowest |μ|max (`out`): the entry in the material, the initial state (the IVP)
    /// chattering where the step bounds keep the first segments near it, the joints slowing
    /// the worst sample below its planned feed, or the cell's state limits.
    fn why_no_stable_plan(
        &self,
        request: &MillRequest,
        out: &MillPlanOutput,
    ) -> Result<String, MillPlanError> {
        let Some(worst) = out.executed.chatter.worst else {
            return Ok(String::new());
        };
        if out.executed.settings.entry == crate::timing::Entry::InMaterial {
            return Ok(format!(
                "the tool starts and stops from rest in the material (entry in_material), so \
                 the ramps pass every feed from 0; the lowest feed in the material is {:.2} mm/s; \
                 a cell enters the material at feed (entry run_in)",
                out.executed
                    .chatter
                    .lowest_feed
                    .map_or(0.0, |l| l.feed * 1e3)
            ));
        }
        let limits = request.effective_limits(self.cell.state_limits());
        let (cell, _) = self.request_cell(request, limits)?;
        let [rpm0, feed0, g0] = request.initial_state();
        let start = cell.evaluate(0, g0, None)?;
        let ivp = kerf_chatter::chatter_indicator(
            &start.modal,
            &cell.milling_process(),
            rpm0,
            feed0,
            cell.indicator_settings(),
        )
        .map(|i| i.spectral_radius)
        .unwrap_or(f64::INFINITY);
        if ivp >= 1.0 {
            return Ok(format!(
                "the initial state itself chatters: |μ|max {ivp:.4} at segment 0 ({rpm0:.0} \
                 rpm, {:.2} mm/s, g = {g0:.4} rad), and the step bounds keep the first segments \
                 near it; start from a stable spindle speed and feed (initial)",
                feed0 * 1e3
            ));
        }
        let planned = out
            .plan
            .segments
            .get(worst.segment)
            .map_or(worst.feed, |s| s.feed);
        if worst.feed < planned * (1.0 - 1e-3) {
            return Ok(format!(
                "the joints' limits slow segment {} to {:.2} mm/s where {:.2} mm/s was planned, \
                 and the cut chatters at that feed",
                worst.segment,
                worst.feed * 1e3,
                planned * 1e3
            ));
        }
        Ok(format!(
            "no planner found a stable plan within the spindle speeds {:.0}–{:.0} rpm, feeds \
             {:.3}–{:.3} m/s and the step bounds of the request",
            limits.spindle_rpm[0], limits.spindle_rpm[1], limits.feed[0], limits.feed[1]
        ))
    }

    /// The plan of `request`'s planner (not [`PlannerKind::Best`]) with the chatter shield's
    /// rounds (step 9), whether or not it chatters as executed.
    fn plan_shielded(
        &self,
        request: &MillRequest,
        budget: &Budget,
    ) -> Result<MillPlanOutput, MillPlanError> {
        let start = Instant::now();
        let shield = self.env_config.chatter_shield;
        let mut out = self.plan_attempt(request, budget, &ShieldRound::first(shield))?;
        // The chatter shield's rounds (SHIELD_ROUNDS): a policy plan that
        // chatters as executed is planned again, the shield judging each
        // segment also at the feed the executed trajectory ran it at, then
        // with a lower limit.
        let mut round = ShieldRound::first(shield);
        // The round before, when it was not answered (else it is `out`).
        let mut last: Option<MillPlanOutput> = None;
        for _ in 1..SHIELD_ROUNDS {
            let previous = last.as_ref().unwrap_or(&out);
            if previous.executed.plan.chatter_free
                || !matches!(out.planner, PlannerKind::Ddpg | PlannerKind::FixedG)
            {
                break;
            }
            let Some(next) = round.next(&previous.executed) else {
                break;
            };
            round = next;
            match self.plan_attempt(request, budget, &round) {
                Ok(again) => {
                    // The same plan again: a lower limit will not change it
                    // (no safe move within a step is left to the shield).
                    let previous = last.as_ref().unwrap_or(&out);
                    let same = again.plan.states() == previous.plan.states();
                    if shield_prefers(&again, &out) {
                        out = again;
                        last = None;
                    } else {
                        last = Some(again);
                    }
                    if same {
                        break;
                    }
                }
                // Cancelled: the node is stopping.
                Err(e @ MillPlanError::Interrupted(kerf_budget::Interrupt::Cancelled { .. })) => {
                    return Err(e)
                }
                // The budget ran out in a later round, or its rollout left
                // the feasible set: the plan in hand (complete, its chatter
                // reported) stands.
                Err(_) => break,
            }
        }
        out.planning_seconds = start.elapsed().as_secs_f64();
        Ok(out)
    }

    /// One plan of [`Self::plan_within`]: steps 1–8 of the module
    /// documentation, the policy's chatter shield as `shield` says.
    ///
    /// Once the path is known to be reachable (step 3), an IK or joint-limit failure of the
    /// planner's states or of their executed trajectory, and an executed trajectory that
    /// cannot be built ([`MillPlanError::NotExecutable`]), are the planner's on this path:
    /// [`MillPlanError::Infeasible`] (issue 28, item 2), not UNREACHABLE or INTERNAL_ERROR.
    fn plan_attempt(
        &self,
        request: &MillRequest,
        budget: &Budget,
        shield: &ShieldRound,
    ) -> Result<MillPlanOutput, MillPlanError> {
        let mut reachable = false;
        self.plan_attempt_checked(request, budget, shield, &mut reachable)
            .map_err(|e| match e {
                MillPlanError::Mill(
                    ref m @ (MillError::JointLimit { .. }
                    | MillError::Unreachable { .. }
                    | MillError::Singular { .. }),
                ) if reachable => MillPlanError::Infeasible {
                    planner: request.planner.clone(),
                    reason: format!(
                        "the path is reachable, but this planner's plan or its executed \
                         trajectory is not: {m}"
                    ),
                },
                // No time law, no settling within the rounds or the point limit: the executed
                // trajectory of this plan on this path cannot be built.
                MillPlanError::NotExecutable { reason } if reachable => MillPlanError::Infeasible {
                    planner: request.planner.clone(),
                    reason: format!("its executed trajectory cannot be built: {reason}"),
                },
                other => other,
            })
    }

    /// [`Self::plan_attempt`]; `reachable` is set once step 3 passed.
    fn plan_attempt_checked(
        &self,
        request: &MillRequest,
        budget: &Budget,
        shield: &ShieldRound,
        reachable: &mut bool,
    ) -> Result<MillPlanOutput, MillPlanError> {
        let start = Instant::now();
        let base = *self.cell.state_limits();
        request.validate_with(&base)?;
        let budget = &budget.tightened(request.time_limit()?);
        let kind = request.planner_kind()?;
        let limits = request.effective_limits(&base);
        budget.check("validation")?;
        let (cell, cache_applies) = self.request_cell(request, limits)?;
        let [rpm0, feed0, g0] = request.initial_state();
        check_reachable(&cell, g0, budget)?;
        if matches!(
            kind,
            PlannerKind::FixedG | PlannerKind::Greedy | PlannerKind::Naive
        ) {
            check_held_g(&cell, kind, g0, budget)?;
        }
        *reachable = true;
        let mut phases = PlanningPhases {
            setup: start.elapsed().as_secs_f64(),
            ..PlanningPhases::default()
        };
        let step = Instant::now();
        let cache = if cache_applies {
            self.cache.clone()
        } else {
            None
        };
        let mut policy_file = None;
        let mut prefetch: Option<Prefetch> = None;
        let states: Vec<PhysicalState> = match kind {
            PlannerKind::Ddpg | PlannerKind::FixedG => {
                let path = match &request.policy_file {
                    Some(p) => resolve_policy_file(p)?,
                    None => match self.default_policies.get(&kind) {
                        Some(p) => p.clone(),
                        None => default_policy_path(kind).ok_or_else(|| {
                            MillPlanError::InvalidConfig {
                                name: "policy_file".to_string(),
                                reason: "no default policy".to_string(),
                            }
                        })?,
                    },
                };
                // A request's minimum 1/K raises the environment's (with the
                // same margin for the dip between midpoints as the default,
                // EnvConfig::min_condition_indicator), never lowers it.
                let min_condition_indicator = match (
                    self.env_config.min_condition_indicator,
                    request.min_condition_indicator(),
                ) {
                    (Some(own), Some(asked)) => Some(own.max((asked + 0.05).min(0.999))),
                    (own, _) => own,
                };
                let config = EnvConfig {
                    initial_rpm: rpm0,
                    initial_feed: feed0,
                    initial_g: g0,
                    fixed_g: kind == PlannerKind::FixedG,
                    min_condition_indicator,
                    // g held (fixed_g) runs no spline between midpoints.
                    chatter_shield: shield.limit,
                    joint_limit_margin: if kind == PlannerKind::FixedG {
                        self.env_config.joint_limit_margin
                    } else {
                        self.env_config
                            .joint_limit_margin
                            .max(crate::env::PLANNER_JOINT_LIMIT_MARGIN)
                    },
                    ..self.env_config
                };
                let policy = self.policy(&path)?;
                // Step 5 evaluates |μ|max directly: a helper thread starts on the
                // states as the rollout makes them ("Overlap" in the module
                // documentation), when there is a second evaluation thread.
                let direct = !(self.indicator_source == IndicatorSource::Cache && cache.is_some());
                if direct && self.eval_threads > 1 {
                    prefetch = Prefetch::start(cell.clone());
                }
                let run = |config: EnvConfig| -> Result<crate::env::Rollout, MillPlanError> {
                    let mut env = MillEnv::new(cell.clone(), cache.clone(), config)?;
                    if let Some(c) = &shield.slowdown {
                        env = env.with_shield_slowdown(c.clone())?;
                    }
                    if let Some(h) = &shield.held {
                        env = env.with_held_g(h.clone())?;
                    }
                    policy.check_observation(&OBSERVATION_LAYOUT, env.action_dim())?;
                    env.rollout(|obs, state| {
                        budget.check("the policy rollout")?;
                        if let Some(p) = &prefetch {
                            p.send(state);
                        }
                        policy.act(obs)
                    })
                };
                let mut rollout = run(config)?;
                if !rollout.completed
                    && config.min_condition_indicator != self.env_config.min_condition_indicator
                {
                    // The request's minimum could not be kept: plan with the
                    // environment's own, and step 8 reports where the plan
                    // falls below the request's (ILL_CONDITIONED).
                    rollout = run(EnvConfig {
                        min_condition_indicator: self.env_config.min_condition_indicator,
                        ..config
                    })?;
                }
                if !rollout.completed {
                    // A valid path the policy cannot finish: the planner's limit on this path
                    // (issue 28, item 2), not a defect of the policy file.
                    let why = rollout.stop_reason();
                    return Err(MillPlanError::Infeasible {
                        planner: kind.name().to_string(),
                        reason: format!(
                            "the policy's greedy rollout left the feasible set at {why}; \
                             planner best (or greedy_best_g, dp) plans it another way"
                        ),
                    });
                }
                policy_file = Some(path);
                let states = rollout.states();
                // The last state is not handed to the policy: send it here.
                if let (Some(p), Some(last)) = (&mut prefetch, states.last()) {
                    p.send(last);
                    p.close();
                }
                states
            }
            PlannerKind::Dp | PlannerKind::Naive => {
                let cache = match &cache {
                    Some(c) if covers_speeds_and_feeds(c, cell.state_limits()) => c.clone(),
                    _ => self.path_cache(request, &cell, g0, budget)?,
                };
                if kind == PlannerKind::Dp {
                    let spec = DpSpec {
                        initial: [rpm0, feed0, g0],
                        ..DpSpec::full(&cell, self.env_config.weights, false)
                    };
                    // The DP with the executed timing in its loop (issue 28, item 5): its
                    // answer holds as executed.
                    let solved = crate::dp_executed::solve_executed(
                        &cell,
                        &cache,
                        &spec,
                        self.eval_threads,
                        budget,
                    )?;
                    match solved.best() {
                        Some(round) => round.result.states.clone(),
                        None => dp::solve_within(&cell, &cache, &spec, budget)?.states,
                    }
                } else {
                    naive::solve_within(&cell, &cache, g0, budget)?.states
                }
            }
            PlannerKind::Greedy => {
                greedy::solve_within(&cell, [rpm0, feed0, g0], g0, budget)?.states
            }
            PlannerKind::Best => {
                return Err(MillPlanError::InvalidConfig {
                    name: "planner".to_string(),
                    reason: "`best` chooses among the other planners (MillPlanner::plan_within)"
                        .to_string(),
                })
            }
            PlannerKind::GreedyBestG => {
                greedy::best_fixed_g_within(
                    &cell,
                    [rpm0, feed0, g0],
                    self.eval_threads,
                    &self.trajectory_settings,
                    budget,
                )?
                .states
            }
        };
        phases.planner = step.elapsed().as_secs_f64();
        let step = Instant::now();
        let weights = &self.env_config.weights;
        let segments = states.len();
        let mut settings = self.trajectory_settings.with_threads(self.eval_threads);
        if let Some(tolerance) = request.path_tolerance() {
            settings.path_tolerance = tolerance;
        }
        if request.entry.is_some() {
            settings.entry = request.entry()?;
        }
        let (plan, indicator, trajectory, branch_jumps, executed) =
            match (self.indicator_source, &cache) {
                (IndicatorSource::Cache, Some(c)) => {
                    let (plan, indicator) = Plan::evaluate_cached(
                        &cell,
                        weights,
                        &states,
                        kind.name(),
                        self.eval_threads,
                        c,
                        budget,
                    )?;
                    phases.evaluation = step.elapsed().as_secs_f64();
                    let step = Instant::now();
                    budget.check("the planned trajectory")?;
                    let (trajectory, branch_jumps) = planned_trajectory(&cell, &plan)?;
                    let executed = executed(
                        &cell,
                        &plan,
                        &settings,
                        weights,
                        self.eval_threads,
                        &indicator,
                        Some(c),
                        budget,
                    )?;
                    phases.trajectory = step.elapsed().as_secs_f64();
                    (plan, indicator, trajectory, branch_jumps, executed)
                }
                (source, _) => {
                    let reason = if source == IndicatorSource::Cache {
                        if self.cache.is_none() {
                            format!("cache requested, but {}", self.cache_note)
                        } else {
                            "cache requested, but this request changes the path/process".to_string()
                        }
                    } else {
                        String::new()
                    };
                    let indicator = IndicatorProvenance::direct(source, segments, &reason);
                    // Step 7 up to the executed plan's assembly, on its own thread while
                    // the |μ|max of step 5 are evaluated: it reads Ω, f, g and the cell
                    // states of the segments, never their |μ|max (module documentation,
                    // "Overlap").
                    let beside = |inputs: &[SegmentInput]| {
                        let limits = joint_limits(&cell)?;
                        budget.check("the executed trajectory")?;
                        let scaling = time_scale_inputs(&cell, inputs, &limits, &settings, budget)?;
                        let reevaluation = Reevaluation::new(
                            &cell,
                            kind.name(),
                            inputs,
                            &scaling.segment_feeds,
                            &scaling.segment_times,
                            self.eval_threads,
                            None,
                            budget,
                        )?;
                        Ok::<_, MillPlanError>((scaling, reevaluation))
                    };
                    let (plan, _, beside, evaluated) = evaluate_direct_alongside(
                        &cell,
                        weights,
                        &states,
                        kind.name(),
                        self.eval_threads,
                        budget,
                        prefetch.take(),
                        beside,
                    )?;
                    phases.evaluation = evaluated;
                    // In the order of the sequential steps: the planned trajectory's
                    // errors before the executed trajectory's.
                    budget.check("the planned trajectory")?;
                    let (trajectory, branch_jumps) = planned_trajectory(&cell, &plan)?;
                    let executed = match beside {
                        Some(result) => {
                            let (scaling, reevaluation) = result?;
                            let (executed_plan, cached_segments) = plan.with_reevaluation(
                                &cell,
                                weights,
                                &scaling.segment_feeds,
                                &scaling.segment_times,
                                &indicator,
                                reevaluation,
                            )?;
                            Executed::assemble(
                                &cell,
                                (scaling, executed_plan),
                                cached_segments,
                                settings,
                                self.eval_threads,
                                budget,
                            )?
                        }
                        // Not run (only when the evaluation failed, which returned above).
                        None => executed(
                            &cell,
                            &plan,
                            &settings,
                            weights,
                            self.eval_threads,
                            &indicator,
                            None,
                            budget,
                        )?,
                    };
                    phases.trajectory = (step.elapsed().as_secs_f64() - evaluated).max(0.0);
                    (plan, indicator, trajectory, branch_jumps, executed)
                }
            };
        if let Some(minimum) = request.min_condition_indicator() {
            let (value, arc_length) = executed.scaling.min_condition_indicator;
            if value < minimum {
                let segment = segment_at(&executed, arc_length);
                return Err(MillPlanError::IllConditioned {
                    value,
                    arc_length,
                    segment,
                    minimum,
                });
            }
        }
        Ok(MillPlanOutput {
            request_id: request.request_id.clone(),
            planner: kind,
            policy_file,
            plan,
            trajectory,
            executed,
            branch_jumps,
            cache_used: cache_applies,
            planning_seconds: start.elapsed().as_secs_f64(),
            phases,
            indicator,
            candidates: Vec::new(),
        })
    }
}

/// Whether a cache's grid spans the spindle-speed range and the largest
/// feed of `limits` (the DP and the naive planner treat states outside the
/// grid as infeasible: a request that widens these ranges on the default
/// path gets a per-path cache that spans them instead). The g range is not
/// compared: the committed cache spans −3…3 rad of the default ±π (the DP
/// does not plan the few g beyond: forbidden, conservative).
fn covers_speeds_and_feeds(cache: &IndicatorCache, limits: &StateLimits) -> bool {
    let grid = cache.grid();
    let span = |nodes: &[f64]| (nodes.first().copied(), nodes.last().copied());
    let (r0, r1) = span(&grid.rpm);
    let (_, f1) = span(&grid.feed);
    r0.is_some_and(|v| v <= limits.spindle_rpm[0])
        && r1.is_some_and(|v| v >= limits.spindle_rpm[1])
        && f1.is_some_and(|v| v >= limits.feed[1])
}

/// Samples of the redundancy-angle range tried per segment by the
/// reachability check (after g0).
const REACH_SAMPLES: usize = 64;

/// Every segment has a feasible g (g0 first, then [`REACH_SAMPLES`] + 1
/// equally spaced values of the g range), and segment 0 is feasible at g0.
///
/// # Errors
/// The cell's error of the least-violating g of the first segment without
/// a feasible g (a joint-limit error beats an unreachable one; among
/// those, the smallest excess or distance).
/// A planner that holds g at the initial g0 (`fixed_g`, `greedy`, `naive`) can plan the path
/// only where every segment is feasible at g0 on the IK branch continued from the previous
/// segment (as [`Plan::evaluate`] chains it): else [`MillPlanError::Infeasible`] naming the
/// segment and the cell's reason (issue 28, item 2).
fn check_held_g(
    cell: &MillCell,
    kind: PlannerKind,
    g0: f64,
    budget: &Budget,
) -> Result<(), MillPlanError> {
    let mut reference: Option<[f64; 6]> = None;
    for segment in 0..cell.path().segments().len() {
        budget.check("the held g's feasibility")?;
        match cell.evaluate(segment, g0, reference.as_ref()) {
            Ok(state) => reference = Some(state.joints),
            Err(e) if is_infeasible(&e) => {
                return Err(MillPlanError::Infeasible {
                    planner: kind.name().to_string(),
                    reason: format!(
                        "it holds g at the initial {g0} rad, and segment {segment} is not \
                         feasible there ({e}); ddpg, greedy_best_g, dp and best move g"
                    ),
                })
            }
            Err(e) => return Err(e.into()),
        }
    }
    Ok(())
}

fn check_reachable(cell: &MillCell, g0: f64, budget: &Budget) -> Result<(), MillPlanError> {
    let [lo, hi] = cell.state_limits().redundancy_angle;
    let mut sweep = vec![g0];
    sweep.extend((0..=REACH_SAMPLES).map(|k| lo + (hi - lo) * k as f64 / REACH_SAMPLES as f64));
    let score = |e: &MillError| match e {
        MillError::JointLimit { excess, .. } => *excess,
        MillError::Unreachable {
            distance_beyond_reach,
            ..
        } => 1e6 + distance_beyond_reach,
        _ => 2e6,
    };
    for segment in 0..cell.path().segments().len() {
        budget.check("the reachability check")?;
        let mut least: Option<MillError> = None;
        let mut ok = false;
        for &g in &sweep {
            match cell.evaluate(segment, g, None) {
                Ok(_) => {
                    ok = true;
                    break;
                }
                Err(e) if is_infeasible(&e) => {
                    if segment == 0 && g == g0 {
                        // The initial state must be feasible itself.
                        return Err(e.into());
                    }
                    if least.as_ref().is_none_or(|l| score(&e) < score(l)) {
                        least = Some(e);
                    }
                }
                Err(e) => return Err(e.into()),
            }
        }
        if !ok {
            if let Some(e) = least {
                return Err(e.into());
            }
        }
    }
    Ok(())
}
