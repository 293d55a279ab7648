//! The training data: corners drawn from a stated distribution, each
//! solved by the NURBS corner's particle swarm (seed 003 eq. 8, the paper's
//! way of making the DRLS data: "the NURBS control point positions and the
//! corresponding NURBS weights are stored as datasets").
//!
//! # Distribution
//! Turning angle θ uniform in [`Distribution::turn_min_deg`],
//! [`Distribution::turn_max_deg`] (default [5°, 175°]); the ratio A / δ of
//! the available length to the tolerance log-uniform in
//! [`Distribution::ratio_min`], [`Distribution::ratio_max`] (default
//! [2, 500]: a 0.02–5 mm segment half at δ = 10 µm). Both are drawn from
//! `kerf_rng::Rng::new(seed)`, θ first, for every sample in turn, before
//! any swarm runs, so the data do not depend on the number of threads.
//!
//! # Labels
//! The swarm's variables (ℓ / A, α, β) ([`crate::corner`]), the weight it
//! solved, and its largest curvature times δ (scale-free), from the swarm
//! settings given (normally [`NurbsSettings::default`], nurbs.rs's).

use std::path::Path;

use kerf_rng::Rng;
use kerf_toolpath::NurbsSettings;
use serde::{Deserialize, Serialize};

use crate::corner::{LocalCorner, OUTPUTS};
use crate::error::CornerNetError;

/// The distribution of corners a network is trained for.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Distribution {
    /// Smallest turning angle \[deg\], > 0.
    pub turn_min_deg: f64,
    /// Largest \[deg\], < 180.
    pub turn_max_deg: f64,
    /// Smallest A / δ, > 0.
    pub ratio_min: f64,
    /// Largest A / δ.
    pub ratio_max: f64,
}

impl Default for Distribution {
    /// θ in [5°, 175°], A / δ in [2, 500].
    fn default() -> Self {
        Distribution {
            turn_min_deg: 5.0,
            turn_max_deg: 175.0,
            ratio_min: 2.0,
            ratio_max: 500.0,
        }
    }
}

impl Distribution {
    /// Checks the bounds.
    ///
    /// # Errors
    /// [`CornerNetError::InvalidParameter`] naming the first bad one.
    pub fn check(&self) -> Result<(), CornerNetError> {
        let bad = |name: &str, value: f64, reason: &str| {
            Err(CornerNetError::InvalidParameter {
                name: name.to_string(),
                value,
                reason: reason.to_string(),
            })
        };
        if !(self.turn_min_deg > 0.0 && self.turn_max_deg < 180.0) {
            return bad(
                "turn range [deg]",
                self.turn_min_deg,
                "must lie in (0, 180)",
            );
        }
        if self.turn_min_deg >= self.turn_max_deg {
            return bad(
                "turn_max_deg",
                self.turn_max_deg,
                "must exceed turn_min_deg",
            );
        }
        if !(self.ratio_min > 0.0 && self.ratio_min < self.ratio_max && self.ratio_max.is_finite())
        {
            return bad(
                "ratio_max",
                self.ratio_max,
                "need 0 < ratio_min < ratio_max < ∞",
            );
        }
        Ok(())
    }

    /// Why a corner lies outside the distribution, or `None` inside.
    pub fn outside(&self, corner: &LocalCorner) -> Option<String> {
        let deg = corner.turn.to_degrees();
        if !(deg >= self.turn_min_deg && deg <= self.turn_max_deg) {
            return Some(format!(
                "turning angle {deg:.3}° outside the trained [{}°, {}°]",
                self.turn_min_deg, self.turn_max_deg
            ));
        }
        if !(corner.ratio >= self.ratio_min && corner.ratio <= self.ratio_max) {
            return Some(format!(
                "available / tolerance {:.4} outside the trained [{}, {}]",
                corner.ratio, self.ratio_min, self.ratio_max
            ));
        }
        None
    }

    /// One corner drawn from the distribution.
    pub fn draw(&self, rng: &mut Rng) -> LocalCorner {
        let deg = rng.uniform(self.turn_min_deg, self.turn_max_deg);
        let ln = rng.uniform(self.ratio_min.ln(), self.ratio_max.ln());
        LocalCorner {
            turn: deg.to_radians(),
            ratio: ln.exp().clamp(self.ratio_min, self.ratio_max),
        }
    }
}

/// One swarm-solved corner.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Sample {
    /// The corner.
    pub turn: f64,
    /// A / δ.
    pub ratio: f64,
    /// The swarm's (ℓ / A, α, β).
    pub x: [f64; OUTPUTS],
    /// Its largest curvature times δ.
    pub curvature: f64,
}

