//! The database of seed 002 (Table 1): reference-point paths of 15, 50 and
//! 100 points at low, medium and high density, over the grid of velocity,
//! acceleration and jerk limits, precision 0.01 mm, period 2 ms.
//!
//! Table 1 gives the maximum velocity in m/min (2.5, 4.0, 6.0, 8.0); kerf
//! converts it to m/s (0.0417 … 0.133 m/s). Densities (section 2.C): high
//! means adjacent points less than 1 mm apart, medium 1–10 mm, low
//! 10–100 mm. The seed does not give the distribution: kerf draws each gap
//! uniformly in [0.1, 1) mm, [1, 10) mm and [10, 100) mm (a gap below
//! 0.1 mm would be within a few precisions of its neighbour), from a
//! seeded generator, so the database is the same on every machine.
//!
//! Section 3: each subset (one length and density) holds 10 paths × the 60
//! limit combinations = 600 processes; training uses one pair of paths
//! (120 processes) and testing the other 8 (480), over 5 successive pairs.

use kerf_rng::Rng;
use serde::Serialize;

use crate::limits::Limits;

/// Table 1: maximum velocities [m/min].
pub const VELOCITIES_M_PER_MIN: [f64; 4] = [2.5, 4.0, 6.0, 8.0];
/// Table 1: maximum accelerations [m/s²].
pub const ACCELERATIONS: [f64; 5] = [1.5, 1.8, 2.0, 2.5, 3.0];
/// Table 1: jerks [m/s³].
pub const JERKS: [f64; 3] = [10.0, 20.0, 30.0];
/// Table 1: target precision [m] (0.01 mm).
pub const PRECISION: f64 = 1e-5;
/// Table 1: time step [s].
pub const PERIOD: f64 = 0.002;
/// Table 1: path lengths (points).
pub const LENGTHS: [usize; 3] = [15, 50, 100];
/// Paths per subset (section 3).
pub const PATHS_PER_SUBSET: usize = 10;

/// Reference-point density of a path (section 2.C).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum Density {
    /// Gaps 10–100 mm.
    Low,
    /// Gaps 1–10 mm.
    Medium,
    /// Gaps below 1 mm.
    High,
}

impl Density {
    /// All three, as Table 1 lists them.
    pub const ALL: [Density; 3] = [Density::Low, Density::Medium, Density::High];

    /// The gap range [m] kerf draws from.
    pub fn gap_range(self) -> (f64, f64) {
        match self {
            Density::Low => (0.01, 0.1),
            Density::Medium => (0.001, 0.01),
            Density::High => (0.0001, 0.001),
        }
    }

    /// "low", "medium", "high".
    pub fn name(self) -> &'static str {
        match self {
            Density::Low => "low",
            Density::Medium => "medium",
            Density::High => "high",
        }
    }
}

/// The 60 limit combinations of Table 1, in table order (velocity
/// slowest, jerk fastest), in SI units.
pub fn limit_grid() -> Vec<Limits> {
    let mut out = Vec::with_capacity(60);
    for v in VELOCITIES_M_PER_MIN {
        for a in ACCELERATIONS {
            for j in JERKS {
                out.push(Limits::new(v / 60.0, a, j));
            }
        }
    }
    out
}

/// Path `index` (0-based) of a subset: `length` points from 0, the gaps
/// drawn for `density` from a generator seeded by the subset and index.
pub fn path(length: usize, density: Density, index: usize) -> Vec<f64> {
    let seed =
        0x5eed_0020_0000_0000 ^ ((length as u64) << 24) ^ ((density as u64) << 16) ^ index as u64;
    let mut rng = Rng::new(seed);
    let (lo, hi) = density.gap_range();
    let mut p = 0.0;
    let mut out = Vec::with_capacity(length);
    out.push(0.0);
    for _ in 1..length {
        p += rng.uniform(lo, hi);
        out.push(p);
    }
    out
}

/// One process of the database: a path and its limits.
#[derive(Debug, Clone, PartialEq)]
pub struct Process {
    /// Path index in its subset (0..10).
    pub path: usize,
    /// Index of the limits in [`limit_grid`].
    pub limits_index: usize,
    /// The limits.
    pub limits: Limits,
    /// Point positions [m], the start first.
    pub points: Vec<f64>,
}

/// The 600 processes of one subset, path-major.
pub fn subset(length: usize, density: Density) -> Vec<Process> {
    let grid = limit_grid();
    let mut out = Vec::with_capacity(PATHS_PER_SUBSET * grid.len());
    for p in 0..PATHS_PER_SUBSET {
        let points = path(length, density, p);
        for (k, limits) in grid.iter().enumerate() {
            out.push(Process {
                path: p,
                limits_index: k,
                limits: *limits,
                points: points.clone(),
            });
        }
    }
    out
}

/// Section 3's split for pair `pair` (0..5): training paths `2·pair` and
/// `2·pair + 1`, every other path for testing.
pub fn split(processes: &[Process], pair: usize) -> (Vec<&Process>, Vec<&Process>) {
    processes.iter().partition(|p| p.path / 2 == pair)
}
