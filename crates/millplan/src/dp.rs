//! The deterministic optimum: dynamic programming over a discretized
//! (Ω, f, g) grid whose spacing equals the per-step bounds (20 rpm,
//! 1e-3 m/s, 0.2 rad on the default cell), so that the moves of −1/0/+1
//! grid steps per segment (27 moves) are exactly the moves the step bounds
//! allow between grid points.
//!
//! # Problem
//!
//! Maximize `Σ_{t=0}^{N−1} r(t, x_t)` (r of seed 004 eq. 12, undiscounted,
//! all N segments as in [`crate::plan`]) over grid sequences with
//! `x_0` = the IVP (2000 rpm, 0.04 m/s, 0 rad) and `x_{t+1} − x_t` ∈
//! {−1, 0, 1}³ grid steps. Bellman backward recursion
//! `V_t(x) = r(t, x) + max_m V_{t+1}(x + m)`, `V_{N−1} = r(N−1, ·)`, with
//! f32 value layers and a u8 backpointer (move code) per (t, x); the plan
//! is read forward from x_0. Moves that would leave the grid are not
//! offered (in the environment, the clip turns them into a smaller move
//! that is also on offer).
//!
//! # What the value means
//!
//! * With α = 1 (no inertial filter) and grid-aligned actions the DP is
//!   exact for the environment on its grid: every DP plan is an action
//!   sequence of [`crate::env::MillEnv`] (normalized actions −1/0/+1).
//! * With α < 1 the filtered moves â are convex combinations of bounded
//!   actions, still within the step bounds: the set of state sequences a
//!   filtered policy can produce is (up to the grid) a SUBSET of the
//!   unfiltered one, so the DP value is an UPPER BOUND of what any policy
//!   of the filtered environment can reach (exactly so on the grid; off
//!   the grid the interpolation error of the cache and the grid spacing
//!   add a small slack).
//! * Feasible set: (t, g) pairs where the cell state is infeasible (IK,
//!   joint limit, singular; a precomputed table) are forbidden, and so are
//!   states whose |μ| the cache cannot give (outside its grid — f below
//!   its lowest feed node, 0.01 m/s on the default cache — or next to an
//!   infeasible node). Excluding f < 0.01 m/s does not lower the optimum on
//!   the default cell: a lower feed lowers r_e and raises |μ| (the feed
//!   lower bound), so it is never optimal. The forbidden count is
//!   reported ([`DpResult::forbidden_states`]).
//! * |μ| comes from the cache (its stated error bound applies): the
//!   committed cache of the default cell, or for any other path or process
//!   the per-path cache the planner builds on first use
//!   ([`crate::path_cache`], its measured error there); the plan is then
//!   re-evaluated directly by [`crate::plan::Plan::evaluate`].
//!   K (eq. 14) uses the cell's reference joints per (t, g), as the cache;
//!   the environment's branch-continuous IK can land on another (wrist-
//!   flipped) branch, with the same K and dynamics (`tests/cache.rs`).
//!
//! # Results on the default cell (measured, release, 2-core machine under load)
//!
//! Full grid 101 × 61 × 31 nodes × 100 segments × 27 moves with the
//! committed cache: 4–10 s with the joint-speed move filter (fixed g:
//! 0.1–0.3 s). Each plan re-evaluated directly by
//! [`crate::plan::Plan::evaluate`]
//! (`cargo run --release -p kerf_millplan --example compare`):
//!
//! | planner | time \[s\] | chatter-free | max \|μ\| | min 1/K | total reward (eq. 12) |
//! |---|---:|---|---:|---:|---:|
//! | DP (default spec: margin, joint speeds) | 16.18 | yes | 0.9525 | 0.363 | 0.540 |
//! | DP, g = 0 | 16.18 | yes | 0.9993 | 0.184 | −0.798 |
//! | DP of eq. 12 alone (no margin, no joint speeds) | 16.18 | no | 1.1442 | 0.464 | 2.063 |
//!
//! * Every DP plan reaches f_max after the 20-segment feed ramp and takes
//!   16.18 s: on this cell a higher feed is more stable (the feed lower
//!   bound of the state-dependent model with the cell's force law), so the
//!   chatter constraint is met with Ω and g, never by slowing down; g buys
//!   stability margin and conditioning, not time.
//! * Without kerf's margin the eq. 12 optimum chatters (|μ| up to 1.144 at
//!   g ≈ −1.2 rad, where the conditioning reward is larger) and turns q4 by
//!   up to 2.4× its speed limit; with it the optimum keeps |μ| ≤ 0.9525.
//! * With g = 0 the DP can only keep |μ| ≤ 0.9993 at the end of the path
//!   (segments 86–99 above 0.95): the paper's "chatter in the second half"
//!   of the fixed-g ablation, here at the margin of stability.

