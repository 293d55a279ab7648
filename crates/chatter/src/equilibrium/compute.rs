//! The fixed-point computation of the T-periodic equilibrium.

use std::f64::consts::PI;

use nalgebra::{Matrix2, Matrix4, Vector2, Vector4};

use super::engagement::engagement_breakpoints;
use super::geometry::{Ctx, Traj, TrajBounds, TrajNodes};
use super::tracks::{build_tracks, chip_with, AngleTable, Point};
use super::{engaged, Equilibrium, EquilibriumSettings};
use crate::error::{check_non_negative, ChatterError};
use crate::model::{force_direction, MillingProcess, Modal2};

/// Linear 4×4 first-order system matrix of `M ö + C ȯ + K o = F`.
pub(super) fn system_matrix(minv: &Matrix2<f64>, modal: &Modal2) -> Matrix4<f64> {
    let mk = -minv * modal.stiffness;
    let mc = -minv * modal.damping;
    let mut a = Matrix4::zeros();
    a[(0, 2)] = 1.0;
    a[(1, 3)] = 1.0;
    for i in 0..2 {
        for j in 0..2 {
            a[(2 + i, j)] = mk[(i, j)];
            a[(2 + i, 2 + j)] = mc[(i, j)];
        }
    }
    a
}

pub(super) fn lift(minv: &Matrix2<f64>, f: &Vector2<f64>) -> Vector4<f64> {
    let a = minv * f;
    Vector4::new(0.0, 0.0, a.x, a.y)
}

/// One RK4 stage derivative `a w + g` for the [`system_matrix`]
/// `a = [0, I; X, Y]` and a [`lift`]ed force `g = (0, 0, g₂, g₃)`, with
/// nalgebra's floating-point operations on the nonzero entries: rows 2 and 3
/// as `(((a_i0 w₀ + a_i1 w₁) + a_i2 w₂) + a_i3 w₃) + g_i` (its gemv goes
/// column by column), rows 0 and 1 as `w₂ + g₀`, `w₃ + g₁`. nalgebra's
/// `a * w + g` also adds the products with the zero entries, which can
/// change only the sign of a zero (or give NaN for a non-finite w, where
/// the iteration fails either way), and adding `g₀ = g₁ = +0` then gives
/// the same bits: the result is bit-identical (tested), at half the
/// multiplications.
fn stage(a: &Matrix4<f64>, w: &Vector4<f64>, g: &Vector4<f64>) -> Vector4<f64> {
    let row =
        |i: usize| a[(i, 0)] * w[0] + a[(i, 1)] * w[1] + a[(i, 2)] * w[2] + a[(i, 3)] * w[3] + g[i];
    Vector4::new(w[2] + g[0], w[3] + g[1], row(2), row(3))
}

