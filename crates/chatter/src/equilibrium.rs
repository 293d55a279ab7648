//! The periodic forced response (equilibrium) õ(t) of the milling tool with
//! the state-dependent regenerative delays of seed 004 section 2 (eq. 1-7),
//! after Bachrathy, Insperger & Stépán (2011, J. Comput. Nonlinear Dynam.
//! 6:041002).
//!
//! # The problem (seed 004 eq. 1, 3, 4)
//!
//! `M ṏ + C õ̇ + K õ = Σ_j a_p F(h_j(t)) b(φ_j(t))` with the chip h_j of
//! tooth j given by the exact tooth-path geometry of [`crate::trochoid`]:
//! for regeneration order m (the surface left by the tooth m positions
//! earlier) the delay τ_j^m solves eq. 3,
//!
//! `g(τ, t) = R sin δ + Δc_x cos φ − Δc_y sin φ = 0`,
//! `δ = Ω τ − 2π m / N_t`, `Δc = (f τ + x(t − τ) − x(t), y(t − τ) − y(t))`,
//!
//! and eq. 4 gives `h^m = R (1 − cos δ) + Δc_x sin φ + Δc_y cos φ`. The
//! chip actually cut is `h = min_m h^m` (the material left on the tooth's
//! radial line is the one no earlier tooth removed, seed 004 Fig. 1b:
//! multiple regeneration); `h ≤ 0` is loss of contact (no force). Orders
//! m = 1 ..= [`EquilibriumSettings::max_regeneration`] (default 3) are
//! searched; a surface older than that is not represented.
//!
//! `F(h)` is the cutting-force law of [`ForceLaw`]: the paper's linear law
//! `F = h` by default (force `a_p h b(φ)`, [`crate::force_direction`]).
//!
//! # Delays along the period: eq. 6 by RK4 (seed 004 eq. 5-7, derived)
//!
//! The extracted eq. 5-7 are garbled, so here is the derivation. Along the
//! solution τ(t) of eq. 3, `d/dt g(τ(t), t) = g_τ τ̇ + g_t = 0`, hence
//!
//! `τ̇ = −g_t / g_τ`  (seed 004 eq. 6), with (φ̇ = Ω, d/dτ x(t−τ) = −ẋ(t−τ))
//!
//! `g_τ = R Ω cos δ + (f − ẋ(t−τ)) cos φ + ẏ(t−τ) sin φ`  (eq. 7: G3 + G4)
//!
//! `g_t = (ẋ(t−τ) − ẋ(t)) cos φ − Ω Δc_x sin φ − (ẏ(t−τ) − ẏ(t)) sin φ
//!        − Ω Δc_y cos φ`  (eq. 7: −(G1 + G2)),
//!
//! which agrees term by term with the paper's G1..G4 once the extraction
//! typos are removed. As in the paper, the order-1 delay is found by
//! Newton's method on eq. 3 where a tooth enters a cut segment and then
//! integrated by explicit RK4 on eq. 6 over the segment's nodes
//! ([`Equilibrium::delay_rk4`]); [`Equilibrium::solve_delay`] is the Newton
//! solution of eq. 3 at any time, used for the higher orders and as a
//! cross-check. Differentiating eq. 4 the same way,
//! `h_τ = R Ω sin δ + (f − ẋ(t−τ)) sin φ − ẏ(t−τ) cos φ` (used by
//! [`crate::linearize`]).
//!
//! # Periodic solution by fixed-point iteration on the cutting force
//!
//! A forward simulation diverges where the equilibrium is unstable, so the
//! T-periodic solution is found instead by iterating on the force: given
//! the current guess õ_k (T-periodic, so `õ(t − τ) = õ(t − τ + nT)` and the
//! delayed state comes from the same period), compute τ(t), h(t) and F(t)
//! on a grid of ≥ 200 nodes per period, then the T-periodic response of the
//! *linear* ODE `M ö + C ȯ + K o = F(t)` by shooting: RK4 over one period
//! gives `z(T) = Φ z(0) + z_p`, and periodicity `(I − Φ) z(0) = z_p` is one
//! 4×4 solve (exact for the RK4 map, the system being linear). Repeat until
//! the node positions change less than the tolerance (relative). The grid
//! is split at every entry/exit time of a tooth so that the force jumps
//! fall on nodes (RK4 then sees a smooth force within each step).
//!
//! With a T-periodic õ the regenerative terms nearly cancel:
//! `õ(t − τ) − õ(t) ≈ −õ̇(t) (τ − T)` and `τ − T = O(f T/(R Ω))`, so the
//! equilibrium chip is `h̃ ≈ f_z sin φ + O(f_z f/(RΩ), f_z õ̇/(RΩ))`
//! whatever the size of the forced response: loss of contact in the
//! equilibrium happens only where `f_z sin φ` itself is small (near φ = 0
//! or π) unless the vibration velocity becomes a sizeable fraction of the
//! cutting speed RΩ. Measured (2 teeth, [0.75π, π], a_p 3 mm): a 25 Hz /
//! 50 kg tool tip at 2000-4000 rpm keeps full contact (min chip 0.01-0.02
//! f_z, at the last grid midpoint before φ = π); at the resonance speed
//! 750 rpm (forced amplitude 2-11 f_z) contact is lost over 2-14 % of the
//! engagement, always next to the exit. The fixed-point map is a strong
//! contraction: 4-6 iterations, up to ~20 at resonance. When the vibration
//! velocity reaches the cutting speed, eq. 3 loses its regular root
//! (`g_τ ≤ 0`) and [`Equilibrium::compute`] reports
//! [`ChatterError::NotConverged`] rather than following a spurious branch.
//!
//! Neglected: the shift of the entry/exit angle at a fixed workpiece wall
//! by the equilibrium's own y-vibration (relative size (ỹ − mean ỹ)/R,
//! below 1e-3 for the cases of seed 004); the linearization accounts for
//! the wall's effect on a perturbation ([`crate::linearize`]).

