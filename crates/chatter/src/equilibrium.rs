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

use nalgebra::Vector2;

use crate::error::ChatterError;
use crate::model::MillingProcess;

mod compute;
mod diagnostics;
mod engagement;
mod geometry;
mod interp;
mod settings;
mod tracks;

pub use diagnostics::EquilibriumDiagnostics;
pub(crate) use engagement::engaged;
pub use settings::{EquilibriumSettings, ForceLaw};

use tracks::{chip_at, track_delay};

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
    /// Eq. 3-4 geometry at each node with its delay.
    geometry: Vec<Geometry>,
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
    /// Bounds of the interpolated position (order skipping in `chip_at`).
    bounds: geometry::TrajBounds,
    tracks: Vec<DelayTrack>,
    iterations: usize,
    residual: f64,
}

impl Equilibrium {
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
    /// from the RK4 track, higher orders by Newton, chip = minimum. An order
    /// whose chip provably exceeds the smallest found so far (a lower bound
    /// from eq. 3-4 and the trajectory's Lipschitz bound, `tracks.rs`) is
    /// not solved: the result is the same, bit for bit; only a Newton
    /// failure of such an order is no longer reported.
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
