//! The variational system (seed 004 eq. 8) of the state-dependent milling
//! model about its periodic equilibrium õ ([`crate::equilibrium`]), sampled
//! as a [`PeriodicDde`] so that the same discretization as the
//! constant-delay model gives its monodromy matrix.
//!
//! # Derivation (seed 004 eq. 3, 4 → eq. 8)
//!
//! Perturb `o = õ + p`. For tooth j cutting the surface of order m, eq. 3
//! `g(τ, o) = R sin δ + Δc_x cos φ − Δc_y sin φ = 0` with
//! `Δc = (f τ + x(t−τ) − x(t), y(t−τ) − y(t))` fixes the delay and eq. 4
//! `h(τ, o) = R (1 − cos δ) + Δc_x sin φ + Δc_y cos φ` the chip. Their
//! first variations, with `Δp := p(t − τ̃) − p(t)` (the variation of Δc at
//! fixed τ) and the delay variation Δτ (which moves the delayed point along
//! the equilibrium: `∂/∂τ õ(t − τ) = −õ̇(t − τ)`), are
//!
//! `δg = g_τ Δτ + w·Δp = 0`, `w(φ) = (cos φ, −sin φ)`,
//! `δh = h_τ Δτ + c·Δp`,     `c(φ) = (sin φ, cos φ)` ([`crate::chip_direction`]),
//!
//! with (derived in [`crate::equilibrium`], checked against
//! [`crate::trochoid`]: differentiate `tangential_residual` and
//! `chip_thickness` in τ)
//!
//! `g_τ = R Ω cos δ + (f − ẋ̃(t−τ)) cos φ + ẏ̃(t−τ) sin φ`,
//! `h_τ = R Ω sin δ + (f − ẋ̃(t−τ)) sin φ − ẏ̃(t−τ) cos φ`.
//!
//! Eliminating `Δτ = −w·Δp / g_τ`:
//!
//! `δh = (c − κ w)·(p(t − τ̃) − p(t))`, `κ = h_τ / g_τ`.
//!
//! The force `a_p F(h) b(φ)` ([`crate::equilibrium::ForceLaw`]) varies by
//! `a_p F'(h̃) b δh`, so
//!
//! `M p̈ + C ṗ + K p = Σ_j W_j(t) (p(t − τ̃_j(t)) − p(t))`,
//! `W_j = a_p F'(h̃_j) b(φ_j) (c(φ_j) − κ_j w(φ_j))ᵀ`
//!
//! — seed 004 eq. 8 (its sign convention `W (Δo(t) − Δo(t − τ))` has
//! `W_paper = −W_j`). A tooth out of contact in the equilibrium (outside the
//! engagement or h̃ ≤ 0) contributes nothing; τ̃_j is the delay of the order
//! that gives the chip (multiple regeneration). With f → 0 and no forced
//! response: κ = R Ω sin δ / (R Ω cos δ) → 0, τ̃ → T, F' = 1, and W_j →
//! `a_p b cᵀ`, the constant-delay model ([`crate::model`] documentation).
//!
//! For the cases of seed 004, κ ≈ δ + f sin φ/(RΩ) = O(f/(RΩ)) ≈ 1e-3…2e-2
//! (measured 0.021-0.023 over the cut at 2000 rpm, 0.06 m/s) and
//! τ̃ − T = O(f T/(RΩ)): with the linear force law the state-dependent
//! corrections of the gains and delays are of that relative size. The
//! first-order chip variation is checked against central finite
//! differences of the exact eq. 3-4 geometry in `tests/state_dependent.rs`
//! (agreement 2e-8 relative, the κ term being ~1e-2).
//!
//! # The workpiece wall (entry/exit term)
//!
//! Where a tooth enters (or leaves) the cut at an angle φ_b strictly inside
//! (0, π) — the entry of down milling with φ_en > 0, the exit of up milling
//! with φ_ex < π — the boundary is the workpiece's free edge, a line y =
//! const fixed in the workpiece and not regenerated. The tooth tip crosses
//! it when `ỹ + p_y − R cos φ = const`, so a perturbation shifts the
//! crossing by `Δφ = −p_y / (R sin φ_b)`, i.e. `Δt = −p_y / (R Ω sin φ_b)`.
//! The force jumps there by `F_b = a_p F(h̃_b) b(φ_b)` (for down milling at
//! φ_en = 0.75π the chip at entry is `f_z sin φ_en ≠ 0`), so the momentum
//! change per pass is `s F_b p_y / (R Ω sin φ_b)` (s = +1 entry: earlier
//! entry, more cutting; s = −1 exit). This is a force impulse on the
//! present displacement only:
//!
//! `−A_wall p = s F_b e_yᵀ p / (R Ω sin φ_b) · δ(t − t_b)`,
//!
//! included (when [`LinearizeSettings::wall_term`] is set, the default) as
//! a present-only gain averaged over the sub-interval that contains t_b.
//! Its size relative to the regenerative gains is O(f_z / R) per pass; it
//! vanishes as f → 0, and at φ_b = 0 or π the chip is zero so there is
//! no jump (not added). Checked against the independent nonlinear
//! time-domain simulation ([`crate::timedomain`]): its growth factor with a
//! moving wall matches |μ| computed with this term, its fixed-window
//! variant matches |μ| without it (`tests/feed_effect.rs`,
//! `tests/time_domain.rs`); e.g. robot mode 80 Hz / 6 kg, 2800 rpm,
//! 0.06 m/s: factor 0.9911 vs |μ| 0.9957 with the wall, 1.0092 vs 1.0137
//! without.
//!
//! # Sampling (the [`PeriodicDde`] convention)
//!
//! On sub-interval i of `[i T/m, (i+1) T/m)` the gains are averaged by
//! 5-point Gauss–Legendre quadrature on each piece between engagement
//! breakpoints (exact cut boundaries) and loss-of-contact switches of the
//! equilibrium (located by bisection); one delayed term per (tooth, order)
//! with a nonzero gain, its delay taken at the sub-interval midpoint (Newton
//! on eq. 3 there). A switch of the regeneration order that gives the chip
//! (multiple regeneration) inside a sub-interval is not located; it is
//! resolved only to the quadrature points (it did not occur in any case of
//! seed 004 that we ran: the order-1 surface always gave the chip).