use std::f64::consts::PI;

use nalgebra::{Matrix2, Matrix4, Vector2, Vector4};

use crate::error::{check_non_negative, check_positive, ChatterError};
use crate::model::{force_direction, MillingProcess, Modal2};

/// Cutting-force law `F(h)`: the force of a tooth with chip h is
/// `a_p F(h) b(φ)` with `F(h) = h_ref (h / h_ref)^x_F` for h > 0, 0 else.
///
/// `x_F = 1` is the paper's linear law (seed 004 eq. 1 with the shear
/// coefficients of its Table 1) and `h_ref` then plays no role. `x_F < 1`
/// is the Kienzle-type power law (x_F ≈ 0.75 in Stépán 2001, Phil. Trans.
/// R. Soc. A 359:739, "Modelling nonlinear regenerative effects in metal
/// cutting"); K_t, K_n are then the coefficients at the chip `h_ref`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForceLaw {
    /// Exponent x_F, 0 < x_F ≤ 1 (default 1: linear).
    pub exponent: f64,
    /// Reference chip h_ref [m] at which K_t, K_n hold (default 1e-4 m).
    pub reference_chip: f64,
}

impl Default for ForceLaw {
    fn default() -> Self {
        Self {
            exponent: 1.0,
            reference_chip: 1e-4,
        }
    }
}

impl ForceLaw {
    /// Checks 0 < x_F ≤ 1 and h_ref > 0.
    ///
    /// # Errors
    /// [`ChatterError::InvalidParameter`].
    pub fn validate(&self) -> Result<(), ChatterError> {
        let x = check_positive("force exponent x_F [-]", self.exponent)?;
        if x > 1.0 {
            return Err(ChatterError::InvalidParameter {
                name: "force exponent x_F [-]".to_string(),
                value: x,
                reason: "must be in (0, 1]".to_string(),
            });
        }
        check_positive("reference chip thickness [m]", self.reference_chip)?;
        Ok(())
    }

    /// `F(h)` [m] (force per unit a_p and per unit coefficient).
    pub fn value(&self, h: f64) -> f64 {
        if h <= 0.0 {
            0.0
        } else if self.exponent == 1.0 {
            h
        } else {
            self.reference_chip * (h / self.reference_chip).powf(self.exponent)
        }
    }

    /// `F'(h) = x_F (h / h_ref)^(x_F − 1)` [-], the factor on the cutting
    /// stiffness of the linearized model; 1 for the linear law.
    pub fn slope(&self, h: f64) -> f64 {
        if self.exponent == 1.0 {
            1.0
        } else {
            self.exponent
                * (h.max(f64::MIN_POSITIVE) / self.reference_chip).powf(self.exponent - 1.0)
        }
    }
}

