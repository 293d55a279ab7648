//! The milling environment of seed 004 section 3: [`MillEnv`] implements
//! [`Environment`] for DDPG and is the reference simulator of every planner.
//!
//! # State, action, transition
//!
//! * **State** `s_t = (t, Ω_t, f_t, g_t)` (seed 004 section 3,
//!   `S = (s_pa, Ω, f, g)`): segment `t` (0-based) is machined at spindle
//!   speed Ω_t, feed f_t and redundancy angle g_t.
//! * **Initial value problem** (seed 004 section 2 end, Algorithm 1
//!   "initial point s_0 = (1, Ω0, f0, g0)"): s_0 = (0, 2000 rpm, 0.04 m/s,
//!   0 rad) by default ([`EnvConfig`]). Segment 0 is machined at the IVP.
//! * **Action** `a = (ΔΩ, Δf, Δg)` normalized to [−1, 1]³ and scaled by the
//!   cell's per-step bounds (|ΔΩ| ≤ 20 rpm, |Δf| ≤ 1e-3 m/s, |Δg| ≤ 0.2
//!   rad, `kerf_mill::StateLimits`). A NaN or an entry outside [−1, 1] is an
//!   error, never clamped. With [`EnvConfig::fixed_g`] (the paper's
//!   ablation) the action is (ΔΩ, Δf) and g stays at g0.
//! * **Transition**, seed 004 eq. 11 (garbled in the extraction; read as
//!   the inertial filter of the brief): `â_{t+1} = α a_{t+1} + (1 − α) â_t`
//!   (â_0 = 0), then `p_{t+1} = clip(p_t + â_{t+1}, p_min, p_max)` for
//!   p = (Ω, f, g), and `t → t + 1`. The clip to the state RANGE is the
//!   paper's (it keeps Ω in [2000, 4000] rpm, f in [0, 0.06] m/s, g in
//!   [−π, π]); since |â| ≤ the step bound (a convex combination of bounded
//!   actions), the per-step bounds hold for the filtered moves too.
//!   Default α = 0.5 (kerf's choice; the paper says α ∈ (0, 1) only): a
//!   reversal of the command takes effect over about two steps, a constant
//!   command reaches 97 % of its step within 5 steps; α = 1 switches the
//!   filter off (then the DP of [`crate::dp`] is exact for this
//!   environment; with α < 1 the DP value is an upper bound).
//! * **Reward of step t** (Algorithm 1: from s_t, action a_t, observe
//!   r_{t+1} and s_{t+1}): `r_{t+1} = r(s_{t+1})` of seed 004 eq. 12,
//!   evaluated on segment t + 1 with the new parameters (the segment the
//!   new state machines). An episode therefore has N − 1 = 99 steps for the
//!   N = 100 segments; segment 0 is machined at the IVP, its reward
//!   r(s_0) is the same for every policy and is reported by
//!   [`MillEnv::initial_info`]. Plan totals ([`Rollout::total_reward`],
//!   [`crate::plan`]) sum all N segments, r(s_0) included.
//! * **Chatter margin** (kerf's, [`EnvConfig::chatter_margin`], on by
//!   default): the step reward is eq. 12 minus
//!   [`ChatterMargin::penalty`] (0 below |μ|max = 0.95). Without it the
//!   optimum of eq. 12 chatters marginally (reward module); `None` gives
//!   the paper's reward exactly.
//! * **Observation** ([`crate::observation`], 37 entries, each in [−1, 1]):
//!   path-independent features (distance left, local curvature, heading,
//!   pose: position, 1/K, wrist angle, 1/K and tool-tip stiffness one
//!   segment ahead for three g), Ω, f, g, the filter state, |μ|max and the
//!   tool-tip stiffness, instead of the paper's segment
//!   index (issue 13, item 4).
//! * **Minimum condition indicator** (kerf's,
//!   [`EnvConfig::min_condition_indicator`], default 0.35, off with
//!   [`EnvConfig::fixed_g`]): a state whose 1/K (seed 004 eq. 14) is below
//!   it is infeasible like an IK failure: the g projection keeps the move
//!   out of the near-singular band, and when the band reaches an unchanged g
//!   the repair moves g by at most the step bound to the nearest feasible
//!   value. Why: the reward of eq. 15 alone (w_o = 0.1) is worth at most
//!   0.1 · 0.6 per step; the policy trained with it on main drove 1/K to
//!   0.074 (issue 13, "Conditioning"). Measured both ways in
//!   `BENCHMARKS.md` ("Milling: a policy that generalizes": the committed
//!   policy without the minimum falls to 0.257–0.337 on 4 of 11 paths).
//! * **Segment time** `l_t / f_t` (the segment's arc length over its feed).
//!   The clip keeps f ≥ [`EnvConfig::min_feed`] (0.01 m/s by default,
//!   kerf's); with `min_feed = 0` a zero feed (reachable through the
//!   paper's clip at f_min = 0) would take infinitely long: it is then a
//!   terminal constraint violation, like an infeasible g.
//! * **Infeasible state** — IK unreachable, a joint limit or a singular
//!   Jacobian at (segment t + 1, g_{t+1}), or a zero feed: the step returns
//!   `done = true` with the reward [`EnvConfig::violation_penalty`]
//!   (default −100) instead of eq. 12. −100 is worse than any continuation
//!   of the remaining ≤ 99 steps whose |μ|max stays below 1.7 (the step
//!   reward is ≥ −w_p e^(|μ|−1) ≥ −1.01 there with the default weights),
//!   so ending an episode on purpose never pays; the default cell's
//!   measured |μ| stays below 1.2.
//! * **Joint speeds** (kerf's, [`EnvConfig::joint_speed_limits`], on by
//!   default): a step whose joints move faster than the URDF's velocity
//!   limits between the two segments' midpoints
//!   ([`crate::joint_speed`]) is a terminal violation like an infeasible g.
//! * **Chatter shield** (kerf's, [`EnvConfig::chatter_shield`], off by
//!   default, on in the planner's rollouts at
//!   [`PLANNER_CHATTER_SHIELD`] = 0.99): a step whose state has |μ|max ≥
//!   the limit is replaced by the feasible move nearest to the filtered one
//!   (Ω and f moves of −1, −½, 0, ½, 1 step bound, g moves in quarters)
//!   whose |μ|max is below it, or, when there is none, by the one of least
//!   |μ|max (the post-posed shield of Alshiekh et al., AAAI 2018; `shield`
//!   module). With [`MillEnv::with_shield_slowdown`] a state is also judged
//!   at the feed an earlier executed trajectory ran its segment at. The
//!   filter state takes the applied move. Why: the policy observes |μ|max
//!   of the current state and stiffness features, not |μ|max of its next
//!   state; on held-out paths the stable band of g and Ω at f_max is
//!   narrow (|μ| alternates between 0.84 and 1.10 within 0.4 rad of g) and
//!   the policy alone chatters on 5 of 10 as executed (`BENCHMARKS.md`,
//!   "Milling: a policy that generalizes", measured with and without the
//!   shield). Training runs without it: the committed policies were trained
//!   so.
//! * **Projection of the g move** (kerf's, [`EnvConfig::project_g`], on by
//!   default): a g move into an infeasible state is shortened to the
//!   largest feasible fraction (bisection) — the clip of eq. 11 extended
//!   from the state range to the feasible set, so that exploring g does
//!   not end episodes at the edge of the reachable band or at a joint-speed
//!   limit; the step is terminal only when keeping g is infeasible too.
//! * **IK branch continuity**: each state's joints are the IK solution
//!   nearest the previous state's joints (`MillCell::evaluate` with the
//!   previous joints as reference).
//! * **|μ|max**: from the [`IndicatorCache`] when one is given and the query
//!   is inside its grid and away from infeasible nodes; evaluated directly
//!   otherwise ([`Evaluation::from_cache`] says which).

