//! Seed 003's DRLS corner networks, ROS-free (issue 30, item 3).
//!
//! Seed 003 smooths a corner by a NURBS with two added control points and
//! a vertex weight, chosen by a particle swarm (its eqs. 7–8), then trains
//! two residual networks, FDLS (the points) and SDLS (the weight), on the
//! swarm's answers so that smoothing no longer runs the swarm. kerf has the
//! NURBS corner and its swarm (`kerf_toolpath::baseline::{nurbs, pso}`);
//! this crate makes the data, trains FDLS, and predicts corners with a
//! verified fallback to the swarm.
//!
//! | module | concept |
//! |---|---|
//! | [`corner`] | a corner's local frame, features and the NURBS built from the swarm's variables |
//! | [`dataset`] | swarm-solved corners over a stated distribution, JSON |
//! | [`net`] | the residual MLP and its plain forward pass |
//! | [`train`] | training with candle |
//! | [`file`] | SafeTensors weights with a JSON sidecar |
//! | [`predict`] | the `drls_net` corner with its fallback |

pub mod corner;
pub mod dataset;
pub mod error;
pub mod file;
pub mod net;
pub mod predict;
pub mod train;

pub use corner::{LocalCorner, INPUTS, OUTPUTS};
pub use dataset::{Dataset, Distribution, Sample};
pub use error::CornerNetError;
pub use file::{Model, Sidecar};
pub use net::{Architecture, Normalization, ResMlp};
pub use predict::{Counts, DrlsCorner, DrlsNet, Source};
pub use train::{TrainReport, TrainSettings};