impl Equilibrium {
    /// Computes the T-periodic equilibrium (module documentation).
    ///
    /// # Arguments
    /// * `modal` — tool-tip dynamics
    /// * `process` — milling process
    /// * `rpm` — spindle speed [rpm]
    /// * `feed` — feed speed f [m/s] (≥ 0)
    /// * `settings` — grid, tolerance, force law
    ///
    /// # Errors
    /// [`ChatterError::InvalidParameter`] for bad inputs (also feed = 0 with
    /// a force exponent < 1, whose stiffness is infinite at h = 0);
    /// [`ChatterError::NotConverged`] when the fixed-point iteration or a
    /// delay's Newton iteration hits its cap, or eq. 3 has no regular root
    /// (`g_τ ≤ 0`: vibration velocity comparable to the cutting speed); [`ChatterError::NonFinite`];
    /// [`ChatterError::Unsupported`] when `I − Φ_T` is singular (undamped
    /// resonance with a harmonic of the tooth frequency).
    ///
    /// # Performance
    /// About 0.22 ms (release) for 200 nodes and 4 iterations (2 teeth,
    /// quarter-turn engagement, 3 regeneration orders): per iteration the
    /// delay tracks (five eq. 3 evaluations per engaged step), the forces
    /// (two chips per engaged step; the higher orders are almost always
    /// skipped by their lower bound, `tracks.rs`) and two RK4 shooting
    /// passes. What does not change between iterations (step matrices,
    /// tooth angles, force directions) is computed once.
    pub fn compute(
        modal: &Modal2,
        process: &MillingProcess,
        rpm: f64,
        feed: f64,
        settings: &EquilibriumSettings,
    ) -> Result<Self, ChatterError> {
        modal.validate()?;
        process.validate()?;
        settings.validate()?;
        let period = process.tooth_period(rpm)?;
        let feed = check_non_negative("feed [m/s]", feed)?;
        if feed == 0.0 && settings.force_law.exponent < 1.0 {
            return Err(ChatterError::InvalidParameter {
                name: "feed [m/s]".to_string(),
                value: feed,
                reason: "must be > 0 with a force exponent < 1 (infinite cutting stiffness at zero chip)".to_string(),
            });
        }
        let omega = rpm * PI / 30.0;
        let breakpoints = engagement_breakpoints(process, omega, period);
        // Nodes: each segment gets steps in proportion to its length.
        let n = settings.points_per_period as f64;
        let mut times = vec![0.0];
        for w in breakpoints.windows(2) {
            let (a, b) = (w[0], w[1]);
            let k = (((b - a) / period) * n).ceil().max(1.0) as usize;
            for i in 1..=k {
                times.push(if i == k {
                    b
                } else {
                    a + (b - a) * i as f64 / k as f64
                });
            }
        }
        let nsteps = times.len() - 1;
        // Engaged teeth per step (judged at the step midpoint: jumps sit on nodes).
        let ctx = Ctx {
            process,
            feed,
            omega,
            period,
        };
        let engaged_steps: Vec<Vec<usize>> = (0..nsteps)
            .map(|k| {
                let tm = 0.5 * (times[k] + times[k + 1]);
                (0..process.teeth)
                    .filter(|&j| engaged(process, ctx.phi(j, tm)))
                    .collect()
            })
            .collect();

        let angles = AngleTable::new(&ctx, &times, &engaged_steps);

        let minv = modal.mass_inverse()?;
        let a = system_matrix(&minv, modal);
        // Monodromy of the RK4 map of the homogeneous system. The step
        // matrix depends on the step length only, and the grid has few
        // distinct lengths (uniform pieces between breakpoints, up to
        // rounding): each distinct value (bit for bit) is computed once.
        let mut phi_t = Matrix4::<f64>::identity();
        let mut step_matrices: Vec<(u64, Matrix4<f64>)> = Vec::new();
        for k in 0..nsteps {
            let h = times[k + 1] - times[k];
            let p = match step_matrices.iter().find(|(bits, _)| *bits == h.to_bits()) {
                Some((_, p)) => *p,
                None => {
                    let ah = a * h;
                    let ah2 = ah * ah;
                    let p =
                        Matrix4::identity() + ah + ah2 * 0.5 + ah2 * ah / 6.0 + ah2 * ah2 / 24.0;
                    step_matrices.push((h.to_bits(), p));
                    p
                }
            };
            phi_t = p * phi_t;
        }
        let lu = (Matrix4::identity() - phi_t).lu();
        let zero = Vector2::zeros();
        let mut pos = vec![zero; nsteps + 1];
        let mut vel = vec![zero; nsteps + 1];
        let mut acc_start = vec![zero; nsteps];
        let mut acc_end = vec![zero; nsteps];
        let mut tracks = Vec::new();
        let mut residual = f64::INFINITY;
        for iteration in 1..=settings.max_iterations {
            let traj = Traj {
                times: &times,
                pos: &pos,
                vel: &vel,
                acc_start: &acc_start,
                acc_end: &acc_end,
                period,
                bounds: TrajBounds::of(TrajNodes {
                    times: &times,
                    pos: &pos,
                    vel: &vel,
                    acc_start: &acc_start,
                    acc_end: &acc_end,
                }),
            };
            tracks = build_tracks(&ctx, &traj, &times, &engaged_steps, &angles)?;
            // Forces at step start, midpoint, end.
            // Force of the teeth engaged on the step (the step's engaged set
            // decides, so a jump sitting on a node gets its one-sided value);
            // the end force of a step is the start force of the next unless
            // the engaged set changes there.
            let force_at = |k: usize, point: Point| -> Result<Vector2<f64>, ChatterError> {
                let mut f = zero;
                let t = point.time(&times, k);
                for &j in &engaged_steps[k] {
                    let here = angles
                        .here(&traj, k, j, point)
                        .unwrap_or_else(|| ctx.here(&traj, j, t));
                    let cs = chip_with(&ctx, &traj, &tracks, settings, &times, j, t, &here)?;
                    if cs.chip > 0.0 {
                        let b = angles
                            .force_direction(k, j, point)
                            .unwrap_or_else(|| force_direction(cs.phi, process.kt, process.kn));
                        f += b * (process.axial_depth * settings.force_law.value(cs.chip));
                    }
                }
                Ok(f)
            };
            let mut forces: Vec<[Vector2<f64>; 3]> = Vec::with_capacity(nsteps);
            for (k, teeth) in engaged_steps.iter().enumerate() {
                let fa = match (k.checked_sub(1), forces.last()) {
                    (Some(prev), Some(last)) if engaged_steps[prev] == *teeth => last[2],
                    _ => force_at(k, Point::Start)?,
                };
                forces.push([fa, force_at(k, Point::ForceMid)?, force_at(k, Point::End)?]);
            }
            // Shooting: particular solution from z = 0, then periodicity.
            // The lifted forces M⁻¹F of each step serve both passes.
            let lifted: Vec<[Vector4<f64>; 3]> = forces
                .iter()
                .map(|f| [lift(&minv, &f[0]), lift(&minv, &f[1]), lift(&minv, &f[2])])
                .collect();
            let step = |z: Vector4<f64>, k: usize| {
                let h = times[k + 1] - times[k];
                let [ga, gm, gb] = lifted[k];
                let k1 = stage(&a, &z, &ga);
                let k2 = stage(&a, &(z + k1 * (0.5 * h)), &gm);
                let k3 = stage(&a, &(z + k2 * (0.5 * h)), &gm);
                let k4 = stage(&a, &(z + k3 * h), &gb);
                z + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0)
            };
            let mut z = Vector4::zeros();
            for k in 0..forces.len() {
                z = step(z, k);
            }
            let mut z = lu.solve(&z).ok_or_else(|| ChatterError::Unsupported {
                reason: "I - monodromy of the tool dynamics is singular (undamped resonance at a tooth-frequency harmonic)".to_string(),
            })?;
            let mut new_pos = Vec::with_capacity(nsteps + 1);
            let mut new_vel = Vec::with_capacity(nsteps + 1);
            let accel = |z: &Vector4<f64>, f: &Vector2<f64>| {
                minv * (f
                    - modal.damping * Vector2::new(z[2], z[3])
                    - modal.stiffness * Vector2::new(z[0], z[1]))
            };
            for (k, f) in forces.iter().enumerate() {
                new_pos.push(Vector2::new(z[0], z[1]));
                new_vel.push(Vector2::new(z[2], z[3]));
                acc_start[k] = accel(&z, &f[0]);
                z = step(z, k);
                acc_end[k] = accel(&z, &f[2]);
            }
            new_pos.push(Vector2::new(z[0], z[1]));
            new_vel.push(Vector2::new(z[2], z[3]));
            let diff = new_pos
                .iter()
                .zip(&pos)
                .map(|(a, b)| (a - b).norm())
                .fold(0.0, f64::max);
            let scale = new_pos.iter().map(|p| p.norm()).fold(0.0, f64::max);
            if !(diff.is_finite() && scale.is_finite()) {
                return Err(ChatterError::NonFinite {
                    what: "equilibrium fixed-point iteration".to_string(),
                });
            }
            pos = new_pos;
            vel = new_vel;
            residual = if scale > 0.0 { diff / scale } else { 0.0 };
            if residual <= settings.tolerance {
                let bounds = TrajBounds::of(TrajNodes {
                    times: &times,
                    pos: &pos,
                    vel: &vel,
                    acc_start: &acc_start,
                    acc_end: &acc_end,
                });
                let traj = Traj {
                    times: &times,
                    pos: &pos,
                    vel: &vel,
                    acc_start: &acc_start,
                    acc_end: &acc_end,
                    period,
                    bounds,
                };
                tracks = build_tracks(&ctx, &traj, &times, &engaged_steps, &angles)?;
                return Ok(Self {
                    process: *process,
                    feed,
                    omega,
                    period,
                    settings: *settings,
                    times,
                    breakpoints,
                    pos,
                    vel,
                    acc_start,
                    acc_end,
                    bounds,
                    tracks,
                    iterations: iteration,
                    residual,
                });
            }
        }
        let _ = tracks;
        Err(ChatterError::NotConverged {
            what: "periodic equilibrium (fixed-point iteration on the cutting force)".to_string(),
            iterations: settings.max_iterations,
            residual,
        })
    }

    pub(super) fn traj(&self) -> Traj<'_> {
        Traj {
            times: &self.times,
            pos: &self.pos,
            vel: &self.vel,
            acc_start: &self.acc_start,
            acc_end: &self.acc_end,
            period: self.period,
            bounds: self.bounds,
        }
    }

    pub(super) fn ctx(&self) -> Ctx<'_> {
        Ctx {
            process: &self.process,
            feed: self.feed,
            omega: self.omega,
            period: self.period,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`stage`] gives the bits of nalgebra's `a * w + g`, zeros of either
    /// sign included.
    #[test]
    fn stage_is_bit_identical_to_the_dense_product() {
        let modal = Modal2 {
            mass: Matrix2::new(31.0, 2.5, 2.5, 17.0),
            damping: Matrix2::new(850.0, -120.0, -120.0, 400.0),
            stiffness: Matrix2::new(1.68e6, -5.3e5, -5.3e5, 8.4e5),
        };
        let minv = modal.mass_inverse().unwrap();
        let a = system_matrix(&minv, &modal);
        let mut x: u64 = 0x2545_f491_4f6c_dd1d;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            match x % 7 {
                0 => 0.0,
                1 => -0.0,
                _ => {
                    ((x >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 10f64.powi((x % 9) as i32 - 6)
                }
            }
        };
        for _ in 0..20_000 {
            let w = Vector4::new(next(), next(), next(), next());
            let g = lift(&minv, &Vector2::new(next(), next()));
            let dense = a * w + g;
            let fast = stage(&a, &w, &g);
            for i in 0..4 {
                assert_eq!(
                    dense[i].to_bits(),
                    fast[i].to_bits(),
                    "w {w:?} g {g:?} row {i}"
                );
            }
        }
    }
}
