//! The cutter of seed 004 eq. 2-4: tooth edges, engagement crossings,
//! the delays and the cutting force on a stored trajectory.

use nalgebra::Vector2;

use super::history::History;
use super::{internal, DELAY_MAX_ITERATIONS};
use crate::error::ChatterError;
use crate::model::{force_direction, MillingProcess};
use crate::trochoid::{chip_thickness, tangential_residual};

/// The cutter of seed 004 eq. 2-4 with its force law.
pub(super) struct Cutter {
    pub(super) teeth: usize,
    pub(super) radius: f64,
    pub(super) depth: f64,
    pub(super) kt: f64,
    pub(super) kn: f64,
    pub(super) entry: f64,
    pub(super) exit: f64,
    pub(super) omega: f64,
    pub(super) feed: f64,
    pub(super) period: f64,
    pub(super) regen: usize,
    /// Half width w of the bracket `δ ∈ [−w, w]` of the delay root.
    pub(super) half_width: f64,
    /// Workpiece-wall level `y_w` \[m\] of the entry edge (tooth tip in the
    /// material while `y(t) − R cos φ ≥ y_w`), if the entry is a wall.
    pub(super) entry_wall: Option<f64>,
    /// Same for the exit edge (in the material while `y − R cos φ ≤ y_w`).
    pub(super) exit_wall: Option<f64>,
    /// Angle offset φ_0 of the step grid \[rad\]: internally
    /// `φ_j = Ω t + φ_0 + 2π j / N_t`, i.e. the internal time is the true
    /// time minus φ_0 / Ω. With a workpiece wall, φ_0 puts the nominal wall
    /// crossings in the middle of a step, so that the actual crossing can
    /// move either way inside that step.
    pub(super) phase: f64,
}

/// One boundary of the RK4 sub-steps of a step.
#[derive(Debug, Clone, Copy)]
pub(super) struct Edge {
    /// Nominal time \[s\] (the tooth crosses the edge angle).
    pub(super) time: f64,
    /// For a workpiece-wall edge: the tooth and the wall level y_w \[m\].
    pub(super) wall: Option<(usize, f64)>,
}

/// Force of all teeth at one instant.
pub(super) struct Cut {
    pub(super) force: Vector2<f64>,
    pub(super) chip: f64,
    pub(super) order: usize,
    pub(super) engaged: usize,
    pub(super) contact: usize,
}

impl Cutter {
    pub(super) fn new(p: &MillingProcess, rpm: f64, feed: f64, period: f64, regen: usize) -> Self {
        let pi = std::f64::consts::PI;
        Self {
            teeth: p.teeth,
            radius: p.radius,
            depth: p.axial_depth,
            kt: p.kt,
            kn: p.kn,
            entry: p.entry_angle,
            exit: p.exit_angle,
            omega: rpm * pi / 30.0,
            feed,
            period,
            regen,
            half_width: (0.25 * pi).min(0.5 * pi / p.teeth as f64),
            entry_wall: None,
            exit_wall: None,
            phase: 0.0,
        }
    }

    /// Boundaries `[t, s_1, .., t + h]` of the RK4 sub-steps of the step
    /// `[t, t + h]`: the step is split where a tooth crosses the entry or
    /// exit angle, so that the force, which jumps there, is smooth on every
    /// sub-step and RK4 keeps its order (a jump inside a step would cost an
    /// O(h) error in the impulse).
    ///
    /// Edges where the tooth meets a workpiece wall carry the wall level
    /// (the simulator then moves them to the actual crossing).
    pub(super) fn substeps(&self, t: f64, h: f64, out: &mut Vec<Edge>) {
        let two_pi = 2.0 * std::f64::consts::PI;
        out.clear();
        out.push(Edge {
            time: t,
            wall: None,
        });
        let eps = 1e-9 * h;
        for j in 0..self.teeth {
            let phi = self.omega * t + self.phase + two_pi * j as f64 / self.teeth as f64;
            for (edge, wall) in [(self.entry, self.entry_wall), (self.exit, self.exit_wall)] {
                let past = (phi - edge).rem_euclid(two_pi);
                let dt = (two_pi - past) / self.omega;
                if dt > eps && dt < h - eps {
                    out.push(Edge {
                        time: t + dt,
                        wall: wall.map(|w| (j, w)),
                    });
                }
            }
        }
        out.push(Edge {
            time: t + h,
            wall: None,
        });
        out.sort_by(|a, b| a.time.total_cmp(&b.time));
        out.dedup_by(|a, b| (a.time - b.time).abs() <= eps);
    }