/// Numerical settings of [`Equilibrium::compute`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EquilibriumSettings {
    /// Grid nodes per tooth period (≥ 200; default 200).
    pub points_per_period: usize,
    /// Highest regeneration order m searched for the chip (1..=8; default 3).
    pub max_regeneration: usize,
    /// Relative change of the node positions that ends the fixed-point
    /// iteration (default 1e-10).
    pub tolerance: f64,
    /// Iteration cap of the fixed-point iteration (default 50).
    pub max_iterations: usize,
    /// Cutting-force law (default linear).
    pub force_law: ForceLaw,
}

impl Default for EquilibriumSettings {
    fn default() -> Self {
        Self {
            points_per_period: 200,
            max_regeneration: 3,
            tolerance: 1e-10,
            max_iterations: 50,
            force_law: ForceLaw::default(),
        }
    }
}

impl EquilibriumSettings {
    /// Checks every field.
    ///
    /// # Errors
    /// [`ChatterError::InvalidParameter`].
    pub fn validate(&self) -> Result<(), ChatterError> {
        let bad = ChatterError::invalid;
        if self.points_per_period < 200 {
            return Err(bad(
                "equilibrium grid points per period",
                self.points_per_period as f64,
                "must be >= 200",
            ));
        }
        if self.points_per_period > 1_000_000 {
            return Err(bad(
                "equilibrium grid points per period",
                self.points_per_period as f64,
                "must be <= 1e6",
            ));
        }
        if !(1..=8).contains(&self.max_regeneration) {
            return Err(bad(
                "maximum regeneration order",
                self.max_regeneration as f64,
                "must be in 1..=8",
            ));
        }
        check_positive("equilibrium tolerance [-]", self.tolerance)?;
        if self.max_iterations == 0 {
            return Err(bad("equilibrium iteration cap", 0.0, "must be >= 1"));
        }
        self.force_law.validate()
    }
}

/// The state of one tooth's cut at one instant of the equilibrium.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChipState {
    /// Immersion angle φ_j(t) [rad], reduced to [0, 2π).
    pub phi: f64,
    /// Chip thickness h̃ = min_m h^m [m] (≤ 0: loss of contact).
    pub chip: f64,
    /// The regeneration order m that gives the minimum.
    pub order: usize,
    /// Delay τ_j^m of that order [s].
    pub delay: f64,
    /// ∂g/∂τ of eq. 3 at that delay [m/s] (module documentation).
    pub g_tau: f64,
    /// ∂h/∂τ of eq. 4 at that delay [m/s].
    pub h_tau: f64,
    /// Whether the tooth cuts (inside the engagement and h̃ > 0, or the
    /// zero-feed limit, see [`Equilibrium::chip_state`]).
    pub in_contact: bool,
}

/// Eq. 3 residual, its partial derivatives, and the eq. 4 chip.
#[derive(Debug, Clone, Copy)]
struct Geometry {
    g: f64,
    h: f64,
    g_tau: f64,
    h_tau: f64,
    g_t: f64,
}

/// One RK4 track of the order-1 delay of one tooth over one cut segment.
#[derive(Debug, Clone)]
struct DelayTrack {
    tooth: usize,
    /// Index of the first node of the track.
    first: usize,
    tau: Vec<f64>,
    taudot: Vec<f64>,
}

/// The T-periodic equilibrium õ(t) (seed 004 eq. 1 with eq. 3-4) and the
/// delays and chips along it. Built by [`Equilibrium::compute`].
#[derive(Debug, Clone)]
pub struct Equilibrium {
    process: MillingProcess,
    feed: f64,
    omega: f64,
    period: f64,
    settings: EquilibriumSettings,
    /// Node times 0 = t_0 < … < t_K = T.
    times: Vec<f64>,
    /// Entry/exit breakpoints (0 and T included), nodes fall on them.
    breakpoints: Vec<f64>,
    pos: Vec<Vector2<f64>>,
    vel: Vec<Vector2<f64>>,
    /// Acceleration at the start / end of each step (one-sided at jumps).
    acc_start: Vec<Vector2<f64>>,
    acc_end: Vec<Vector2<f64>>,
    tracks: Vec<DelayTrack>,
    iterations: usize,
    residual: f64,
}

