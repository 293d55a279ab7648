//! Reference-point stepping for kerf (seed 002,
//! `../shared/seeds/002_*.txt`, issue 29): a per-period feed controller
//! that passes each reference point of a path within a target precision in
//! as few control periods as it can (RPRO), its DDQN imitation, stepping
//! along multi-axis paths, and a Ruckig reference.
//!
//! | module | what | source |
//! |---|---|---|
//! | [`lattice`] | exact jerk-per-period motion on an integer lattice | seed 002 eq. 1 |
//! | [`tracker`] | exact jerk-limited velocity tracking and stop | |
//! | [`course`] | reference points as windows of ± precision | seed 002 Table 1 |
//! | [`rpro`] | kerf's reading of RPRO: greedy decisions with a viability look-ahead | seed 002 §2.A, ref. [6] |
//! | [`run`] | the per-period loop, passes, steps and accuracy | seed 002 §3 |
//! | [`spline`] | natural cubic spline through N-D points over chord length, derivative bounds | de Boor 1978 ch. IV |
//! | [`multi`] | stepping along 2D/3D and joint paths: path limits from the axis limits | chain rule |
//! | [`ruckig_ref`] | jerk-limited reference through the same points (rsruckig), steps and accuracy | Berscheid & Kröger 2021 |
//! | [`points`] | reference points as text (1 to 6 coordinates per line) | |
//! | [`stream`] | the executor's streaming mode: rules, batches from rest to rest | issue 29 |
//! | [`database`] | the paths and limit grid of Table 1, the train/test split | seed 002 Table 1, §3 |
//! | [`ddqn`] | the DDQN imitation of RPRO: Q-network, agent, shield, training, Tables 4–6 metrics | seed 002 §3, Tables 2–6; van Hasselt et al. 2016 |

pub mod course;
pub mod database;
pub mod ddqn;
pub mod error;
pub mod lattice;
pub mod limits;
pub mod multi;
pub mod points;
pub mod rpro;
pub mod ruckig_ref;
pub mod run;
pub mod spline;
pub mod stream;
pub mod tracker;

pub use course::Course;
pub use error::StepError;
pub use lattice::{Action, Lattice, State};
pub use limits::Limits;
pub use rpro::{Rpro, RproSettings};
pub use run::{run, Controller, Decision, Pass, Run};