mod shield;

use std::sync::Arc;

use kerf_mill::MillCell;

use crate::cache::{is_infeasible, IndicatorCache};
use crate::error::MillPlanError;
use crate::joint_speed;
use crate::observation::{observe, PathFeatures, PoseFeatures, StateFeatures, OBSERVATION_DIM};
use crate::reward::step_reward;
use crate::rl::{Environment, Transition};

pub use crate::env_config::{
    EnvConfig, PLANNER_CHATTER_SHIELD, PLANNER_JOINT_LIMIT_MARGIN, PROJECTION_BISECTIONS,
    REPAIR_STEPS, SHIELD_FRACTIONS,
};
pub use crate::rollout::{Evaluation, PhysicalState, Rollout, StepInfo};

/// The environment (module documentation).
#[derive(Debug, Clone)]
pub struct MillEnv {
    cell: Arc<MillCell>,
    cache: Option<Arc<IndicatorCache>>,
    config: EnvConfig,
    current: Option<StepInfo>,
    initial: Option<StepInfo>,
    filter: [f64; 3],
    joints: [f64; 6],
    done: bool,
    /// Joint velocity limits of the cell's robot \[rad/s\].
    velocity_limits: [f64; 6],
    /// Joint acceleration limits \[rad/s²\] (infinite where the robot
    /// states none).
    acceleration_limits: [f64; 6],
    /// The joints at the midpoint before the current one and the time
    /// between the two midpoints \[s\] (for
    /// [`EnvConfig::acceleration_penalty`]).
    previous: Option<([f64; 6], f64)>,
    /// The path's observed geometry ([`crate::observation`]).
    features: Arc<PathFeatures>,
    /// The slowdown per segment the chatter shield assumes
    /// ([`MillEnv::with_shield_slowdown`]).
    shield_slowdown: Option<Arc<[f64]>>,
    /// The moves whose g the planner holds ([`MillEnv::with_held_g`]).
    held_g: Option<Arc<[bool]>>,
}

