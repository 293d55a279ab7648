//! The delay equation (seed 004 eq. 3) and the chip (eq. 4) on a
//! trajectory: the trajectory view, Newton on the delay and its rate.

use std::f64::consts::PI;

use nalgebra::Vector2;

use super::interp::{hermite, locate_guess};
use super::Geometry;
use crate::error::ChatterError;
use crate::model::MillingProcess;

/// Trajectory view used while iterating (positions at nodes etc.).
pub(super) struct Traj<'a> {
    pub(super) times: &'a [f64],
    pub(super) pos: &'a [Vector2<f64>],
    pub(super) vel: &'a [Vector2<f64>],
    pub(super) acc_start: &'a [Vector2<f64>],
    pub(super) acc_end: &'a [Vector2<f64>],
    pub(super) period: f64,
    /// Bounds of the interpolated position (for the chip lower bound of
    /// [`super::tracks`]).
    pub(super) bounds: TrajBounds,
}

/// Bounds of the interpolated position õ(t) of a [`Traj`]: a Lipschitz
/// constant L and the jump J at the period's wrap, so that for any two
/// times `|õ(a) − õ(b)| ≤ L · d(a, b) + J` with d the distance of a and b
/// on the circle of circumference T.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct TrajBounds {
    /// L [m/s], a bound of `|dõ/dt|` of the cubic Hermite interpolant. On a
    /// step, `dõ/dt = (p₁ − p₀)/h · 6s(1 − s) + v₀ (3s² − 4s + 1) +
    /// v₁ (3s² − 2s)`, whose three factors are at most 1.5, 1 and 1 in
    /// modulus on [0, 1], so `L = 1.5 max |p₁ − p₀|/h + 2 max |v|`; NaN if
    /// a node is not finite (then nothing is bounded).
    pub(super) lipschitz: f64,
    /// J [m]: `|õ(T⁻) − õ(0)|` (the periodic response closes up to rounding).
    pub(super) wrap_jump: f64,
}

impl TrajBounds {
    /// The bounds of the Hermite interpolant through the nodes.
    pub(super) fn of(traj_nodes: TrajNodes) -> Self {
        let TrajNodes {
            times,
            pos,
            vel,
            acc_start,
            acc_end,
        } = traj_nodes;
        let (mut slope2, mut speed2, mut finite) = (0.0_f64, 0.0_f64, true);
        for (k, w) in times.windows(2).enumerate() {
            let d = (pos[k + 1] - pos[k]).norm_squared() / ((w[1] - w[0]) * (w[1] - w[0]));
            finite &= d.is_finite();
            slope2 = slope2.max(d);
        }
        for v in vel {
            let v2 = v.norm_squared();
            finite &= v2.is_finite();
            speed2 = speed2.max(v2);
        }
        finite &= acc_start
            .iter()
            .chain(acc_end)
            .all(|a| a.x.is_finite() && a.y.is_finite());
        let wrap_jump = match (pos.first(), pos.last()) {
            (Some(a), Some(b)) => (b - a).norm(),
            _ => 0.0,
        };
        Self {
            lipschitz: if finite {
                1.5 * slope2.sqrt() + 2.0 * speed2.sqrt()
            } else {
                f64::NAN
            },
            wrap_jump,
        }
    }
}

/// The node data of a [`Traj`] (for [`TrajBounds::of`]).
pub(super) struct TrajNodes<'a> {
    pub(super) times: &'a [f64],
    pub(super) pos: &'a [Vector2<f64>],
    pub(super) vel: &'a [Vector2<f64>],
    pub(super) acc_start: &'a [Vector2<f64>],
    pub(super) acc_end: &'a [Vector2<f64>],
}

impl Traj<'_> {
    pub(super) fn state(&self, t: f64) -> (Vector2<f64>, Vector2<f64>) {
        // rem_euclid, without fmod on the two common cases (bit-identical:
        // fmod(t, T) = t exactly for |t| < T).
        let tt = if t >= 0.0 && t < self.period {
            t
        } else if t < 0.0 && t >= -self.period {
            t + self.period
        } else {
            t.rem_euclid(self.period)
        };
        let k = locate_guess(self.times, tt);
        let (t0, t1) = (self.times[k], self.times[k + 1]);
        let h = t1 - t0;
        let s = ((tt - t0) / h).clamp(0.0, 1.0);
        let p = hermite(
            s,
            h,
            self.pos[k],
            self.vel[k],
            self.pos[k + 1],
            self.vel[k + 1],
        );
        let v = hermite(
            s,
            h,
            self.vel[k],
            self.acc_start[k],
            self.vel[k + 1],
            self.acc_end[k],
        );
        (p, v)
    }

    /// [`Traj::state`] at node k, t = `times[k]`, without the
    /// interpolation: there `s = 0`, the Hermite weights are exactly
    /// (1, 0, 0, 0) and the interpolant is the node value plus zeros, i.e.
    /// the node value itself when it is finite and nonzero (all nodes
    /// finite: [`TrajBounds::lipschitz`] not NaN). Otherwise, and at t = T
    /// (which wraps to node 0), it interpolates: bit-identical either way.
    pub(super) fn node_state(&self, k: usize) -> (Vector2<f64>, Vector2<f64>) {
        let t = self.times[k];
        let (p, v) = (self.pos[k], self.vel[k]);
        let plain = t >= 0.0
            && t < self.period
            && k + 1 < self.times.len()
            && !self.bounds.lipschitz.is_nan()
            && p.x != 0.0
            && p.y != 0.0
            && v.x != 0.0
            && v.y != 0.0;
        if plain {
            (p, v)
        } else {
            self.state(t)
        }
    }
}

