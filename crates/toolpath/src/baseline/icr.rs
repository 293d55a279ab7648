//! ICR, the inscribed corner rounding of Zhao, Zhu and Ding, "A real-time
//! look-ahead interpolation methodology with curvature-continuous B-spline
//! transition scheme for CNC machining of short line segments", IJMTM 65,
//! 2013, pp. 88–98 (seed 000's baseline "ICR", Table 1).
//!
//! # Reading
//! Seed 000 only names the method ("curvature-continuous B-splines with G2
//! continuity"). This is our reading of Zhao et al.'s transition
//! (written from its published description, not from their text, which we
//! could not consult; equation numbers of theirs are therefore not cited): a
//! cubic B-spline with five control points and knots {0, 0, 0, 0, ½, 1, 1,
//! 1, 1}, the vertex V the middle one, two on each segment at equal
//! spacing d:
//!
//! P₀ = V − 2d t₁, P₁ = V − d t₁, P₂ = V, P₃ = V + d t₂, P₄ = V + 2d t₂.
//!
//! P₀, P₁, P₂ lie on the incoming line, so the curve leaves it tangentially
//! with zero curvature (the B-spline form of Farin eq. 10.5 at an end:
//! κ ∝ |Δb₀ × Δb₁| = 0); likewise at the outgoing line: **G2** with both
//! lines (C2 inside: a cubic with a simple inner knot).
//!
//! # Deviation (exact)
//! At u = ½ only N₁, N₂, N₃ are non-zero, (¼, ½, ¼) (Cox–de Boor, seed 003
//! eq. 2; a test checks them), so C(½) = V + (d/4)(t₂ − t₁). The signed
//! distance to the incoming line is the B-spline of the control points'
//! distances (0, 0, 0, d sin θ, 2d sin θ), non-decreasing, hence
//! non-decreasing in u (variation diminishing, Piegl and Tiller section
//! 3.2); the foot's coordinate along −t₁ from V is the spline of (2d, d,
//! 0, −d cos θ, −2d cos θ): at u ≤ ½ it is ≥ (d/4)(1 − cos θ) ≥ 0 and ≤ 2d,
//! so the foot lies on the incoming segment. As for kerf's corner, the
//! distance from the polyline is then largest at u = ½:
//!
//! e = (d/4) sin θ.
//!
//! Zhao et al. bound the distance from the vertex, |C(½) − V| =
//! (d/2) sin(θ/2), which is larger; kerf measures every method by the
//! distance from the polyline (the tolerance the machine part sees), which
//! lets ICR use a larger d, to its advantage.
//!
//! # Scale
//! d = min(4δ / sin θ, available / 2) (the curve uses 2d of each segment).

use crate::corner::CornerTransition;
use crate::error::ToolpathError;
use crate::spline::CubicSpline;
use crate::vec3::{add, scale, sub};

/// The knots.
pub const KNOTS: [f64; 9] = [0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0];

/// N₃(½) with [`KNOTS`]: the deviation is this times d sin θ.
pub const MID_WEIGHT: f64 = 0.25;

/// The curve at spacing `d`.
pub fn curve(
    v: [f64; 3],
    t1: [f64; 3],
    t2: [f64; 3],
    d: f64,
) -> Result<CubicSpline, ToolpathError> {
    let control = [
        sub(v, scale(t1, 2.0 * d)),
        sub(v, scale(t1, d)),
        v,
        add(v, scale(t2, d)),
        add(v, scale(t2, 2.0 * d)),
    ];
    CubicSpline::new(&control, &[1.0; 5], &KNOTS)
}

/// The ICR transition at a corner (directions t₁, t₂, turning angle θ).
///
/// # Errors
/// [`ToolpathError::InvalidParameter`] if the curve cannot be built (not
/// finite).
pub fn transition(
    v: [f64; 3],
    t1: [f64; 3],
    t2: [f64; 3],
    turn: f64,
    tolerance: f64,
    available: f64,
) -> Result<CornerTransition, ToolpathError> {
    super::scaled_transition(
        v,
        turn,
        tolerance,
        available,
        MID_WEIGHT * turn.sin(),
        2.0,
        |d| curve(v, t1, t2, d),
    )
}