use kerf_budget::Budget;
use std::time::Instant;

use kerf_mill::MillCell;

use crate::cache::{is_infeasible, IndicatorCache};
use crate::env::PhysicalState;
use crate::error::MillPlanError;
use crate::joint_speed;
use crate::reward::{
    efficiency_reward, operational_reward, stability_reward, ChatterMargin, RewardWeights,
};

pub use crate::grid_dp::{solve_grid, solve_grid_with_history, solve_grid_with_moves, GridPath};

/// The DP grid: node ranges on each axis, in multiples of the step bound
/// from the initial state (so the IVP is a node).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DpSpec {
    /// Initial state (Ω0 \[rpm\], f0 [m/s], g0 \[rad\]).
    pub initial: [f64; 3],
    /// Ω range \[rpm\] (clipped to the cell's range, aligned to Ω0 + k·ΔΩ).
    pub rpm_range: [f64; 2],
    /// Feed range [m/s].
    pub feed_range: [f64; 2],
    /// g range \[rad\]; `[g0, g0]` is the paper's fixed-g ablation.
    pub g_range: [f64; 2],
    /// Reward weights.
    pub weights: RewardWeights,
    /// Optional hard chatter constraint `(limit, from_segment)`: states with
    /// cached |μ| ≥ limit are forbidden at segments ≥ from_segment. `None`
    /// (default) optimizes eq. 12 alone, the objective of DDPG: eq. 17 has
    /// no jump at |μ| = 1, so that optimum may ride marginally above 1
    /// where the efficiency gain outweighs w_p (e^(|μ|−1) − 1).
    pub chatter_limit: Option<(f64, usize)>,
    /// kerf's chatter margin subtracted from each state's reward, as in
    /// the environment ([`crate::env::EnvConfig::chatter_margin`]); the
    /// default spec uses the environment's default.
    pub chatter_margin: Option<ChatterMargin>,
    /// Forbid moves whose joints would exceed the URDF's velocity limits
    /// between the two segments' midpoints, as the environment does
    /// ([`crate::joint_speed`]; joints of the cell's reference IK branch,
    /// compared over the equivalent wrist solutions).
    pub joint_speed_limits: bool,
    /// Also forbid moves whose joint ACCELERATIONS at the planned feeds
    /// exceed the robot's limits (issue 13, item 3: "the DP with the
    /// executed timing in its cost, accelerations in its state"): the
    /// previous g move is part of the state
    /// ([`crate::grid_dp::solve_grid_with_history`], 3× the states), and
    /// a move from segment t to t + 1 after one from t − 1 is allowed when
    /// a_j = 2 ((q_{t+1} − q_t)/h₂ − (q_t − q_{t−1})/h₁) / (h₁ + h₂) (the
    /// second derivative of the parabola through the three midpoints'
    /// joints, Fornberg 1988, as the environment's acceleration shaping)
    /// is within |a_j| ≤ a_max,j for every joint; h₁ is the midpoint
    /// interval at the feed of segment t on both sides (the previous feed is
    /// not in the state; it differs by at most one feed step), h₂ at the
    /// feeds of the move. Segment 0 is not checked (the executed trajectory
    /// starts from rest with its own ramp). Jerk limits are not modelled.
    /// Off by default ([`DpSpec::full`]).
    pub joint_acceleration_limits: bool,
}

