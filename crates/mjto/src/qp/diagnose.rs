//! Diagnosis of an infeasible QP: which constraint family is at fault and,
//! when it is a kinematic family, the largest feasible feedrate.

use crate::error::ConstraintFamily;
use crate::PlanError;

/// Relative precision of the feedrate bisection (0.1 %).
pub(crate) const FEEDRATE_REL_TOL: f64 = 1e-3;

/// Most halvings of the feedrate while looking for a feasible one
/// (2⁻⁶⁰ ≈ 10⁻¹⁸ of the requested feedrate).
const MAX_HALVINGS: usize = 60;

/// The constraint families that a diagnosis had to drop to reach a
/// feasible problem.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Culprit {
    /// The family reported: the first of the candidate set that worked, or
    /// the last one of a cumulative drop (callers may refine it).
    pub family: ConstraintFamily,
    /// Every family dropped.
    pub dropped: Vec<ConstraintFamily>,
}

/// Finds the first candidate set of families whose removal makes the
/// problem feasible. If none does, drops the families of `cumulative`
/// one after the other, in that order, until the problem becomes
/// feasible, and reports the last one dropped with the whole list.
///
/// `feasible_without(dropped)` re-solves the problem without the given
/// families and says whether it is feasible.
///
/// # Returns
/// `None` if the problem stays infeasible with every family of
/// `cumulative` dropped.
///
/// # Errors
/// Whatever `feasible_without` returns.
pub(crate) fn culprit(
    candidates: &[&[ConstraintFamily]],
    cumulative: &[ConstraintFamily],
    feasible_without: &mut dyn FnMut(&[ConstraintFamily]) -> Result<bool, PlanError>,
) -> Result<Option<Culprit>, PlanError> {
    for set in candidates {
        let Some(&family) = set.first() else { continue };
        if feasible_without(set)? {
            return Ok(Some(Culprit {
                family,
                dropped: set.to_vec(),
            }));
        }
    }
    let mut dropped = Vec::with_capacity(cumulative.len());
    for &family in cumulative {
        dropped.push(family);
        if dropped.len() > 1 && feasible_without(&dropped)? {
            return Ok(Some(Culprit { family, dropped }));
        }
    }
    Ok(None)
}

/// The largest feedrate (to [`FEEDRATE_REL_TOL`]) at which the problem is
/// feasible, given that it is infeasible at `f_infeasible`.
///
/// Correctness rests on monotonicity: the velocity, acceleration and jerk
/// bounds of seed 001 eq. 15 (and 40-42) are `L_r·σ^r/f^r`, decreasing in
/// `f`, while the position, boundary (u-units, eq. 45) and RTO constraints
/// do not depend on `f`. So the feasible set at `f₂ > f₁` is a subset of the
/// one at `f₁`: feasibility is monotone non-increasing in `f`, and
/// bisection between a feasible and an infeasible feedrate converges to the
/// threshold. The feedrate is first halved until feasible (such a feedrate
/// exists whenever the problem without the kinematic families is feasible,
/// since its solution has finite derivative coefficients), then bisected.
///
/// # Returns
/// The largest feedrate found feasible (always one that was solved
/// successfully, never the infeasible end), or `None` if no feedrate down
/// to `2⁻⁶⁰·f_infeasible` is feasible.
///
/// # Errors
/// Whatever `feasible_at` returns.
///
/// # Performance
/// About `log₂(1/FEEDRATE_REL_TOL) ≈ 10` solves plus one per halving.
pub(crate) fn max_feasible_feedrate(
    f_infeasible: f64,
    feasible_at: &mut dyn FnMut(f64) -> Result<bool, PlanError>,
) -> Result<Option<f64>, PlanError> {
    let mut hi = f_infeasible;
    let mut lo = None;
    for _ in 0..MAX_HALVINGS {
        let f = 0.5 * hi;
        if feasible_at(f)? {
            lo = Some(f);
            break;
        }
        hi = f;
    }
    let Some(mut lo) = lo else {
        return Ok(None);
    };
    // Each step halves hi − lo, which starts at ≤ lo: 2 + log₂(1/tol) steps.
    while hi - lo > FEEDRATE_REL_TOL * lo {
        let mid = 0.5 * (lo + hi);
        if feasible_at(mid)? {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(Some(lo))
}

#[cfg(test)]
mod tests {
    use super::*;
    use ConstraintFamily::*;

    #[test]
    fn bisection_brackets_the_threshold() {
        let threshold = 0.3137;
        let mut calls = 0;
        let f = max_feasible_feedrate(2.0, &mut |f| {
            calls += 1;
            Ok(f <= threshold)
        })
        .unwrap()
        .unwrap();
        assert!(f <= threshold && f >= threshold / (1.0 + FEEDRATE_REL_TOL));
        assert!(calls < 20, "{calls} calls");
        let none = max_feasible_feedrate(1.0, &mut |_| Ok(false)).unwrap();
        assert_eq!(none, None);
    }

    #[test]
    fn candidate_sets_then_cumulative_drop() {
        let order = [Jerk, Acceleration, Velocity, Position, Rto, Boundary];
        let sets: [&[ConstraintFamily]; 5] = [
            &[Jerk],
            &[Acceleration],
            &[Velocity],
            &[Jerk, Acceleration, Velocity],
            &[Rto],
        ];
        // Feasible as soon as Velocity is dropped.
        let c = culprit(&sets, &order, &mut |d| Ok(d.contains(&Velocity)))
            .unwrap()
            .unwrap();
        assert_eq!((c.family, c.dropped), (Velocity, vec![Velocity]));
        // Needs all three kinematic families dropped (or the RTOs): the
        // kinematic set comes first.
        let c = culprit(&sets, &order, &mut |d| Ok(d.len() == 3 || d.contains(&Rto)))
            .unwrap()
            .unwrap();
        assert_eq!(c.dropped, vec![Jerk, Acceleration, Velocity]);
        // Needs Jerk and Position: only the cumulative drop finds it.
        let c = culprit(&sets, &order, &mut |d| {
            Ok(d.contains(&Jerk) && d.contains(&Position))
        })
        .unwrap()
        .unwrap();
        assert_eq!(c.family, Position);
        assert_eq!(c.dropped, vec![Jerk, Acceleration, Velocity, Position]);
        assert_eq!(culprit(&sets, &order, &mut |_| Ok(false)).unwrap(), None);
    }
}
