//! kerf's corner transition: a symmetric quintic Bézier curve replacing a
//! corner of a G01 polyline, curvature-continuous (G2) with the two lines,
//! whose largest distance from the polyline is known exactly.
//!
//! # Shape
//! At a vertex V with incoming unit direction t₁, outgoing t₂ and turning
//! angle θ = ∠(t₁, t₂) ∈ (0, π), the control points are (the symmetric
//! quintic corner of Sencer, Ishizaki and Shamoto, "A curvature optimal
//! sharp corner smoothing algorithm for high-speed feed motion generation of
//! NC systems along linear tool paths", IJAMT 76, 2015, section 2):
//!
//! P₀ = V − (a+b+c) s t₁, P₁ = V − (a+b) s t₁, P₂ = V − a s t₁,
//! P₃ = V + a s t₂, P₄ = V + (a+b) s t₂, P₅ = V + (a+b+c) s t₂,
//!
//! with the shape (a = 1, b, c) > 0 and the scale s > 0. P₀, P₁, P₂ lie on
//! the incoming line, so the curve leaves it tangentially with zero
//! curvature (Farin eq. 10.5 at u = 0: κ(0) = (4/5) |Δb₀ × Δb₁| / |Δb₀|³ =
//! 0), and likewise joins the outgoing line: G2 continuity with both lines.
//!
//! # Deviation (proof)
//! The signed distance to the incoming line is affine, so along the curve it
//! is the Bernstein polynomial of the control points' distances (0, 0, 0,
//! a s sin θ, (a+b) s sin θ, (a+b+c) s sin θ): non-decreasing coefficients,
//! hence non-decreasing in u (Farin eq. 5.3 with Δ ≥ 0). For u ≤ ½ the
//! curve's foot on the incoming line lies on the segment before V (its
//! coordinate along −t₁ is the Bernstein polynomial of ((a+b+c)s, (a+b)s,
//! a s, −a s cos θ, −(a+b)s cos θ, −(a+b+c)s cos θ): non-increasing for
//! θ ≤ π/2, positive for θ > π/2, and ((16a + 6b + c)/32) s (1 − cos θ) ≥
//! 0 at u = ½), so the distance to the polyline is at most the distance to
//! the incoming line, at most its value at u = ½; the second half is the
//! mirror image. Hence, exactly (attained at u = ½):
//!
//! e = max_u dist(b(u), polyline) = sin θ · s (16a + 6b + c) / 32,
//!
//! provided P₀ and P₅ lie on their segments ((a+b+c) s ≤ the available
//! length on each side).
//!
//! # Choice of a, b, c and s
//! s is the largest with e ≤ δ and (a+b+c) s ≤ the available length. The
//! shape is chosen from a table per turning angle for the binding
//! constraint, by one of two objectives ([`ShapeObjective`]):
//! * **Jerk** (the default): the least largest jerk norm
//!   g = √(κ′² + κ⁴) (κ′ = dκ/ds), g_max · δ² (tolerance binding) or
//!   g_max · L² (length binding), [`JERK_SHAPES`]. At constant speed v the
//!   Cartesian jerk along the corner is v³ g ([`crate::corner_jerk`]): this
//!   shape allows the highest jerk-limited corner speed. Over the table's
//!   rows its g_max is 8.9–40 times (tolerance binding) and 13–44 times
//!   (length binding) below the curvature shape's, for a κ_max 5–20 % and
//!   8–67 % above the least (`tests/corner_jerk.rs` prints the ranges). Its
//!   g is nearly constant along the curve (equiripple): at 150° g_max is
//!   only 15 % above the least κ_max² of any shape, at 90° 38 %, at 30° 3.8
//!   times, where κ′ dominates: κ must rise from 0 to its peak over half
//!   the curve. A symmetric G3 septic (four control points on each line,
//!   three free legs, the same deviation proof with weights C(7, k)/128)
//!   was tried by a coordinate search at 30°, 90° and 150°: its best g_max ·
//!   δ² was 0.0045, 0.119 and 0.648, the quintic's 0.0045, 0.119 and 0.642;
//!   no gain, so it is not built.
//! * **Curvature**: the least κ_max · δ or κ_max · L, [`SHAPES`]. Its short
//!   end leg (c ≈ 0.02–0.7) makes the curvature rise steeply where the curve
//!   leaves the line: κ′(0) = 0.48 a sin θ / (c³ s²) (the derivative of
//!   Farin eq. 10.5 at u = 0), which the jerk shape's longer leg avoids.
//!
//! Both tables come from the grid search of [`search_shape`] (`cargo run -p
//! kerf_toolpath --example corner_shapes` prints them; a test checks them
//! against the search). Any positive shape satisfies the bound above: the
//! tables only choose among exact, proven corners.