impl DpSpec {
    /// The full state ranges of the cell from the IVP (2000 rpm, 0.04 m/s,
    /// 0 rad), the default [`ChatterMargin`] (the environment's objective);
    /// `fixed_g` restricts g to g0 = 0.
    pub fn full(cell: &MillCell, weights: RewardWeights, fixed_g: bool) -> Self {
        let lim = cell.state_limits();
        Self {
            initial: [2000.0, 0.04, 0.0],
            rpm_range: lim.spindle_rpm,
            feed_range: lim.feed,
            g_range: if fixed_g {
                [0.0, 0.0]
            } else {
                lim.redundancy_angle
            },
            weights,
            chatter_limit: None,
            chatter_margin: Some(ChatterMargin::default()),
            joint_speed_limits: true,
            joint_acceleration_limits: false,
        }
    }
}

/// Most nodes of one axis of the DP grid (spindle speed, feed or g): the DP's tables grow
/// with the product of the three.
pub const MAX_AXIS_NODES: usize = 100_000;

/// Grid nodes `x0 + k h` within [lo, hi] (with a 1e-9 relative tolerance),
/// and the index of x0.
fn axis(x0: f64, h: f64, lo: f64, hi: f64) -> Result<(Vec<f64>, usize), MillPlanError> {
    if !(h > 0.0 && x0.is_finite() && lo <= x0 + 1e-9 * h && x0 <= hi + 1e-9 * h) {
        return Err(MillPlanError::InvalidParameter {
            name: "DP initial state".to_string(),
            value: x0,
            reason: format!("must be inside its range [{lo}, {hi}]"),
        });
    }
    // Counted in f64 before any allocation: a range of 1e308 rpm would saturate the casts and
    // overflow the node count (issue 33: "capacity overflow").
    let below = ((x0 - lo) / h + 1e-9).floor();
    let above = ((hi - x0) / h + 1e-9).floor();
    let nodes = below + above;
    if nodes.is_nan() || nodes >= MAX_AXIS_NODES as f64 {
        return Err(MillPlanError::InvalidParameter {
            name: "DP grid axis (range / step)".to_string(),
            value: below + above + 1.0,
            reason: format!(
                "[{lo}, {hi}] at steps of {h} needs more than {MAX_AXIS_NODES} grid nodes"
            ),
        });
    }
    let (below, above) = (below as usize, above as usize);
    let nodes = (0..=below + above)
        .map(|k| x0 + (k as f64 - below as f64) * h)
        .collect();
    Ok((nodes, below))
}

/// The DP plan on a cell.
#[derive(Debug, Clone, PartialEq)]
pub struct DpResult {
    /// Optimal state sequence (one per segment).
    pub states: Vec<PhysicalState>,
    /// Optimal total reward on the grid (cache |μ|).
    pub value: f64,
    /// Grid sizes (Ω, f, g).
    pub dims: [usize; 3],
    /// States excluded (infeasible cell state or not given by the cache),
    /// over all segments.
    pub forbidden_states: usize,
    /// Wall-clock time \[s\] (tables and DP).
    pub seconds: f64,
}

/// Solves the DP of the module documentation on `cell` with |μ| from
/// `cache`.
///
/// # Errors
/// [`MillPlanError::InvalidParameter`] for an initial state outside its
/// range; [`MillPlanError::InvalidConfig`] when the initial state is
/// forbidden; [`MillPlanError::Infeasible`] when no feasible plan exists; cell-model errors other than
/// infeasibility.
///
/// # Performance
/// Default cell, full grid (101 × 61 × 31 nodes × 100 segments × 27
/// moves): 2.1–3.6 s in release (module documentation); memory: two f32
/// value layers and one u8 backpointer per state (19 MB).
pub fn solve(
    cell: &MillCell,
    cache: &IndicatorCache,
    spec: &DpSpec,
) -> Result<DpResult, MillPlanError> {
    solve_within(cell, cache, spec, &Budget::unlimited())
}

