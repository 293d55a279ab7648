//! The ranges and per-step bounds of the planning state.

use crate::error::{check_finite, check_positive, MillError};

/// Ranges and per-step bounds of the planning state (seed 004 Table 1,
/// "State range" and the action bounds of eq. 9-11).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StateLimits {
    /// Spindle speed range \[rpm\] (rpm at the API boundary, as named).
    pub spindle_rpm: [f64; 2],
    /// Feed range [m/s].
    pub feed: [f64; 2],
    /// Redundancy angle range \[rad\].
    pub redundancy_angle: [f64; 2],
    /// Largest feed change per step |Δf| [m/s].
    pub max_feed_step: f64,
    /// Largest spindle-speed change per step |ΔΩ| \[rpm\].
    pub max_spindle_step_rpm: f64,
    /// Largest redundancy-angle change per step |Δg| \[rad\].
    pub max_redundancy_step: f64,
}

impl StateLimits {
    /// Checks the limits with the rules of the cell YAML's `process`
    /// section ([`MillCell::from_yaml_str`](super::MillCell::from_yaml_str)): every value finite; each
    /// range `[min, max]` with min < max; the spindle range above 0 rpm;
    /// the feed range from ≥ 0 m/s; the redundancy-angle range inside
    /// [−π, π] (1e-12 slack); every step bound > 0.
    ///
    /// # Errors
    /// [`MillError::InvalidParameter`] naming the field as
    /// `state_limits.<field>[index]` with its unit.
    pub fn validate(&self) -> Result<(), MillError> {
        use std::f64::consts::PI;
        let range = |name: &str, r: [f64; 2], min: f64, max: f64| -> Result<(), MillError> {
            for (i, v) in r.iter().enumerate() {
                check_finite(&format!("state_limits.{name}[{i}]"), *v)?;
            }
            if r[1] <= r[0] {
                return Err(MillError::InvalidParameter {
                    name: format!("state_limits.{name}[1]"),
                    value: r[1],
                    reason: format!("must be > state_limits.{name}[0] = {}", r[0]),
                });
            }
            if r[0] < min {
                return Err(MillError::InvalidParameter {
                    name: format!("state_limits.{name}[0]"),
                    value: r[0],
                    reason: format!("must be >= {min}"),
                });
            }
            if r[1] > max {
                return Err(MillError::InvalidParameter {
                    name: format!("state_limits.{name}[1]"),
                    value: r[1],
                    reason: format!("must be <= {max}"),
                });
            }
            Ok(())
        };
        range("spindle_rpm [rpm]", self.spindle_rpm, 0.0, f64::INFINITY)?;
        check_positive("state_limits.spindle_rpm[0] [rpm]", self.spindle_rpm[0])?;
        range("feed [m/s]", self.feed, 0.0, f64::INFINITY)?;
        range(
            "redundancy_angle [rad]",
            self.redundancy_angle,
            -PI - 1e-12,
            PI + 1e-12,
        )?;
        check_positive("state_limits.max_feed_step [m/s]", self.max_feed_step)?;
        check_positive(
            "state_limits.max_spindle_step_rpm [rpm]",
            self.max_spindle_step_rpm,
        )?;
        check_positive(
            "state_limits.max_redundancy_step [rad]",
            self.max_redundancy_step,
        )?;
        Ok(())
    }
}