use crate::bezier::QuinticBezier;
use crate::corner_curve::CornerCurve;
use crate::corner_jerk::{max_jerk_norm, normalized_jerk, PowerQuintic};
use crate::error::{check_positive, ToolpathError};
use crate::maximum::sampled_maximum;
use crate::vec3::{add, dot, norm, scale, sub};

/// Turning angles below this are straight \[rad\]: no transition.
pub const MIN_TURN: f64 = 1e-9;

/// Turning angles above π − this are reversals \[rad\]: no G2 transition
/// exists inside a tolerance (the path must stop at the vertex).
pub const REVERSAL_MARGIN: f64 = 1e-6;

/// Samples of the half curve for its largest curvature (then refined).
pub const CURVATURE_SAMPLES: usize = 64;

/// A corner shape: b/a and c/a (a = 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CornerShape {
    /// b / a.
    pub b: f64,
    /// c / a.
    pub c: f64,
}

impl CornerShape {
    /// 16a + 6b + c (a = 1): the deviation per unit scale is sin θ times
    /// this over 32.
    pub fn deviation_weight(&self) -> f64 {
        16.0 + 6.0 * self.b + self.c
    }

    /// a + b + c (a = 1): the tangent length per unit scale.
    pub fn length_weight(&self) -> f64 {
        1.0 + self.b + self.c
    }
}

/// Which constraint fixes a corner's scale.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Binding {
    /// The tolerance δ.
    Tolerance,
    /// The length available on the shorter side.
    Length,
}

/// What a corner's shape minimizes (module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ShapeObjective {
    /// The largest jerk norm √(κ′² + κ⁴) ([`crate::corner_jerk`]):
    /// [`JERK_SHAPES`].
    #[default]
    Jerk,
    /// The largest curvature κ_max: [`SHAPES`].
    Curvature,
}

impl ShapeObjective {
    /// The objective of a shape per unit of the binding constraint:
    /// [`normalized_curvature`] or [`crate::corner_jerk::normalized_jerk`].
    pub fn normalized(&self, turn: f64, shape: CornerShape, binding: Binding) -> f64 {
        match self {
            ShapeObjective::Curvature => normalized_curvature(turn, shape, binding),
            ShapeObjective::Jerk => normalized_jerk(turn, shape, binding),
        }
    }

    /// The objective of a built curve (its largest curvature or jerk norm).
    fn of_curve(&self, c: &QuinticBezier, max_curvature: f64) -> f64 {
        match self {
            ShapeObjective::Curvature => max_curvature,
            ShapeObjective::Jerk => max_jerk_norm(c),
        }
    }

    /// The grid of [`search_shape`]: the largest b and c.
    fn search_box(&self) -> (f64, f64) {
        match self {
            ShapeObjective::Curvature => (4.0, 2.0),
            ShapeObjective::Jerk => (6.0, 4.0),
        }
    }
}

/// A corner's transition: kerf's ([`corner_transition`]) or a baseline's
/// ([`crate::baseline`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CornerTransition {
    /// The curve, from its first point on the incoming segment to its last
    /// on the outgoing one.
    pub curve: CornerCurve,
    /// The vertex it replaces.
    pub vertex: [f64; 3],
    /// Turning angle θ \[rad\].
    pub turn: f64,
    /// kerf's shape (a = 1, b, c); `None` for a baseline.
    pub shape: Option<CornerShape>,
    /// The construction's scale \[m\]: kerf's s, ICR's and CCR's control
    /// point spacing d, the NURBS corner's tangent length ℓ.
    pub scale: f64,
    /// |first point − V| = |last point − V| \[m\].
    pub tangent_length: f64,
    /// The largest distance from the polyline \[m\]: exact for kerf's
    /// corner (module documentation), exact or an upper bound for a
    /// baseline (its module says which).
    pub deviation: f64,
    /// The largest curvature \[1/m\] (sampled, then refined).
    pub max_curvature: f64,
    /// The constraint that fixed the scale.
    pub binding: Binding,
}

