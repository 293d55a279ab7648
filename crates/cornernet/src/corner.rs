//! One corner of the NURBS method in its local frame: the networks' input
//! features, the swarm's variables, and the corner built from them.
//!
//! # Local frame and inputs (seed 003 Fig. 6 (1))
//! The vertex V = Pᵢ is the origin, x runs along the incoming direction t₁
//! and y towards the outgoing side, so t₂ = (cos θ, sin θ) for the turning
//! angle θ. Method 1's five control points (seed 003 Fig. 2b) are taken at
//! the two ends of the length `available` = A kerf lets the corner use and
//! at its middle: Pᵢ₋₂ = −A t₁, Pᵢ₋₁ = −A t₁ / 2, Pᵢ = 0, Pᵢ₊₁ = A t₂ / 2,
//! Pᵢ₊₂ = A t₂. Divided by A they are ten numbers in the unit disc that
//! depend on θ only. The paper fixes δ_max, so its five points carry the
//! whole corner; kerf's tolerance varies, so an eleventh input ln(A / δ)
//! carries the scale (the swarm's answer depends on θ and A / δ only: its
//! box is relative to A and its weight is solved from δ).
//!
//! # Outputs
//! The swarm's own variables x = (ℓ / A, α, β) of
//! [`kerf_toolpath::baseline::nurbs`]: the added points are
//! Pᵢ₊₃ = −βαℓ t₁ and its mirror Pᵢ₊₄ = βαℓ t₂ (seed 003 Fig. 6 (2)), and
//! the outer ones move to ℓ and αℓ. They are bounded (the swarm's box),
//! scale-free, and every x of the box gives a corner; the weight w then
//! follows from δ in closed form (seed 003 eq. 7, last line, as nurbs.rs
//! solves it), so the deviation is exactly ≤ δ whatever the network says.

use kerf_toolpath::baseline::nurbs;
use kerf_toolpath::vec3::sub;
use kerf_toolpath::ToolpathError;
use kerf_toolpath::{CornerCurve, CornerTransition, NurbsSettings};

/// The number of input features (ten coordinates and ln(A / δ)).
pub const INPUTS: usize = 11;

/// The number of outputs (ℓ / A, α, β).
pub const OUTPUTS: usize = 3;

/// The swarm's search box for (ℓ / A, α, β): nurbs.rs's.
pub use kerf_toolpath::baseline::nurbs::{LOWER, UPPER};

/// A corner reduced to what the swarm's answer depends on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalCorner {
    /// Turning angle θ \[rad\].
    pub turn: f64,
    /// A / δ, the available length over the tolerance.
    pub ratio: f64,
}

impl LocalCorner {
    /// The input features (module documentation), before normalization.
    pub fn features(&self) -> [f64; INPUTS] {
        let (s, c) = self.turn.sin_cos();
        [
            -1.0,
            0.0,
            -0.5,
            0.0,
            0.0,
            0.0,
            0.5 * c,
            0.5 * s,
            c,
            s,
            self.ratio.ln(),
        ]
    }

    /// The incoming and outgoing directions in the local frame.
    pub fn directions(&self) -> ([f64; 3], [f64; 3]) {
        let (s, c) = self.turn.sin_cos();
        ([1.0, 0.0, 0.0], [c, s, 0.0])
    }

    /// The swarm's corner at δ = 1 (the swarm's answer is scale-free), its
    /// seed's index 0 (every corner draws the same swarm).
    ///
    /// # Returns
    /// The swarm's variables and its transition.
    ///
    /// # Errors
    /// [`ToolpathError`] from the swarm (bad settings, no feasible point).
    ///
    /// # Performance
    /// One swarm: particles × (iterations + 1) curve evaluations at 25
    /// curvature samples each (measured by the example and the bench).
    pub fn swarm(
        &self,
        settings: &NurbsSettings,
    ) -> Result<([f64; OUTPUTS], CornerTransition), ToolpathError> {
        let (t1, t2) = self.directions();
        let t = nurbs::transition([0.0; 3], t1, t2, self.turn, 1.0, self.ratio, settings, 0)?;
        let x = variables_of(&t, self.ratio).ok_or_else(|| ToolpathError::InvalidParameter {
            name: "NURBS transition".to_string(),
            value: t.scale,
            reason: "not a seven-point NURBS corner".to_string(),
        })?;
        Ok((x, t))
    }
}

/// The swarm's variables (ℓ / A, α, β) read back from a NURBS transition
/// at the origin (control points −ℓ t₁, −αℓ t₁, −βαℓ t₁, 0, …).
///
/// # Returns
/// `None` when the curve is not a seven-point spline.
pub fn variables_of(t: &CornerTransition, available: f64) -> Option<[f64; OUTPUTS]> {
    let CornerCurve::Spline(s) = t.curve else {
        return None;
    };
    let p = s.control();
    if p.len() != 7 {
        return None;
    }
    let dist = |q: [f64; 3]| kerf_toolpath::vec3::norm(sub(q, t.vertex));
    let l = dist(p[0]);
    let outer = dist(p[1]);
    let inner = dist(p[2]);
    Some([l / available, outer / l, inner / outer])
}