impl Sample {
    /// The corner.
    pub fn corner(&self) -> LocalCorner {
        LocalCorner {
            turn: self.turn,
            ratio: self.ratio,
        }
    }
}

/// A dataset and how it was made.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Dataset {
    /// The corners' distribution.
    pub distribution: Distribution,
    /// The swarm that labelled them.
    pub swarm: NurbsSettings,
    /// The seed of the draws.
    pub seed: u64,
    /// The samples, in draw order.
    pub samples: Vec<Sample>,
}

impl Dataset {
    /// Draws `count` corners and solves each by the swarm, on `threads`
    /// threads (the result does not depend on `threads`).
    ///
    /// # Errors
    /// [`CornerNetError::InvalidParameter`] for a bad distribution, swarm
    /// or thread count; [`CornerNetError::Corner`] when a swarm fails.
    ///
    /// # Performance
    /// `count` swarms (see [`LocalCorner::swarm`]) shared by the threads.
    pub fn generate(
        distribution: Distribution,
        swarm: &NurbsSettings,
        seed: u64,
        count: usize,
        threads: usize,
    ) -> Result<Self, CornerNetError> {
        distribution.check()?;
        swarm
            .check()
            .map_err(|source| CornerNetError::Corner { index: 0, source })?;
        if threads == 0 {
            return Err(CornerNetError::InvalidParameter {
                name: "threads".to_string(),
                value: 0.0,
                reason: "must be ≥ 1".to_string(),
            });
        }
        let mut rng = Rng::new(seed);
        let corners: Vec<LocalCorner> = (0..count).map(|_| distribution.draw(&mut rng)).collect();
        let chunk = count.div_ceil(threads).max(1);
        let solved: Vec<Result<Vec<Sample>, CornerNetError>> = std::thread::scope(|s| {
            let handles: Vec<_> = corners
                .chunks(chunk)
                .enumerate()
                .map(|(c, part)| {
                    s.spawn(move || {
                        part.iter()
                            .enumerate()
                            .map(|(k, corner)| solve(corner, swarm, c * chunk + k))
                            .collect::<Result<Vec<_>, _>>()
                    })
                })
                .collect();
            handles
                .into_iter()
                .map(|h| {
                    h.join().unwrap_or_else(|_| {
                        Err(CornerNetError::InvalidParameter {
                            name: "dataset thread".to_string(),
                            value: 0.0,
                            reason: "panicked".to_string(),
                        })
                    })
                })
                .collect()
        });
        let mut samples = Vec::with_capacity(count);
        for part in solved {
            samples.extend(part?);
        }
        Ok(Dataset {
            distribution,
            swarm: *swarm,
            seed,
            samples,
        })
    }

    /// The first `1 − held_out` of the samples for training, the rest held out.
    pub fn split(&self, held_out: f64) -> (&[Sample], &[Sample]) {
        let n = self.samples.len();
        let test = ((n as f64) * held_out.clamp(0.0, 1.0)).round() as usize;
        self.samples.split_at(n - test.min(n))
    }

    /// Writes the dataset as JSON.
    ///
    /// # Errors
    /// [`CornerNetError::Io`] when the file cannot be written.
    pub fn save(&self, path: &Path) -> Result<(), CornerNetError> {
        let io = |reason: String| CornerNetError::Io {
            path: path.display().to_string(),
            reason,
        };
        let text = serde_json::to_string(self).map_err(|e| io(e.to_string()))?;
        std::fs::write(path, text).map_err(|e| io(e.to_string()))
    }

    /// Reads a dataset written by [`Self::save`].
    ///
    /// # Errors
    /// [`CornerNetError::Io`] when the file cannot be read or parsed.
    pub fn load(path: &Path) -> Result<Self, CornerNetError> {
        let io = |reason: String| CornerNetError::Io {
            path: path.display().to_string(),
            reason,
        };
        let text = std::fs::read_to_string(path).map_err(|e| io(e.to_string()))?;
        serde_json::from_str(&text).map_err(|e| io(e.to_string()))
    }
}

/// One corner solved by the swarm.
fn solve(
    corner: &LocalCorner,
    swarm: &NurbsSettings,
    index: usize,
) -> Result<Sample, CornerNetError> {
    let (x, t) = corner
        .swarm(swarm)
        .map_err(|source| CornerNetError::Corner { index, source })?;
    Ok(Sample {
        turn: corner.turn,
        ratio: corner.ratio,
        x,
        curvature: t.max_curvature,
    })
}