use std::collections::BTreeMap;

use nalgebra::{Matrix2, Vector2};

use crate::equilibrium::{engaged, Equilibrium};
use crate::error::ChatterError;
use crate::model::{chip_direction, force_direction, DdeSample, DelayTerm, PeriodicDde};

/// Options of [`linearize`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearizeSettings {
    /// Number of sub-intervals m of the period (≥ 2).
    pub steps: usize,
    /// Include the workpiece-wall entry/exit term (module documentation;
    /// default true).
    pub wall_term: bool,
}

impl Default for LinearizeSettings {
    fn default() -> Self {
        Self {
            steps: 40,
            wall_term: true,
        }
    }
}

const GL_X: [f64; 5] = [
    -0.906_179_845_938_664,
    -0.538_469_310_105_683_1,
    0.0,
    0.538_469_310_105_683_1,
    0.906_179_845_938_664,
];
const GL_W: [f64; 5] = [
    0.236_926_885_056_189_1,
    0.478_628_670_499_366_5,
    0.568_888_888_888_888_9,
    0.478_628_670_499_366_5,
    0.236_926_885_056_189_1,
];

/// First-order chip sensitivity of tooth j at time t (module
/// documentation): `δh = direction · (p(t − delay) − p(t))`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChipSensitivity {
    /// `c(φ) − κ w(φ)` [-].
    pub direction: Vector2<f64>,
    /// κ = h_τ / g_τ [-].
    pub kappa: f64,
    /// The delay τ̃ of the cut's regeneration order [s].
    pub delay: f64,
    /// That order m.
    pub order: usize,
    /// Equilibrium chip h̃ [m].
    pub chip: f64,
    /// Immersion angle φ [rad] in [0, 2π).
    pub phi: f64,
}