fn check_range(name: &str, v: f64, lo: f64, hi: f64) -> Result<f64, MillPlanError> {
    if !(v.is_finite() && v >= lo && v <= hi) {
        return Err(MillPlanError::InvalidParameter {
            name: name.to_string(),
            value: v,
            reason: format!("must be in [{lo}, {hi}]"),
        });
    }
    Ok(v)
}

impl MillEnv {
    /// A new environment (call [`Environment::reset`] before stepping).
    ///
    /// # Arguments
    /// * `cell` — the milling cell; `cache` — optional indicator cache (it
    ///   must have been built for this cell: [`IndicatorCache::load`]
    ///   checks that); `config` — settings.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidParameter`] for α ∉ (0, 1], an IVP outside
    /// the state ranges, a zero initial feed, a non-negative or NaN
    /// penalty, bad weights; [`MillPlanError::InvalidConfig`] for a path of
    /// fewer than 2 segments.
    pub fn new(
        cell: Arc<MillCell>,
        cache: Option<Arc<IndicatorCache>>,
        config: EnvConfig,
    ) -> Result<Self, MillPlanError> {
        config.weights.validate()?;
        if !(config.alpha > 0.0 && config.alpha <= 1.0) {
            return Err(MillPlanError::InvalidParameter {
                name: "inertia coefficient alpha [-]".to_string(),
                value: config.alpha,
                reason: "must be in (0, 1] (seed 004 eq. 11)".to_string(),
            });
        }
        let lim = *cell.state_limits();
        check_range(
            "initial spindle speed [rpm]",
            config.initial_rpm,
            lim.spindle_rpm[0],
            lim.spindle_rpm[1],
        )?;
        check_range(
            "initial feed [m/s]",
            config.initial_feed,
            lim.feed[0],
            lim.feed[1],
        )?;
        if config.initial_feed <= 0.0 {
            return Err(MillPlanError::InvalidParameter {
                name: "initial feed [m/s]".to_string(),
                value: config.initial_feed,
                reason: "must be > 0 (a zero feed never finishes a segment)".to_string(),
            });
        }
        if !(config.min_feed.is_finite()
            && config.min_feed >= 0.0
            && config.min_feed <= lim.feed[1])
        {
            return Err(MillPlanError::InvalidParameter {
                name: "minimum feed of the clip [m/s]".to_string(),
                value: config.min_feed,
                reason: format!("must be in [0, {}] (the maximum feed)", lim.feed[1]),
            });
        }
        if config.initial_feed < config.min_feed {
            return Err(MillPlanError::InvalidParameter {
                name: "initial feed [m/s]".to_string(),
                value: config.initial_feed,
                reason: format!(
                    "is below the planner's minimum feed {} m/s (the lowest feed it plans with)",
                    config.min_feed
                ),
            });
        }
        check_range(
            "initial redundancy angle [rad]",
            config.initial_g,
            lim.redundancy_angle[0],
            lim.redundancy_angle[1],
        )?;
        if !(config.violation_penalty.is_finite() && config.violation_penalty < 0.0) {
            return Err(MillPlanError::InvalidParameter {
                name: "violation penalty [-]".to_string(),
                value: config.violation_penalty,
                reason: "must be finite and < 0".to_string(),
            });
        }
        if let Some(m) = &config.chatter_margin {
            m.validate()?;
        }
        if cell.path().segments().len() < 2 {
            return Err(MillPlanError::InvalidConfig {
                name: "milling path".to_string(),
                reason: "needs at least 2 segments".to_string(),
            });
        }
        let velocity_limits = joint_speed::velocity_limits(&cell)?;
        let mut acceleration_limits = [f64::INFINITY; 6];
        for (a, j) in acceleration_limits.iter_mut().zip(cell.robot().joints()) {
            if let Some(max) = j.max_acceleration {
                *a = max;
            }
        }
        if let Some(w) = config.acceleration_penalty {
            if !(w.is_finite() && w >= 0.0) {
                return Err(MillPlanError::InvalidParameter {
                    name: "acceleration penalty weight".to_string(),
                    value: w,
                    reason: "must be finite and >= 0".to_string(),
                });
            }
        }
        if !(config.joint_limit_margin.is_finite()
            && (0.0..0.5).contains(&config.joint_limit_margin))
        {
            return Err(MillPlanError::InvalidParameter {
                name: "joint limit margin [rad]".to_string(),
                value: config.joint_limit_margin,
                reason: "must be in [0, 0.5)".to_string(),
            });
        }
        if let Some(c) = config.min_condition_indicator {
            if !(c.is_finite() && (0.0..1.0).contains(&c)) {
                return Err(MillPlanError::InvalidParameter {
                    name: "minimum condition indicator 1/K [-]".to_string(),
                    value: c,
                    reason: "must be in [0, 1) (1/K of seed 004 eq. 14 is in (0, 1])".to_string(),
                });
            }
        }
        shield::check_shield(&config)?;
        let features = Arc::new(PathFeatures::new(&cell)?);
        Ok(Self {
            features,
            shield_slowdown: None,
            held_g: None,
            cell,
            cache,
            config,
            velocity_limits,
            acceleration_limits,
            previous: None,
            current: None,
            initial: None,
            filter: [0.0; 3],
            joints: [0.0; 6],
            done: false,
        })
    }

