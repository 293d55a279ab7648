//! Milling chatter stability for kerf's milling planner (seed 004,
//! `../shared/seeds/004_*.txt`).
//!
//! * [`model`] — tool-tip dynamics, milling process, the linear periodic DDE.
//! * [`error`] — [`ChatterError`].

pub mod error;
pub mod model;

pub use error::ChatterError;
pub use model::{
    chip_direction, force_direction, DdeSample, DelayTerm, MillingProcess, Modal2, Mode,
    PeriodicDde,
};
