//! Run-time settings of a cell: mode, rates, gravity, servo gains.

use crate::CellError;

/// Highest physics rate (Hz) a cell accepts: what one control period runs in real time with a
/// margin, whatever the control rate (the sub-steps of one period cost `physics rate ×
/// period × sub-step cost`, so the bound is on the physics rate itself).
///
/// One sub-step of the dynamic laser cutter with its head in contact with the B-pillar (the
/// dearest case) costs 40 µs on the mean and 82 µs at the 99th percentile on the 2-core
/// reference machine (BENCHMARKS.md, "Simulated cell": 161 µs mean and 327 µs p99 per 4 ms
/// cycle of 4 sub-steps, `cargo bench -p kerf_cell --bench cycle`). At 5 kHz the sub-steps
/// take 20 % of wall time on the mean and 41 % at the p99, leaving the rest of each period to
/// the executor, the contact watch and DDS; at 10 kHz the p99 would take 82 %. Above this
/// rate the simulation falls behind real time (`sim_physics_rate:=1e9` ran 1000 × slower).
pub const MAX_PHYSICS_RATE_HZ: f64 = 5_000.0;

/// The refusal of a physics rate over [`MAX_PHYSICS_RATE_HZ`].
pub const PHYSICS_RATE_BOUND: &str = "must be <= 5000 Hz (MAX_PHYSICS_RATE_HZ): one physics \
     sub-step costs up to about 80 us, so a higher rate cannot run in real time with a margin";

/// How the robot follows its commands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Positions follow the commands exactly (the multibody's joint positions are set at
    /// every physics sub-step); contacts are checked. A drop-in for
    /// `kerf_executor::MockHardware`.
    Kinematic,
    /// Joint drives: PD on the position error plus inverse-dynamics feed-forward
    /// (acceleration, velocity, gravity, friction), efforts limited by the URDF; rapier
    /// integrates the multibody.
    Dynamic,
}

/// Settings of a cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellSettings {
    /// Kinematic or dynamic.
    pub mode: Mode,
    /// Control rate (Hz): one [`crate::Cell::step`] per control period.
    pub control_rate_hz: f64,
    /// Physics rate (Hz): an integer multiple of the control rate.
    pub physics_rate_hz: f64,
    /// Gravity in the base frame (m/s²).
    pub gravity: [f64; 3],
    /// Closed-loop bandwidth of each joint's PD (Hz): `Kp = M_jj ω²`, `Kd = 2 ζ M_jj ω` with
    /// `ω = 2π · bandwidth` and `M_jj` the joint's diagonal of the mass matrix (with armature)
    /// at the commanded position, recomputed every control period.
    pub bandwidth_hz: f64,
    /// Damping ratio ζ of each joint's PD.
    pub damping_ratio: f64,
}

impl Default for CellSettings {
    /// Kinematic, 250 Hz control, 1 kHz physics, g = 9.81 m/s² along −z, 20 Hz critically
    /// damped servo.
    fn default() -> Self {
        Self {
            mode: Mode::Kinematic,
            control_rate_hz: 250.0,
            physics_rate_hz: 1000.0,
            gravity: [0.0, 0.0, -9.81],
            bandwidth_hz: 20.0,
            damping_ratio: 1.0,
        }
    }
}

impl CellSettings {
    /// The number of physics steps per control period.
    ///
    /// # Errors
    /// [`CellError::InvalidValue`] for a rate that is not finite and > 0, a physics rate over
    /// [`MAX_PHYSICS_RATE_HZ`], a gain setting out of range or gravity not finite; [`CellError::RateRatio`] when the physics rate is not
    /// an integer multiple (≥ 1) of the control rate (relative tolerance 1e-9).
    pub fn substeps(&self) -> Result<usize, CellError> {
        for (field, v) in [
            ("control_rate_hz", self.control_rate_hz),
            ("physics_rate_hz", self.physics_rate_hz),
            ("bandwidth_hz", self.bandwidth_hz),
            ("damping_ratio", self.damping_ratio),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(CellError::InvalidValue {
                    field: field.into(),
                    value: v,
                    requirement: "must be finite and > 0",
                });
            }
        }
        if self.physics_rate_hz > MAX_PHYSICS_RATE_HZ {
            return Err(CellError::InvalidValue {
                field: "physics_rate_hz".into(),
                value: self.physics_rate_hz,
                requirement: PHYSICS_RATE_BOUND,
            });
        }
        if let Some(&g) = self.gravity.iter().find(|g| !g.is_finite()) {
            return Err(CellError::InvalidValue {
                field: "gravity".into(),
                value: g,
                requirement: "must be finite",
            });
        }
        let ratio = self.physics_rate_hz / self.control_rate_hz;
        let n = ratio.round();
        if n < 1.0 || (ratio - n).abs() > 1e-9 * ratio {
            return Err(CellError::RateRatio {
                physics_hz: self.physics_rate_hz,
                control_hz: self.control_rate_hz,
                ratio,
            });
        }
        // Explicit PD on a semi-implicit Euler step: keep ω·dt well inside the stable range
        // (ω dt < 2 for the undamped oscillator; 0.5 leaves room for the coupling of the
        // mass matrix, whose off-diagonal terms raise the effective ω).
        let w_dt = 2.0 * std::f64::consts::PI * self.bandwidth_hz / self.physics_rate_hz;
        if w_dt > 0.5 {
            return Err(CellError::InvalidValue {
                field: "bandwidth_hz".into(),
                value: self.bandwidth_hz,
                requirement: "2 pi bandwidth / physics rate must be <= 0.5 (explicit PD stability)",
            });
        }
        Ok(n as usize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn physics_rates_are_bounded_by_what_a_period_runs() {
        let at = |hz: f64| CellSettings {
            physics_rate_hz: hz,
            ..CellSettings::default()
        };
        assert_eq!(at(MAX_PHYSICS_RATE_HZ).substeps().unwrap(), 20);
        for hz in [
            MAX_PHYSICS_RATE_HZ + 250.0,
            2.5e8,
            1e9,
            f64::INFINITY,
            f64::NAN,
        ] {
            let e = at(hz).substeps().unwrap_err().to_string();
            assert!(e.contains("physics_rate_hz"), "{hz}: {e}");
        }
        let e = at(1e9).substeps().unwrap_err().to_string();
        assert!(e.contains("5000 Hz") && e.contains("real time"), "{e}");
        // The message states the constant.
        assert!(PHYSICS_RATE_BOUND.contains(&format!("{MAX_PHYSICS_RATE_HZ}")));
    }
}
