//! Milling chatter stability for kerf's milling planner (seed 004,
//! `../shared/seeds/004_*.txt`).
//!
//! * [`model`] — tool-tip dynamics, milling process, the linear periodic DDE.
//! * [`error`] — [`ChatterError`].

pub mod error;
pub mod model;

// Constant-delay model, discretization, spectral radius, lobes.
pub mod directional;
pub mod fdm;
pub mod lobes;
pub mod spectral;

// State-dependent model (seed 004 section 2) and time-domain simulation.
pub mod equilibrium;
pub mod indicator;
pub mod linearize;
pub mod timedomain;
pub mod trochoid;

pub use error::ChatterError;
pub use model::{
    chip_direction, force_direction, DdeSample, DelayTerm, MillingProcess, Modal2, Mode,
    PeriodicDde,
};