/// Step of node `k` of a trajectory and the local parameter, for `t` in [0, T).
fn locate(times: &[f64], t: f64) -> usize {
    let n = times.len().saturating_sub(1).max(1);
    match times.binary_search_by(|x| x.total_cmp(&t)) {
        Ok(k) => k.min(n - 1),
        Err(k) => k.saturating_sub(1).min(n - 1),
    }
}

/// [`locate`] for a grid close to uniform: starts at the proportional
/// index and walks (the same index as the binary search for a finite t
/// and strictly increasing times).
fn locate_guess(times: &[f64], t: f64) -> usize {
    let len = times.len();
    if len < 3 || !t.is_finite() {
        return locate(times, t);
    }
    let n = len - 1;
    let (first, last) = (times[0], times[n]);
    let x = (t - first) / (last - first) * n as f64;
    let mut k = if x > 0.0 { (x as usize).min(n) } else { 0 };
    while k > 0 && times[k] > t {
        k -= 1;
    }
    while k < n && times[k + 1] <= t {
        k += 1;
    }
    k.min(n - 1)
}

fn hermite(
    s: f64,
    h: f64,
    p0: Vector2<f64>,
    v0: Vector2<f64>,
    p1: Vector2<f64>,
    v1: Vector2<f64>,
) -> Vector2<f64> {
    let s2 = s * s;
    let s3 = s2 * s;
    p0 * (2.0 * s3 - 3.0 * s2 + 1.0)
        + v0 * (h * (s3 - 2.0 * s2 + s))
        + p1 * (-2.0 * s3 + 3.0 * s2)
        + v1 * (h * (s3 - s2))
}

fn hermite1(s: f64, h: f64, p0: f64, v0: f64, p1: f64, v1: f64) -> f64 {
    let s2 = s * s;
    let s3 = s2 * s;
    p0 * (2.0 * s3 - 3.0 * s2 + 1.0)
        + v0 * (h * (s3 - 2.0 * s2 + s))
        + p1 * (-2.0 * s3 + 3.0 * s2)
        + v1 * (h * (s3 - s2))
}

/// Sorted entry/exit times of all teeth in [0, T), with 0 and T.
fn engagement_breakpoints(process: &MillingProcess, omega: f64, period: f64) -> Vec<f64> {
    let nt = process.teeth as f64;
    let mut pts = vec![0.0, period];
    for j in 0..process.teeth {
        let phase = 2.0 * PI * j as f64 / nt;
        for phib in [process.entry_angle, process.exit_angle] {
            // φ_j(t) = Ω t + phase ≡ φ_b (mod 2π)
            let t = ((phib - phase).rem_euclid(2.0 * PI)) / omega;
            // one period covers 2π/N_t of angle: at most one solution in [0, T)
            if t < period {
                pts.push(t);
            }
        }
    }
    pts.sort_by(|a, b| a.total_cmp(b));
    let tol = 1e-9 * period;
    let mut out: Vec<f64> = Vec::with_capacity(pts.len());
    for p in pts {
        if out.last().is_none_or(|&q| p - q > tol) {
            out.push(p);
        } else if (p - period).abs() <= tol {
            if let Some(last) = out.last_mut() {
                *last = period;
            }
        }
    }
    out
}

/// Whether angle φ (any real) lies in the engagement [φ_en, φ_ex] (mod 2π).
pub(crate) fn engaged(process: &MillingProcess, phi: f64) -> bool {
    let p = phi.rem_euclid(2.0 * PI);
    p >= process.entry_angle && p <= process.exit_angle
}

/// Trajectory view used while iterating (positions at nodes etc.).
struct Traj<'a> {
    times: &'a [f64],
    pos: &'a [Vector2<f64>],
    vel: &'a [Vector2<f64>],
    acc_start: &'a [Vector2<f64>],
    acc_end: &'a [Vector2<f64>],
    period: f64,
}

impl Traj<'_> {
    fn state(&self, t: f64) -> (Vector2<f64>, Vector2<f64>) {
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
}

/// The tooth angle's sine, cosine and the state (position, velocity) at
/// one time: shared by every delay and order evaluated at that time.
struct Here {
    s: f64,
    c: f64,
    p: Vector2<f64>,
    v: Vector2<f64>,
}

struct Ctx<'a> {
    process: &'a MillingProcess,
    feed: f64,
    omega: f64,
    period: f64,
}