    /// The environment whose chatter shield ([`EnvConfig::chatter_shield`])
    /// also checks each segment at its feed divided by `slowdown[segment]`:
    /// the feed the executed trajectory ran it at in an earlier plan
    /// ([`crate::timing::TimeScaling::segment_slowdown`]; the planner's
    /// shield rounds, [`crate::planner::SHIELD_ROUNDS`]).
    ///
    /// # Arguments
    /// * `slowdown` — one factor per segment, each finite and ≥ 1.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] for another length;
    /// [`MillPlanError::InvalidParameter`] for a factor below 1 or NaN.
    pub fn with_shield_slowdown(mut self, slowdown: Arc<[f64]>) -> Result<Self, MillPlanError> {
        if slowdown.len() != self.segment_count() {
            return Err(MillPlanError::InvalidConfig {
                name: "shield slowdown".to_string(),
                reason: format!(
                    "{} factors for {} segments",
                    slowdown.len(),
                    self.segment_count()
                ),
            });
        }
        if let Some(bad) = slowdown.iter().find(|c| !(c.is_finite() && **c >= 1.0)) {
            return Err(MillPlanError::InvalidParameter {
                name: "shield slowdown factor [-]".to_string(),
                value: *bad,
                reason: "must be finite and >= 1".to_string(),
            });
        }
        self.shield_slowdown = Some(slowdown);
        Ok(self)
    }