/// The curve of a shape at a scale.
fn curve(v: [f64; 3], t1: [f64; 3], t2: [f64; 3], shape: CornerShape, s: f64) -> QuinticBezier {
    let (a, b, c) = (s, shape.b * s, shape.c * s);
    QuinticBezier {
        control: [
            sub(v, scale(t1, a + b + c)),
            sub(v, scale(t1, a + b)),
            sub(v, scale(t1, a)),
            add(v, scale(t2, a)),
            add(v, scale(t2, a + b)),
            add(v, scale(t2, a + b + c)),
        ],
    }
}

/// The largest curvature of a symmetric corner curve: the first half
/// sampled at [`CURVATURE_SAMPLES`] + 1 points, the best refined by golden
/// section on its neighbouring interval.
fn max_curvature(curve: &QuinticBezier) -> f64 {
    let power = PowerQuintic::new(curve);
    sampled_maximum(|u| power.curvature(u), 0.0, 0.5, CURVATURE_SAMPLES)
}

/// The unit direction from `a` to `b` and the distance.
fn direction(a: [f64; 3], b: [f64; 3]) -> ([f64; 3], f64) {
    let d = sub(b, a);
    let l = norm(d);
    (scale(d, 1.0 / l), l)
}

/// A corner's incoming and outgoing unit directions and turning angle.
#[derive(Debug, Clone, Copy)]
pub struct CornerFrame {
    /// t₁.
    pub t1: [f64; 3],
    /// t₂.
    pub t2: [f64; 3],
    /// θ \[rad\].
    pub turn: f64,
}

/// The checks every corner method shares, and the corner's directions.
///
/// # Returns
/// `None` for a straight corner (θ < [`MIN_TURN`]), else the incoming and
/// outgoing unit directions t₁, t₂ and the turning angle θ.
///
/// # Errors
/// As [`corner_transition`].
pub fn corner_frame(
    prev: [f64; 3],
    vertex: [f64; 3],
    next: [f64; 3],
    tolerance: f64,
    available: f64,
) -> Result<Option<CornerFrame>, ToolpathError> {
    check_positive(&[
        ("tolerance [m]", tolerance),
        ("available length [m]", available),
    ])?;
    let (t1, l1) = direction(prev, vertex);
    let (t2, l2) = direction(vertex, next);
    if !(l1 > 0.0 && l2 > 0.0 && l1.is_finite() && l2.is_finite()) {
        return Err(ToolpathError::BadPoint {
            index: usize::from(l1 > 0.0),
            reason: "coincides with its neighbour (or is not finite)".to_string(),
        });
    }
    let turn = dot(t1, t2).clamp(-1.0, 1.0).acos();
    if turn < MIN_TURN {
        return Ok(None);
    }
    if turn > std::f64::consts::PI - REVERSAL_MARGIN {
        return Err(ToolpathError::InvalidParameter {
            name: "turning angle [rad]".to_string(),
            value: turn,
            reason: "a reversal: no curvature-continuous transition fits a tolerance (stop at \
                     the vertex)"
                .to_string(),
        });
    }
    Ok(Some(CornerFrame { t1, t2, turn }))
}

/// The transition at the corner `prev` → `vertex` → `next`.
///
/// # Arguments
/// * `tolerance` — δ \[m\], > 0: the transition stays within δ of the
///   polyline.
/// * `available` — the longest tangent length allowed on each side \[m\]
///   (at most the shorter adjacent segment's length; the caller shares
///   segments between neighbouring corners).
///
/// # Returns
/// `None` for a straight corner (θ < [`MIN_TURN`]); the transition
/// otherwise, of the default objective's table shape
/// ([`ShapeObjective::Jerk`]: [`JERK_SHAPES`]) with the smaller largest
/// jerk norm of the two bindings.
///
/// # Errors
/// [`ToolpathError::InvalidParameter`] for δ or `available` not finite
/// and positive, or a reversal (θ > π − [`REVERSAL_MARGIN`]);
/// [`ToolpathError::BadPoint`] for coincident points.
///
/// # Performance
/// Two curvature searches of about 100 curve evaluations each.
pub fn corner_transition(
    prev: [f64; 3],
    vertex: [f64; 3],
    next: [f64; 3],
    tolerance: f64,
    available: f64,
) -> Result<Option<CornerTransition>, ToolpathError> {
    corner_transition_with(
        prev,
        vertex,
        next,
        tolerance,
        available,
        ShapeObjective::default(),
    )
}

