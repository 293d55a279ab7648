//! Seed 003's NURBS corner (DRLS, "method 2" of its Fig. 2), its control
//! points chosen by the particle swarm the paper uses to make its training
//! data (eq. 8; the paper's networks only imitate that swarm).
//!
//! # Reading (seed 003 section "NURBS" and eq. 7)
//! A cubic NURBS (eqs. 1–6) with seven control points: the five of method
//! 1 (two on each segment and the vertex V = Pᵢ) and two added ones,
//! Pᵢ₊₃ between Pᵢ₋₁ and Pᵢ and its mirror image Pᵢ₊₄, in the order
//! Pᵢ₋₂, Pᵢ₋₁, Pᵢ₊₃, Pᵢ, Pᵢ₊₄, Pᵢ₊₁, Pᵢ₊₂. With tangent length ℓ and
//! fractions α, β ∈ (0, 1):
//!
//! Pᵢ₋₂ = V − ℓ t₁, Pᵢ₋₁ = V − αℓ t₁, Pᵢ₊₃ = V − βαℓ t₁, Pᵢ = V,
//!
//! mirrored on the outgoing side, weights (1, 1, 1, w, 1, 1, 1) and knots
//! {0, 0, 0, 0, ¼, ½, ¾, 1, 1, 1, 1}. The seed gives neither the degree nor
//! the knots; eq. 7's last line, where C(½) involves only Pᵢ₊₃, Pᵢ and
//! Pᵢ₊₄, fits a cubic with a simple knot at ½ and we take the inner knots
//! uniform.
//!
//! What the extraction gets wrong, checked: eq. 7 lists
//! `Pᵢ,ₓ < Pᵢ₊₄,ₓ < Pᵢ₊₁,ₓ` twice (the second must be the y bound); its
//! prose asks the angles at Pᵢ₋₁ and Pᵢ₊₃ to be "smaller than" the angle
//! at Pᵢ where eq. 7 writes ">" (as interior angles ">" is the one that
//! puts the largest turn at the vertex, which we follow); eq. 6 is the
//! radius, not the curvature. Table 2's "92.7 %" for corner b is
//! (27.06 − 14.04) / 14.04, relative to the optimized value: the reduction
//! is 48.1 %, and case 1's "maximum reduction of up to 92.7 %" should
//! read 48.1 %.
//!
//! Departures from the paper, each stated:
//! * eq. 7 lets Pᵢ₊₃ anywhere in the box between Pᵢ₋₁ and Pᵢ; off the
//!   incoming line the curve's curvature at its start is not zero (κ(0) ∝
//!   |Δb₀ × Δb₁|), a curvature jump at the line: only G1. We keep Pᵢ₊₃ on
//!   the segment Pᵢ₋₁Pᵢ (the box's diagonal), so the corner is **G2** with
//!   both lines, like kerf's and ICR; eq. 7's two angle constraints then
//!   hold (the polygon is straight at Pᵢ₋₁ and Pᵢ₊₃).
//! * The paper takes Pᵢ₋₂, Pᵢ₋₁ from its input; the swarm here also moves
//!   them (ℓ and α), which only enlarges its search.
//! * The weight: eq. 7's last line sets the distance of C(½) from the
//!   vertex to δ and solves for the weight; we solve the same equation for
//!   the distance from the polyline (kerf's measure for every method),
//!   w = N₂(½)(βαℓ sin θ / δ − 2) / N₃(½), raised to
//!   [`NurbsSettings::min_weight`] when smaller (the deviation is then
//!   below δ); above [`NurbsSettings::max_weight`] the point is infeasible.
//! * The objective is eq. 7's: the corner's largest curvature; its
//!   `cur_i < cur_i,max` is not imposed (no limit given).
//!
//! # Deviation (exact)
//! The control points' distances to the incoming line, (0, 0, 0, 0,
//! βαℓ sin θ, αℓ sin θ, ℓ sin θ), do not decrease; with positive weights a
//! NURBS is variation diminishing (Piegl and Tiller section 4.2), so the
//! distance grows with u; the foot stays on the segment as for ICR (module
//! [`super::icr`]). Hence the distance from the polyline is largest at
//! u = ½, where N₂ = N₄ = 1/6 and N₃ = 2/3 (a test checks them):
//!
//! e = N₂(½) βαℓ sin θ / (2 N₂(½) + N₃(½) w).

use kerf_budget::Budget;

use super::pso::{minimize_within, Swarm};
use crate::corner::{Binding, CornerTransition};
use crate::corner_curve::CornerCurve;
use crate::error::ToolpathError;
use crate::spline::CubicSpline;
use crate::vec3::{add, scale, sub};

/// The knots.
pub const KNOTS: [f64; 11] = [0.0, 0.0, 0.0, 0.0, 0.25, 0.5, 0.75, 1.0, 1.0, 1.0, 1.0];

/// N₂(½) = N₄(½) with [`KNOTS`].
pub const SIDE_WEIGHT: f64 = 1.0 / 6.0;