impl Ctx<'_> {
    fn phi(&self, tooth: usize, t: f64) -> f64 {
        self.omega * t + 2.0 * PI * tooth as f64 / self.process.teeth as f64
    }

    /// The tooth angle's sine and cosine and the state at time t.
    fn here(&self, traj: &Traj, tooth: usize, t: f64) -> Here {
        let (s, c) = self.phi(tooth, t).sin_cos();
        let (p, v) = traj.state(t);
        Here { s, c, p, v }
    }

    /// Eq. 3 residual, eq. 4 chip and their partial derivatives (module doc).
    fn geometry(&self, traj: &Traj, tooth: usize, order: usize, t: f64, tau: f64) -> Geometry {
        let here = self.here(traj, tooth, t);
        self.geometry_at(traj, &here, order, t, tau)
    }

    /// [`Ctx::geometry`] with the quantities at t precomputed.
    fn geometry_at(&self, traj: &Traj, here: &Here, order: usize, t: f64, tau: f64) -> Geometry {
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
    fn newton(
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
    fn newton_at(
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

    fn taudot_at(&self, traj: &Traj, here: &Here, t: f64, tau: f64) -> f64 {
        let geo = self.geometry_at(traj, here, 1, t, tau);
        -geo.g_t / geo.g_tau
    }
}

/// Linear 4×4 first-order system matrix of `M ö + C ȯ + K o = F`.
fn system_matrix(minv: &Matrix2<f64>, modal: &Modal2) -> Matrix4<f64> {
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

fn lift(minv: &Matrix2<f64>, f: &Vector2<f64>) -> Vector4<f64> {
    let a = minv * f;
    Vector4::new(0.0, 0.0, a.x, a.y)
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
    /// About 0.8 ms (dev profile, opt-level 1) for 200 nodes and 4
    /// iterations (2 teeth, quarter-turn engagement, 3 regeneration orders).
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

        let minv = modal.mass_inverse()?;
        let a = system_matrix(&minv, modal);
        // Monodromy of the RK4 map of the homogeneous system.
        let mut phi_t = Matrix4::<f64>::identity();
        for k in 0..nsteps {
            let h = times[k + 1] - times[k];
            let ah = a * h;
            let ah2 = ah * ah;
            let p = Matrix4::identity() + ah + ah2 * 0.5 + ah2 * ah / 6.0 + ah2 * ah2 / 24.0;
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
            };
            tracks = build_tracks(&ctx, &traj, &times, &engaged_steps)?;
            // Forces at step start, midpoint, end.
            // Force of the teeth engaged on the step (the step's engaged set
            // decides, so a jump sitting on a node gets its one-sided value);
            // the end force of a step is the start force of the next unless
            // the engaged set changes there.
            let force_at = |teeth: &[usize], t: f64| -> Result<Vector2<f64>, ChatterError> {
                let mut f = zero;
                for &j in teeth {
                    let cs = chip_at(&ctx, &traj, &tracks, settings, &times, j, t)?;
                    if cs.chip > 0.0 {
                        f += force_direction(cs.phi, process.kt, process.kn)
                            * (process.axial_depth * settings.force_law.value(cs.chip));
                    }
                }
                Ok(f)
            };
            let mut forces: Vec<[Vector2<f64>; 3]> = Vec::with_capacity(nsteps);
            for (k, teeth) in engaged_steps.iter().enumerate() {
                let tm = 0.5 * (times[k] + times[k + 1]);
                let fa = match (k.checked_sub(1), forces.last()) {
                    (Some(prev), Some(last)) if engaged_steps[prev] == *teeth => last[2],
                    _ => force_at(teeth, times[k])?,
                };
                forces.push([fa, force_at(teeth, tm)?, force_at(teeth, times[k + 1])?]);
            }
            // Shooting: particular solution from z = 0, then periodicity.
            let step = |z: Vector4<f64>, k: usize, f: &[Vector2<f64>; 3]| {
                let h = times[k + 1] - times[k];
                let (ga, gm, gb) = (lift(&minv, &f[0]), lift(&minv, &f[1]), lift(&minv, &f[2]));
                let k1 = a * z + ga;
                let k2 = a * (z + k1 * (0.5 * h)) + gm;
                let k3 = a * (z + k2 * (0.5 * h)) + gm;
                let k4 = a * (z + k3 * h) + gb;
                z + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0)
            };
            let mut z = Vector4::zeros();
            for (k, f) in forces.iter().enumerate() {
                z = step(z, k, f);
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
                z = step(z, k, f);
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
                let traj = Traj {
                    times: &times,
                    pos: &pos,
                    vel: &vel,
                    acc_start: &acc_start,
                    acc_end: &acc_end,
                    period,
                };
                tracks = build_tracks(&ctx, &traj, &times, &engaged_steps)?;
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

    fn traj(&self) -> Traj<'_> {
        Traj {
            times: &self.times,
            pos: &self.pos,
            vel: &self.vel,
            acc_start: &self.acc_start,
            acc_end: &self.acc_end,
            period: self.period,
        }
    }

    fn ctx(&self) -> Ctx<'_> {
        Ctx {
            process: &self.process,
            feed: self.feed,
            omega: self.omega,
            period: self.period,
        }
    }

    /// Tooth period T [s].
    pub fn period(&self) -> f64 {
        self.period
    }

    /// Spindle speed Ω [rad/s].
    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// Feed speed f [m/s].
    pub fn feed(&self) -> f64 {
        self.feed
    }

    /// Feed per tooth f_z = f T [m].
    pub fn feed_per_tooth(&self) -> f64 {
        self.feed * self.period
    }

    /// The milling process.
    pub fn process(&self) -> &MillingProcess {
        &self.process
    }

    /// The settings used.
    pub fn settings(&self) -> &EquilibriumSettings {
        &self.settings
    }

    /// Fixed-point iterations used.
    pub fn iterations(&self) -> usize {
        self.iterations
    }

    /// Final relative change of the node positions.
    pub fn residual(&self) -> f64 {
        self.residual
    }

    /// Node times 0 = t_0 < … < t_K = T [s].
    pub fn node_times(&self) -> &[f64] {
        &self.times
    }

    /// Entry/exit times of all teeth in [0, T] (0 and T included) [s].
    pub fn breakpoints(&self) -> &[f64] {
        &self.breakpoints
    }

    /// Immersion angle φ_j(t) = Ω t + 2π j / N_t [rad] (not reduced).
    pub fn angle(&self, tooth: usize, t: f64) -> f64 {
        self.ctx().phi(tooth, t)
    }

    /// Equilibrium displacement õ(t) [m] (T-periodic, cubic Hermite
    /// interpolation between nodes).
    pub fn position(&self, t: f64) -> Vector2<f64> {
        self.traj().state(t).0
    }

    /// Equilibrium velocity õ̇(t) [m/s].
    pub fn velocity(&self, t: f64) -> Vector2<f64> {
        self.traj().state(t).1
    }

    /// Largest deviation of õ from its mean over the nodes [m] (the forced
    /// vibration amplitude; the mean is the static deflection).
    pub fn forced_amplitude(&self) -> f64 {
        let k = self.pos.len().saturating_sub(1).max(1);
        let mean = self.pos.iter().take(k).sum::<Vector2<f64>>() / k as f64;
        self.pos
            .iter()
            .map(|p| (p - mean).norm())
            .fold(0.0, f64::max)
    }

    /// The eq. 3 residual g(τ, t) [m] of tooth j, order m, at a given delay
    /// τ (for checks).
    pub fn eq3_residual(&self, tooth: usize, order: usize, t: f64, tau: f64) -> f64 {
        self.ctx().geometry(&self.traj(), tooth, order, t, tau).g
    }

    /// The order-1 delay τ_j(t) from the RK4 integration of eq. 6 (Hermite
    /// interpolation between nodes), or `None` where tooth j is outside the
    /// engagement (no track there).
    pub fn delay_rk4(&self, tooth: usize, t: f64) -> Option<f64> {
        track_delay(&self.tracks, &self.times, self.period, tooth, t)
    }

    /// The delay τ_j^m(t) solving eq. 3 by Newton's method, started at
    /// `m T`.
    ///
    /// # Errors
    /// [`ChatterError::NotConverged`] / [`ChatterError::NonFinite`].
    pub fn solve_delay(&self, tooth: usize, order: usize, t: f64) -> Result<f64, ChatterError> {
        if order == 0 || tooth >= self.process.teeth {
            return Err(ChatterError::InvalidParameter {
                name: "tooth / regeneration order".to_string(),
                value: order as f64,
                reason: format!("need order >= 1 and tooth < {}", self.process.teeth),
            });
        }
        self.ctx()
            .newton(&self.traj(), tooth, order, t, order as f64 * self.period)
    }

    /// Delay τ_j^m (Newton on eq. 3) and chip h_j^m (eq. 4) [s, m] of one
    /// regeneration order m: the surface left by the tooth m positions
    /// earlier (seed 004 Fig. 1b).
    ///
    /// # Errors
    /// As [`Equilibrium::solve_delay`].
    pub fn chip_of_order(
        &self,
        tooth: usize,
        order: usize,
        t: f64,
    ) -> Result<(f64, f64), ChatterError> {
        let tau = self.solve_delay(tooth, order, t)?;
        let geo = self.ctx().geometry(&self.traj(), tooth, order, t, tau);
        Ok((tau, geo.h))
    }

    /// The cut of tooth j at time t (module documentation): order-1 delay
    /// from the RK4 track, higher orders by Newton, chip = minimum.
    /// Outside the nominal engagement `in_contact` is false. At zero feed
    /// the chip is identically zero; the state is then the limit f → 0⁺
    /// (in contact over the whole engagement).
    ///
    /// # Errors
    /// As [`Equilibrium::solve_delay`].
    pub fn chip_state(&self, tooth: usize, t: f64) -> Result<ChipState, ChatterError> {
        if tooth >= self.process.teeth {
            return Err(ChatterError::InvalidParameter {
                name: "tooth index".to_string(),
                value: tooth as f64,
                reason: format!("must be < {}", self.process.teeth),
            });
        }
        chip_at(
            &self.ctx(),
            &self.traj(),
            &self.tracks,
            &self.settings,
            &self.times,
            tooth,
            t,
        )
    }
}

/// Summary of an [`Equilibrium`] over the nominal engagement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EquilibriumDiagnostics {
    /// Smallest equilibrium chip h̃ over the engagement [m] (≤ 0: loss of
    /// contact somewhere).
    pub min_chip: f64,
    /// Fraction of the nominal engagement time with h̃ > 0 [-] (sampled at
    /// the grid-step midpoints, so resolved to about 1/(engaged steps)).
    pub contact_fraction: f64,
    /// max |τ_j(t) − m T| / T over the engagement (order m of the cut) [-].
    pub max_delay_deviation: f64,
    /// Forced-vibration amplitude max |õ − mean õ| [m].
    pub forced_amplitude: f64,
    /// Highest regeneration order that gives the chip somewhere.
    pub max_order: usize,
}

