//! The node's parameters, read once at start-up and checked.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use kerf_cell::CellSurroundings;
use kerf_mill::MillCell;
use kerf_millplan::{
    default_policy_path, plan::IndicatorSource, IndicatorCache, MillPlanner, PlannerKind,
};
use kerf_robot::roots::AllowedRoots;
use kerf_ros::{planner::HarnessSettings, Params};

use crate::NodeError;

/// Parameter names this node reads; others are refused at start-up.
pub const KNOWN_PARAMS: &[&str] = &[
    "cell_file",
    "indicator_cache_file",
    "ddpg_policy_file",
    "fixed_g_policy_file",
    "indicator_source",
    "eval_threads",
    "queue_depth",
    "plan_timeout",
    "allowed_file_roots",
    "collision_cell_file",
];

pub use kerf_ros::planner::DEFAULT_QUEUE_DEPTH;

/// Everything the node needs, checked.
#[derive(Debug)]
pub struct NodeConfig {
    /// The planner: the cell, and its indicator cache when one applies.
    pub planner: MillPlanner,
    /// Where the cell came from (for the start-up log).
    pub cell_source: String,
    /// Whether and from where the indicator cache was loaded, or why not (start-up log).
    pub cache_note: String,
    /// The policy of `ddpg` requests that name none.
    pub ddpg_policy_file: PathBuf,
    /// The policy of `fixed_g` requests that name none.
    pub fixed_g_policy_file: PathBuf,
    /// Where the plans' |μ|max come from (`indicator_source`).
    pub indicator_source: IndicatorSource,
    /// Requests waiting or being planned before new ones are refused (≥ 1).
    pub harness: HarnessSettings,
    /// Where a request's policy file may be (`allowed_file_roots`).
    pub allowed_roots: AllowedRoots,
    /// The robot against the cell's objects, for the approach and retract of every plan with
    /// a start (`collision_cell_file`).
    pub surroundings: CellSurroundings,
}

/// A path parameter: `None` when unset, an error when set to the empty string.
fn path_param(params: &Params, name: &str) -> Result<Option<PathBuf>, NodeError> {
    match params.string(name)? {
        None => Ok(None),
        Some(s) if s.trim().is_empty() => Err(NodeError::config(
            name,
            "is empty; leave it unset for the default, or give a file path",
        )),
        Some(s) => Ok(Some(PathBuf::from(s))),
    }
}

/// The shipped policy of `kind` (a planner with a policy).
fn shipped_policy(kind: PlannerKind) -> Result<PathBuf, NodeError> {
    default_policy_path(kind).ok_or_else(|| {
        NodeError::config(
            &format!("{}_policy_file", kind.name()),
            "kerf_millplan names no shipped policy for this planner",
        )
    })
}

