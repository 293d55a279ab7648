//! The corner-smoothing baselines of issue 14, pluggable next to kerf's
//! quintic corner ([`crate::corner`]) through [`CornerMethod`] and
//! [`crate::smooth::smooth_polyline_with`]:
//!
//! * [`icr`]: Zhao, Zhu and Ding 2013, inscribed cubic B-spline (G2);
//! * [`ccr`]: Xu and Sun 2018, circumscribed double cubic B-spline through
//!   the vertex (G2);
//! * [`nurbs`]: seed 003's NURBS corner with two added control points and
//!   a weight, chosen by a particle swarm ([`pso`]) (G2).
//!
//! Every one stays within δ of the polyline (each module proves its bound)
//! and, like kerf's, uses at most the length the caller makes available on
//! each side (half of a segment shared with another corner).

pub mod ccr;
pub mod icr;
pub mod nurbs;
pub mod pso;

pub use nurbs::NurbsSettings;

use kerf_budget::Budget;

use crate::corner::{
    corner_frame, corner_transition, corner_transition_with, Binding, CornerTransition,
    ShapeObjective,
};
use crate::corner_curve::CornerCurve;
use crate::error::ToolpathError;
use crate::spline::CubicSpline;

/// Curvature samples on the half curve for a baseline's largest curvature
/// (then refined), as kerf's corner ([`crate::corner::CURVATURE_SAMPLES`]).
pub const CURVATURE_SAMPLES: usize = 64;

/// How a corner is smoothed.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum CornerMethod {
    /// kerf's symmetric quintic ([`crate::corner`]), its shape of least
    /// jerk norm √(κ′² + κ⁴) ([`crate::corner::ShapeObjective::Jerk`]).
    #[default]
    Kerf,
    /// kerf's symmetric quintic, its shape of least κ_max
    /// ([`crate::corner::ShapeObjective::Curvature`]).
    KerfCurvature,
    /// ICR ([`icr`]).
    Icr,
    /// CCR ([`ccr`]).
    Ccr,
    /// Seed 003's NURBS corner by a particle swarm ([`nurbs`]).
    Nurbs(NurbsSettings),
}

impl CornerMethod {
    /// The method's short name (for tables).
    pub fn name(&self) -> &'static str {
        match self {
            CornerMethod::Kerf => "kerf",
            CornerMethod::KerfCurvature => "kerf min-κ",
            CornerMethod::Icr => "ICR",
            CornerMethod::Ccr => "CCR",
            CornerMethod::Nurbs(_) => "NURBS-PSO",
        }
    }

    /// Checks the method's settings.
    ///
    /// # Errors
    /// [`ToolpathError::InvalidParameter`] for a bad swarm setting.
    pub fn check(&self) -> Result<(), ToolpathError> {
        match self {
            CornerMethod::Nurbs(s) => s.check(),
            _ => Ok(()),
        }
    }

    /// The transition at the corner `prev` → `vertex` → `next`, as
    /// [`corner_transition`] for every method.
    ///
    /// # Arguments
    /// * `tolerance`, `available` — as [`corner_transition`].
    /// * `index` — the vertex's index in its polyline (the swarm's seed
    ///   mixes it in; the other methods ignore it).
    ///
    /// # Returns
    /// `None` for a straight corner, else the method's transition.
    ///
    /// # Errors
    /// As [`corner_transition`]; for [`CornerMethod::Nurbs`] also bad
    /// settings or no feasible corner.
    pub fn transition(
        &self,
        prev: [f64; 3],
        vertex: [f64; 3],
        next: [f64; 3],
        tolerance: f64,
        available: f64,
        index: usize,
    ) -> Result<Option<CornerTransition>, ToolpathError> {
        self.transition_within(
            prev,
            vertex,
            next,
            tolerance,
            available,
            index,
            &Budget::unlimited(),
        )
    }

    /// [`Self::transition`] under a budget (the NURBS swarm checks it at every particle's
    /// move; the other methods build a corner in microseconds and leave the check to their
    /// caller).
    ///
    /// # Errors
    /// As [`Self::transition`]; [`ToolpathError::Interrupted`] when the budget runs out.
    #[allow(clippy::too_many_arguments)] // the corner, its limits, the budget
    pub fn transition_within(
        &self,
        prev: [f64; 3],
        vertex: [f64; 3],
        next: [f64; 3],
        tolerance: f64,
        available: f64,
        index: usize,
        budget: &Budget,
    ) -> Result<Option<CornerTransition>, ToolpathError> {
        self.check()?;
        let framed =
            |build: &dyn Fn([f64; 3], [f64; 3], f64) -> Result<CornerTransition, ToolpathError>| {
                match corner_frame(prev, vertex, next, tolerance, available)? {
                    None => Ok(None),
                    Some(f) => build(f.t1, f.t2, f.turn).map(Some),
                }
            };
        match self {
            CornerMethod::Kerf => corner_transition(prev, vertex, next, tolerance, available),
            CornerMethod::KerfCurvature => corner_transition_with(
                prev,
                vertex,
                next,
                tolerance,
                available,
                ShapeObjective::Curvature,
            ),
            CornerMethod::Icr => {
                framed(&|t1, t2, turn| icr::transition(vertex, t1, t2, turn, tolerance, available))
            }
            CornerMethod::Ccr => {
                framed(&|t1, t2, turn| ccr::transition(vertex, t1, t2, turn, tolerance, available))
            }
            CornerMethod::Nurbs(s) => framed(&|t1, t2, turn| {
                nurbs::transition_within(
                    vertex, t1, t2, turn, tolerance, available, s, index, budget,
                )
            }),
        }
    }
}

/// A symmetric spline corner whose spacing d scales both its deviation and its reach: d is
/// the smaller of the tolerance's (`tolerance / deviation_per_d`) and the segments'
/// (`available / reach_per_d`), and the transition is built from `curve(d)` (ICR and CCR).
///
/// # Arguments
/// * `deviation_per_d` — the exact deviation from the polyline per unit of d.
/// * `reach_per_d` — the distance from the vertex to the curve's ends per unit of d.
///
/// # Errors
/// The curve's own ([`CubicSpline::new`]).
pub(crate) fn scaled_transition(
    v: [f64; 3],
    turn: f64,
    tolerance: f64,
    available: f64,
    deviation_per_d: f64,
    reach_per_d: f64,
    curve: impl Fn(f64) -> Result<CubicSpline, ToolpathError>,
) -> Result<CornerTransition, ToolpathError> {
    let by_tolerance = tolerance / deviation_per_d;
    let by_length = available / reach_per_d;
    let (d, binding) = if by_tolerance <= by_length {
        (by_tolerance, Binding::Tolerance)
    } else {
        (by_length, Binding::Length)
    };
    let c = CornerCurve::Spline(curve(d)?);
    Ok(CornerTransition {
        curve: c,
        vertex: v,
        turn,
        shape: None,
        scale: d,
        tangent_length: reach_per_d * d,
        deviation: deviation_per_d * d,
        max_curvature: c.max_curvature_on(0.0, 0.5, CURVATURE_SAMPLES),
        binding,
    })
}