    /// The environment with g held on some moves: `held[t]` makes the
    /// step from segment t to t + 1 keep g (the policy's and the filter's g
    /// move are set to 0, and the chatter shield offers no g move); only
    /// the repair of [`EnvConfig::min_condition_indicator`] still moves g
    /// when keeping it is infeasible. The planner's shield rounds hold g
    /// around segments an earlier executed trajectory slowed into chatter
    /// ([`crate::planner::SHIELD_ROUNDS`]).
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] unless there is one entry per
    /// segment.
    pub fn with_held_g(mut self, held: Arc<[bool]>) -> Result<Self, MillPlanError> {
        if held.len() != self.segment_count() {
            return Err(MillPlanError::InvalidConfig {
                name: "held g moves".to_string(),
                reason: format!(
                    "{} entries for {} segments",
                    held.len(),
                    self.segment_count()
                ),
            });
        }
        self.held_g = Some(held);
        Ok(self)
    }

    /// Whether the move from `segment` to the next keeps g
    /// ([`MillEnv::with_held_g`]).
    fn holds_g(&self, segment: usize) -> bool {
        self.held_g
            .as_ref()
            .and_then(|h| h.get(segment))
            .copied()
            .unwrap_or(false)
    }

    /// The cell.
    pub fn cell(&self) -> &MillCell {
        &self.cell
    }

    /// The settings.
    pub fn config(&self) -> &EnvConfig {
        &self.config
    }

    /// Number of path segments N.
    pub fn segment_count(&self) -> usize {
        self.cell.path().segments().len()
    }

    /// The current physical state (`None` before the first reset).
    pub fn state(&self) -> Option<PhysicalState> {
        self.current.as_ref().map(|c| c.state)
    }

    /// Diagnostics of the current state (the last step's, or the initial
    /// state's after a reset).
    pub fn last_info(&self) -> Option<&StepInfo> {
        self.current.as_ref()
    }

    /// Diagnostics of s_0 (its reward r(s_0) is not part of any step).
    pub fn initial_info(&self) -> Option<&StepInfo> {
        self.initial.as_ref()
    }

    /// The filter state â_t (physical units: rpm, m/s, rad).
    pub fn filter_state(&self) -> [f64; 3] {
        self.filter
    }

    /// Whether the episode has ended.
    pub fn is_done(&self) -> bool {
        self.done
    }

    /// Evaluates a state: `Ok(Ok(evaluation))`, `Ok(Err(reason))` for a
    /// constraint violation, `Err` for a model failure.
    ///
    /// # Errors
    /// Cell-model errors other than infeasibility; chatter-model errors.
    pub fn evaluate_state(
        &self,
        state: &PhysicalState,
        reference: Option<&[f64; 6]>,
    ) -> Result<Result<Evaluation, String>, MillPlanError> {
        let segment = self.cell.path().segment(state.segment)?;
        if state.feed.is_nan() || state.feed <= 0.0 {
            return Ok(Err(format!(
                "zero feed at segment {}: the segment would take infinitely long",
                state.segment
            )));
        }
        let cs = match self.cell.evaluate(state.segment, state.g, reference) {
            Ok(cs) => cs,
            Err(e) if is_infeasible(&e) => return Ok(Err(e.to_string())),
            Err(e) => return Err(e.into()),
        };
        let cached = match &self.cache {
            Some(c) => c.try_query(state.segment, state.rpm, state.feed, state.g)?,
            None => None,
        };
        let (mu, from_cache) = match cached {
            Some(mu) => (mu, true),
            None => {
                let ind = kerf_chatter::indicator::chatter_indicator(
                    &cs.modal,
                    &self.cell.milling_process(),
                    state.rpm,
                    state.feed,
                    self.cell.indicator_settings(),
                )?;
                (ind.spectral_radius, false)
            }
        };
        let max_feed = self.cell.state_limits().feed[1];
        let reward = step_reward(
            &self.config.weights,
            cs.condition_number,
            state.feed,
            max_feed,
            mu,
        )?;
        let chatter_penalty = match &self.config.chatter_margin {
            Some(m) => m.penalty(mu)?,
            None => 0.0,
        };
        Ok(Ok(Evaluation {
            joints: cs.joints,
            condition_number: cs.condition_number,
            condition_indicator: cs.condition_indicator,
            spectral_radius: mu,
            from_cache,
            segment_time: segment.length / state.feed,
            reward,
            chatter_penalty,
        }))
    }

    /// The observation of the current state ([`crate::observation`]).
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] before the first reset; cell-model
    /// errors other than infeasibility of the lookahead.
    pub fn observation(&self) -> Result<Vec<f32>, MillPlanError> {
        let info = self
            .current
            .as_ref()
            .ok_or_else(|| MillPlanError::InvalidConfig {
                name: "environment".to_string(),
                reason: "no state: call reset".to_string(),
            })?;
        let state = info.state;
        let lim = self.cell.state_limits();
        let stiffness = |m: &kerf_chatter::model::Modal2| {
            [
                m.stiffness[(0, 0)],
                m.stiffness[(1, 1)],
                m.stiffness[(0, 1)],
            ]
        };
        let pose = match info.evaluation.as_ref() {
            None => None,
            Some(e) => {
                // The state's tool-tip dynamics on its own IK branch (its
                // joints are the environment's current joints).
                let cs = self
                    .cell
                    .evaluate(state.segment, state.g, Some(&self.joints))?;
                Some(PoseFeatures {
                    condition_indicator: e.condition_indicator,
                    wrist_angle: e.joints[4],
                    chatter_indicator: e.spectral_radius,
                    stiffness: stiffness(&cs.modal),
                })
            }
        };
        let mut condition_ahead = [0.0; 3];
        let mut stiffness_ahead = [None; 3];
        if pose.is_some() {
            let next = (state.segment + 1).min(self.segment_count() - 1);
            let step = lim.max_redundancy_step;
            for (k, dg) in [-step, 0.0, step].into_iter().enumerate() {
                let g = state.g + dg;
                if g < lim.redundancy_angle[0] || g > lim.redundancy_angle[1] {
                    continue;
                }
                match self.cell.evaluate(next, g, Some(&self.joints)) {
                    Ok(cs) => {
                        condition_ahead[k] = cs.condition_indicator;
                        stiffness_ahead[k] = Some(stiffness(&cs.modal));
                    }
                    Err(e) if is_infeasible(&e) => {}
                    Err(e) => return Err(e.into()),
                }
            }
        }
        observe(
            &self.features,
            lim,
            &StateFeatures {
                segment: state.segment,
                rpm: state.rpm,
                feed: state.feed,
                g: state.g,
                filter: self.filter,
                pose,
                condition_ahead,
                stiffness_ahead,
            },
        )
    }

    /// Why the joints of a state at `next` violate
    /// [`EnvConfig::joint_limit_margin`], if they do.
    fn margin_violation(&self, next: &PhysicalState, joints: &[f64; 6]) -> Option<String> {
        let m = self.config.joint_limit_margin;
        if m <= 0.0 {
            return None;
        }
        self.cell
            .kinematics()
            .joints()
            .iter()
            .zip(joints)
            .find(|(r, q)| **q < r.lower + m || **q > r.upper - m)
            .map(|(r, q)| {
                format!(
                    "joint {} = {q:.4} rad at segment {} (g = {:.3} rad) is within the margin \
                     {m} rad of its limits [{}, {}]",
                    r.name, next.segment, next.g, r.lower, r.upper
                )
            })
    }

    /// Why 1/K of a state at `next` violates
    /// [`EnvConfig::min_condition_indicator`], if it does (never with
    /// [`EnvConfig::fixed_g`]: g cannot move away).
    fn condition_violation(&self, next: &PhysicalState, indicator: f64) -> Option<String> {
        let min = self.config.min_condition_indicator?;
        if self.config.fixed_g || indicator >= min {
            return None;
        }
        Some(format!(
            "condition indicator 1/K = {indicator:.3} at segment {} (g = {:.3} rad) is below \
             the minimum {min} (near a singularity)",
            next.segment, next.g
        ))
    }

    /// [`MillEnv::evaluate_state`] of `next` (IK from the current joints)
    /// plus the joint-speed check from `current` when
    /// [`EnvConfig::joint_speed_limits`] is set.
    fn checked_evaluation(
        &self,
        current: &PhysicalState,
        next: &PhysicalState,
    ) -> Result<Result<Evaluation, String>, MillPlanError> {
        let eval = self.evaluate_state(next, Some(&self.joints))?;
        let Ok(e) = &eval else {
            return Ok(eval);
        };
        if let Some(reason) = self.condition_violation(next, e.condition_indicator) {
            return Ok(Err(reason));
        }
        if let Some(reason) = self.margin_violation(next, &e.joints) {
            return Ok(Err(reason));
        }
        Ok(match self.speed_violation(current, next, &e.joints) {
            Some(reason) => Err(reason),
            None => eval,
        })
    }

    /// The joint-speed violation of moving from the current joints to
    /// `joints` at `next` ([`EnvConfig::joint_speed_limits`]), if any.
    fn speed_violation(
        &self,
        current: &PhysicalState,
        next: &PhysicalState,
        joints: &[f64; 6],
    ) -> Option<String> {
        if !self.config.joint_speed_limits {
            return None;
        }
        let dt = self.midpoint_time(current, next);
        let motion: [f64; 6] = std::array::from_fn(|j| joints[j] - self.joints[j]);
        joint_speed::first_violation(&motion, dt, &self.velocity_limits).map(|(j, speed)| {
            format!(
                "joint {} would move at {speed:.3} rad/s between segments {} and {} (limit \
                 {:.3} rad/s)",
                j + 1,
                current.segment,
                next.segment,
                self.velocity_limits.get(j).copied().unwrap_or(f64::NAN)
            )
        })
    }

    /// Whether `next` is feasible from `current` (feed > 0, IK within the
    /// joint limits from the current joints, joint speeds when
    /// [`EnvConfig::joint_speed_limits`] is set), without the chatter
    /// evaluation.
    ///
    /// # Errors
    /// Cell-model errors other than infeasibility.
    fn feasible(
        &self,
        current: &PhysicalState,
        next: &PhysicalState,
    ) -> Result<bool, MillPlanError> {
        if next.feed.is_nan() || next.feed <= 0.0 {
            return Ok(false);
        }
        let cs = match self.cell.evaluate(next.segment, next.g, Some(&self.joints)) {
            Ok(cs) => cs,
            Err(e) if is_infeasible(&e) => return Ok(false),
            Err(e) => return Err(e.into()),
        };
        if self
            .condition_violation(next, cs.condition_indicator)
            .is_some()
            || self.margin_violation(next, &cs.joints).is_some()
        {
            return Ok(false);
        }
        Ok(self.speed_violation(current, next, &cs.joints).is_none())
    }

    /// The time between the midpoints of two consecutive segments at their
    /// feeds \[s\] ([`joint_speed::midpoint_interval`]).
    fn midpoint_time(&self, current: &PhysicalState, next: &PhysicalState) -> f64 {
        let segments = self.cell.path().segments();
        let lengths = [
            segments.get(current.segment).map_or(0.0, |s| s.length),
            segments.get(next.segment).map_or(0.0, |s| s.length),
        ];
        joint_speed::midpoint_interval(lengths, [current.feed, next.feed])
    }

    /// Σ_j (|a_j| / a_max,j − 1)₊ at the middle of three midpoints (joints
    /// `q0`, `q1`, `q2`, intervals `h1`, `h2`): a_j = 2 ((q2 − q1)/h2 −
    /// (q1 − q0)/h1) / (h1 + h2), the second derivative of the parabola
    /// through the three (Fornberg 1988). Non-finite values count as 0 (a
    /// zero interval cannot occur: feeds are ≥ `min_feed` > 0).
    fn acceleration_excess(
        &self,
        q0: &[f64; 6],
        q1: &[f64; 6],
        q2: &[f64; 6],
        h1: f64,
        h2: f64,
    ) -> f64 {
        let mut sum = 0.0;
        for j in 0..6 {
            let a = 2.0 * ((q2[j] - q1[j]) / h2 - (q1[j] - q0[j]) / h1) / (h1 + h2);
            let excess = (a.abs() / self.acceleration_limits[j] - 1.0).max(0.0);
            if excess.is_finite() {
                sum += excess;
            }
        }
        sum
    }

    fn info_from(
        &self,
        state: PhysicalState,
        filtered_action: [f64; 3],
        eval: Result<Evaluation, String>,
    ) -> StepInfo {
        match eval {
            Ok(e) => StepInfo {
                state,
                filtered_action,
                reward: e.reward.total - e.chatter_penalty,
                evaluation: Some(e),
                violation: None,
            },
            Err(reason) => StepInfo {
                state,
                filtered_action,
                reward: self.config.violation_penalty,
                evaluation: None,
                violation: Some(reason),
            },
        }
    }

    /// Runs one episode from the IVP with a policy.
    ///
    /// # Arguments
    /// * `policy` — maps (observation, physical state) to a normalized
    ///   action.
    ///
    /// # Returns
    /// The [`Rollout`]; it ends at the last segment or the first violation.
    ///
    /// # Errors
    /// Those of [`Environment::reset`] and [`Environment::step`], and the
    /// policy's.
    pub fn rollout<P>(&mut self, mut policy: P) -> Result<Rollout, MillPlanError>
    where
        P: FnMut(&[f32], &PhysicalState) -> Result<Vec<f32>, MillPlanError>,
    {
        let mut obs = self.reset()?;
        let initial = self
            .current
            .clone()
            .ok_or_else(|| MillPlanError::InvalidConfig {
                name: "environment".to_string(),
                reason: "no state after reset".to_string(),
            })?;
        let mut steps = Vec::with_capacity(self.max_steps());
        let mut total = initial.reward;
        while !self.done {
            let state = self.state().ok_or_else(|| MillPlanError::InvalidConfig {
                name: "environment".to_string(),
                reason: "no state".to_string(),
            })?;
            let action = policy(&obs, &state)?;
            let tr = self.step(&action)?;
            obs = tr.observation;
            total += tr.reward;
            if let Some(info) = &self.current {
                steps.push(info.clone());
            }
        }
        let completed =
            steps.len() == self.max_steps() && steps.iter().all(|s| s.violation.is_none());
        Ok(Rollout {
            initial,
            steps,
            total_reward: total,
            completed,
        })
    }

    /// Runs one episode with a fixed action sequence; when the sequence is
    /// shorter than the episode, the remaining actions are zero.
    ///
    /// # Errors
    /// As [`MillEnv::rollout`] (a bad action is an error).
    pub fn rollout_actions(&mut self, actions: &[Vec<f32>]) -> Result<Rollout, MillPlanError> {
        let dim = self.action_dim();
        let mut t = 0usize;
        self.rollout(|_, _| {
            let a = actions.get(t).cloned().unwrap_or_else(|| vec![0.0; dim]);
            t += 1;
            Ok(a)
        })
    }
}