/// The tooth angle's sine, cosine and the state (position, velocity) at
/// one time: shared by every delay and order evaluated at that time.
pub(super) struct Here {
    pub(super) s: f64,
    pub(super) c: f64,
    pub(super) p: Vector2<f64>,
    pub(super) v: Vector2<f64>,
}

pub(super) struct Ctx<'a> {
    pub(super) process: &'a MillingProcess,
    pub(super) feed: f64,
    pub(super) omega: f64,
    pub(super) period: f64,
}

impl Ctx<'_> {
    pub(super) fn phi(&self, tooth: usize, t: f64) -> f64 {
        self.omega * t + 2.0 * PI * tooth as f64 / self.process.teeth as f64
    }

    /// The tooth angle's sine and cosine and the state at time t.
    pub(super) fn here(&self, traj: &Traj, tooth: usize, t: f64) -> Here {
        let (s, c) = self.phi(tooth, t).sin_cos();
        let (p, v) = traj.state(t);
        Here { s, c, p, v }
    }

    /// Eq. 3 residual, eq. 4 chip and their partial derivatives (module doc).
    pub(super) fn geometry(
        &self,
        traj: &Traj,
        tooth: usize,
        order: usize,
        t: f64,
        tau: f64,
    ) -> Geometry {
        let here = self.here(traj, tooth, t);
        self.geometry_at(traj, &here, order, t, tau)
    }

    /// [`Ctx::geometry`] with the quantities at t precomputed.
    pub(super) fn geometry_at(
        &self,
        traj: &Traj,
        here: &Here,
        order: usize,
        t: f64,
        tau: f64,
    ) -> Geometry {
        let r = self.process.radius;
        let (s, c, p, v) = (here.s, here.c, here.p, here.v);
        let delta = self.omega * tau - 2.0 * PI * order as f64 / self.process.teeth as f64;
        let (sd, cd) = delta.sin_cos();
        let (pd, vd) = traj.state(t - tau);
        let dcx = self.feed * tau + pd.x - p.x;
        let dcy = pd.y - p.y;
        Geometry {
            g: r * sd + dcx * c - dcy * s,
            h: r * (1.0 - cd) + dcx * s + dcy * c,
            g_tau: r * self.omega * cd + (self.feed - vd.x) * c + vd.y * s,
            h_tau: r * self.omega * sd + (self.feed - vd.x) * s - vd.y * c,
            g_t: (vd.x - v.x) * c - self.omega * dcx * s - (vd.y - v.y) * s - self.omega * dcy * c,
        }
    }

    /// Newton's method on eq. 3 from `guess` (cap 50 iterations).
    pub(super) fn newton(
        &self,
        traj: &Traj,
        tooth: usize,
        order: usize,
        t: f64,
        guess: f64,
    ) -> Result<f64, ChatterError> {
        let here = self.here(traj, tooth, t);
        self.newton_at(traj, &here, tooth, order, t, guess)
    }

    /// [`Ctx::newton`] with the quantities at t precomputed.
    pub(super) fn newton_at(
        &self,
        traj: &Traj,
        here: &Here,
        tooth: usize,
        order: usize,
        t: f64,
        guess: f64,
    ) -> Result<f64, ChatterError> {
        let mut tau = guess;
        let nominal = order as f64 * self.period;
        let mut last = f64::NAN;
        for _ in 0..50 {
            let geo = self.geometry_at(traj, here, order, t, tau);
            if !(geo.g_tau.is_finite() && geo.g.is_finite()) {
                return Err(ChatterError::NonFinite {
                    what: format!("eq. 3 Newton step (tooth {tooth}, order {order}, t = {t:e} s)"),
                });
            }
            if geo.g_tau <= 0.0 {
                // off the branch |δ| < π/2 (or the vibration velocity
                // exceeds the cutting speed): no delay to follow
                return Err(ChatterError::NotConverged {
                    what: format!(
                        "eq. 3 delay by Newton (tooth {tooth}, order {order}, t = {t:e} s): dg/dtau = {:e} <= 0",
                        geo.g_tau
                    ),
                    iterations: 50,
                    residual: geo.g,
                });
            }
            let step = geo.g / geo.g_tau;
            tau -= step;
            last = step.abs();
            if (tau - nominal).abs() > 0.5 * self.period {
                return Err(ChatterError::NotConverged {
                    what: format!("eq. 3 delay (tooth {tooth}, order {order}): left (m T ± T/2)"),
                    iterations: 50,
                    residual: geo.g,
                });
            }
            if last <= 1e-15 * self.period {
                return Ok(tau);
            }
        }
        Err(ChatterError::NotConverged {
            what: format!("eq. 3 delay by Newton (tooth {tooth}, order {order})"),
            iterations: 50,
            residual: last,
        })
    }

    pub(super) fn taudot_at(&self, traj: &Traj, here: &Here, t: f64, tau: f64) -> f64 {
        let geo = self.geometry_at(traj, here, 1, t, tau);
        -geo.g_t / geo.g_tau
    }
}
