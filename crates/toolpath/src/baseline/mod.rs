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

use crate::corner::{corner_frame, corner_transition, CornerTransition};
use crate::error::ToolpathError;

/// Curvature samples on the half curve for a baseline's largest curvature
/// (then refined), as kerf's corner ([`crate::corner::CURVATURE_SAMPLES`]).
pub const CURVATURE_SAMPLES: usize = 64;

/// How a corner is smoothed.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum CornerMethod {
    /// kerf's curvature-optimal symmetric quintic ([`crate::corner`]).
    #[default]
    Kerf,
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
            CornerMethod::Icr => {
                framed(&|t1, t2, turn| icr::transition(vertex, t1, t2, turn, tolerance, available))
            }
            CornerMethod::Ccr => {
                framed(&|t1, t2, turn| ccr::transition(vertex, t1, t2, turn, tolerance, available))
            }
            CornerMethod::Nurbs(s) => framed(&|t1, t2, turn| {
                nurbs::transition(vertex, t1, t2, turn, tolerance, available, s, index)
            }),
        }
    }
}
