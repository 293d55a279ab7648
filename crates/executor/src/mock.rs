//! Simulated hardware for tests and dry runs.

use crate::error::ExecutorError;
use crate::types::{JointLimits, JointSample};

/// Mock hardware, like ros2_control's `mock_components/GenericSystem`: by default the state
/// follows the command exactly (state = command). Optionally each joint's position lags the
/// command as a first-order system with time constant τ, so that tests can provoke
/// tolerance violations.
///
/// With a lag, one write over `dt` applies the exact discretization of
/// `dx/dt = (x_cmd − x)/τ` for a command held over `dt`:
/// `x ← x + (1 − e^(−dt/τ)) (x_cmd − x)`; velocity and acceleration are the backward
/// differences of the positions.
#[derive(Debug, Clone, PartialEq)]
pub struct MockHardware {
    state: JointSample,
    time_constant: f64,
}

impl MockHardware {
    /// Ideal hardware at rest at `initial_positions`.
    pub fn new(initial_positions: Vec<f64>) -> Self {
        Self {
            state: JointSample::at_rest(initial_positions),
            time_constant: 0.0,
        }
    }

    /// Hardware whose positions lag the command with time constant `time_constant` (s).
    ///
    /// # Returns
    /// `Err(InvalidConfig)` unless `time_constant` is finite and ≥ 0 (0 = ideal).
    pub fn with_lag(
        initial_positions: Vec<f64>,
        time_constant: f64,
    ) -> Result<Self, ExecutorError> {
        if !(time_constant.is_finite() && time_constant >= 0.0) {
            return Err(ExecutorError::InvalidConfig {
                field: "mock time_constant".to_string(),
                value: time_constant,
                requirement: "must be finite and >= 0",
            });
        }
        Ok(Self {
            state: JointSample::at_rest(initial_positions),
            time_constant,
        })
    }

    /// The current state (positions, velocities, accelerations).
    pub fn state(&self) -> &JointSample {
        &self.state
    }

    /// Applies `command` (model order, full) for `dt` seconds.
    ///
    /// # Arguments
    /// * `limits` — the robot model, to check the command's shape.
    /// * `command` — the reference from [`crate::Executor::update`].
    /// * `dt` — time since the previous write (s), finite and > 0.
    ///
    /// # Returns
    /// `Err` for a malformed command or `dt`; the state is then unchanged.
    pub fn write(
        &mut self,
        limits: &[JointLimits],
        command: &JointSample,
        dt: f64,
    ) -> Result<(), ExecutorError> {
        command.check("mock command", limits, true)?;
        if !(dt.is_finite() && dt > 0.0) {
            return Err(ExecutorError::InvalidConfig {
                field: "mock write dt".to_string(),
                value: dt,
                requirement: "must be finite and > 0",
            });
        }
        if self.state.positions.len() != command.positions.len() {
            return Err(ExecutorError::StateLength {
                what: "mock command",
                field: "positions",
                actual: command.positions.len(),
                expected: self.state.positions.len(),
                empty_note: "",
            });
        }
        if self.time_constant == 0.0 {
            self.state.clone_from(command);
            return Ok(());
        }
        let alpha = 1.0 - (-dt / self.time_constant).exp();
        for j in 0..self.state.positions.len() {
            let x = self.state.positions[j];
            let x_new = x + alpha * (command.positions[j] - x);
            let v_new = (x_new - x) / dt;
            self.state.accelerations[j] = (v_new - self.state.velocities[j]) / dt;
            self.state.velocities[j] = v_new;
            self.state.positions[j] = x_new;
        }
        Ok(())
    }
}
