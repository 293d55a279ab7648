//! The `drls-net` corner method (issue 30, item 3): seed 003's learned NURBS corner
//! ([`kerf_cornernet::DrlsNet`]) predicts every corner of a run, verifies it (δ, the weight's
//! bound, a finite curvature) and falls back to the swarm of `nurbs` when the corner lies
//! outside the trained distribution or the prediction fails its check; the plan counts the
//! fallbacks ([`crate::GcodePlan::corner_fallbacks`]) and says why the first one fell back.
//!
//! The network is read once per process from the data root ([`NETWORK_FILE`], loaded lazily
//! by the first plan that asks for it: [`committed_network`]), or given by the caller
//! ([`crate::plan::plan_program_with`]).

use std::path::Path;
use std::sync::OnceLock;

use kerf_budget::Budget;
use kerf_cornernet::{CornerNetError, Distribution, DrlsNet, Model, Source};
use kerf_toolpath::corner::MIN_TURN;
use kerf_toolpath::vec3::{dot, norm, scale, sub};
use kerf_toolpath::{smooth_polyline_by, SmoothedPath, ToolpathError};

use crate::error::GcodePlanError;

/// The committed DRLS weights, relative to the data root (their JSON sidecar next to them).
pub const NETWORK_FILE: &str = "crates/cornernet/weights/drls.safetensors";

/// Reads a DRLS network (`path` and its `.json` sidecar) trained for the default corner
/// distribution ([`Distribution::default`]).
///
/// # Errors
/// [`GcodePlanError::InvalidRequest`] naming `method drls-net`, the file and why it was
/// refused (missing, unreadable, another format or distribution).
pub fn load_network(path: &Path) -> Result<Model, GcodePlanError> {
    Model::load(path, &Distribution::default()).map_err(|e| GcodePlanError::InvalidRequest {
        field: "method drls-net".to_string(),
        reason: format!("cannot load the DRLS network {}: {e}", path.display()),
    })
}

/// The committed network ([`NETWORK_FILE`] below the data root), read by the first call of
/// the process; later calls return the same model, or the same error.
///
/// # Errors
/// As [`load_network`].
pub fn committed_network() -> Result<&'static Model, GcodePlanError> {
    static NETWORK: OnceLock<Result<Model, GcodePlanError>> = OnceLock::new();
    NETWORK
        .get_or_init(|| load_network(&kerf_robot::data::default_path(NETWORK_FILE)))
        .as_ref()
        .map_err(Clone::clone)
}

/// The learned corners of one plan: the predictor, its counts and the first fallback's
/// reason.
#[derive(Debug, Clone)]
pub(crate) struct LearnedCorners {
    net: DrlsNet,
    /// The first fallback: the run's first line, the vertex index, why.
    first_fallback: Option<(usize, usize, String)>,
}

impl LearnedCorners {
    /// A predictor of `model` (its fallback swarm the one that labelled its data).
    pub(crate) fn new(model: &Model) -> Self {
        LearnedCorners {
            net: DrlsNet::new(model.clone()),
            first_fallback: None,
        }
    }

    /// Corners predicted and verified, and corners that fell back to the swarm.
    pub(crate) fn counts(&self) -> kerf_cornernet::Counts {
        self.net.counts()
    }

    /// The summary warning of a plan with fallbacks (`None` without).
    pub(crate) fn warning(&self) -> Option<String> {
        let c = self.counts();
        let (line, index, why) = self.first_fallback.as_ref()?;
        Some(format!(
            "drls-net: {} of {} corners fell back to the NURBS swarm (the first in the run from \
             line {line}, point {index}: {why})",
            c.fallback,
            c.fallback + c.network
        ))
    }

    /// Smooths a run's polyline (as `kerf_toolpath::smooth_polyline_within`), every corner
    /// predicted or, failing that, the swarm's; a straight corner (θ below
    /// [`MIN_TURN`]) is no corner and is not counted.
    ///
    /// # Errors
    /// As `kerf_toolpath::smooth_polyline_within` for the NURBS method: the swarm's errors
    /// (a reversal, no feasible corner, the budget).
    pub(crate) fn smooth(
        &mut self,
        polyline: &[[f64; 3]],
        tolerance: f64,
        line: usize,
        budget: &Budget,
    ) -> Result<SmoothedPath, ToolpathError> {
        smooth_polyline_by(
            polyline,
            tolerance,
            budget,
            |prev, vertex, next, tolerance, available, index| {
                if straight(prev, vertex, next) {
                    return Ok(None);
                }
                let corner = self
                    .net
                    .transition_within(prev, vertex, next, tolerance, available, index, budget)
                    .map_err(|e| match e {
                        CornerNetError::Corner { source, .. } => source,
                        other => ToolpathError::InvalidParameter {
                            name: "drls-net corner".to_string(),
                            value: f64::NAN,
                            reason: other.to_string(),
                        },
                    })?;
                if let (Source::Fallback(why), None) = (&corner.source, &self.first_fallback) {
                    self.first_fallback = Some((line, index, why.clone()));
                }
                Ok(corner.transition)
            },
        )
    }
}

/// Whether the corner `prev` → `vertex` → `next` turns by less than [`MIN_TURN`] (every
/// method's straight corner); coincident points are not straight (the smoothing refuses them
/// before).
fn straight(prev: [f64; 3], vertex: [f64; 3], next: [f64; 3]) -> bool {
    let (d1, d2) = (sub(vertex, prev), sub(next, vertex));
    let (l1, l2) = (norm(d1), norm(d2));
    if !(l1 > 0.0 && l2 > 0.0) {
        return false;
    }
    let turn = dot(scale(d1, 1.0 / l1), scale(d2, 1.0 / l2))
        .clamp(-1.0, 1.0)
        .acos();
    turn < MIN_TURN
}
