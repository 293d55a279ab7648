//! The settings of the milling environment ([`EnvConfig`] of
//! [`crate::env::MillEnv`]; the module documentation of [`crate::env`]
//! says what each does).

use crate::reward::{ChatterMargin, RewardWeights};

/// Settings of [`MillEnv`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnvConfig {
    /// Reward weights (seed 004 eq. 12).
    pub weights: RewardWeights,
    /// Inertia coefficient α ∈ (0, 1] of the filter (seed 004 eq. 11).
    pub alpha: f64,
    /// Ω0 \[rpm\] of the initial value problem.
    pub initial_rpm: f64,
    /// f0 [m/s].
    pub initial_feed: f64,
    /// g0 \[rad\].
    pub initial_g: f64,
    /// Reward of a terminal constraint violation (< 0).
    pub violation_penalty: f64,
    /// The paper's ablation: g fixed at g0, action (ΔΩ, Δf).
    pub fixed_g: bool,
    /// kerf's chatter margin subtracted from the step reward
    /// ([`ChatterMargin`]; `None` = seed 004 eq. 12 alone).
    pub chatter_margin: Option<ChatterMargin>,
    /// Whether a step whose joints would move faster than the URDF's
    /// velocity limits between the two segments' midpoints is a terminal
    /// violation ([`crate::joint_speed`]; kerf's constraint, default on).
    pub joint_speed_limits: bool,
    /// kerf's projection of the g move (default on): when the filtered move
    /// leads to an infeasible state (IK, joint limit, joint speed), the
    /// largest fraction of its g part that keeps the state feasible is
    /// applied instead (bisection, [`PROJECTION_BISECTIONS`] steps), and
    /// the filter state takes the applied move. Only when g unchanged is
    /// infeasible too is the step a terminal violation.
    pub project_g: bool,
    /// Lowest feed of the clip of eq. 11 [m/s] (default 0.01, kerf's): the
    /// transitions clip f to [max(f_min, min_feed), f_max]. Why: f = 0 is
    /// no machining state (the segment never ends; it is undefined under the
    /// cell's sublinear force law) and the indicator cache starts at
    /// 0.01 m/s; with the paper's f_min = 0 a policy that drives the feed
    /// down ends its episode with the violation penalty, a cliff that
    /// measurably destabilized training. 0 restores the paper's clip (a zero
    /// feed is then a terminal violation). The initial feed must be at least
    /// this.
    pub min_feed: f64,
    /// kerf's joint-acceleration shaping (default `None`: off): with
    /// `Some(w)`, w · Σ_j (|a_j| / a_max,j − 1)₊ is subtracted from the
    /// step reward, a_j the acceleration of joint j at the current segment's
    /// midpoint estimated from the joints at three consecutive midpoints
    /// (second divided difference over the midpoint intervals, Fornberg
    /// 1988 three-point formula), a_max,j the limits YAML's (joints
    /// without one are not counted). Why: the plans are timed by the feed
    /// and the executor interpolates the joints; a g that changes
    /// direction from one segment to the next asks the wrist for several
    /// times its acceleration limit and the trajectory must be slowed
    /// ([`crate::timing`]). A soft term, not a constraint: a terminal
    /// acceleration violation made training collapse (issue-5 note).
    pub acceleration_penalty: Option<f64>,
    /// kerf's minimum condition indicator (default `Some(0.35)`): a state
    /// reached by a step whose 1/K (seed 004 eq. 14) is below it is
    /// infeasible (projection, repair, else a terminal violation); the
    /// initial state is exempt (it is given), and so is the
    /// [`EnvConfig::fixed_g`] ablation (g cannot move away). Why 0.35: the
    /// goal of issue 13 is ≥ 0.3 along the EXECUTED path, whose g between
    /// midpoints is a spline through the midpoint values; 0.05 of margin
    /// covers the dip between midpoints (measured: where the bound binds,
    /// the executed minimum is 0.347–0.350, at most 0.003 below it;
    /// `BENCHMARKS.md`, "Milling: a policy that generalizes"). `None`: the
    /// paper's environment, where
    /// only the reward of eq. 15 keeps the robot away from singularities.
    pub min_condition_indicator: Option<f64>,
    /// kerf's joint-limit margin \[rad\] (default 0: the limits of the
    /// limits YAML as they are): a state reached by a step whose joints lie
    /// within this margin of a joint's limit is infeasible (projection,
    /// repair, else a terminal violation). The planner's rollouts use
    /// [`PLANNER_JOINT_LIMIT_MARGIN`]. Why: the environment checks the joints
    /// at segment midpoints; the executed trajectory runs g as a spline
    /// between them and was measured 0.0006 rad past joint 5's limit on a
    /// held-out path (the executor refuses that), so the planner keeps a
    /// margin that training did not need.
    pub joint_limit_margin: f64,
    /// kerf's chatter shield (default `None`: off; the planner's rollouts
    /// use [`PLANNER_CHATTER_SHIELD`]): with `Some(limit)`, a step whose
    /// state has |μ|max ≥ `limit` is replaced by the feasible move within
    /// the step bounds nearest the filtered one whose |μ|max is below it
    /// ([`crate::env`], "Chatter shield").
    pub chatter_shield: Option<f64>,
}