/// [`solve`] under a time budget: checked per segment while the tables are
/// built and per row of the grid of every stage while the DP runs
/// ([`crate::grid_dp::solve_grid_with_moves`]).
///
/// # Errors
/// As [`solve`], and [`MillPlanError::Interrupted`].
pub fn solve_within(
    cell: &MillCell,
    cache: &IndicatorCache,
    spec: &DpSpec,
    budget: &Budget,
) -> Result<DpResult, MillPlanError> {
    solve_holding(cell, cache, spec, &[], budget)
}

/// [`solve_within`] with g held on some moves: `held[t]` forbids every
/// move from segment t to t + 1 that changes g (missing entries: not held).
/// [`crate::dp_executed`] holds g where the executed trajectory of an
/// earlier plan had to slow down.
///
/// # Errors
/// As [`solve_within`].
pub fn solve_holding(
    cell: &MillCell,
    cache: &IndicatorCache,
    spec: &DpSpec,
    held: &[bool],
    budget: &Budget,
) -> Result<DpResult, MillPlanError> {
    let start_time = Instant::now();
    spec.weights.validate()?;
    if let Some(m) = &spec.chatter_margin {
        m.validate()?;
    }
    let lim = *cell.state_limits();
    let clip = |r: [f64; 2], l: [f64; 2]| [r[0].max(l[0]), r[1].min(l[1])];
    let (rpm, i0) = axis(
        spec.initial[0],
        lim.max_spindle_step_rpm,
        clip(spec.rpm_range, lim.spindle_rpm)[0],
        clip(spec.rpm_range, lim.spindle_rpm)[1],
    )?;
    let (feed, j0) = axis(
        spec.initial[1],
        lim.max_feed_step,
        clip(spec.feed_range, lim.feed)[0],
        clip(spec.feed_range, lim.feed)[1],
    )?;
    let (g, k0) = axis(
        spec.initial[2],
        lim.max_redundancy_step,
        clip(spec.g_range, lim.redundancy_angle)[0],
        clip(spec.g_range, lim.redundancy_angle)[1],
    )?;
    let n = cell.path().segments().len();
    // (segment, g) table of r_o = 1/(K + ε); None = infeasible.
    let mut ro: Vec<Option<f64>> = Vec::with_capacity(n * g.len());
    let mut joints: Vec<[f64; 6]> = Vec::with_capacity(n * g.len());
    for t in 0..n {
        budget.check("the DP's cell states")?;
        for gv in &g {
            match cell.evaluate(t, *gv, None) {
                Ok(cs) => {
                    ro.push(Some(operational_reward(cs.condition_number)?));
                    joints.push(cs.joints);
                }
                Err(e) if is_infeasible(&e) => {
                    ro.push(None);
                    joints.push([f64::NAN; 6]);
                }
                Err(e) => return Err(e.into()),
            }
        }
    }
    // Joint speeds: the time the joints need between (t, g_k) and
    // (t + 1, g_k + dk), max_j |Δq_j| / v_j (infinite when either state is
    // infeasible), precomputed per (t, k, dk); a move is allowed when the
    // time between the midpoints at its feeds is at least that.
    let velocity_limits = joint_speed::velocity_limits(cell)?;
    let lengths: Vec<f64> = cell.path().segments().iter().map(|s| s.length).collect();
    let ng = g.len();
    let mut need = vec![f64::INFINITY; n * ng * 3];
    if spec.joint_speed_limits {
        for t in 0..n.saturating_sub(1) {
            budget.check("the DP's joint-speed table")?;
            for k in 0..ng {
                for dk in 0..3usize {
                    let Some(nk) = (k + dk).checked_sub(1).filter(|v| *v < ng) else {
                        continue;
                    };
                    let (Some(a), Some(b)) =
                        (joints.get(t * ng + k), joints.get((t + 1) * ng + nk))
                    else {
                        continue;
                    };
                    let motion = joint_speed::smallest_motion(a, b);
                    let time = (0..6)
                        .map(|j| motion[j].abs() / velocity_limits[j])
                        .fold(0.0, f64::max);
                    if let (false, Some(slot)) =
                        (time.is_nan(), need.get_mut((t * ng + k) * 3 + dk))
                    {
                        *slot = time;
                    }
                }
            }
        }
    }
    let allowed = |t: usize, x: [usize; 3], y: [usize; 3]| -> bool {
        if x[2] != y[2] && held.get(t).copied().unwrap_or(false) {
            return false;
        }
        if !spec.joint_speed_limits {
            return true;
        }
        let dk = y[2] + 1 - x[2];
        let (Some(need), Some(la), Some(lb), Some(fa), Some(fb)) = (
            need.get((t * ng + x[2]) * 3 + dk),
            lengths.get(t),
            lengths.get(t + 1),
            feed.get(x[1]),
            feed.get(y[1]),
        ) else {
            return false;
        };
        joint_speed::midpoint_interval([*la, *lb], [*fa, *fb]) >= *need
    };
    // Joint accelerations: a table over (t, k, p, dk, j, dj) of whether the
    // move from (t, g_k, f_j) to (t + 1, g_{k+dk−1}, f_{j+dj−1}) after a g
    // move coded p into (t, k) is within the acceleration limits (the
    // field's documentation); empty when not asked for.
    let nf = feed.len();
    let acc_index = |t: usize, k: usize, p: usize, dk: usize, j: usize, dj: usize| {
        ((((t * ng + k) * 3 + p) * 3 + dk) * nf + j) * 3 + dj
    };
    let mut acc_ok: Vec<bool> = Vec::new();
    if spec.joint_acceleration_limits {
        let acceleration_limits = acceleration_limits(cell);
        acc_ok = vec![false; n * ng * 9 * nf * 3];
        for t in 1..n.saturating_sub(1) {
            budget.check("the DP's joint-acceleration table")?;
            let (Some(l0), Some(l1), Some(l2)) =
                (lengths.get(t - 1), lengths.get(t), lengths.get(t + 1))
            else {
                continue;
            };
            for k in 0..ng {
                let Some(q1) = joints.get(t * ng + k) else {
                    continue;
                };
                for p in 0..3usize {
                    let Some(q0) = (k + 1)
                        .checked_sub(p)
                        .filter(|v| *v < ng)
                        .and_then(|pk| joints.get((t - 1) * ng + pk))
                    else {
                        continue;
                    };
                    for dk in 0..3usize {
                        let Some(q2) = (k + dk)
                            .checked_sub(1)
                            .filter(|v| *v < ng)
                            .and_then(|nk| joints.get((t + 1) * ng + nk))
                        else {
                            continue;
                        };
                        let back_motion = joint_speed::smallest_motion(q0, q1);
                        let ahead = joint_speed::smallest_motion(q1, q2);
                        for (j, fj) in feed.iter().enumerate() {
                            if *fj <= 0.0 {
                                continue;
                            }
                            let h1 = joint_speed::midpoint_interval([*l0, *l1], [*fj, *fj]);
                            for dj in 0..3usize {
                                let Some(fn_) = (j + dj).checked_sub(1).and_then(|v| feed.get(v))
                                else {
                                    continue;
                                };
                                if *fn_ <= 0.0 {
                                    continue;
                                }
                                let h2 = joint_speed::midpoint_interval([*l1, *l2], [*fj, *fn_]);
                                let ok = (0..6).all(|q| {
                                    let a = 2.0 * (ahead[q] / h2 - back_motion[q] / h1) / (h1 + h2);
                                    a.is_finite() && a.abs() <= acceleration_limits[q]
                                });
                                if let Some(slot) = acc_ok.get_mut(acc_index(t, k, p, dk, j, dj)) {
                                    *slot = ok;
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    let allowed3 = |t: usize, p: usize, x: [usize; 3], y: [usize; 3]| -> bool {
        if t == 0 {
            return true;
        }
        let dk = y[2] + 1 - x[2];
        let dj = y[1] + 1 - x[1];
        acc_ok
            .get(acc_index(t, x[2], p, dk, x[1], dj))
            .copied()
            .unwrap_or(false)
    };
    let re: Vec<f64> = feed
        .iter()
        .map(|f| efficiency_reward(*f, lim.feed[1]))
        .collect::<Result<_, _>>()?;
    let w = spec.weights;
    let mut forbidden = 0usize;
    let mut error: Option<MillPlanError> = None;
    let stage = |t: usize, [i, j, k]: [usize; 3]| {
        if error.is_some() {
            return None;
        }
        let ro = ro.get(t * g.len() + k).copied().flatten();
        let (Some(ro), Some(re)) = (ro, re.get(j)) else {
            forbidden += 1;
            return None;
        };
        if feed[j] <= 0.0 {
            forbidden += 1;
            return None;
        }
        match cache.try_query(t, rpm[i], feed[j], g[k]) {
            Ok(Some(mu))
                if spec
                    .chatter_limit
                    .is_some_and(|(l, from)| t >= from && mu >= l) =>
            {
                forbidden += 1;
                None
            }
            Ok(Some(mu)) => match stability_reward(mu).and_then(|rs| {
                let penalty = match &spec.chatter_margin {
                    Some(m) => m.penalty(mu)?,
                    None => 0.0,
                };
                Ok(w.operational * ro + w.efficiency * re + w.stability * rs - penalty)
            }) {
                Ok(r) => Some(r),
                Err(e) => {
                    error.get_or_insert(e);
                    None
                }
            },
            Ok(None) => {
                forbidden += 1;
                None
            }
            Err(e) => {
                error.get_or_insert(e);
                None
            }
        }
    };
    let dims = [rpm.len(), feed.len(), g.len()];
    let path = if spec.joint_acceleration_limits {
        solve_grid_with_history(n, dims, [i0, j0, k0], stage, allowed, allowed3, budget)?
    } else {
        solve_grid_with_moves(n, dims, [i0, j0, k0], stage, allowed, budget)?
    };
    if let Some(e) = error {
        return Err(e);
    }
    let path = path.ok_or_else(|| MillPlanError::Infeasible {
        planner: "dp".to_string(),
        reason: "no feasible plan from the initial state on its grid (every sequence of grid \
                 states within the step bounds leaves the feasible set)"
            .to_string(),
    })?;
    let states = path
        .nodes
        .iter()
        .enumerate()
        .map(|(t, [i, j, k])| PhysicalState {
            segment: t,
            rpm: rpm[*i],
            feed: feed[*j],
            g: g[*k],
        })
        .collect();
    Ok(DpResult {
        states,
        value: path.value,
        dims: [rpm.len(), feed.len(), g.len()],
        forbidden_states: forbidden,
        seconds: start_time.elapsed().as_secs_f64(),
    })
}

/// The joints' acceleration limits of the cell's robot \[rad/s²\], in the
/// kinematic chain's order (infinite where the robot gives none, as the
/// environment).
fn acceleration_limits(cell: &MillCell) -> [f64; 6] {
    let mut out = [f64::INFINITY; 6];
    let joints = cell.robot().joints();
    for (slot, k) in out.iter_mut().zip(cell.kinematics().joints()) {
        if let Some(a) = joints
            .iter()
            .find(|j| j.name == k.name)
            .and_then(|j| j.max_acceleration)
        {
            *slot = a;
        }
    }
    out
}