    /// The actual time at which `tooth` meets the workpiece wall `y_w`
    /// near its nominal crossing `nominal`: the root of
    /// `g(t) = y(t) − R cos φ(t) − y_w` (the tooth tip reaches the wall
    /// line, fixed in the workpiece: Bachrathy et al. 2011, and the wall term
    /// of [`crate::linearize`]), with `y(t)` from the sub-step `sub` started
    /// at `start` (the tooth still on its side before the crossing). Newton
    /// with `ġ = ẏ + R Ω sin φ`, kept inside `(start, upper)`; a crossing
    /// outside that window (only for a vibration comparable to `R Ω h`) is
    /// clamped to it.
    ///
    /// # Errors
    /// [`ChatterError::NotConverged`] at the iteration cap; errors of `sub`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn wall_crossing<F>(
        &self,
        tooth: usize,
        wall: f64,
        start: f64,
        nominal: f64,
        upper: f64,
        h: f64,
        sub: &mut F,
    ) -> Result<f64, ChatterError>
    where
        F: FnMut(f64) -> Result<(Vector2<f64>, Vector2<f64>), ChatterError>,
    {
        let offset = 2.0 * std::f64::consts::PI * tooth as f64 / self.teeth as f64;
        let (lo, hi) = (start + 1e-9 * h, upper - 1e-9 * h);
        let mut tc = nominal;
        let mut g = f64::NAN;
        for _ in 0..DELAY_MAX_ITERATIONS {
            let (p, v) = sub(tc)?;
            let (s, c) = (self.omega * tc + self.phase + offset).sin_cos();
            g = p.y - self.radius * c - wall;
            let dg = v.y + self.radius * self.omega * s;
            if !(g.is_finite() && dg.is_finite()) {
                return Err(ChatterError::NonFinite {
                    what: "workpiece-wall crossing".to_string(),
                });
            }
            if g == 0.0 || dg <= 0.0 {
                return Ok(tc);
            }
            let next = (tc - g / dg).clamp(lo, hi);
            if (next - tc).abs() <= 1e-9 * h || next == lo || next == hi {
                return Ok(next);
            }
            tc = next;
        }
        Err(ChatterError::NotConverged {
            what: format!("workpiece-wall crossing of tooth {tooth}"),
            iterations: DELAY_MAX_ITERATIONS,
            residual: g,
        })
    }

    /// Nominal delays m T, laid out `[tooth * M + (m − 1)]`.
    pub(super) fn nominal_delays(&self) -> Vec<f64> {
        (0..self.teeth * self.regen)
            .map(|i| ((i % self.regen) + 1) as f64 * self.period)
            .collect()
    }

    /// Cutting force at time `t` with present position `o` and the history
    /// `hist` (module documentation); `warm` holds the last delay of every
    /// (tooth, m) as the Newton start. Whether a tooth is inside the
    /// engagement window is decided at `member` (the midpoint of the current
    /// RK4 sub-step, which no window edge crosses), so that every stage of a
    /// sub-step sees the same set of teeth.
    pub(super) fn force<H: History>(
        &self,
        t: f64,
        member: f64,
        o: Vector2<f64>,
        hist: &H,
        warm: &mut [f64],
    ) -> Result<Cut, ChatterError> {
        let two_pi = 2.0 * std::f64::consts::PI;
        let mut cut = Cut {
            force: Vector2::zeros(),
            chip: 0.0,
            order: 0,
            engaged: 0,
            contact: 0,
        };
        for j in 0..self.teeth {
            let offset = two_pi * j as f64 / self.teeth as f64;
            let inside = (self.omega * member + self.phase + offset).rem_euclid(two_pi);
            if inside < self.entry || inside > self.exit {
                continue;
            }
            let phi = self.omega * t + self.phase + offset;
            cut.engaged += 1;
            let (mut h, mut order) = (f64::INFINITY, 0);
            for m in 1..=self.regen {
                let slot = warm.get_mut(j * self.regen + m - 1).ok_or_else(internal)?;
                let (tau, hm) = self.solve_delay(t, phi, o, m, hist, *slot)?;
                *slot = tau;
                if hm < h {
                    h = hm;
                    order = m;
                }
            }
            if h > 0.0 {
                cut.contact += 1;
                if h > cut.chip {
                    cut.chip = h;
                    cut.order = order;
                }
                cut.force += self.depth * h * force_direction(phi, self.kt, self.kn);
            }
        }
        Ok(cut)
    }

    /// Solves seed 004 eq. 3 for the delay τ of regeneration order m by a
    /// safeguarded Newton iteration on the bracket `δ ∈ [−w, w]`
    /// (`δ = Ω τ − 2π m / N_t`) and returns τ and the chip of seed 004
    /// eq. 4.
    ///
    /// Residual and derivative (s = t − τ, history interpolant x, y):
    /// `g(τ) = R sin δ + (f τ + x(s) − x(t)) cos φ − (y(s) − y(t)) sin φ`,
    /// `g'(τ) = R Ω cos δ + (f − ẋ(s)) cos φ + ẏ(s) sin φ`.
    pub(super) fn solve_delay<H: History>(
        &self,
        t: f64,
        phi: f64,
        o: Vector2<f64>,
        m: usize,
        hist: &H,
        guess: f64,
    ) -> Result<(f64, f64), ChatterError> {
        let base = 2.0 * std::f64::consts::PI * m as f64 / self.teeth as f64;
        let (sphi, cphi) = phi.sin_cos();
        let eval = |tau: f64| -> Result<(f64, f64, f64, f64, f64), ChatterError> {
            let (p, v) = hist.at(t - tau)?;
            let delta = self.omega * tau - base;
            let dcx = self.feed * tau + p.x - o.x;
            let dcy = p.y - o.y;
            let g = tangential_residual(self.radius, delta, dcx, dcy, phi);
            let dg = self.radius * self.omega * delta.cos() + (self.feed - v.x) * cphi + v.y * sphi;
            Ok((g, dg, delta, dcx, dcy))
        };
        let mut lo = (base - self.half_width) / self.omega;
        let mut hi = (base + self.half_width) / self.omega;
        let glo = eval(lo)?.0;
        let ghi = eval(hi)?.0;
        if !(glo < 0.0 && ghi > 0.0) {
            return Err(ChatterError::NotConverged {
                what: format!(
                    "delay of regeneration order {m} (seed 004 eq. 3): no sign change on its \
                     bracket at phi = {:.4} rad (vibration too large for the tool radius?)",
                    phi.rem_euclid(2.0 * std::f64::consts::PI)
                ),
                iterations: 0,
                residual: if glo.is_finite() { glo } else { ghi },
            });
        }
        let tol = 1e-12 * self.period;
        let mut tau = if guess > lo && guess < hi {
            guess
        } else {
            0.5 * (lo + hi)
        };
        let mut last = f64::NAN;
        for _ in 0..DELAY_MAX_ITERATIONS {
            let (g, dg, delta, dcx, dcy) = eval(tau)?;
            if !g.is_finite() || !dg.is_finite() {
                return Err(ChatterError::NonFinite {
                    what: format!("delay residual of regeneration order {m} (seed 004 eq. 3)"),
                });
            }
            last = g;
            if g < 0.0 {
                lo = tau;
            } else {
                hi = tau;
            }
            let newton = tau - g / dg;
            let next = if dg > 0.0 && newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            if g == 0.0 || (next - tau).abs() <= tol {
                let h = chip_thickness(self.radius, delta, dcx, dcy, phi);
                return Ok((tau, h));
            }
            tau = next;
        }
        Err(ChatterError::NotConverged {
            what: format!("delay of regeneration order {m} (seed 004 eq. 3)"),
            iterations: DELAY_MAX_ITERATIONS,
            residual: last,
        })
    }
}