/// N₃(½) with [`KNOTS`].
pub const CENTRE_WEIGHT: f64 = 2.0 / 3.0;

/// The swarm's search box for (ℓ / available, α, β).
pub const LOWER: [f64; 3] = [0.05, 0.02, 0.02];
/// Its upper corner.
pub const UPPER: [f64; 3] = [1.0, 0.98, 0.98];

/// Curvature samples on the half curve inside the swarm's objective.
const OBJECTIVE_SAMPLES: usize = 24;

/// The settings of the NURBS corner's swarm.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct NurbsSettings {
    /// Particles, ≥ 2.
    pub particles: usize,
    /// Iterations, ≥ 1.
    pub iterations: usize,
    /// Inertia w of eq. 8, in [0, 1).
    pub inertia: f64,
    /// c₁ of eq. 8, finite, ≥ 0.
    pub c1: f64,
    /// c₂ of eq. 8, finite, ≥ 0.
    pub c2: f64,
    /// c₃ of eq. 8, finite, ≥ 0.
    pub c3: f64,
    /// The seed (each corner draws from it and its index).
    pub seed: u64,
    /// The smallest weight w of the vertex, finite, > 0.
    pub min_weight: f64,
    /// The largest, finite, > `min_weight`.
    pub max_weight: f64,
}

impl Default for NurbsSettings {
    /// 20 particles, 40 iterations, w 0.7, c₁ = c₂ = 1.5, c₃ 0.2 (the seed
    /// gives no values), weights in [0.01, 100].
    fn default() -> Self {
        NurbsSettings {
            particles: 20,
            iterations: 40,
            inertia: 0.7,
            c1: 1.5,
            c2: 1.5,
            c3: 0.2,
            seed: 0x5eed,
            min_weight: 0.01,
            max_weight: 100.0,
        }
    }
}

impl NurbsSettings {
    /// Checks every setting.
    ///
    /// # Errors
    /// [`ToolpathError::InvalidParameter`] naming the first bad one.
    pub fn check(&self) -> Result<(), ToolpathError> {
        let bad = |name: &str, value: f64, reason: &str| {
            Err(ToolpathError::InvalidParameter {
                name: format!("NURBS swarm {name}"),
                value,
                reason: reason.to_string(),
            })
        };
        if self.particles < 2 {
            return bad("particles", self.particles as f64, "must be ≥ 2");
        }
        if self.iterations < 1 {
            return bad("iterations", self.iterations as f64, "must be ≥ 1");
        }
        if !(self.inertia.is_finite() && (0.0..1.0).contains(&self.inertia)) {
            return bad("inertia", self.inertia, "must be in [0, 1)");
        }
        for (name, c) in [("c1", self.c1), ("c2", self.c2), ("c3", self.c3)] {
            if !(c.is_finite() && c >= 0.0) {
                return bad(name, c, "must be finite and ≥ 0");
            }
        }
        if self.c1 + self.c2 <= 0.0 {
            return bad(
                "c1 + c2",
                self.c1 + self.c2,
                "must be > 0 (else nothing moves)",
            );
        }
        if !(self.min_weight.is_finite() && self.min_weight > 0.0) {
            return bad("min_weight", self.min_weight, "must be finite and > 0");
        }
        if !(self.max_weight.is_finite() && self.max_weight > self.min_weight) {
            return bad(
                "max_weight",
                self.max_weight,
                "must be finite and > min_weight",
            );
        }
        Ok(())
    }
}

/// One corner's data for the swarm.
#[derive(Clone, Copy)]
struct Corner<'a> {
    v: [f64; 3],
    t1: [f64; 3],
    t2: [f64; 3],
    sin_turn: f64,
    tolerance: f64,
    available: f64,
    settings: &'a NurbsSettings,
}

/// The corner's geometry for the swarm's variables x = (ℓ / available, α,
/// β): the curve, its weight and its deviation, or `None` if infeasible
/// (the weight needed for δ exceeds `max_weight`).
fn candidate(corner: &Corner, x: &[f64; 3]) -> Option<(CubicSpline, f64, f64, f64)> {
    let Corner {
        v,
        t1,
        t2,
        sin_turn,
        tolerance,
        available,
        settings,
    } = *corner;
    let l = x[0] * available;
    let (outer, inner) = (x[1] * l, x[2] * x[1] * l);
    let needed = SIDE_WEIGHT * (inner * sin_turn / tolerance - 2.0) / CENTRE_WEIGHT;
    if needed > settings.max_weight || needed.is_nan() {
        return None;
    }
    let w = needed.max(settings.min_weight);
    let control = [
        sub(v, scale(t1, l)),
        sub(v, scale(t1, outer)),
        sub(v, scale(t1, inner)),
        v,
        add(v, scale(t2, inner)),
        add(v, scale(t2, outer)),
        add(v, scale(t2, l)),
    ];
    let weights = [1.0, 1.0, 1.0, w, 1.0, 1.0, 1.0];
    let curve = CubicSpline::new(&control, &weights, &KNOTS).ok()?;
    let deviation = SIDE_WEIGHT * inner * sin_turn / (2.0 * SIDE_WEIGHT + CENTRE_WEIGHT * w);
    Some((curve, w, deviation, l))
}