/// The transition at the corner `prev` → `vertex` → `next` whose shape
/// minimizes `objective`.
///
/// # Arguments
/// * `tolerance`, `available` — as [`corner_transition`].
/// * `objective` — the table the shape comes from ([`ShapeObjective`]).
///
/// # Returns
/// `None` for a straight corner; the transition otherwise, of the table
/// shape of the two bindings whose curve has the smaller objective.
///
/// # Errors
/// As [`corner_transition`].
///
/// # Performance
/// Two curvature searches, and for [`ShapeObjective::Jerk`] two jerk
/// searches, of about 100 curve evaluations each.
pub fn corner_transition_with(
    prev: [f64; 3],
    vertex: [f64; 3],
    next: [f64; 3],
    tolerance: f64,
    available: f64,
    objective: ShapeObjective,
) -> Result<Option<CornerTransition>, ToolpathError> {
    let Some(CornerFrame { t1, t2, turn }) =
        corner_frame(prev, vertex, next, tolerance, available)?
    else {
        return Ok(None);
    };
    let mut best: Option<(f64, CornerTransition)> = None;
    for binding in [Binding::Tolerance, Binding::Length] {
        let shape = objective.table_shape(turn, binding);
        let by_tolerance = 32.0 * tolerance / (turn.sin() * shape.deviation_weight());
        let by_length = available / shape.length_weight();
        let (s, bound) = if by_tolerance <= by_length {
            (by_tolerance, Binding::Tolerance)
        } else {
            (by_length, Binding::Length)
        };
        let c = curve(vertex, t1, t2, shape, s);
        let max_curvature = max_curvature(&c);
        let t = CornerTransition {
            curve: CornerCurve::Quintic(c),
            vertex,
            turn,
            shape: Some(shape),
            scale: s,
            tangent_length: s * shape.length_weight(),
            deviation: turn.sin() * s * shape.deviation_weight() / 32.0,
            max_curvature,
            binding: bound,
        };
        let value = objective.of_curve(&c, max_curvature);
        if best.is_none_or(|(b, _)| value < b) {
            best = Some((value, t));
        }
    }
    Ok(best.map(|(_, t)| t))
}

/// The largest curvature per unit of the binding constraint of a shape at a
/// turning angle: κ_max · δ (tolerance) or κ_max · L (length).
pub fn normalized_curvature(turn: f64, shape: CornerShape, binding: Binding) -> f64 {
    max_curvature(&unit_curve(turn, shape, binding))
}

/// The corner curve of a shape at a turning angle, in the plane z = 0 at
/// the origin, scaled to a unit of its binding constraint: deviation 1
/// (tolerance) or tangent length 1 (length). The curve behind the shape
/// tables' normalized figures.
pub(crate) fn unit_curve(turn: f64, shape: CornerShape, binding: Binding) -> QuinticBezier {
    let s = match binding {
        Binding::Tolerance => 32.0 / (turn.sin() * shape.deviation_weight()),
        Binding::Length => 1.0 / shape.length_weight(),
    };
    curve(
        [0.0; 3],
        [1.0, 0.0, 0.0],
        [turn.cos(), turn.sin(), 0.0],
        shape,
        s,
    )
}

/// The grid search behind [`SHAPES`] ([`ShapeObjective::search_shape`] for
/// [`ShapeObjective::Curvature`]).
pub fn search_shape(turn: f64, binding: Binding, steps: usize) -> CornerShape {
    ShapeObjective::Curvature.search_shape(turn, binding, steps)
}

/// The curvature table's shape ([`ShapeObjective::table_shape`] for
/// [`ShapeObjective::Curvature`]).
pub fn table_shape(turn: f64, binding: Binding) -> CornerShape {
    ShapeObjective::Curvature.table_shape(turn, binding)
}

