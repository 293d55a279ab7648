//! CCR, the circumscribed corner rounding of Xu and Sun, "A circumscribed
//! corner rounding method based on double cubic B-splines for a five-axis
//! linear tool path", IJAMT 94, 2018, pp. 451–462 (seed 000's baseline
//! "CCR", Table 1).
//!
//! # Reading
//! Seed 000 only names the method ("inserting transition curves using
//! double cubic B-splines at junctions"). Our reading of Xu and Sun's
//! construction (written from its published description, not from their
//! text, which we could not consult; no equation of theirs is cited): the
//! transition passes through the vertex V ("circumscribed": it runs
//! outside the corner), made of two cubic B-splines mirror-symmetric
//! about the corner's bisector, each with five control points and knots
//! {0, 0, 0, 0, ½, 1, 1, 1, 1}. With m = (t₁ + t₂)/|t₁ + t₂| the tangent at
//! V and spacing d, the first is
//!
//! Q₀ = V − 3d t₁, Q₁ = V − 2d t₁, Q₂ = V − d t₁, Q₃ = V − d m, Q₄ = V,
//!
//! the second its mirror image (V, V + d m, V + d t₂, V + 2d t₂, V + 3d t₂).
//! They are stored as one cubic B-spline with 9 control points and knots
//! {0, 0, 0, 0, ¼, ½, ½, ½, ¾, 1, 1, 1, 1}: the triple knot at ½ makes it
//! pass through V, and with equal spans on both sides both halves reach V
//! with the same derivative d/du = 12 d m, so the path chains as one piece.
//!
//! # Continuity
//! Q₀, Q₁, Q₂ on the incoming line: tangent with zero curvature there
//! (likewise at the outgoing line), **G2** with both lines. At V the
//! tangents agree (m); the curvature vectors are mirror images across the
//! bisector's plane, and being normal to m they are unchanged by it: **G2**
//! at V too (C1 in the parameter, not C2). The curvature changes sign on
//! each half (the curve first bends outwards, then back through V).
//!
//! # Deviation (a bound, exact up to θ = 90°)
//! On the first half the signed distance to the incoming line is the
//! B-spline of (0, 0, 0, −d sin(θ/2), 0): −d sin(θ/2) N₃(u), outside the
//! corner, largest where N₃ is, N₃ ≤ [`PEAK`] (its maximum, at u ≈ 0.7735
//! of the half; a test checks it by dense sampling). The foot's coordinate
//! along t₁ is the spline of (−3d, −2d, −d, −d cos(θ/2), 0) ∈ [−3d, 0]: on
//! the segment. So the distance from the polyline is at most
//!
//! e = PEAK · d · sin(θ/2),
//!
//! with equality for θ ≤ 90° (the outgoing segment is then no nearer); the
//! second half is the mirror image.
//!
//! # Scale
//! d = min(δ / (PEAK sin(θ/2)), available / 3) (3d of each segment).
//! The spacing ratios (equal steps on the line, |Q₃ − V| = d) are our
//! choice: the seed does not give Xu and Sun's.

use crate::corner::CornerTransition;
use crate::error::ToolpathError;
use crate::spline::CubicSpline;
use crate::vec3::{add, norm, scale, sub};

/// The knots of the two halves as one spline.
pub const KNOTS: [f64; 13] = [
    0.0, 0.0, 0.0, 0.0, 0.25, 0.5, 0.5, 0.5, 0.75, 1.0, 1.0, 1.0, 1.0,
];

/// max N₃(u) for the knots {0, 0, 0, 0, ½, 1, 1, 1, 1} (golden-section
/// search to rounding; a test checks it).
pub const PEAK: f64 = 0.598_238_948_958_872_6;

/// The curve at spacing `d`.
pub fn curve(
    v: [f64; 3],
    t1: [f64; 3],
    t2: [f64; 3],
    d: f64,
) -> Result<CubicSpline, ToolpathError> {
    let sum = add(t1, t2);
    let m = scale(sum, 1.0 / norm(sum));
    let control = [
        sub(v, scale(t1, 3.0 * d)),
        sub(v, scale(t1, 2.0 * d)),
        sub(v, scale(t1, d)),
        sub(v, scale(m, d)),
        v,
        add(v, scale(m, d)),
        add(v, scale(t2, d)),
        add(v, scale(t2, 2.0 * d)),
        add(v, scale(t2, 3.0 * d)),
    ];
    CubicSpline::new(&control, &[1.0; 9], &KNOTS)
}

/// The CCR transition at a corner (directions t₁, t₂, turning angle θ).
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
        PEAK * (0.5 * turn).sin(),
        3.0,
        |d| curve(v, t1, t2, d),
    )
}