/// The NURBS transition at a corner (directions t₁, t₂, turning angle θ),
/// its control points chosen by the swarm.
///
/// # Arguments
/// * `index` — the corner's index in the polyline, mixed into the seed.
///
/// # Errors
/// [`ToolpathError::InvalidParameter`] when the swarm found no feasible
/// point (every one drawn needed a weight above `max_weight`).
#[allow(clippy::too_many_arguments)] // the corner's geometry, its limits and the swarm
pub fn transition(
    v: [f64; 3],
    t1: [f64; 3],
    t2: [f64; 3],
    turn: f64,
    tolerance: f64,
    available: f64,
    settings: &NurbsSettings,
    index: usize,
) -> Result<CornerTransition, ToolpathError> {
    transition_within(
        v,
        t1,
        t2,
        turn,
        tolerance,
        available,
        settings,
        index,
        &Budget::unlimited(),
    )
}

/// [`transition`] under a budget, checked at every particle's move of the swarm.
///
/// # Errors
/// As [`transition`]; [`ToolpathError::Interrupted`] when the budget runs out.
#[allow(clippy::too_many_arguments)] // the corner's geometry, its limits, the swarm, the budget
pub fn transition_within(
    v: [f64; 3],
    t1: [f64; 3],
    t2: [f64; 3],
    turn: f64,
    tolerance: f64,
    available: f64,
    settings: &NurbsSettings,
    index: usize,
    budget: &Budget,
) -> Result<CornerTransition, ToolpathError> {
    let corner = Corner {
        v,
        t1,
        t2,
        sin_turn: turn.sin(),
        tolerance,
        available,
        settings,
    };
    let objective = |x: &[f64; 3]| match candidate(&corner, x) {
        Some((c, ..)) => {
            let c = CornerCurve::Spline(c);
            (0..=OBJECTIVE_SAMPLES)
                .map(|k| c.curvature(0.5 * k as f64 / OBJECTIVE_SAMPLES as f64))
                .fold(0.0, f64::max)
        }
        None => f64::INFINITY,
    };
    let swarm = Swarm {
        particles: settings.particles,
        iterations: settings.iterations,
        inertia: settings.inertia,
        c1: settings.c1,
        c2: settings.c2,
        c3: settings.c3,
    };
    let seed = settings.seed ^ (index as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    let (x, value) = minimize_within(objective, LOWER, UPPER, &swarm, seed, budget)?;
    let found = candidate(&corner, &x);
    let (curve, w, deviation, l) = match found {
        Some(f) if value.is_finite() => f,
        _ => {
            return Err(ToolpathError::InvalidParameter {
                name: "NURBS swarm max_weight".to_string(),
                value: settings.max_weight,
                reason: "no feasible corner found: every point drawn needed a larger vertex weight"
                    .to_string(),
            })
        }
    };
    Ok(assemble(&corner, turn, curve, w, deviation, l))
}

/// The transition of a corner's curve with its weight `w`, deviation and
/// tangent length `l`.
fn assemble(
    corner: &Corner,
    turn: f64,
    curve: CubicSpline,
    w: f64,
    deviation: f64,
    l: f64,
) -> CornerTransition {
    let c = CornerCurve::Spline(curve);
    CornerTransition {
        curve: c,
        vertex: corner.v,
        turn,
        shape: None,
        scale: l,
        tangent_length: l,
        deviation,
        max_curvature: c.max_curvature_on(0.0, 0.5, super::CURVATURE_SAMPLES),
        binding: if w > corner.settings.min_weight {
            Binding::Tolerance
        } else {
            Binding::Length
        },
    }
}

/// The NURBS transition for given swarm variables `x = (ℓ / available, α,
/// β)` (each clamped to the swarm's box), without the swarm: what a learned
/// model's prediction builds (`kerf_cornernet`).
///
/// # Returns
/// `None` when the vertex weight that δ needs exceeds `max_weight` (the
/// curve would leave δ), or the spline is refused.
///
/// # Performance
/// One spline and its curvature samples (a few microseconds).
#[allow(clippy::too_many_arguments)] // the corner's geometry, its limits and the variables
pub fn transition_at(
    v: [f64; 3],
    t1: [f64; 3],
    t2: [f64; 3],
    turn: f64,
    tolerance: f64,
    available: f64,
    x: [f64; 3],
    settings: &NurbsSettings,
) -> Option<CornerTransition> {
    let corner = Corner {
        v,
        t1,
        t2,
        sin_turn: turn.sin(),
        tolerance,
        available,
        settings,
    };
    let x: [f64; 3] = std::array::from_fn(|k| x[k].clamp(LOWER[k], UPPER[k]));
    let (curve, w, deviation, l) = candidate(&corner, &x)?;
    Some(assemble(&corner, turn, curve, w, deviation, l))
}
