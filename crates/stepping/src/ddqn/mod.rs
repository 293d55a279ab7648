//! The DDQN imitation of RPRO (seed 002 sections 2.B and 3): a small
//! Q-network that maps the axis state to accelerate / keep / decelerate,
//! trained by Double DQN with a reward for agreeing with RPRO (eq. 4).
//!
//! | module | what | source |
//! |---|---|---|
//! | [`net`] | the Q-network 3 → N → N → 3 of Table 2, plain and on candle | seed 002 Fig. 2, Table 2 |
//! | [`features`] | the input v/V, a/A, d/d_max | seed 002 §3 |
//! | [`file`] | the network file: safetensors with the architecture in its metadata | |
//! | [`agent`] | the greedy agent as a controller, and the agent behind RPRO's shield | |
//! | [`env`] | the training environment: replays of RPRO's stored runs from a uniformly drawn step, rewarded against RPRO's decisions | seed 002 §2.C, eq. 4 |
//! | [`adam`] | Adam on the plain weights | Kingma & Ba 2015 |
//! | [`train`] | Double DQN with the Table 3 hyper-parameters | van Hasselt et al. 2016, seed 002 Table 3 |
//! | [`metrics`] | closed-loop runs of the raw agent (paper-style completion to the last point, and completion at rest); steps correlation, median mean error, median steps | seed 002 Tables 4–6 |
//!
//! The raw [`Agent`] is what the paper measures ([`closed_loop`]: actions
//! outside the limits are replaced by the nearest allowed one and counted,
//! missed points are measured). A deployment runs [`Shielded`]: the agent's
//! action when RPRO's viability check allows it and it keeps the axis
//! moving, RPRO's decision otherwise.

pub mod adam;
pub mod agent;
pub mod env;
pub mod features;
pub mod file;
pub mod metrics;
pub mod net;
pub mod train;

pub use agent::{Agent, Shielded};
pub use features::features;
pub use metrics::{baseline, closed_loop, evaluate, ClosedLoop, Evaluation};
pub use net::{Activation, Architecture, Weights};
pub use train::{courses, train, DdqnSettings, Trained};
