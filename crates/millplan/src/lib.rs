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
pub mod cache_file;
pub mod direct;
pub mod dp;
pub mod dp_executed;
pub mod env;
pub mod env_config;
pub mod evaluation;
pub mod fingerprint;
pub mod greedy;
pub mod grid_dp;
pub mod grid_spec;
pub mod joint_speed;
pub mod naive;
pub mod observation;
pub mod path_cache;
pub mod path_distribution;
pub mod plan;
pub mod propose_refine;
pub mod provenance;
pub mod reward;
pub mod rollout;
pub mod slowdown;
pub mod spline1d;
pub mod time_law;
pub mod timing;

// The joint trajectory (the executor's type), as planned and as executed.
pub mod chatter_judge;
pub mod deviation;
pub mod executed;
pub mod planned;
pub mod trajectory;

// The planner node's ROS-free front half: requests and planning.
pub mod output;
mod parallel;
pub mod planner;
pub mod request;
pub mod status;

// DDPG (seed 004 Algorithm 1, Table 2) on candle.
pub mod adamw;
pub mod cpu_tuning;
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
pub use executed::{execute, Executed};
pub use naive::NaiveResult;
pub use output::{Candidate, MillPlanOutput, PlanningPhases};
pub use plan::{comparison_table, ComparisonRow, Plan};
pub use planner::{default_policy_path, MillPlanner};
pub use request::{MillRequest, PlannerKind};
pub use reward::{RewardParts, RewardWeights};
pub use status::status_of;
pub use timing::{time_scale, JointLimit, TimeScaling, TrajectorySettings};
pub use trajectory::{JointTrajectory, TrajectoryPoint, TrajectoryRequest};