impl ShapeObjective {
    /// The grid search behind [`SHAPES`] and [`JERK_SHAPES`]: b and c on
    /// `steps` × `steps` points of (0, b_max] × (0, c_max] ((0, 4] × (0, 2]
    /// for the curvature, (0, 6] × (0, 4] for the jerk, both times
    /// min(1, (π − θ)/(π/6)) past 150°), the shape of least
    /// [`ShapeObjective::normalized`], then the same count of points on a
    /// local grid of ± one step around it.
    pub fn search_shape(&self, turn: f64, binding: Binding, steps: usize) -> CornerShape {
        let mut best = (f64::INFINITY, CornerShape { b: 1.0, c: 0.5 });
        let scan = |b_lo: f64, b_hi: f64, c_lo: f64, c_hi: f64, best: &mut (f64, CornerShape)| {
            for i in 0..=steps {
                for j in 0..=steps {
                    let shape = CornerShape {
                        b: b_lo + (b_hi - b_lo) * i as f64 / steps as f64,
                        c: c_lo + (c_hi - c_lo) * j as f64 / steps as f64,
                    };
                    if shape.b <= 0.0 || shape.c <= 0.0 {
                        continue;
                    }
                    let k = self.normalized(turn, shape, binding);
                    if k < best.0 {
                        *best = (k, shape);
                    }
                }
            }
        };
        // Near a reversal the best shapes shrink about as π − θ (the tables'
        // last rows): the box with them, so that the grid resolves them.
        let shrink = ((std::f64::consts::PI - turn) / std::f64::consts::FRAC_PI_6).clamp(1e-3, 1.0);
        let (b_max, c_max) = self.search_box();
        let (b_max, c_max) = (b_max * shrink, c_max * shrink);
        scan(0.0, b_max, 0.0, c_max, &mut best);
        let (db, dc) = (b_max / steps as f64, c_max / steps as f64);
        let centre = best.1;
        scan(
            centre.b - db,
            centre.b + db,
            centre.c - dc,
            centre.c + dc,
            &mut best,
        );
        best.1
    }

    /// The table shape at a turning angle: linear interpolation in
    /// [`SHAPES`] or [`JERK_SHAPES`] between their rows (θ = 5°, 10°, …,
    /// 175°, then 176°, …, 179°, 179.5°, 179.8°, 179.9°, 179.95°; clamped
    /// outside).
    pub fn table_shape(&self, turn: f64, binding: Binding) -> CornerShape {
        let table = match self {
            ShapeObjective::Curvature => &SHAPES,
            ShapeObjective::Jerk => &JERK_SHAPES,
        };
        let last = table.len() - 1;
        let deg = turn.to_degrees().clamp(table[0][0], table[last][0]);
        // The row at or below θ, at most the last but one.
        let k = table
            .partition_point(|row| row[0] <= deg)
            .saturating_sub(1)
            .min(last - 1);
        let f = (deg - table[k][0]) / (table[k + 1][0] - table[k][0]);
        let pick = |row: &[f64; 5]| match binding {
            Binding::Tolerance => (row[1], row[2]),
            Binding::Length => (row[3], row[4]),
        };
        let (b0, c0) = pick(&table[k]);
        let (b1, c1) = pick(&table[k + 1]);
        CornerShape {
            b: b0 + f * (b1 - b0),
            c: c0 + f * (c1 - c0),
        }
    }
}

/// The turning angles of the rows of [`SHAPES`] and [`JERK_SHAPES`]
/// \[degrees\]: every 5° to 175°, then closer towards the reversal.
pub fn table_angles() -> Vec<f64> {
    let mut out: Vec<f64> = (0..35).map(|k| 5.0 + 5.0 * k as f64).collect();
    out.extend([176.0, 177.0, 178.0, 179.0, 179.5, 179.8, 179.9, 179.95]);
    out
}

/// Per turning angle (degrees): the shape (b, c) of least κ_max · δ and of
/// least κ_max · L ([`ShapeObjective::search_shape`] with 40 steps;
/// generated by `cargo run -p kerf_toolpath --example corner_shapes`).
pub const SHAPES: [[f64; 5]; 43] = include!("corner_shapes.in");

/// Per turning angle (degrees): the shape (b, c) of least g_max · δ² and of
/// least g_max · L² (g = √(κ′² + κ⁴), [`crate::corner_jerk`];
/// [`ShapeObjective::search_shape`] with 40 steps; generated by `cargo run
/// -p kerf_toolpath --example corner_shapes -- jerk`).
pub const JERK_SHAPES: [[f64; 5]; 43] = include!("corner_jerk_shapes.in");
