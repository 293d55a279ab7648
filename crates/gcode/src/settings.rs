//! [`ReaderSettings`] of the interpreter (builder, validated).

use crate::error::GcodeError;

/// Settings of [`crate::Program`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReaderSettings {
    /// Largest difference between an arc's start and end radius that is
    /// accepted, absolute \[m\] (default 5e-6: 5 µm, the default of
    /// Beckhoff TwinCAT CNC's P-CHAN-00171 "maximum permissible absolute
    /// radius difference"). An arc is refused only when the difference
    /// exceeds both this and [`ReaderSettings::arc_relative_tolerance`].
    pub arc_tolerance: f64,
    /// Relative radius difference accepted (default 1e-3 of the start
    /// radius, kerf's: CAM output rounded to 3 decimals in mm on a 1 mm
    /// radius differs by up to 0.07 %).
    pub arc_relative_tolerance: f64,
    /// Skip blocks that start with `/` (the block delete switch on; default
    /// `true`). The count of skipped blocks is reported
    /// ([`crate::Program::skipped_blocks`]).
    pub block_delete: bool,
    /// Where the machine is when the program starts \[m\].
    pub start: [f64; 3],
}

impl Default for ReaderSettings {
    fn default() -> Self {
        Self {
            arc_tolerance: 5e-6,
            arc_relative_tolerance: 1e-3,
            block_delete: true,
            start: [0.0; 3],
        }
    }
}

impl ReaderSettings {
    /// With the absolute arc tolerance \[m\].
    pub fn with_arc_tolerance(mut self, tolerance: f64) -> Self {
        self.arc_tolerance = tolerance;
        self
    }

    /// With the relative arc tolerance.
    pub fn with_arc_relative_tolerance(mut self, tolerance: f64) -> Self {
        self.arc_relative_tolerance = tolerance;
        self
    }

    /// With the block delete switch.
    pub fn with_block_delete(mut self, on: bool) -> Self {
        self.block_delete = on;
        self
    }

    /// With the start position \[m\].
    pub fn with_start(mut self, start: [f64; 3]) -> Self {
        self.start = start;
        self
    }

    /// Checks every setting.
    ///
    /// # Errors
    /// [`GcodeError::InvalidSetting`] for a tolerance that is not finite
    /// and > 0, or a start that is not finite.
    pub fn validate(&self) -> Result<(), GcodeError> {
        for (name, v) in [
            ("arc_tolerance [m]", self.arc_tolerance),
            ("arc_relative_tolerance [-]", self.arc_relative_tolerance),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(GcodeError::InvalidSetting {
                    name: name.to_string(),
                    value: v,
                    reason: "must be finite and > 0".to_string(),
                });
            }
        }
        if let Some(v) = self.start.iter().find(|v| !v.is_finite()) {
            return Err(GcodeError::InvalidSetting {
                name: "start [m]".to_string(),
                value: *v,
                reason: "must be finite".to_string(),
            });
        }
        Ok(())
    }
}
