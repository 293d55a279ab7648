//! Kinematic limits of one axis and the control period.

use serde::{Deserialize, Serialize};

use crate::error::{check_positive, StepError};

/// Velocity, acceleration and jerk limits of one axis (SI: m/s, m/s², m/s³,
/// or rad/s, rad/s², rad/s³ for a joint).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Limits {
    /// Largest speed.
    pub velocity: f64,
    /// Largest |acceleration|.
    pub acceleration: f64,
    /// Jerk of one "accelerate" or "decelerate" step (its largest |jerk|).
    pub jerk: f64,
}

impl Limits {
    /// Limits from velocity, acceleration and jerk.
    pub fn new(velocity: f64, acceleration: f64, jerk: f64) -> Self {
        Self {
            velocity,
            acceleration,
            jerk,
        }
    }

    /// Every limit finite and > 0.
    ///
    /// # Errors
    /// [`StepError::InvalidParameter`] naming the first bad limit.
    pub fn validate(&self) -> Result<(), StepError> {
        check_positive("velocity limit", self.velocity)?;
        check_positive("acceleration limit", self.acceleration)?;
        check_positive("jerk limit", self.jerk)
    }
}

/// Control period [s], validated: finite, > 0 and at most 1 s.
///
/// # Errors
/// [`StepError::InvalidParameter`].
pub fn check_period(period: f64) -> Result<(), StepError> {
    check_positive("period [s]", period)?;
    if period > 1.0 {
        return Err(StepError::InvalidParameter {
            name: "period [s]".to_string(),
            value: period,
            reason: "must be at most 1 s".to_string(),
        });
    }
    Ok(())
}