impl Equilibrium {
    /// Evaluates [`EquilibriumDiagnostics`] at the midpoints of the grid
    /// steps (weighted by step length).
    ///
    /// # Errors
    /// As [`Equilibrium::chip_state`].
    pub fn diagnostics(&self) -> Result<EquilibriumDiagnostics, ChatterError> {
        let mut min_chip = f64::INFINITY;
        let mut engaged_time = 0.0;
        let mut contact_time = 0.0;
        let mut dev: f64 = 0.0;
        let mut max_order = 0;
        for w in self.times.windows(2) {
            let tm = 0.5 * (w[0] + w[1]);
            let h = w[1] - w[0];
            for j in 0..self.process.teeth {
                if !engaged(&self.process, self.angle(j, tm)) {
                    continue;
                }
                let cs = self.chip_state(j, tm)?;
                engaged_time += h;
                min_chip = min_chip.min(cs.chip);
                dev = dev.max((cs.delay - cs.order as f64 * self.period).abs() / self.period);
                if cs.in_contact {
                    contact_time += h;
                    max_order = max_order.max(cs.order);
                }
            }
        }
        Ok(EquilibriumDiagnostics {
            min_chip: if min_chip.is_finite() { min_chip } else { 0.0 },
            contact_fraction: if engaged_time > 0.0 {
                contact_time / engaged_time
            } else {
                0.0
            },
            max_delay_deviation: dev,
            forced_amplitude: self.forced_amplitude(),
            max_order,
        })
    }
}

