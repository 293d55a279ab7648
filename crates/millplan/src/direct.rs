//! |μ|max evaluated directly with the chatter model ([`direct_indicator`]),
//! and which cell-model errors mean an infeasible state
//! ([`is_infeasible`]).

use kerf_chatter::indicator::chatter_indicator;
use kerf_mill::{MillCell, MillError};

use crate::error::MillPlanError;

/// Whether a cell-model error means "this (segment, g) is not a feasible
/// state" (unreachable, joint limit, singular) rather than a failure.
pub fn is_infeasible(e: &MillError) -> bool {
    matches!(
        e,
        MillError::Unreachable { .. } | MillError::JointLimit { .. } | MillError::Singular { .. }
    )
}

/// |μ|max evaluated directly (no cache): the cell state at (segment, g)
/// with IK nearest `reference` (the cell's reference joints for `None`),
/// then `chatter_indicator` with the cell's process and settings.
///
/// # Returns
/// `Ok(None)` when the cell state is infeasible ([`is_infeasible`]).
///
/// # Errors
/// Other cell-model errors, and every chatter-model error (NaN, non
/// convergence) as [`MillPlanError::Chatter`].
pub fn direct_indicator(
    cell: &MillCell,
    segment: usize,
    rpm: f64,
    feed: f64,
    g: f64,
    reference: Option<&[f64; 6]>,
) -> Result<Option<f64>, MillPlanError> {
    let state = match cell.evaluate(segment, g, reference) {
        Ok(s) => s,
        Err(e) if is_infeasible(&e) => return Ok(None),
        Err(e) => return Err(e.into()),
    };
    let ind = chatter_indicator(
        &state.modal,
        &cell.milling_process(),
        rpm,
        feed,
        cell.indicator_settings(),
    )?;
    Ok(Some(ind.spectral_radius))
}
