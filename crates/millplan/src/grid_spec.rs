//! The node lists of the indicator cache's grid ([`GridSpec`]).

use serde::{Deserialize, Serialize};

use crate::error::MillPlanError;

/// Node lists of the cache grid (each strictly increasing, ≥ 2 nodes, except
/// that a single segment node is allowed for a one-segment cache).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GridSpec {
    /// Path segment indices (0-based).
    pub segments: Vec<usize>,
    /// Spindle speeds \[rpm\].
    pub rpm: Vec<f64>,
    /// Feeds [m/s] (> 0: the indicator of a zero feed is not a cutting
    /// state of a plan, [`crate::env`]).
    pub feed: Vec<f64>,
    /// Redundancy angles \[rad\].
    pub g: Vec<f64>,
}

/// `count` equally spaced values from `min` to `max` (both included).
fn linspace(min: f64, max: f64, count: usize) -> Vec<f64> {
    if count <= 1 {
        return vec![min];
    }
    (0..count)
        .map(|i| min + (max - min) * i as f64 / (count - 1) as f64)
        .collect()
}

impl GridSpec {
    /// A grid with every `stride`-th segment of `0..segment_count` plus the
    /// last, and equally spaced Ω, f and g nodes.
    ///
    /// # Arguments
    /// * `segment_count`, `stride` — segments 0, k, 2k, …, and N − 1;
    /// * `rpm`, `feed`, `g` — (min, max, count) per axis.
    ///
    /// # Errors
    /// As [`GridSpec::validate`]; `stride` or `segment_count` 0.
    pub fn uniform(
        segment_count: usize,
        stride: usize,
        rpm: (f64, f64, usize),
        feed: (f64, f64, usize),
        g: (f64, f64, usize),
    ) -> Result<Self, MillPlanError> {
        if stride == 0 || segment_count == 0 {
            return Err(MillPlanError::InvalidConfig {
                name: "cache grid segments".to_string(),
                reason: format!("segment count {segment_count} and stride {stride} must be >= 1"),
            });
        }
        let mut segments: Vec<usize> = (0..segment_count).step_by(stride).collect();
        if segments.last() != Some(&(segment_count - 1)) {
            segments.push(segment_count - 1);
        }
        let spec = Self {
            segments,
            rpm: linspace(rpm.0, rpm.1, rpm.2),
            feed: linspace(feed.0, feed.1, feed.2),
            g: linspace(g.0, g.1, g.2),
        };
        spec.validate()?;
        Ok(spec)
    }

    /// Checks the node lists.
    ///
    /// # Errors
    /// [`MillPlanError::InvalidConfig`] for an axis that is empty, not
    /// strictly increasing, non-finite, or has fewer than 2 nodes (Ω, f, g);
    /// feeds ≤ 0 or spindle speeds ≤ 0.
    pub fn validate(&self) -> Result<(), MillPlanError> {
        let bad = |name: &str, reason: &str| MillPlanError::InvalidConfig {
            name: format!("cache grid {name}"),
            reason: reason.to_string(),
        };
        if self.segments.is_empty() {
            return Err(bad("segments", "no nodes"));
        }
        if self.segments.windows(2).any(|w| w[1] <= w[0]) {
            return Err(bad("segments", "must be strictly increasing"));
        }
        for (name, axis, positive) in [
            ("rpm", &self.rpm, true),
            ("feed", &self.feed, true),
            ("g", &self.g, false),
        ] {
            if axis.len() < 2 {
                return Err(bad(name, "needs at least 2 nodes"));
            }
            if axis.iter().any(|v| !v.is_finite()) {
                return Err(bad(name, "non-finite node"));
            }
            if axis.windows(2).any(|w| w[1] <= w[0]) {
                return Err(bad(name, "must be strictly increasing"));
            }
            if positive && axis.first().is_some_and(|v| *v <= 0.0) {
                return Err(bad(name, "nodes must be > 0"));
            }
        }
        Ok(())
    }

    /// Number of nodes (segments × Ω × f × g).
    pub fn node_count(&self) -> usize {
        self.segments.len() * self.rpm.len() * self.feed.len() * self.g.len()
    }

    pub(crate) fn index(&self, s: usize, r: usize, f: usize, g: usize) -> usize {
        ((s * self.rpm.len() + r) * self.feed.len() + f) * self.g.len() + g
    }
}
