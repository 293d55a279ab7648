//! The milling planner of kerf (seed 004, `../shared/seeds/004_*.txt`):
//! chooses spindle speed Ω, feed f and the redundancy angle g per path
//! segment under the chatter constraint, with DDPG, and measures it against
//! a dynamic-programming optimum and naive baselines on the same model.
//!
//! * [`rl`] — the agent/environment interface.
//! * [`error`] — [`MillPlanError`].

pub mod error;
pub mod rl;

// The environment of seed 004 section 3 and the baselines.
pub mod cache;
pub mod dp;
pub mod env;
pub mod joint_speed;
pub mod naive;
pub mod plan;
pub mod reward;
pub mod timing;

// The planner node's ROS-free front half: requests and planning.
pub mod planner;
pub mod request;

// DDPG (seed 004 Algorithm 1, Table 2) on candle.
pub mod ddpg;
pub mod history;
pub mod nets;
pub mod policy;
pub mod replay;
pub mod rng;

pub use error::MillPlanError;
pub use rl::{Environment, Transition};

// DDPG and trained policies.
pub use ddpg::{train, DdpgSettings, EpisodeReport, TrainedAgent};
pub use policy::{Policy, PolicyMetadata};

// The environment, the indicator cache, the baselines and plans.
pub use cache::{GridSpec, IndicatorCache};
pub use dp::{DpResult, DpSpec};
pub use env::{EnvConfig, MillEnv, PhysicalState, Rollout, StepInfo};
pub use naive::NaiveResult;
pub use plan::{comparison_table, ComparisonRow, Plan};
pub use planner::{
    default_policy_path, execute, status_of, Executed, JointTrajectory, MillPlanOutput,
    MillPlanner, TrajectoryPoint,
};
pub use request::{MillRequest, PlannerKind};
pub use reward::{RewardParts, RewardWeights};
pub use timing::{time_scale, JointLimit, TimeScaling};