/// The chatter shield of the planner's rollouts
/// ([`EnvConfig::chatter_shield`]): |μ|max must stay below 0.99 as planned;
/// the planner's rounds ([`crate::planner::SHIELD_ROUNDS`]) then check the
/// plan as executed and lower it when needed. Why 0.99 and not lower from
/// the start: every intervention replaces the policy's smooth g move by
/// another, and the executed trajectory slows where g changes its rate, at
/// feeds where |μ|max is higher on the default cell; measured on the held-out
/// paths, a first limit of 0.97 left 4 of 10 chattering as executed, 0.99
/// with the rounds 2 (`BENCHMARKS.md`, "Milling: a policy that generalizes").
pub const PLANNER_CHATTER_SHIELD: f64 = 0.99;

/// Candidate Ω and f moves of the chatter shield: the step bound times −1,
/// −½, 0, ½, 1.
pub const SHIELD_FRACTIONS: [f64; 5] = [-1.0, -0.5, 0.0, 0.5, 1.0];

/// The most |μ|max evaluations of one shield step (the nearest feasible
/// candidates). Why 32: a step with no safe candidate evaluated all 225 (90
/// ms with the direct indicator), and the planner's rounds made a held-out
/// plan take 26 s; measured on the held-out paths, 32 keeps the same
/// chatter-free plans (`BENCHMARKS.md`, "Milling: a policy that
/// generalizes").
pub const SHIELD_MAX_EVALUATIONS: usize = 32;

/// Candidate g moves of the chatter shield: the g step bound times −1,
/// −¾, …, ¾, 1 (finer than Ω and f: with halves only, the replacements
/// alternated between ½ and 0 and the stair in g slowed the executed
/// trajectory 2–3×; measured on the held-out paths, quarters cut their
/// executed times by up to 4 s).
pub const SHIELD_G_FRACTIONS: [f64; 9] = [-1.0, -0.75, -0.5, -0.25, 0.0, 0.25, 0.5, 0.75, 1.0];

/// The joint-limit margin of the planner's rollouts \[rad\]
/// ([`EnvConfig::joint_limit_margin`]).
pub const PLANNER_JOINT_LIMIT_MARGIN: f64 = 0.01;

/// Steps of the repair search of [`EnvConfig::min_condition_indicator`]
/// on each side of the current g (resolution 1/8 of the g step bound).
pub const REPAIR_STEPS: usize = 8;

/// The default [`EnvConfig::min_condition_indicator`].
pub const DEFAULT_MIN_CONDITION_INDICATOR: f64 = 0.35;

/// Bisection steps of [`EnvConfig::project_g`] (resolution 2⁻⁸ of the move).
pub const PROJECTION_BISECTIONS: usize = 8;

impl Default for EnvConfig {
    /// Seed 004's IVP (2000 rpm, 0.04 m/s, 0 rad), α = 0.5, penalty −100,
    /// default weights, g free, the default [`ChatterMargin`] (module
    /// documentation).
    fn default() -> Self {
        Self {
            weights: RewardWeights::default(),
            alpha: 0.5,
            initial_rpm: 2000.0,
            initial_feed: 0.04,
            initial_g: 0.0,
            violation_penalty: -100.0,
            fixed_g: false,
            chatter_margin: Some(ChatterMargin::default()),
            joint_speed_limits: true,
            project_g: true,
            min_feed: 0.01,
            acceleration_penalty: None,
            min_condition_indicator: Some(DEFAULT_MIN_CONDITION_INDICATOR),
            joint_limit_margin: 0.0,
            chatter_shield: None,
        }
    }
}