fn track_delay(
    tracks: &[DelayTrack],
    times: &[f64],
    period: f64,
    tooth: usize,
    t: f64,
) -> Option<f64> {
    let tt = t.rem_euclid(period);
    for tr in tracks.iter().filter(|tr| tr.tooth == tooth) {
        let last = tr.first + tr.tau.len() - 1;
        if tt >= times[tr.first] && tt <= times[last] {
            let k = locate(&times[tr.first..=last], tt);
            let (t0, t1) = (times[tr.first + k], times[tr.first + k + 1]);
            let h = t1 - t0;
            let s = ((tt - t0) / h).clamp(0.0, 1.0);
            return Some(hermite1(
                s,
                h,
                tr.tau[k],
                tr.taudot[k],
                tr.tau[k + 1],
                tr.taudot[k + 1],
            ));
        }
    }
    None
}

/// Order-1 delay tracks: Newton at the start of every maximal run of steps
/// in which a tooth is engaged, then RK4 on eq. 6 node by node.
fn build_tracks(
    ctx: &Ctx,
    traj: &Traj,
    times: &[f64],
    engaged_steps: &[Vec<usize>],
) -> Result<Vec<DelayTrack>, ChatterError> {
    let mut tracks = Vec::new();
    for j in 0..ctx.process.teeth {
        let mut k = 0;
        while k < engaged_steps.len() {
            if !engaged_steps[k].contains(&j) {
                k += 1;
                continue;
            }
            let first = k;
            let mut end = k;
            while end < engaged_steps.len() && engaged_steps[end].contains(&j) {
                end += 1;
            }
            let t0 = times[first];
            let here0 = ctx.here(traj, j, t0);
            let mut tau = ctx.newton_at(traj, &here0, j, 1, t0, ctx.period)?;
            let mut taus = vec![tau];
            let mut dots = vec![ctx.taudot_at(traj, &here0, t0, tau)];
            for s in first..end {
                let (ta, tb) = (times[s], times[s + 1]);
                let h = tb - ta;
                let k1 = dots[dots.len() - 1];
                let tm = ta + 0.5 * h;
                let mid = ctx.here(traj, j, tm);
                let k2 = ctx.taudot_at(traj, &mid, tm, tau + 0.5 * h * k1);
                let k3 = ctx.taudot_at(traj, &mid, tm, tau + 0.5 * h * k2);
                let end_here = ctx.here(traj, j, tb);
                let k4 = ctx.taudot_at(traj, &end_here, tb, tau + h * k3);
                tau += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
                if !tau.is_finite() {
                    return Err(ChatterError::NonFinite {
                        what: format!("RK4 delay integration (eq. 6), tooth {j}"),
                    });
                }
                taus.push(tau);
                dots.push(ctx.taudot_at(traj, &end_here, tb, tau));
            }
            tracks.push(DelayTrack {
                tooth: j,
                first,
                tau: taus,
                taudot: dots,
            });
            k = end;
        }
    }
    Ok(tracks)
}

