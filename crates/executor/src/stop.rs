//! Controlled stop: all joints decelerate together, linearly in velocity, to rest.

use crate::types::{JointLimits, JointSample};

/// A synchronized stop from a state `(p0, v0)` at time `t0`.
///
/// Joint i follows `v_i(τ) = v0_i (1 − τ/T_i)`, `p_i(τ) = p0_i + v0_i (τ − τ²/(2 T_i))`,
/// `a_i = −v0_i / T_i` for `τ = t − t0 ∈ [0, T_i]`, then holds `p0_i + v0_i T_i / 2`.
/// Normally every `T_i = T = max_j |v0_j| / a_max_j`, so all joints stop at the same instant,
/// keep the direction of motion in joint space, and each decelerates within its limit
/// (`|v0_i| / T ≤ a_max_i`). If a joint would so pass one of its position limits, it stops
/// in its own shortest time `|v0_i| / a_max_i` instead (leaving the straight line, keeping
/// within the position limits when its state came from a validated trajectory, which can
/// itself stop within them). The initial acceleration is dropped (no jerk limit).
#[derive(Debug, Clone, PartialEq)]
pub struct StopProfile {
    t0: f64,
    p0: Vec<f64>,
    v0: Vec<f64>,
    /// Stop time of each joint (s); 0 for a joint at rest.
    durations: Vec<f64>,
}

impl StopProfile {
    /// Plans the stop from `state` (model order, full) at time `t0`.
    ///
    /// # Arguments
    /// * `limits` — the robot model (acceleration and position limits).
    /// * `state` — commanded state at `t0`; empty velocities count as zero.
    /// * `t0` — absolute time (s).
    pub fn new(limits: &[JointLimits], state: &JointSample, t0: f64) -> Self {
        let n = limits.len();
        let v0: Vec<f64> = (0..n)
            .map(|j| state.velocities.get(j).copied().unwrap_or(0.0))
            .collect();
        let common = limits
            .iter()
            .zip(&v0)
            .map(|(l, v)| v.abs() / l.max_acceleration)
            .fold(0.0, f64::max);
        let durations = limits
            .iter()
            .zip(&v0)
            .zip(&state.positions)
            .map(|((l, &v), &p)| {
                if v == 0.0 {
                    return 0.0;
                }
                let end = p + 0.5 * v * common;
                if end < l.min_position || end > l.max_position {
                    v.abs() / l.max_acceleration
                } else {
                    common
                }
            })
            .collect();
        Self {
            t0,
            p0: state.positions.clone(),
            v0,
            durations,
        }
    }

    /// Absolute time at which the last joint comes to rest (s).
    pub fn end_time(&self) -> f64 {
        self.t0 + self.durations.iter().copied().fold(0.0, f64::max)
    }

    /// Positions at rest after the stop.
    pub fn final_positions(&self) -> Vec<f64> {
        self.p0
            .iter()
            .zip(&self.v0)
            .zip(&self.durations)
            .map(|((p, v), d)| p + 0.5 * v * d)
            .collect()
    }

    /// Writes the commanded state at time `t` into `out` (resized to the joint count).
    ///
    /// # Performance
    /// O(joints), no allocation once `out` has the capacity.
    pub fn sample_into(&self, t: f64, out: &mut JointSample) {
        out.resize_full(self.p0.len());
        let tau = (t - self.t0).max(0.0);
        for j in 0..self.p0.len() {
            let (p0, v0, d) = (self.p0[j], self.v0[j], self.durations[j]);
            let (p, v, a) = if d == 0.0 {
                (p0, 0.0, 0.0)
            } else if tau >= d {
                (p0 + 0.5 * v0 * d, 0.0, 0.0)
            } else {
                (
                    p0 + v0 * (tau - 0.5 * tau * tau / d),
                    v0 * (1.0 - tau / d),
                    -v0 / d,
                )
            };
            out.positions[j] = p;
            out.velocities[j] = v;
            out.accelerations[j] = a;
        }
    }
}