/// [`ChipSensitivity`] of tooth j at time t, or `None` when the tooth does
/// not cut there in the equilibrium.
///
/// # Errors
/// As [`Equilibrium::chip_state`].
pub fn chip_sensitivity(
    eq: &Equilibrium,
    tooth: usize,
    t: f64,
) -> Result<Option<ChipSensitivity>, ChatterError> {
    let cs = eq.chip_state(tooth, t)?;
    if !cs.in_contact {
        return Ok(None);
    }
    let kappa = cs.h_tau / cs.g_tau;
    let w = Vector2::new(cs.phi.cos(), -cs.phi.sin());
    Ok(Some(ChipSensitivity {
        direction: chip_direction(cs.phi) - w * kappa,
        kappa,
        delay: cs.delay,
        order: cs.order,
        chip: cs.chip,
        phi: cs.phi,
    }))
}

/// The gain `W_j(t) = a_p F'(h̃) b (c − κ w)ᵀ` [N/m] (module documentation)
/// of tooth j at time t, with the order of its regeneration, or `None`
/// when the tooth does not cut.
///
/// # Errors
/// As [`Equilibrium::chip_state`].
pub fn tooth_gain(
    eq: &Equilibrium,
    tooth: usize,
    t: f64,
) -> Result<Option<(Matrix2<f64>, usize)>, ChatterError> {
    let Some(sens) = chip_sensitivity(eq, tooth, t)? else {
        return Ok(None);
    };
    let p = eq.process();
    let slope = eq.settings().force_law.slope(sens.chip);
    let b = force_direction(sens.phi, p.kt, p.kn) * (p.axial_depth * slope);
    Ok(Some((b * sens.direction.transpose(), sens.order)))
}

/// Linearizes the state-dependent model about `eq` (seed 004 eq. 8) and
/// samples it on `settings.steps` sub-intervals.
///
/// # Arguments
/// * `eq` — the periodic equilibrium
/// * `settings` — m and the wall term
///
/// # Returns
/// The [`PeriodicDde`] `M p̈ + C ṗ + K p = −A p(t) + Σ B_k p(t − τ_k)`.
///
/// # Errors
/// [`ChatterError::InvalidParameter`] for m < 2 or m > 100 000; errors of
/// the delay computation ([`Equilibrium::chip_state`]); [`ChatterError::NonFinite`].
pub fn linearize(
    eq: &Equilibrium,
    settings: &LinearizeSettings,
) -> Result<PeriodicDde, ChatterError> {
    let m = settings.steps;
    if !(2..=100_000).contains(&m) {
        return Err(ChatterError::InvalidParameter {
            name: "number of sub-intervals m".to_string(),
            value: m as f64,
            reason: "must be in 2..=100000".to_string(),
        });
    }
    let period = eq.period();
    let dt = period / m as f64;
    let process = *eq.process();
    let bps = eq.breakpoints();
    let mut samples = Vec::with_capacity(m);
    for i in 0..m {
        let (a, b) = (i as f64 * dt, (i + 1) as f64 * dt);
        // Pieces between breakpoints inside [a, b].
        let mut cuts = vec![a];
        cuts.extend(bps.iter().copied().filter(|&t| t > a && t < b));
        cuts.push(b);
        let mut present = Matrix2::zeros();
        let mut groups: BTreeMap<(usize, usize), Matrix2<f64>> = BTreeMap::new();
        for w in cuts.windows(2) {
            let (pa, pb) = (w[0], w[1]);
            let mid = 0.5 * (pa + pb);
            for j in 0..process.teeth {
                if !engaged(&process, eq.angle(j, mid)) {
                    continue;
                }
                for (ca, cb) in contact_pieces(eq, j, pa, pb)? {
                    let half = 0.5 * (cb - ca);
                    let mid = 0.5 * (ca + cb);
                    for (x, wq) in GL_X.iter().zip(GL_W) {
                        let t = mid + half * x;
                        if let Some((gain, order)) = tooth_gain(eq, j, t)? {
                            let g = gain * (wq * half / dt);
                            present += g;
                            *groups.entry((j, order)).or_insert_with(Matrix2::zeros) += g;
                        }
                    }
                }
            }
        }
        let tmid = 0.5 * (a + b);
        let mut delayed = Vec::with_capacity(groups.len());
        for ((j, order), gain) in groups {
            let delay = eq.solve_delay(j, order, tmid)?;
            delayed.push(DelayTerm { gain, delay });
        }
        samples.push(DdeSample { present, delayed });
    }
    if settings.wall_term {
        add_wall_terms(eq, &mut samples, dt)?;
    }
    let dde = PeriodicDde { period, samples };
    dde.validate()?;
    Ok(dde)
}