fn chip_at(
    ctx: &Ctx,
    traj: &Traj,
    tracks: &[DelayTrack],
    settings: &EquilibriumSettings,
    times: &[f64],
    tooth: usize,
    t: f64,
) -> Result<ChipState, ChatterError> {
    let phi = ctx.phi(tooth, t);
    let here = ctx.here(traj, tooth, t);
    let tau1 = match track_delay(tracks, times, ctx.period, tooth, t) {
        Some(tau) => tau,
        None => ctx.newton_at(traj, &here, tooth, 1, t, ctx.period)?,
    };
    let mut best = (ctx.geometry_at(traj, &here, 1, t, tau1), 1usize, tau1);
    for order in 2..=settings.max_regeneration {
        // no-vibration scaling: τ^m − mT ≈ m (τ^1 − T), i.e. τ^m ≈ m τ^1
        let guess = order as f64 * tau1;
        let tau = ctx.newton_at(traj, &here, tooth, order, t, guess)?;
        let geo = ctx.geometry_at(traj, &here, order, t, tau);
        if geo.h < best.0.h {
            best = (geo, order, tau);
        }
    }
    let (geo, order, delay) = best;
    if !geo.h.is_finite() {
        return Err(ChatterError::NonFinite {
            what: format!("chip thickness (eq. 4), tooth {tooth}"),
        });
    }
    let inside = engaged(ctx.process, phi);
    Ok(ChipState {
        phi: phi.rem_euclid(2.0 * PI),
        chip: geo.h,
        order,
        delay,
        g_tau: geo.g_tau,
        h_tau: geo.h_tau,
        in_contact: inside && (geo.h > 0.0 || ctx.feed == 0.0),
    })
}
