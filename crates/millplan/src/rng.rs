//! The seeded generator of DDPG training: [`kerf_rng::Rng`], shared with
//! the stepping agent (`kerf_stepping`).

pub use kerf_rng::*;
