//! [`ApproachSettings`] and its validating builder.

use crate::ApproachError;

/// Default control period (s): the executor's 250 Hz.
pub const DEFAULT_CONTROL_PERIOD: f64 = 0.004;

/// Default longest move (s).
pub const DEFAULT_MAX_DURATION: f64 = 600.0;

/// Settings of an [`crate::ApproachPlanner`]. SI units throughout. Built by
/// [`ApproachSettings::builder`], which refuses any number that is not finite and > 0.
///
/// ```
/// use kerf_approach::ApproachSettings;
/// let settings = ApproachSettings::builder()
///     .clearance(0.01)
///     .control_period(0.004)
///     .lipschitz(vec![1.8, 0.8])
///     .safe_pose(vec![0.0, 2.5])
///     .build()?;
/// assert_eq!(settings.clearance(), 0.01);
/// # Ok::<(), kerf_approach::ApproachError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct ApproachSettings {
    clearance: f64,
    control_period: f64,
    lipschitz: Vec<f64>,
    safe_poses: Vec<Vec<f64>>,
    max_duration: f64,
}

impl ApproachSettings {
    /// A builder with the defaults: control period [`DEFAULT_CONTROL_PERIOD`], max duration
    /// [`DEFAULT_MAX_DURATION`], no safe pose; clearance and Lipschitz bounds required.
    pub fn builder() -> ApproachSettingsBuilder {
        ApproachSettingsBuilder::default()
    }

    /// Distance (m) every configuration of a move keeps from every obstacle.
    pub fn clearance(&self) -> f64 {
        self.clearance
    }

    /// The executor's control period (s): moves are timed in whole periods and checked at
    /// (at most) this step.
    pub fn control_period(&self) -> f64 {
        self.control_period
    }

    /// Per joint: bound on how far (m) any robot point moves per rad (or m) of that joint.
    pub fn lipschitz(&self) -> &[f64] {
        &self.lipschitz
    }

    /// Safe poses (joint configurations above the part), tried in this order when the direct
    /// approach is not clear.
    pub fn safe_poses(&self) -> &[Vec<f64>] {
        &self.safe_poses
    }

    /// Longest move (s) the planner builds.
    pub fn max_duration(&self) -> f64 {
        self.max_duration
    }
}

/// Builder of [`ApproachSettings`] (owned-chain style: `builder().x(..).y(..).build()`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ApproachSettingsBuilder {
    clearance: Option<f64>,
    control_period: Option<f64>,
    lipschitz: Option<Vec<f64>>,
    safe_poses: Vec<Vec<f64>>,
    max_duration: Option<f64>,
}

impl ApproachSettingsBuilder {
    /// The clearance (m), required.
    pub fn clearance(mut self, metres: f64) -> Self {
        self.clearance = Some(metres);
        self
    }

    /// The control period (s); default [`DEFAULT_CONTROL_PERIOD`].
    pub fn control_period(mut self, seconds: f64) -> Self {
        self.control_period = Some(seconds);
        self
    }

    /// The per-joint Lipschitz bounds (m/rad, or m/m for a prismatic joint), required.
    pub fn lipschitz(mut self, metres_per_unit: Vec<f64>) -> Self {
        self.lipschitz = Some(metres_per_unit);
        self
    }

    /// Adds one safe pose (joint configuration).
    pub fn safe_pose(mut self, q: Vec<f64>) -> Self {
        self.safe_poses.push(q);
        self
    }

    /// Replaces the safe poses.
    pub fn safe_poses(mut self, poses: Vec<Vec<f64>>) -> Self {
        self.safe_poses = poses;
        self
    }

    /// The longest move (s); default [`DEFAULT_MAX_DURATION`].
    pub fn max_duration(mut self, seconds: f64) -> Self {
        self.max_duration = Some(seconds);
        self
    }

    /// Validates and builds.
    ///
    /// # Returns
    /// [`ApproachError::MissingSetting`] for a missing clearance or Lipschitz list;
    /// [`ApproachError::InvalidSetting`] naming the field for a number that is not finite
    /// and positive, an empty Lipschitz list, a safe pose value that is not finite, or a
    /// `max_duration / control_period` above [`crate::MAX_SAMPLES`];
    /// [`ApproachError::JointCount`] for a safe pose of another length than the Lipschitz
    /// list. Position limits are checked by [`crate::ApproachPlanner::new`].
    pub fn build(self) -> Result<ApproachSettings, ApproachError> {
        let clearance = self
            .clearance
            .ok_or(ApproachError::MissingSetting { field: "clearance" })?;
        positive("clearance", clearance)?;
        let control_period = self.control_period.unwrap_or(DEFAULT_CONTROL_PERIOD);
        positive("control_period", control_period)?;
        let max_duration = self.max_duration.unwrap_or(DEFAULT_MAX_DURATION);
        positive("max_duration", max_duration)?;
        // Both finite and > 0: the ratio is a number or +inf, never NaN.
        if max_duration / control_period > crate::MAX_SAMPLES as f64 {
            return Err(ApproachError::InvalidSetting {
                field: "max_duration".into(),
                value: max_duration,
                requirement: "max_duration / control_period must be <= MAX_SAMPLES (1e6)",
            });
        }
        let lipschitz = self
            .lipschitz
            .ok_or(ApproachError::MissingSetting { field: "lipschitz" })?;
        positive_list("lipschitz", &lipschitz)?;
        for (i, pose) in self.safe_poses.iter().enumerate() {
            if pose.len() != lipschitz.len() {
                return Err(ApproachError::JointCount {
                    what: format!("safe_poses[{i}]"),
                    expected: lipschitz.len(),
                    found: pose.len(),
                });
            }
            if let Some((j, &v)) = pose.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                return Err(ApproachError::InvalidSetting {
                    field: format!("safe_poses[{i}][{j}]"),
                    value: v,
                    requirement: "must be finite",
                });
            }
        }
        Ok(ApproachSettings {
            clearance,
            control_period,
            lipschitz,
            safe_poses: self.safe_poses,
            max_duration,
        })
    }
}

/// Refuses a number that is not finite and > 0.
pub(crate) fn positive(field: &str, value: f64) -> Result<(), ApproachError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(ApproachError::InvalidSetting {
            field: field.into(),
            value,
            requirement: "must be finite and > 0",
        })
    }
}

/// Refuses an empty list or an element that is not finite and > 0 (named `field[i]`).
pub(crate) fn positive_list(field: &str, values: &[f64]) -> Result<(), ApproachError> {
    if values.is_empty() {
        return Err(ApproachError::InvalidSetting {
            field: field.into(),
            value: 0.0,
            requirement: "must not be empty: one value per joint",
        });
    }
    for (i, &v) in values.iter().enumerate() {
        positive(&format!("{field}[{i}]"), v)?;
    }
    Ok(())
}