impl NodeConfig {
    /// Reads and checks every parameter, loads the cell and the indicator cache, and builds
    /// the planner.
    ///
    /// # Parameters
    /// * `cell_file` (string): the milling cell YAML (robot files, tool, path, dynamics,
    ///   process, limits, chatter settings); unset = the shipped `urdf/irb6660_milling.yaml`.
    /// * `indicator_cache_file` (string): the |μ|max cache of the cell
    ///   (`kerf_millplan::IndicatorCache`). Unset = the shipped
    ///   `crates/millplan/data/indicator_cache.bin`, used when it was built for this cell and
    ///   otherwise skipped with a warning (the `dp` and `naive` planners then build a per-path
    ///   cache on a request's first use, `kerf_millplan::path_cache`; `ddpg` and `fixed_g`
    ///   evaluate directly). Set = it must load and fit the cell, else the
    ///   node does not start.
    /// * `ddpg_policy_file`, `fixed_g_policy_file` (strings): the policy (safetensors actor)
    ///   used by `ddpg` / `fixed_g` requests that name none; unset = the shipped
    ///   `crates/millplan/policies/{ddpg,fixed_g}.safetensors`. The files are read per request
    ///   (a missing or incompatible one is that request's POLICY_ERROR), so they may be
    ///   replaced while the node runs.
    /// * `indicator_source` (string, `direct` or `cache`, default `direct`): where the plan's
    ///   per-segment |μ|max come from (`kerf_millplan::MillPlanner::with_indicator_source`):
    ///   every segment evaluated directly with the chatter model, or the indicator cache's
    ///   interpolation where it applies, with its stated error bound (faster; `chatter_free`
    ///   is then claimed only where |μ|max + bound < 1, and the answer's message says which
    ///   segments were cached).
    /// * `eval_threads` (integer ≥ 1, default: the planner's): threads of the direct plan
    ///   evaluation (the plan does not depend on it, only the latency).
    /// * `queue_depth` (integer ≥ 1, default 10): requests waiting or being planned; a request
    ///   arriving when the queue is full is answered at once with status QUEUE_FULL.
    /// * `plan_timeout` (seconds, default 60): the time budget of every plan; a request may ask
    ///   for less with its `time_budget`. A plan that runs out of it is answered TIMEOUT.
    /// * `allowed_file_roots` (string array, default: any): directories a request's
    ///   `policy_file` must resolve under (links resolved; the shipped data is always
    ///   allowed); a policy outside is POLICY_ERROR.
    /// * `collision_cell_file` (string): the kerf_cell cell file (the one the executor's
    ///   `sim_cell` reads) whose objects every approach and retract keeps its clearance from:
    ///   the robot's URDF shapes and the cell's tool shapes against its objects, the cell's
    ///   allowances (the cutter in the stock) left out only on the lead-in and lead-out;
    ///   unset = the shipped `urdf/cells/irb6660_plate.yaml` (the stock under the default
    ///   path at z = 1.7 m, on its fixture plate). Its robot must be the cell's. (Not
    ///   `cell_file`: that is the milling cell above.)
    ///
    /// Empty strings are refused (leave a parameter unset for its default). Relative paths
    /// are relative to the node's working directory.
    ///
    /// # Errors
    /// [`NodeError::Config`] naming the parameter, [`NodeError::Ros`] for a wrong type,
    /// [`NodeError::Setup`] when the cell or a given cache does not load.
    pub fn from_params(params: &Params) -> Result<Self, NodeError> {
        let cell_file = path_param(params, "cell_file")?;
        let cache_file = path_param(params, "indicator_cache_file")?;
        let ddpg_policy_file = match path_param(params, "ddpg_policy_file")? {
            Some(p) => p,
            None => shipped_policy(PlannerKind::Ddpg)?,
        };
        let fixed_g_policy_file = match path_param(params, "fixed_g_policy_file")? {
            Some(p) => p,
            None => shipped_policy(PlannerKind::FixedG)?,
        };
        let indicator_source = match params.string("indicator_source")?.as_deref() {
            None | Some("direct") => IndicatorSource::Direct,
            Some("cache") => IndicatorSource::Cache,
            Some(other) => {
                return Err(NodeError::config(
                    "indicator_source",
                    format!("must be direct or cache, got {other:?}"),
                ))
            }
        };
        let eval_threads = match params.get("eval_threads") {
            None => None,
            Some(_) => {
                let n = params.i64_or("eval_threads", 1)?;
                Some(usize::try_from(n).ok().filter(|n| *n >= 1).ok_or_else(|| {
                    NodeError::config("eval_threads", format!("must be >= 1, got {n}"))
                })?)
            }
        };
        let harness = HarnessSettings::from_params(params)?;
        let allowed_roots = kerf_ros::planner::allowed_roots(params)?;
        let collision_cell_file = path_param(params, "collision_cell_file")?;

        let (planner, cell_source, cache_note) = match (cell_file, cache_file) {
            (None, None) => {
                // The library's default: the shipped cell, its cache when fresh.
                let planner = MillPlanner::with_default_cell().map_err(NodeError::setup)?;
                let path = IndicatorCache::default_path();
                let note = if planner.cache().is_some() {
                    format!("indicator cache {}", path.display())
                } else {
                    let why = IndicatorCache::load(&path, planner.cell())
                        .err()
                        .map(|e| e.to_string())
                        .unwrap_or_else(|| "it changed while loading".to_string());
                    format!("no indicator cache (dp and naive build per-path caches): {why}")
                };
                let source = MillCell::default_path().display().to_string();
                (planner, source, note)
            }
            (cell_file, cache_file) => {
                let cell_path = cell_file.unwrap_or_else(MillCell::default_path);
                let cell = Arc::new(MillCell::load(&cell_path).map_err(NodeError::setup)?);
                let (cache, note) = match cache_file {
                    Some(path) => {
                        let cache = IndicatorCache::load(&path, &cell).map_err(NodeError::setup)?;
                        (Some(Arc::new(cache)), cache_source(&path))
                    }
                    None => {
                        let path = IndicatorCache::default_path();
                        match IndicatorCache::load(&path, &cell) {
                            Ok(c) => (Some(Arc::new(c)), cache_source(&path)),
                            Err(e) => (
                                None,
                                format!(
                                    "no indicator cache (dp and naive build per-path caches): the \
                                     shipped one does not fit this cell: {e}"
                                ),
                            ),
                        }
                    }
                };
                let planner = MillPlanner::new(cell, cache).map_err(NodeError::setup)?;
                (planner, cell_path.display().to_string(), note)
            }
        };
        let surroundings =
            kerf_cell::milling_surroundings(planner.cell(), collision_cell_file.as_deref())
                .map_err(|e| NodeError::config("collision_cell_file", e.to_string()))?;
        let mut planner = planner
            .with_indicator_source(indicator_source)
            .with_default_policy(PlannerKind::Ddpg, ddpg_policy_file.clone())
            .with_default_policy(PlannerKind::FixedG, fixed_g_policy_file.clone());
        if let Some(n) = eval_threads {
            planner = planner.with_eval_threads(n).map_err(NodeError::setup)?;
        }
        Ok(Self {
            planner,
            indicator_source,
            cell_source,
            cache_note,
            ddpg_policy_file,
            fixed_g_policy_file,
            harness,
            allowed_roots,
            surroundings,
        })
    }

    /// The policy a `ddpg` / `fixed_g` request without `policy_file` uses; `None` for the
    /// planners without a policy.
    pub fn default_policy(&self, kind: PlannerKind) -> Option<&Path> {
        match kind {
            PlannerKind::Ddpg => Some(&self.ddpg_policy_file),
            PlannerKind::FixedG => Some(&self.fixed_g_policy_file),
            PlannerKind::Dp
            | PlannerKind::Naive
            | PlannerKind::Greedy
            | PlannerKind::GreedyBestG
            | PlannerKind::Best => None,
        }
    }
}

fn cache_source(path: &Path) -> String {
    format!("indicator cache {}", path.display())
}