impl Environment for MillEnv {
    fn observation_dim(&self) -> usize {
        OBSERVATION_DIM
    }

    fn observation_layout(&self) -> Vec<String> {
        crate::observation::layout()
    }

    fn action_dim(&self) -> usize {
        if self.config.fixed_g {
            2
        } else {
            3
        }
    }

    fn max_steps(&self) -> usize {
        self.segment_count() - 1
    }

    fn reset(&mut self) -> Result<Vec<f32>, MillPlanError> {
        let state = PhysicalState {
            segment: 0,
            rpm: self.config.initial_rpm,
            feed: self.config.initial_feed,
            g: self.config.initial_g,
        };
        let eval = self.evaluate_state(&state, None)?;
        let eval = eval.map_err(|reason| MillPlanError::InvalidConfig {
            name: "initial state (segment 0, Omega0, f0, g0)".to_string(),
            reason,
        })?;
        self.joints = eval.joints;
        let info = self.info_from(state, [0.0; 3], Ok(eval));
        self.initial = Some(info.clone());
        self.current = Some(info);
        self.filter = [0.0; 3];
        self.previous = None;
        self.done = false;
        self.observation()
    }

    fn step(&mut self, action: &[f32]) -> Result<Transition, MillPlanError> {
        let Some(current) = self.current.as_ref().map(|c| c.state) else {
            return Err(MillPlanError::InvalidConfig {
                name: "environment".to_string(),
                reason: "step before reset".to_string(),
            });
        };
        if self.done {
            return Err(MillPlanError::InvalidConfig {
                name: "environment".to_string(),
                reason: "the episode is over: call reset".to_string(),
            });
        }
        if action.len() != self.action_dim() {
            return Err(MillPlanError::InvalidConfig {
                name: "action".to_string(),
                reason: format!("{} entries, expected {}", action.len(), self.action_dim()),
            });
        }
        for (i, a) in action.iter().enumerate() {
            if !(a.is_finite() && (-1.0..=1.0).contains(a)) {
                return Err(MillPlanError::InvalidParameter {
                    name: format!("action[{i}] [-]"),
                    value: f64::from(*a),
                    reason: "must be in [-1, 1] (normalized action; NaN is refused)".to_string(),
                });
            }
        }
        let lim = *self.cell.state_limits();
        let bounds = [
            lim.max_spindle_step_rpm,
            lim.max_feed_step,
            lim.max_redundancy_step,
        ];
        let mut raw = [0.0; 3];
        for (k, r) in raw.iter_mut().enumerate() {
            *r = action.get(k).map(|a| f64::from(*a)).unwrap_or(0.0) * bounds[k];
        }
        if self.config.fixed_g {
            raw[2] = 0.0;
        }
        // Seed 004 eq. 11: inertial filter, then the clip to the state range.
        // The environment changes only when the evaluation succeeds (a model
        // failure leaves the state and the filter as they were).
        let alpha = self.config.alpha;
        let mut filter = self.filter;
        for (f, r) in filter.iter_mut().zip(raw) {
            *f = alpha * r + (1.0 - alpha) * *f;
        }
        if self.holds_g(current.segment) {
            filter[2] = 0.0;
        }
        let next = PhysicalState {
            segment: current.segment + 1,
            rpm: (current.rpm + filter[0]).clamp(lim.spindle_rpm[0], lim.spindle_rpm[1]),
            feed: (current.feed + filter[1])
                .clamp(lim.feed[0].max(self.config.min_feed), lim.feed[1]),
            g: (current.g + filter[2]).clamp(lim.redundancy_angle[0], lim.redundancy_angle[1]),
        };
        let mut next = next;
        let mut eval = self.checked_evaluation(&current, &next)?;
        // kerf's projection of the g move (EnvConfig::project_g): the
        // largest fraction of the filtered g move that keeps the state
        // feasible (IK, joint limits, joint speeds), by bisection.
        if eval.is_err() && self.config.project_g && !self.config.fixed_g && filter[2] != 0.0 {
            let full = filter[2];
            let at = |fraction: f64| PhysicalState {
                g: (current.g + fraction * full)
                    .clamp(lim.redundancy_angle[0], lim.redundancy_angle[1]),
                ..next
            };
            let still = at(0.0);
            if self.feasible(&current, &still)? {
                // Bisection on feasibility alone (IK, limits, joint speeds:
                // no chatter evaluation), then one evaluation of the result.
                let (mut good, mut bad) = (0.0, 1.0);
                for _ in 0..PROJECTION_BISECTIONS {
                    let mid = 0.5 * (good + bad);
                    if self.feasible(&current, &at(mid))? {
                        good = mid;
                    } else {
                        bad = mid;
                    }
                }
                next = at(good);
                eval = self.checked_evaluation(&current, &next)?;
                filter[2] = next.g - current.g;
            }
        }
        // kerf's repair (EnvConfig::min_condition_indicator): when g
        // unchanged is infeasible too (the near-singular band or the edge of
        // the reachable set has reached it), the feasible g nearest the
        // current one within the step bound, if any.
        if eval.is_err()
            && self.config.project_g
            && !self.config.fixed_g
            && self.config.min_condition_indicator.is_some()
        {
            let still = PhysicalState {
                g: current.g,
                ..next
            };
            if !self.feasible(&current, &still)? {
                let step = lim.max_redundancy_step / REPAIR_STEPS as f64;
                'search: for k in 1..=REPAIR_STEPS {
                    for sign in [1.0, -1.0] {
                        let g = current.g + sign * step * k as f64;
                        if g < lim.redundancy_angle[0] || g > lim.redundancy_angle[1] {
                            continue;
                        }
                        let candidate = PhysicalState { g, ..next };
                        if self.feasible(&current, &candidate)? {
                            next = candidate;
                            eval = self.checked_evaluation(&current, &next)?;
                            filter[2] = next.g - current.g;
                            break 'search;
                        }
                    }
                }
            }
        }
        // kerf's chatter shield (EnvConfig::chatter_shield): a move into a
        // state at or above the limit is replaced by the nearest safe one.
        if let (Some(limit), Ok(e)) = (self.config.chatter_shield, &eval) {
            let mu = self.shielded_radius(&next, e)?;
            if mu >= limit {
                if let Some((state, e)) = self.shield(&current, &next, mu, limit)? {
                    filter = [
                        state.rpm - current.rpm,
                        state.feed - current.feed,
                        state.g - current.g,
                    ];
                    next = state;
                    eval = Ok(e);
                }
            }
        }
        self.filter = filter;
        let violated = eval.is_err();
        let before = self.joints;
        let mut shaping = 0.0;
        if let Ok(e) = &eval {
            let dt = self.midpoint_time(&current, &next);
            if let (Some(w), Some((q0, dt0))) = (self.config.acceleration_penalty, self.previous) {
                shaping = w * self.acceleration_excess(&q0, &before, &e.joints, dt0, dt);
            }
            self.previous = Some((before, dt));
            self.joints = e.joints;
        }
        let mut info = self.info_from(next, self.filter, eval);
        info.reward -= shaping;
        let reward = info.reward;
        self.current = Some(info);
        self.done = violated || next.segment + 1 >= self.segment_count();
        Ok(Transition {
            observation: self.observation()?,
            reward,
            done: self.done,
        })
    }
}
