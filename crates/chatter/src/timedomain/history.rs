//! The stored trajectory the delayed terms read: a ring of the last
//! periods on the step grid, or a periodic orbit, with cubic Hermite
//! interpolation.

use nalgebra::Vector2;

use super::internal;
use crate::error::ChatterError;

/// Stored tool-centre positions and velocities, read by cubic Hermite
/// interpolation.
pub(super) trait History {
    /// Position and velocity at time `s` \[s\].
    fn at(&self, s: f64) -> Result<(Vector2<f64>, Vector2<f64>), ChatterError>;
}

/// Cubic Hermite interpolation on `[0, h]` between (p0, v0) and (p1, v1)
/// at `θ = (s − t0) / h`; returns the interpolant and its derivative.
pub(super) fn hermite(
    p0: Vector2<f64>,
    v0: Vector2<f64>,
    p1: Vector2<f64>,
    v1: Vector2<f64>,
    h: f64,
    th: f64,
) -> (Vector2<f64>, Vector2<f64>) {
    let t2 = th * th;
    let t3 = t2 * th;
    let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
    let h10 = t3 - 2.0 * t2 + th;
    let h01 = -2.0 * t3 + 3.0 * t2;
    let h11 = t3 - t2;
    let p = h00 * p0 + (h10 * h) * v0 + h01 * p1 + (h11 * h) * v1;
    let d00 = 6.0 * t2 - 6.0 * th;
    let d10 = 3.0 * t2 - 4.0 * th + 1.0;
    let d11 = 3.0 * t2 - 2.0 * th;
    let dp = (d00 / h) * (p0 - p1) + d10 * v0 + d11 * v1;
    (p, dp)
}

/// The last few periods of the simulated trajectory, on the step grid
/// `t_k = k h` (k may be negative: the prefilled periodic history).
pub(super) struct RingHistory {
    pub(super) step: f64,
    pub(super) newest: i64,
    pub(super) buf: Vec<(Vector2<f64>, Vector2<f64>)>,
}

impl RingHistory {
    pub(super) fn slot(&self, k: i64) -> Result<usize, ChatterError> {
        let len = self.buf.len() as i64;
        if k > self.newest || k <= self.newest - len {
            return Err(ChatterError::Unsupported {
                reason: format!(
                    "delayed time step {k} outside the stored history ({}..={})",
                    self.newest - len + 1,
                    self.newest
                ),
            });
        }
        Ok(k.rem_euclid(len) as usize)
    }

    pub(super) fn get(&self, k: i64) -> Result<(Vector2<f64>, Vector2<f64>), ChatterError> {
        let i = self.slot(k)?;
        self.buf.get(i).copied().ok_or_else(internal)
    }

    /// Stores step `k`; `k` becomes the newest step if it is later.
    pub(super) fn set(
        &mut self,
        k: i64,
        p: Vector2<f64>,
        v: Vector2<f64>,
    ) -> Result<(), ChatterError> {
        let len = self.buf.len() as i64;
        if k > self.newest {
            self.newest = k;
        }
        if k <= self.newest - len {
            return Err(internal());
        }
        let i = k.rem_euclid(len) as usize;
        let slot = self.buf.get_mut(i).ok_or_else(internal)?;
        *slot = (p, v);
        Ok(())
    }
}

impl History for RingHistory {
    fn at(&self, s: f64) -> Result<(Vector2<f64>, Vector2<f64>), ChatterError> {
        let (k, frac) = grid_cell(s, self.step)?;
        let (p0, v0) = self.get(k)?;
        let (p1, v1) = self.get(k + 1)?;
        Ok(hermite(p0, v0, p1, v1, self.step, frac))
    }
}

/// A T-periodic trajectory sampled at `t_k = k h`, k = 0..n−1.
pub(super) struct PeriodicHistory {
    pub(super) step: f64,
    pub(super) pos: Vec<Vector2<f64>>,
    pub(super) vel: Vec<Vector2<f64>>,
}

impl History for PeriodicHistory {
    fn at(&self, s: f64) -> Result<(Vector2<f64>, Vector2<f64>), ChatterError> {
        let (k0, frac) = grid_cell(s, self.step)?;
        let n = self.pos.len() as i64;
        let i0 = k0.rem_euclid(n) as usize;
        let i1 = (k0 + 1).rem_euclid(n) as usize;
        let get = |i: usize| {
            self.pos
                .get(i)
                .copied()
                .zip(self.vel.get(i).copied())
                .ok_or_else(internal)
        };
        let (p0, v0) = get(i0)?;
        let (p1, v1) = get(i1)?;
        Ok(hermite(p0, v0, p1, v1, self.step, frac))
    }
}

/// The grid cell of time `s` on a grid of spacing `step`: the index k of
/// `t_k = k step ≤ s` and the fraction `(s − t_k)/step` in [0, 1).
///
/// # Errors
/// [`ChatterError::NonFinite`] for a non-finite time.
pub(super) fn grid_cell(s: f64, step: f64) -> Result<(i64, f64), ChatterError> {
    let u = s / step;
    let k = u.floor();
    if !k.is_finite() {
        return Err(ChatterError::NonFinite {
            what: "delayed time".to_string(),
        });
    }
    Ok((k as i64, u - k))
}
