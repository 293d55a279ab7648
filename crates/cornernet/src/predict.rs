//! The `drls_net` corner: predict the swarm's variables with FDLS, build
//! the NURBS corner from them (`kerf_toolpath::baseline::nurbs::transition_at`), verify it, and
//! fall back to the swarm itself when the corner lies outside the trained
//! distribution or the verification fails; fallbacks are counted.
//!
//! Verified: the corner is feasible (the weight solved from δ by seed 003
//! eq. 7's last line is within the swarm's `max_weight`), its exact
//! deviation (nurbs.rs, "Deviation (exact)") is ≤ δ, its largest curvature
//! is finite and, when a limit is given, below it (eq. 7's
//! cur_i < cur_i,max).
//!
//! SDLS (seed 003, "the output is the weights … obtained by solving the
//! equations" of eq. 7's last line) is not a network here: in kerf's
//! parametrization that equation has a closed-form solution for w, which
//! is exact where a second network could only add error and break δ.

use kerf_budget::Budget;
use kerf_toolpath::baseline::nurbs;
use kerf_toolpath::{corner_frame, CornerTransition, NurbsSettings};

use crate::corner::{LocalCorner, OUTPUTS};
use crate::error::CornerNetError;
use crate::file::Model;

/// How a corner was made.
#[derive(Debug, Clone, PartialEq)]
pub enum Source {
    /// By the network, verified.
    Network,
    /// By the swarm, and why.
    Fallback(String),
}

/// One corner's result.
#[derive(Debug, Clone, PartialEq)]
pub struct DrlsCorner {
    /// The transition (`None` for a straight corner).
    pub transition: Option<CornerTransition>,
    /// Who made it.
    pub source: Source,
}

/// Corners made so far.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Counts {
    /// By the network.
    pub network: usize,
    /// By the swarm.
    pub fallback: usize,
}

/// The DRLS corner method.
#[derive(Debug, Clone)]
pub struct DrlsNet {
    model: Model,
    swarm: NurbsSettings,
    /// eq. 7's cur_i,max \[1/m\], if any.
    pub curvature_limit: Option<f64>,
    counts: Counts,
}

impl DrlsNet {
    /// The method of a trained model; its fallback swarm is the one that
    /// labelled the data.
    pub fn new(model: Model) -> Self {
        let swarm = model.sidecar.swarm;
        DrlsNet {
            model,
            swarm,
            curvature_limit: None,
            counts: Counts::default(),
        }
    }

    /// The model.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// Corners made so far.
    pub fn counts(&self) -> Counts {
        self.counts
    }

    /// FDLS's (ℓ / A, α, β) for a local corner, clamped to the swarm's box.
    ///
    /// # Performance
    /// One plain-Rust forward pass ([`crate::net::ResMlp::forward`]).
    pub fn variables(&self, corner: &LocalCorner) -> [f64; OUTPUTS] {
        let n = &self.model.sidecar.normalization;
        n.variables(&self.model.net.forward(&n.input(&corner.features())))
    }

    /// The transition at `prev` → `vertex` → `next`, as
    /// `kerf_toolpath::CornerMethod::transition`.
    ///
    /// # Arguments
    /// * `tolerance` — δ \[m\].
    /// * `available` — the longest tangent length allowed on each side \[m\].
    ///
    /// # Errors
    /// [`CornerNetError::Corner`] when the fallback swarm fails (bad
    /// points, a reversal, no feasible corner).
    pub fn transition(
        &mut self,
        prev: [f64; 3],
        vertex: [f64; 3],
        next: [f64; 3],
        tolerance: f64,
        available: f64,
    ) -> Result<DrlsCorner, CornerNetError> {
        self.transition_within(
            prev,
            vertex,
            next,
            tolerance,
            available,
            0,
            &Budget::unlimited(),
        )
    }

    /// [`Self::transition`] as a corner of a polyline under a budget: the fallback swarm
    /// mixes `index` (the vertex's index in its polyline) into its seed and checks `budget`
    /// at every particle's move, as `kerf_toolpath::CornerMethod::transition_within`.
    ///
    /// # Errors
    /// As [`Self::transition`], the swarm's error (its
    /// `kerf_toolpath::ToolpathError::Interrupted` when the budget runs out) carried by
    /// [`CornerNetError::Corner`] with `index`.
    #[allow(clippy::too_many_arguments)] // the corner, its limits, its index, the budget
    pub fn transition_within(
        &mut self,
        prev: [f64; 3],
        vertex: [f64; 3],
        next: [f64; 3],
        tolerance: f64,
        available: f64,
        index: usize,
        budget: &Budget,
    ) -> Result<DrlsCorner, CornerNetError> {
        let reason = match self.attempt(prev, vertex, next, tolerance, available) {
            Ok(t) => {
                self.counts.network += 1;
                return Ok(DrlsCorner {
                    transition: Some(t),
                    source: Source::Network,
                });
            }
            Err(reason) => reason,
        };
        self.counts.fallback += 1;
        let t = kerf_toolpath::CornerMethod::Nurbs(self.swarm)
            .transition_within(prev, vertex, next, tolerance, available, index, budget)
            .map_err(|source| CornerNetError::Corner { index, source })?;
        Ok(DrlsCorner {
            transition: t,
            source: Source::Fallback(reason),
        })
    }

    /// The network's corner, verified, or why not.
    fn attempt(
        &self,
        prev: [f64; 3],
        vertex: [f64; 3],
        next: [f64; 3],
        tolerance: f64,
        available: f64,
    ) -> Result<CornerTransition, String> {
        // The checks and the frame every corner method shares (toolpath's).
        let frame = corner_frame(prev, vertex, next, tolerance, available)
            .map_err(|e| e.to_string())?
            .ok_or_else(|| "a straight corner (no transition)".to_string())?;
        let (t1, t2, turn) = (frame.t1, frame.t2, frame.turn);
        let corner = LocalCorner {
            turn,
            ratio: available / tolerance,
        };
        if let Some(why) = self.model.sidecar.distribution.outside(&corner) {
            return Err(format!("outside the trained distribution: {why}"));
        }
        let x = self.variables(&corner);
        let t = nurbs::transition_at(vertex, t1, t2, turn, tolerance, available, x, &self.swarm)
            .ok_or_else(|| {
                "infeasible prediction: the weight needed exceeds max_weight".to_string()
            })?;
        if t.deviation.is_nan() || t.deviation > tolerance * (1.0 + 1e-9) {
            return Err(format!("deviation {:e} above δ {tolerance:e}", t.deviation));
        }
        if !t.max_curvature.is_finite() {
            return Err("curvature not finite".to_string());
        }
        if let Some(limit) = self.curvature_limit {
            if t.max_curvature > limit {
                return Err(format!(
                    "curvature {:e} above the limit {limit:e}",
                    t.max_curvature
                ));
            }
        }
        Ok(t)
    }
}

/// The swarm's corner for the same arguments (the reference the bench
/// compares with), its seed's index 0 as the fallback's.
///
/// # Errors
/// [`CornerNetError::Corner`] from the swarm.
pub fn swarm_transition(
    swarm: &NurbsSettings,
    prev: [f64; 3],
    vertex: [f64; 3],
    next: [f64; 3],
    tolerance: f64,
    available: f64,
) -> Result<Option<CornerTransition>, CornerNetError> {
    kerf_toolpath::CornerMethod::Nurbs(*swarm)
        .transition(prev, vertex, next, tolerance, available, 0)
        .map_err(|source| CornerNetError::Corner { index: 0, source })
}