/// Sub-intervals of `[pa, pb]` (inside the engagement of tooth j) where
/// the tooth is in contact in the equilibrium: the contact state is
/// sampled at 9 points and every change is located by bisection (50
/// steps), so that a loss-of-contact window changes the gains continuously
/// with the parameters instead of by quadrature-point jumps (the
/// linearized gain does not vanish at h̃ = 0⁺: W ∝ b cᵀ).
fn contact_pieces(
    eq: &Equilibrium,
    tooth: usize,
    pa: f64,
    pb: f64,
) -> Result<Vec<(f64, f64)>, ChatterError> {
    const SAMPLES: usize = 8;
    let inset = 1e-9 * (pb - pa);
    let at = |i: usize| {
        let t = pa + (pb - pa) * i as f64 / SAMPLES as f64;
        t.clamp(pa + inset, pb - inset)
    };
    let contact =
        |t: f64| -> Result<bool, ChatterError> { Ok(eq.chip_state(tooth, t)?.in_contact) };
    let mut pieces = Vec::new();
    let mut start = if contact(at(0))? { Some(pa) } else { None };
    let mut prev_t = at(0);
    let mut prev_c = start.is_some();
    for i in 1..=SAMPLES {
        let t = at(i);
        let c = contact(t)?;
        if c != prev_c {
            // bisection for the switch in (prev_t, t)
            let (mut lo, mut hi) = (prev_t, t);
            for _ in 0..50 {
                let m = 0.5 * (lo + hi);
                if contact(m)? == prev_c {
                    lo = m;
                } else {
                    hi = m;
                }
            }
            let switch = 0.5 * (lo + hi);
            if c {
                start = Some(switch);
            } else if let Some(s0) = start.take() {
                pieces.push((s0, switch));
            }
        }
        prev_t = t;
        prev_c = c;
    }
    if let Some(s0) = start {
        pieces.push((s0, pb));
    }
    Ok(pieces)
}

/// Adds the entry/exit wall impulses (module documentation) to `samples`.
fn add_wall_terms(
    eq: &Equilibrium,
    samples: &mut [DdeSample],
    dt: f64,
) -> Result<(), ChatterError> {
    let process = *eq.process();
    let period = eq.period();
    let omega = eq.omega();
    let nt = process.teeth as f64;
    let m = samples.len();
    for j in 0..process.teeth {
        let phase = 2.0 * std::f64::consts::PI * j as f64 / nt;
        for (phib, sign) in [(process.entry_angle, 1.0), (process.exit_angle, -1.0)] {
            let sb = phib.sin();
            if sb < 1e-9 {
                continue;
            }
            let tb = ((phib - phase).rem_euclid(2.0 * std::f64::consts::PI)) / omega;
            if tb >= period {
                continue;
            }
            // Chip just inside the cut.
            let inside = tb + sign * 1e-9 * period;
            let cs = eq.chip_state(j, inside)?;
            if !cs.in_contact || cs.chip <= 0.0 {
                continue;
            }
            let fb = force_direction(phib, process.kt, process.kn)
                * (process.axial_depth * eq.settings().force_law.value(cs.chip));
            let impulse_per_py = fb * (sign / (process.radius * omega * sb));
            let idx = ((inside / dt).floor() as usize).min(m - 1);
            // −A p = impulse p_y / dt  →  A −= impulse e_yᵀ / dt
            let mut a = Matrix2::zeros();
            a[(0, 1)] = -impulse_per_py.x / dt;
            a[(1, 1)] = -impulse_per_py.y / dt;
            if let Some(s) = samples.get_mut(idx) {
                s.present += a;
            }
        }
    }
    Ok(())
}
